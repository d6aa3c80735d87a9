//! Loads of the words a value's uses read: a struct loaded through a pointer whose every
//! use takes one of its fields (with a constant index), or passes it to a function that
//! only takes fields of that argument, loads those fields' words alone.
//!
//! Why: the path tracer's BVH loop loads three 12-word nodes per step (`nodes[i]` for its
//! count and first index, then each child for `enter_box`, which reads its two corners):
//! 36 words through a pointer, member by member, where 14 are read.
//!
//! Sound because a word left unloaded is never read:
//! - a field of a struct value is the value's own registers at the field's offset
//!   ([`super::compiler`]), so a use taking a field reads that field's words alone, and the
//!   field's register layout is its memory layout (structs holding f16 are left whole);
//! - the uses counted must add up to naga's reference count of the load, so a use of any
//!   other kind (a store of the whole value, a return, a compose, ...) keeps the full
//!   load;
//! - a callee's argument counts as read field by field only where every reference to it
//!   (naga's counts again, over each `FunctionArgument` expression) takes a field; an
//!   inlined callee reads the caller's registers, a called one copies them all (copying
//!   words nobody reads);
//! - the words that are loaded are loaded as the whole load would (a word outside the
//!   buffer reads 0 either way; [`super::execute`]).

use super::insn::Runs;
use super::layout::{member_step, own_register_layout, words_of};
use super::load_alias::nested;
use naga::valid::{FunctionInfo, ModuleInfo};
use naga::{Block, Expression, Function, Handle, Module, Statement, TypeInner};

/// Per expression of `function` (validated: `info`, the module's: `module_info`): for a
/// load of a struct whose uses read only some of its words, those words.
pub(super) fn partial_loads(
    module: &Module,
    module_info: &ModuleInfo,
    function: &Function,
    info: &FunctionInfo,
) -> Vec<Option<Runs>> {
    let count = function.expressions.len();
    // Per candidate load: its words read (one flag each) and the uses counted.
    let mut read: Vec<Option<Vec<bool>>> = vec![None; count];
    let mut found = vec![0usize; count];
    for (handle, expression) in function.expressions.iter() {
        if let Expression::Load { .. } = *expression
            && let Some(words) = struct_words(module, info[handle].ty.inner_with(&module.types))
        {
            read[handle.index()] = Some(vec![false; words as usize]);
        }
    }
    for (_, expression) in function.expressions.iter() {
        if let Expression::AccessIndex { base, index } = *expression
            && let Some(words) = read[base.index()].as_mut()
        {
            let inner = info[base].ty.inner_with(&module.types);
            mark_field(module, inner, index, words);
            found[base.index()] += 1;
        }
    }
    calls(&function.body, &mut |callee, arguments| {
        for (at, argument) in arguments.iter().enumerate() {
            let Some(words) = read[argument.index()].as_mut() else { continue };
            found[argument.index()] += 1;
            match argument_fields(module, module_info, callee, at as u32) {
                Some(callee_words) => words.iter_mut().zip(callee_words).for_each(|(w, c)| *w |= c),
                None => words.fill(true),
            }
        }
    });
    function
        .expressions
        .iter()
        .zip(read)
        .map(|((handle, _), words)| {
            let words = words?;
            let all_uses = found[handle.index()] == info[handle].ref_count;
            (all_uses && words.iter().any(|w| !w)).then(|| runs(&words))
        })
        .collect()
}

/// Words of a struct type the analysis may split (no f16 or bool: register and memory
/// layouts agree), `None` for other types.
fn struct_words(module: &Module, inner: &TypeInner) -> Option<u32> {
    match inner {
        TypeInner::Struct { .. } if !own_register_layout(module, inner) => words_of(module, inner).ok(),
        _ => None,
    }
}

/// Marks the words of field `index` of struct `inner` in `words`.
fn mark_field(module: &Module, inner: &TypeInner, index: u32, words: &mut [bool]) {
    let TypeInner::Struct { ref members, .. } = *inner else { return words.fill(true) };
    let Some(member) = members.get(index as usize) else { return words.fill(true) };
    let first = member_step(module, inner, index, false) as usize;
    let len = words_of(module, &module.types[member.ty].inner).map_or(words.len(), |n| n as usize);
    match words.get_mut(first..first + len) {
        Some(field) => field.fill(true),
        None => words.fill(true),
    }
}

/// Calls `visit` with the callee and arguments of every call statement in `block`.
fn calls(block: &Block, visit: &mut impl FnMut(Handle<Function>, &[Handle<Expression>])) {
    for statement in block.iter() {
        if let Statement::Call { function, arguments, .. } = statement {
            visit(*function, arguments);
        }
        nested(statement, |inner| calls(inner, visit));
    }
}

/// The words of argument `at` of `callee` that it reads, where it only takes fields of
/// it (every reference to the argument a field access); `None` where it may read all.
fn argument_fields(module: &Module, module_info: &ModuleInfo, callee: Handle<Function>, at: u32) -> Option<Vec<bool>> {
    let function = &module.functions[callee];
    let info = &module_info[callee];
    let argument = function.arguments.get(at as usize)?;
    let inner = &module.types[argument.ty].inner;
    let mut words = vec![false; struct_words(module, inner)? as usize];
    let is_argument =
        |h: Handle<Expression>| matches!(function.expressions[h], Expression::FunctionArgument(i) if i == at);
    let mut references = 0;
    let mut fields = 0;
    for (handle, expression) in function.expressions.iter() {
        if is_argument(handle) {
            references += info[handle].ref_count;
        } else if let Expression::AccessIndex { base, index } = *expression
            && is_argument(base)
        {
            mark_field(module, inner, index, &mut words);
            fields += 1;
        }
    }
    (fields == references).then_some(words)
}

/// The runs of set flags in `words`.
fn runs(words: &[bool]) -> Runs {
    let mut runs = Vec::new();
    let mut at = 0;
    while at < words.len() {
        if words[at] {
            let len = words[at..].iter().take_while(|&&w| w).count();
            runs.push((at as u32, len as u32));
            at += len;
        } else {
            at += 1;
        }
    }
    runs.into_boxed_slice()
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
    use super::super::insn::Insn;
    use super::runs;

    #[test]
    fn runs_are_the_stretches_of_words_read() {
        assert_eq!(&*runs(&[true, true, false, false, true, false, true]), &[(0, 2), (4, 1), (6, 1)]);
        assert!(runs(&[false, false]).is_empty());
    }

    /// The loads through a pointer register of `body` (with `Node`, an array of them
    /// bound as `nodes` and a helper taking one), as (words, runs loaded).
    fn loads(body: &str) -> Vec<(u32, Vec<(u32, u32)>)> {
        let source = format!(
            "{body} }}
            struct Node {{ lo: vec3<f32>, pad0: u32, hi: vec3<f32>, pad1: u32, count: u32, first: u32, a: u32, b: u32 }}
            @group(0) @binding(1) var<storage, read> nodes: array<Node>;
            fn corners(n: Node) -> f32 {{ return n.lo.x + n.hi.y; }}
            fn whole(n: Node) -> Node {{ return n; }}
            fn unused() {{"
        );
        compiled(&source)
            .iter()
            .filter_map(|insn| match insn {
                // (The prelude's one-word load of `data` left out.)
                Insn::Load { len, .. } if *len > 1 => Some((*len, vec![(0, *len)])),
                Insn::LoadRuns { len, runs, .. } => Some((*len, runs.to_vec())),
                // The same loads of a buffer element, fused with their pointer.
                Insn::LoadElement(load) => match &load.runs {
                    Some(runs) => Some((load.len, runs.to_vec())),
                    None if load.len > 1 => Some((load.len, vec![(0, load.len)])),
                    None => None,
                },
                _ => None,
            })
            .collect()
    }

    #[test]
    fn a_struct_loads_only_the_fields_its_uses_read() {
        // Two fields: their words alone.
        assert_eq!(loads("let n = nodes[id.x]; data[id.x] = n.count + n.first;"), vec![(12, vec![(8, 2)])]);
        // A callee reading two fields of its argument (inlined here; a called one copies
        // every word of the argument and reads the same two).
        assert_eq!(
            loads("data[id.x] = u32(corners(nodes[id.x]));"),
            vec![(12, vec![(0, 3), (4, 3)])],
            "corners reads lo.x and hi.y: the fields lo (words 0-2) and hi (4-6)"
        );
        // Whole uses load every word: a callee returning its argument, a store of the value.
        assert_eq!(loads("data[id.x] = whole(nodes[id.x]).count;"), vec![(12, vec![(0, 12)])]);
        assert_eq!(loads("var m = nodes[id.x]; m.count += 1u; data[id.x] = m.count;"), vec![(12, vec![(0, 12)])]);
    }
}
