//! Editing naga IR in place, for the rewrites that make naga's output defined on a back
//! end ([`crate::integer_division`], [`crate::signed_image_levels`]): visiting every
//! block of a function, and putting statements where an expression was emitted.

use naga::{Block, Expression, Function, Handle, Span, Statement};

/// Calls `f` on `block` and every block nested in it.
pub(crate) fn visit_blocks(block: &mut Block, f: &mut impl FnMut(&mut Block)) {
    f(block);
    for statement in block.iter_mut() {
        match statement {
            Statement::Block(inner) => visit_blocks(inner, f),
            Statement::If { accept, reject, .. } => {
                visit_blocks(accept, f);
                visit_blocks(reject, f);
            }
            Statement::Switch { cases, .. } => cases.iter_mut().for_each(|case| visit_blocks(&mut case.body, f)),
            Statement::Loop { body, continuing, .. } => {
                visit_blocks(body, f);
                visit_blocks(continuing, f);
            }
            _ => {}
        }
    }
}

/// Splits the `Emit` that covers `handle` around it and puts `statements` there: in its
/// place (`emit_handle` false: they now produce it, as a call does) or before it
/// (`emit_handle` true: it is still emitted, after them).
pub(crate) fn replace_emit(body: &mut Block, handle: Handle<Expression>, statements: &[Statement], emit_handle: bool) {
    visit_blocks(body, &mut |block| {
        let Some(position) = block.iter().position(|s| match s {
            Statement::Emit(range) => range.index_range().contains(&(handle.index() as u32)),
            _ => false,
        }) else {
            return;
        };
        let range = match &block[position] {
            Statement::Emit(range) => range.clone(),
            _ => unreachable!("found as an Emit"),
        };
        let indices = range.index_range();
        let at = handle.index() as u32;
        let mut replacement = Block::new();
        let emit = |from: u32, to: u32| {
            // Rebuild a range over [from, to) from the original one's handles.
            let all: Vec<Handle<Expression>> = range.clone().collect();
            let pick: Vec<Handle<Expression>> =
                all.into_iter().filter(|h| (from..to).contains(&(h.index() as u32))).collect();
            pick.first().map(|first| Statement::Emit(naga::Range::new_from_bounds(*first, *pick.last().unwrap())))
        };
        if let Some(before) = emit(indices.start, at) {
            replacement.push(before, Span::UNDEFINED);
        }
        for statement in statements {
            replacement.push(statement.clone(), Span::UNDEFINED);
        }
        let rest = if emit_handle { at } else { at + 1 };
        if let Some(after) = emit(rest, indices.end) {
            replacement.push(after, Span::UNDEFINED);
        }
        block.splice(position..position + 1, replacement);
    });
}

/// Puts `helpers` before every function of `module` (naga requires callees before their
/// callers) and points every call at its callee's new handle. Returns the helpers'
/// handles and, per old function handle's index, its new handle.
pub(crate) fn prepend_functions(
    module: &mut naga::Module,
    helpers: Vec<Function>,
) -> (Vec<Handle<Function>>, Vec<Handle<Function>>) {
    let old = std::mem::take(&mut module.functions);
    let count = helpers.len();
    let helper_handles: Vec<Handle<Function>> =
        helpers.into_iter().map(|function| module.functions.append(function, Span::UNDEFINED)).collect();
    let moved: Vec<Handle<Function>> =
        old.iter().map(|(handle, function)| module.functions.append(function.clone(), old.get_span(handle))).collect();
    let remap = |handle: Handle<Function>| moved[handle.index()];
    for (_, function) in module.functions.iter_mut().skip(count) {
        remap_calls(function, &remap);
    }
    for entry in &mut module.entry_points {
        remap_calls(&mut entry.function, &remap);
    }
    (helper_handles, moved)
}

/// Points every call at the moved callee.
fn remap_calls(function: &mut Function, remap: &impl Fn(Handle<Function>) -> Handle<Function>) {
    for (_, expression) in function.expressions.iter_mut() {
        if let Expression::CallResult(callee) = expression {
            *callee = remap(*callee);
        }
    }
    visit_blocks(&mut function.body, &mut |block| {
        for statement in block.iter_mut() {
            if let Statement::Call { function, .. } = statement {
                *function = remap(*function);
            }
        }
    });
}

/// Calls `f` on every function of `module` with its validation info: each of
/// `module.functions` (with its handle), then each entry point's (`None` and its index).
pub(crate) fn visit_functions(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    f: &mut impl FnMut(&Function, &naga::valid::FunctionInfo, Option<Handle<Function>>, usize),
) {
    for (handle, function) in module.functions.iter() {
        f(function, &info[handle], Some(handle), 0);
    }
    for (index, entry) in module.entry_points.iter().enumerate() {
        f(&entry.function, info.get_entry_point(index), None, index);
    }
}

/// Validates a module a rewrite of this crate produced (every capability: the rewrites
/// keep what the source used), for the writer it is handed to; an error names `what`
/// made it invalid, a bug of that rewrite.
pub(crate) fn revalidate(module: &naga::Module, what: &str) -> Result<naga::valid::ModuleInfo, String> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .subgroup_stages(naga::valid::ShaderStages::COMPUTE)
        .subgroup_operations(naga::valid::SubgroupOperationSet::all())
        .validate(module)
        .map_err(|e| format!("{what} made an invalid module: {e:?}"))
}
