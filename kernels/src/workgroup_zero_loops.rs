//! WGSL's zeroed workgroup memory written into naga's IR as loops over the invocations,
//! for a writer whose own zeroing is one store or constructor per array. Used by
//! `translate` for every language where the shader zeroes its own memory
//! (`WorkgroupZeroInit::Polyfill`: the kernel package, the embed pass on a device without
//! the driver's zeroing, the check's glslang and Slang paths; naga's SPIR-V polyfill made
//! lavapipe compile a block-histogram kernel in 25-30 s) and by the wgpu backend on GL.
//!
//! naga's GLSL writer zeroes workgroup memory with one statement per variable, an array
//! being one constructor with an argument per element (`uint[1024](0u, 0u, ...)`). wgpu
//! writes its GL shaders itself, so the text cannot be rewritten as it is for ash-glsl
//! ([`crate::glsl_zero_init`]), and Mesa's GLSL compiler and LLVM spent about a minute
//! per block-histogram kernel on those constructors (most of a first `cargo xtask check`
//! on the wgpu-gl path, BENCHMARKS.md). [`zero_in_loops`] puts at the start of the entry
//! point, for each workgroup variable it uses, a loop storing zero to the variable's
//! elements (arrays of arrays flattened), the invocations sharing them by their local
//! index, then a workgroup barrier; the pipeline is then created with the writer's own
//! zeroing off. Variables of override-sized arrays, structs holding atomics, or an entry
//! point whose workgroup size is an override are left to the writer (`None`).

use crate::ir_edit::revalidate;
use naga::{
    ArraySize, Barrier, BinaryOperator, Binding, Block, BuiltIn, Expression, Function, FunctionArgument, Handle,
    Literal, LocalVariable, Module, Scalar, Span, Statement, Type, TypeInner,
};

/// `module` with the workgroup variables entry point `entry` uses zeroed by loops at its
/// start (module documentation), validated; `None` where the writer's zeroing must stay
/// (nothing to zero, an override-sized array or workgroup size, a struct with an atomic).
pub fn zero_in_loops(
    module: &Module,
    info: &naga::valid::ModuleInfo,
    entry: &str,
) -> Result<Option<(Module, naga::valid::ModuleInfo)>, String> {
    let Some(index) = module.entry_points.iter().position(|e| e.name == entry) else {
        return Err(format!("no entry point `{entry}`"));
    };
    let point = &module.entry_points[index];
    if point.workgroup_size_overrides.is_some() {
        return Ok(None);
    }
    let used = info.get_entry_point(index);
    let globals: Vec<_> = module
        .global_variables
        .iter()
        .filter(|(h, v)| v.space == naga::AddressSpace::WorkGroup && !used[*h].is_empty())
        .map(|(h, v)| (h, v.ty))
        .collect();
    if globals.is_empty() {
        return Ok(None);
    }
    let mut module = module.clone();
    // Each variable's array sizes (outermost first) and element type.
    let mut shapes = Vec::new();
    for &(global, ty) in &globals {
        let (mut dims, mut element) = (Vec::new(), ty);
        while let TypeInner::Array { base, size, .. } = module.types[element].inner {
            match size {
                ArraySize::Constant(n) => dims.push(n.get()),
                _ => return Ok(None),
            }
            element = base;
        }
        // The value stored: zero of the element, or of an atomic's scalar (naga's IR
        // stores a scalar to an atomic). A type holding an atomic deeper has no zero value.
        let value_ty = match module.types[element].inner {
            TypeInner::Atomic(scalar) => scalar_type(&mut module, scalar),
            _ if holds_atomic(&module, element) => return Ok(None),
            _ => element,
        };
        shapes.push((global, dims, value_ty));
    }
    let invocations: u32 = point.workgroup_size.iter().product();
    let u32_ty = scalar_type(&mut module, Scalar::U32);
    let function = &mut module.entry_points[index].function;
    let mut prologue = Block::new();
    let local_index = local_invocation_index(&module.types, function, u32_ty, &mut prologue);
    for (global, dims, value_ty) in shapes {
        zero_loop(function, &mut prologue, local_index, u32_ty, (global, &dims, value_ty), invocations);
    }
    prologue.push(Statement::ControlBarrier(Barrier::WORK_GROUP), Span::UNDEFINED);
    let body = std::mem::take(&mut function.body);
    prologue.extend_block(body);
    function.body = prologue;
    let info = revalidate(&module, "zeroing workgroup memory in loops")?;
    Ok(Some((module, info)))
}

/// The handle of the type `scalar`, added if the module has none.
fn scalar_type(module: &mut Module, scalar: Scalar) -> Handle<Type> {
    module.types.insert(Type { name: None, inner: TypeInner::Scalar(scalar) }, Span::UNDEFINED)
}

/// Whether `ty` holds an atomic anywhere (a struct member, an array's element).
fn holds_atomic(module: &Module, ty: Handle<Type>) -> bool {
    match module.types[ty].inner {
        TypeInner::Atomic(_) => true,
        TypeInner::Array { base, .. } | TypeInner::BindingArray { base, .. } => holds_atomic(module, base),
        TypeInner::Struct { ref members, .. } => members.iter().any(|m| holds_atomic(module, m.ty)),
        _ => false,
    }
}

/// An expression of the entry point's local invocation index: its argument, a member
/// of a struct argument (emitted in `prologue`), or a new argument.
fn local_invocation_index(
    types: &naga::UniqueArena<Type>,
    function: &mut Function,
    u32_ty: Handle<Type>,
    prologue: &mut Block,
) -> Handle<Expression> {
    let builtin = Some(Binding::BuiltIn(BuiltIn::LocalInvocationIndex));
    if let Some(at) = function.arguments.iter().position(|a| a.binding == builtin) {
        return function.expressions.append(Expression::FunctionArgument(at as u32), Span::UNDEFINED);
    }
    for (at, argument) in function.arguments.iter().enumerate() {
        let TypeInner::Struct { ref members, .. } = types[argument.ty].inner else { continue };
        if let Some(member) = members.iter().position(|m| m.binding == builtin) {
            let exprs = &mut function.expressions;
            let base = exprs.append(Expression::FunctionArgument(at as u32), Span::UNDEFINED);
            let start = exprs.len();
            let value = exprs.append(Expression::AccessIndex { base, index: member as u32 }, Span::UNDEFINED);
            prologue.push(Statement::Emit(exprs.range_from(start)), Span::UNDEFINED);
            return value;
        }
    }
    function.arguments.push(FunctionArgument { name: Some("_zi_index".into()), ty: u32_ty, binding: builtin });
    function.expressions.append(Expression::FunctionArgument(function.arguments.len() as u32 - 1), Span::UNDEFINED)
}

/// Appends to `prologue`: `i = index; loop { if i >= total { break; } VAR[i / ...][i % ...] = 0; i += invocations; }`.
fn zero_loop(
    function: &mut Function,
    prologue: &mut Block,
    index: Handle<Expression>,
    u32_ty: Handle<Type>,
    (global, dims, value_ty): (Handle<naga::GlobalVariable>, &[u32], Handle<Type>),
    invocations: u32,
) {
    let total: u32 = dims.iter().product();
    let variable = function
        .local_variables
        .append(LocalVariable { name: Some("_zi".into()), ty: u32_ty, init: None }, Span::UNDEFINED);
    let exprs = &mut function.expressions;
    let mut pre = |e: Expression| exprs.append(e, Span::UNDEFINED);
    let counter = pre(Expression::LocalVariable(variable));
    let total_value = pre(Expression::Literal(Literal::U32(total)));
    let step = pre(Expression::Literal(Literal::U32(invocations)));
    let base = pre(Expression::GlobalVariable(global));
    let zero = pre(Expression::ZeroValue(value_ty));
    // Strides of the flattened index: dims [a, b, c] -> [b*c, c, 1].
    let strides: Vec<u32> = (0..dims.len()).map(|d| dims[d + 1..].iter().product()).collect();
    let stride_values: Vec<(Handle<Expression>, Handle<Expression>)> = strides
        .iter()
        .zip(dims)
        .map(|(&s, &d)| (pre(Expression::Literal(Literal::U32(s))), pre(Expression::Literal(Literal::U32(d)))))
        .collect();
    let exprs = &mut function.expressions;
    prologue.push(Statement::Store { pointer: counter, value: index }, Span::UNDEFINED);
    // Body: the test, then the element's pointer and the store.
    let mut body = Block::new();
    let start = exprs.len();
    let current = exprs.append(Expression::Load { pointer: counter }, Span::UNDEFINED);
    let done = exprs.append(
        Expression::Binary { op: BinaryOperator::GreaterEqual, left: current, right: total_value },
        Span::UNDEFINED,
    );
    body.push(Statement::Emit(exprs.range_from(start)), Span::UNDEFINED);
    let mut accept = Block::new();
    accept.push(Statement::Break, Span::UNDEFINED);
    body.push(Statement::If { condition: done, accept, reject: Block::new() }, Span::UNDEFINED);
    let start = exprs.len();
    let mut pointer = base;
    for &(stride, dim) in &stride_values {
        let quotient = exprs
            .append(Expression::Binary { op: BinaryOperator::Divide, left: current, right: stride }, Span::UNDEFINED);
        let position = exprs
            .append(Expression::Binary { op: BinaryOperator::Modulo, left: quotient, right: dim }, Span::UNDEFINED);
        pointer = exprs.append(Expression::Access { base: pointer, index: position }, Span::UNDEFINED);
    }
    if exprs.len() > start {
        body.push(Statement::Emit(exprs.range_from(start)), Span::UNDEFINED);
    }
    body.push(Statement::Store { pointer, value: zero }, Span::UNDEFINED);
    // Continuing: i += invocations.
    let mut continuing = Block::new();
    let start = exprs.len();
    let again = exprs.append(Expression::Load { pointer: counter }, Span::UNDEFINED);
    let next = exprs.append(Expression::Binary { op: BinaryOperator::Add, left: again, right: step }, Span::UNDEFINED);
    continuing.push(Statement::Emit(exprs.range_from(start)), Span::UNDEFINED);
    continuing.push(Statement::Store { pointer: counter, value: next }, Span::UNDEFINED);
    prologue.push(Statement::Loop { body, continuing, break_if: None }, Span::UNDEFINED);
}

#[cfg(test)]
mod tests {
    use super::zero_in_loops;
    use crate::registry::Kernel;

    #[test]
    fn workgroup_arrays_are_zeroed_in_loops_and_the_module_validates() {
        let source = "var<workgroup> counter: atomic<u32>;
            var<workgroup> grid: array<array<vec3<f32>, 128>, 4>;
            var<workgroup> flags: array<atomic<u32>, 64>;
            @group(0) @binding(0) var<storage, read_write> o: array<u32>;
            @compute @workgroup_size(64) fn main(@builtin(local_invocation_id) id: vec3<u32>) {
                atomicAdd(&counter, 1u);
                atomicAdd(&flags[id.x], 1u);
                workgroupBarrier();
                o[id.x] = atomicLoad(&counter) + u32(grid[id.x % 4u][id.x].x) + atomicLoad(&flags[id.x]);
            }";
        let kernel = Kernel::from_wgsl("zeroing.wgsl", source.into(), "main", false).unwrap();
        let (module, _) = zero_in_loops(&kernel.module, &kernel.info, "main").unwrap().expect("rewritten");
        let function = &module.entry_points[0].function;
        assert_eq!(function.arguments.len(), 2, "a local index argument added");
        let loops = function.body.iter().filter(|s| matches!(s, naga::Statement::Loop { .. })).count();
        assert_eq!(loops, 3);
        let options = naga::back::glsl::Options {
            version: naga::back::glsl::Version::Desktop(450),
            zero_initialize_workgroup_memory: false,
            ..Default::default()
        };
        let info = crate::ir_edit::revalidate(&module, "test").unwrap();
        let pipeline = naga::back::glsl::PipelineOptions {
            shader_stage: naga::ShaderStage::Compute,
            entry_point: "main".into(),
            multiview: None,
        };
        let mut text = String::new();
        let mut writer = naga::back::glsl::Writer::new(
            &mut text,
            &module,
            &info,
            &options,
            &pipeline,
            naga::proc::BoundsCheckPolicies::default(),
        )
        .unwrap();
        writer.write().unwrap();
        assert!(!text.contains("vec3[128](vec3(0.0)"), "a zeroing constructor:\n{text}");
    }
}
