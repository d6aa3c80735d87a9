//! Check of the ReSTIR kernels (the five passes, the temporal-first order's two and the
//! denoiser's guide). Like the path tracer they have no Rust mirror: the
//! reference executor is the CPU interpreter running the same WGSL. Each case renders
//! two frames (so the temporal merge has a history) of the default scene, or of the same
//! room with a glass box, a rough-metal box and an environment (every fourth seed with a
//! glossy wall resampled by random replay), at sizes with partial
//! workgroups and blocks, on the interpreter, recording every pass's inputs and outputs
//! (see [`super::replay`]). Each backend then runs each kernel's pass of the second
//! frame alone on the interpreter's exact inputs, so a difference is that pass's own:
//! integer words (object ids, materials, flags, candidate kinds, lights, temporal
//! sources) must be identical and f32 words within the registry's bound for the kernel
//! (its reasons are in the catalogue), with at most one value in 10 000 beyond it. The
//! temporal-first order's passes (`restir_reservoir_keys`, `restir_spatial`) are recorded
//! from a chain of their own in that order, at the sizes up to 64x48.

use super::replay::{Recording, recorded, recorded_outputs, replayed_outputs};
use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use std::sync::Arc;
use strata_backends::Backend;
use strata_kernels::selection::{SamplerVariant, SelectionSettings};
use strata_kernels::{KernelId, Registry};
use strata_render::histogram_pass::PassError;
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings, ReuseOrder};
use strata_render::scene::Material;

/// Checks one of the ReSTIR kernels ([`KernelId::RestirCandidates`] and the seven after it).
pub struct RestirCheck(pub KernelId);

/// Whether `case` resamples by random replay: the glass, metal and environment room with
/// its left wall a glossy conductor (GGX alpha 0.03, below `min_roughness`) and
/// `glossy_replay` on, every fourth seed from 1 (each method in turn over the full check's
/// seeds; seed 1, restir, in the quick one), up to 64x48 pixels (every candidate a replay
/// pixel weighs is a traced path: at 128x128 the interpreter's recording took 2.5 min).
fn resamples_by_random_replay(case: &Case) -> bool {
    case.family == 1 && case.seed % 4 == 1 && case.width * case.height <= 64 * 48
}

/// Renders two frames of `case` (so the temporal passes have a history) in `order`.
fn frame(backend: &mut dyn Backend, case: &Case, order: ReuseOrder) -> Result<(), PassError> {
    let mut scene = super::path::scene(case);
    if resamples_by_random_replay(case) {
        scene.materials.push(Material::RoughConductor {
            alpha: 0.03,
            eta: [0.2, 0.9, 1.1],
            k: [3.9, 2.4, 2.2],
            two_sided: true,
        });
        let glossy = scene.materials.len() - 1;
        scene.shapes.iter_mut().filter(|shape| shape.name == "left").for_each(|shape| shape.material = glossy);
    }
    let gpu_scene = GpuScene::build(&scene)?;
    let render =
        RenderSettings { rr_depth: 2, ..RenderSettings::for_scene(&scene, case.width, case.height, case.seed as u32) };
    let method = [Method::Strata, Method::Restir, Method::RestirDisc][(case.seed % 3) as usize];
    // Besides its own reprojected reservoir, strata merges 4 drawn from the temporal
    // histogram, restir none, restir-disc 2 from its disc.
    let temporal_candidates = [4, 0, 2][(case.seed % 3) as usize];
    let settings = RestirSettings {
        method,
        // Every sampler variant and K in turn (the seed's remaining digits), so the
        // in-kernel selection numbers (§4.2) are compared for each.
        selection: SelectionSettings {
            block_size: case.block_size,
            candidates: 1 + (case.seed / 3 % 4) as u32,
            sampler: SamplerVariant::ALL[(case.seed / 3) as usize % SamplerVariant::ALL.len()],
            ..SelectionSettings::default()
        },
        disc_radius: 4.0,
        temporal_candidates,
        glossy_replay: resamples_by_random_replay(case),
        // restir-disc's cases also permute the history and run the boiling filter (whose
        // workgroup barrier and shared sum every backend must agree on). At 0.8 a
        // reservoir is emptied above 3.5 times its workgroup's mean W, which the
        // heavy-tailed W of two frames reaches; a W within rounding of that threshold
        // could be emptied on one backend and kept on another (a few floats of one pixel,
        // which the large cases' max_outside tolerates).
        permutation_sampling: method == Method::RestirDisc,
        boiling_filter: if method == Method::RestirDisc { 0.8 } else { 0.0 },
        reuse_order: order,
        ..RestirSettings::default()
    };
    let mut renderer = RestirRenderer::new(backend, &gpu_scene, &render, settings, scene.extent())?;
    let result = (|| {
        renderer.enable_guides(backend)?;
        renderer.render_frame(backend, None)?;
        renderer.render_frame(backend, None).map(drop)
    })();
    renderer.destroy(backend)?;
    result
}

/// The ReSTIR kernels (the five passes and the denoiser's guide), recorded together
/// from one chain.
const RESTIR_KERNELS: [KernelId; 6] = [
    KernelId::RestirCandidates,
    KernelId::RestirSelect,
    KernelId::RestirTemporalKeys,
    KernelId::RestirTemporal,
    KernelId::RestirShade,
    KernelId::RestirGuide,
];

/// The passes only the temporal-first order runs, recorded from a chain in that order.
const TEMPORAL_FIRST_KERNELS: [KernelId; 2] = [KernelId::RestirReservoirKeys, KernelId::RestirSpatial];

/// The interpreter's two-frame chain of `case` that runs `kernel`, recorded once per case.
fn recording(kernel: KernelId, case: &Case) -> Arc<Recording> {
    if TEMPORAL_FIRST_KERNELS.contains(&kernel) {
        return recorded(&TEMPORAL_FIRST_KERNELS, &case.label, |backend| {
            frame(backend, case, ReuseOrder::TemporalFirst)
        });
    }
    recorded(&RESTIR_KERNELS, &case.label, |backend| frame(backend, case, ReuseOrder::SpatialFirst))
}

impl RestirCheck {
    fn float_compare(&self) -> Compare {
        let ulp = Registry::shared().ok().and_then(|r| r.get(self.0).spec.float_ulp_bound).unwrap_or(0);
        // One value in 10 000 may exceed the bound: a coordinate near the origin of a
        // point hit after a grazing glossy bounce, whose absolute error (5e-4 scene
        // units) is many ULPs of its small value (2 of 196 608 values at 128², glass,
        // metal and environment room).
        Compare::Float { ulp, max_outside: 1e-4 }
    }
}

impl KernelCheck for RestirCheck {
    fn kernel(&self) -> KernelId {
        self.0
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let seeds = if config.full { 20 } else { 3 };
        let sizes: &[(u32, u32)] =
            if config.full { &[(1, 1), (13, 9), (40, 24), (128, 128)] } else { &[(13, 9), (64, 48), (128, 128)] };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            for &(width, height) in sizes {
                let family = (seed % 2) as u32;
                let block_size = [4, 8, 16][(seed % 3) as usize];
                let mut case = Case { label: String::new(), width, height, block_size, seed, family };
                case.label = format!(
                    "{width}x{height} seed {seed} B{block_size} {} {}",
                    ["strata T=4", "restir T=0", "restir-disc T=2 permuted, boiling 0.8"][(seed % 3) as usize],
                    match (family, resamples_by_random_replay(&case)) {
                        (0, _) => "default scene",
                        (_, false) => "glass, metal, environment",
                        (_, true) => "glass, metal, environment, glossy wall replayed",
                    }
                );
                cases.push(case);
            }
        }
        // The temporal-first chain is a second recording on the interpreter: its
        // passes are checked at the sizes up to 64x48 (partial workgroups and blocks),
        // which keeps `cargo xtask check` under its minute.
        if TEMPORAL_FIRST_KERNELS.contains(&self.0) {
            cases.retain(|case| case.width * case.height <= 64 * 48);
        }
        // restir-disc (every third seed) has no histogram, so no keys for it.
        if self.0 == KernelId::RestirReservoirKeys {
            cases.retain(|case| case.seed % 3 != 2);
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        Ok(replayed_outputs(backend, self.0, &recording(self.0, case), self.float_compare())?)
    }

    fn quick_slots(&self) -> Option<&'static [&'static str]> {
        Some(&["cpu", "wgpu-vulkan", "ash", "webgpu"])
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        recorded_outputs(self.0, &recording(self.0, case), self.float_compare())
    }
}
