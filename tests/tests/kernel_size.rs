//! The size of each registry kernel as a driver compiles it: every function call inlined
//! at its call site (what Mesa's NIR, and so lavapipe, does before LLVM sees the kernel).
//! A heavy function (the BVH traversal, the path loop, next-event estimation) called from
//! two places of a kernel is compiled twice; before 2026-11-27 `restir_candidates` held
//! 61k naga expressions that way (seven path loops, sixteen traversals) and lavapipe took
//! minutes to compile the ReSTIR kernels on a fresh machine (BENCHMARKS "First run on a
//! fresh machine"). The budgets below are today's sizes with a little room: a change that
//! calls one of the heavy functions from one more place (a path loop is 3.5k expressions)
//! fails here and should choose its arguments in branches and make one call instead.

use std::collections::HashMap;

use naga::{Block, Function, Handle, Module, Statement};
use strata_kernels::Registry;

/// Most expressions a kernel may hold once its calls are inlined; kernels not named here
/// get `DEFAULT_BUDGET`.
///
/// Raised on 2026-11-29 (candidates 15.7k → 20.5k, the selection, temporal and spatial
/// passes 11.8k → 14.4k) when the scene moved into one buffer of rows and sine and cosine
/// into WGSL (`render/turns.wgsl`): a record read through its generated reader is a few
/// expressions per field (a row load, a swizzle, a bitcast) where an array read was one,
/// with no heavy function called from one more place; the main command on a fresh Mesa cache took 77 s
/// after against 79-80 s before (docs/benchmarks/first-run.md).
///
/// Raised again on 2026-11-30 (candidates 20.5k → 22.7k, the three reuse passes 14.4k →
/// 15.7k, the path tracer 4.9k → 5.4k) when every row of the scene came through
/// `scene_row` (`render/scene.wgsl`), which reads the storage buffer or its uniform copy
/// as the `scene_in_uniform` override says: both reads stay in the general module that
/// this test counts, and a specialised pipeline keeps one (the driver drops the other).
const BUDGETS: &[(&str, usize)] = &[
    ("restir_candidates", 24_000),
    ("restir_select", 16_500),
    ("restir_spatial", 16_500),
    ("restir_temporal", 16_500),
];

/// The budget of every other kernel: the block histograms (9k) are the largest.
const DEFAULT_BUDGET: usize = 10_000;

/// Functions each call statement of `block` calls, nested blocks included.
fn called(block: &Block, out: &mut Vec<Handle<Function>>) {
    for statement in block.iter() {
        match statement {
            Statement::Call { function, .. } => out.push(*function),
            Statement::Block(inner) => called(inner, out),
            Statement::If { accept, reject, .. } => {
                called(accept, out);
                called(reject, out);
            }
            Statement::Loop { body, continuing, .. } => {
                called(body, out);
                called(continuing, out);
            }
            Statement::Switch { cases, .. } => cases.iter().for_each(|case| called(&case.body, out)),
            _ => {}
        }
    }
}

/// Expressions of `function` with every call inlined, and how many copies of each named
/// function that makes (added to `copies`). WGSL has no recursion, so this ends.
fn inlined_size(module: &Module, function: &Function, copies: &mut HashMap<String, usize>) -> usize {
    let mut callees = Vec::new();
    called(&function.body, &mut callees);
    let mut size = function.expressions.len();
    for callee in callees {
        let callee = &module.functions[callee];
        *copies.entry(callee.name.clone().unwrap_or_default()).or_default() += 1;
        size += inlined_size(module, callee, copies);
    }
    size
}

/// The copies of the heaviest functions, for the failure message.
fn heavy_copies(copies: &HashMap<String, usize>) -> String {
    let mut heavy: Vec<String> = ["path_from", "traverse", "direct_light", "bsdf_sample", "bsdf_eval"]
        .iter()
        .filter_map(|name| copies.get(*name).map(|count| format!("{name} x{count}")))
        .collect();
    if heavy.is_empty() {
        heavy.push("none of the path tracer's functions".into());
    }
    heavy.join(", ")
}

#[test]
fn every_kernel_inlines_within_its_budget() {
    let registry = Registry::load().expect("the registry's kernels load");
    let mut over = Vec::new();
    for kernel in registry.kernels() {
        let entry = &kernel.module.entry_points[kernel.entry_index()];
        let mut copies = HashMap::new();
        let size = inlined_size(&kernel.module, &entry.function, &mut copies);
        let budget = BUDGETS.iter().find(|(name, _)| *name == kernel.name()).map_or(DEFAULT_BUDGET, |b| b.1);
        // Shown with --nocapture: the sizes to set a budget from.
        println!("{:24} {size:>6} of {budget:>6} ({})", kernel.name(), heavy_copies(&copies));
        if size > budget {
            over.push(format!(
                "{}: {size} expressions inlined, budget {budget} ({})",
                kernel.name(),
                heavy_copies(&copies)
            ));
        }
    }
    assert!(over.is_empty(), "kernels over their inlined size:\n{}", over.join("\n"));
}

/// The counting itself: a kernel calling the path loop through two call sites holds two
/// copies of it, and the size adds up both.
#[test]
fn inlined_size_counts_each_call_site() {
    let source = r"
        fn leaf(x: f32) -> f32 { return x * 2.0 + 1.0; }
        fn twice(x: f32) -> f32 { return leaf(x) + leaf(x + 1.0); }
        @group(0) @binding(0) var<storage, read_write> out: array<f32>;
        @compute @workgroup_size(1) fn main() { out[0] = twice(out[0]); }
    ";
    let module = naga::front::wgsl::parse_str(source).expect("the test shader parses");
    let function_size = |name: &str| {
        let (_, function) = module.functions.iter().find(|(_, f)| f.name.as_deref() == Some(name)).unwrap();
        function.expressions.len()
    };
    let mut copies = HashMap::new();
    let size = inlined_size(&module, &module.entry_points[0].function, &mut copies);
    let expected =
        module.entry_points[0].function.expressions.len() + function_size("twice") + 2 * function_size("leaf");
    assert_eq!(size, expected);
    assert_eq!(copies.get("leaf"), Some(&2));
    assert_eq!(copies.get("twice"), Some(&1));
}
