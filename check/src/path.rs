//! Check of the path-tracing kernel. It has no Rust mirror: its reference executor is
//! the CPU interpreter of the same WGSL, so on the `cpu` slot the check only shows that
//! the interpreter is deterministic. The interpreter renders one sample per pixel through
//! a recording backend and every backend replays the recorded `path_trace` dispatch on
//! the same inputs (see [`super::replay`]). Paths branch on float results (which
//! triangle, which lobe, Russian roulette), so one rounding difference can send a path
//! elsewhere: the registry's ULP bound holds for most values, and a share of values
//! ([`MAX_OUTSIDE`]) may differ beyond it. Inputs: the default scene (area light,
//! diffuse) and a furnace-like scene with a conductor, a dielectric and an environment
//! map, at sizes with partial workgroups up to 128².

use super::replay::{Recording, recorded, recorded_outputs, replayed_outputs};
use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use std::sync::Arc;
use strata_backends::Backend;
use strata_kernels::render_types::SCENE_UNIFORM_ROWS;
use strata_kernels::{KernelId, Registry};
use strata_render::histogram_pass::PassError;
use strata_render::render::{GpuScene, RenderSettings, render};
use strata_render::scene::{Albedo, Material, Scene, default_scene};

/// Checks [`KernelId::PathTrace`].
pub struct PathTraceCheck;

/// The default room with its tall box turned to glass, its short box to rough metal and
/// a small environment map shining in (family 1), or the plain default scene (family 0).
pub(super) fn scene(case: &Case) -> Scene {
    let mut scene = default_scene();
    if case.family == 1 {
        scene.materials.push(Material::Dielectric { int_ior: 1.5, ext_ior: 1.0 });
        scene.materials.push(Material::RoughConductor {
            alpha: 0.2,
            eta: [0.2, 0.9, 1.1],
            k: [3.9, 2.4, 2.2],
            two_sided: true,
        });
        let count = scene.materials.len();
        for shape in &mut scene.shapes {
            if shape.name.contains("tall") {
                shape.material = count - 2;
            } else if shape.name.contains("short") {
                shape.material = count - 1;
            }
        }
        scene.environment = Some(crate::fuzz::build::generated_environment(1.0));
    }
    scene
}

/// The scene the path tracer's check renders: [`scene`], with family 1 given unused
/// materials enough that its rows overflow their uniform copy. The path tracer then runs
/// the kernel that reads the storage buffer (`scene_in_uniform` false, render/scene.wgsl)
/// for that family and the one that reads the uniform copy for family 0, so both reads are
/// checked on every backend. (The ReSTIR checks render [`scene`] itself, from the uniform
/// copy: their kernels read the scene through the same `scene_row`, and a second variant
/// of each would be compiled on every path of a new machine, about 35 s of CI.)
fn path_scene(case: &Case) -> Scene {
    let mut scene = scene(case);
    if case.family == 1 {
        let unused = Material::Diffuse { albedo: Albedo::Constant([0.5; 3]), two_sided: false };
        scene.materials.extend(std::iter::repeat_n(unused, SCENE_UNIFORM_ROWS as usize / 4));
    }
    scene
}

fn settings(case: &Case, scene: &Scene) -> RenderSettings {
    RenderSettings { rr_depth: 2, ..RenderSettings::for_scene(scene, case.width, case.height, case.seed as u32) }
}

/// The interpreter's one-sample render of `case` with its `path_trace` dispatch
/// recorded, once per case.
fn recording(case: &Case) -> Arc<Recording> {
    let scene = path_scene(case);
    recorded(&[KernelId::PathTrace], &case.label, |backend| {
        render(backend, &GpuScene::build(&scene)?, &settings(case, &scene), 1, |_| {}).map(drop)
    })
}

/// The share of values that may exceed the bound, per case. On identical inputs (the
/// recorded camera rays and accumulation) at most 0.001 % of values did over 80 cases
/// on six slots (`--full`: max 15256 ULP otherwise): pixels whose path took another
/// branch on a float comparison (Russian roulette `u < p`, the lobe choice of the
/// dielectric and the conductor, a closest-hit near-tie). 1 % leaves room for one such
/// pixel in the smallest images; through the whole chain, with a 4096-ULP bound, 0.7 %
/// of values differed at 13×9.
const MAX_OUTSIDE: f64 = 0.01;

fn float_compare() -> Compare {
    let ulp = Registry::shared().ok().and_then(|r| r.get(KernelId::PathTrace).spec.float_ulp_bound).unwrap_or(0);
    Compare::Float { ulp, max_outside: MAX_OUTSIDE }
}

impl KernelCheck for PathTraceCheck {
    fn kernel(&self) -> KernelId {
        KernelId::PathTrace
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let seeds = if config.full { 20 } else { 2 };
        let sizes: &[(u32, u32)] =
            if config.full { &[(1, 1), (13, 9), (32, 24), (128, 128)] } else { &[(13, 9), (128, 128)] };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            for &(width, height) in sizes {
                let family = (seed % 2) as u32;
                cases.push(Case {
                    label: format!(
                        "{width}x{height} seed {seed} {}",
                        ["default scene", "glass, metal, environment"][family as usize]
                    ),
                    width,
                    height,
                    block_size: 0,
                    seed: 7 + seed,
                    family,
                });
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        Ok(replayed_outputs(backend, KernelId::PathTrace, &recording(case), float_compare())?)
    }

    fn quick_slots(&self) -> Option<&'static [&'static str]> {
        Some(&["cpu", "wgpu-vulkan", "ash", "webgpu"])
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        recorded_outputs(KernelId::PathTrace, &recording(case), float_compare())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The path tracer's check covers both reads of the scene: family 0 fits the rows'
    /// uniform copy, family 1 (padded) does not; the ReSTIR checks' family 1 fits.
    #[test]
    fn the_families_read_the_scene_both_ways() {
        let case = |family| Case { label: String::new(), width: 8, height: 8, block_size: 8, seed: 1, family };
        let fits = |scene: &Scene| GpuScene::build(scene).unwrap().fits_uniform_copy();
        assert!(fits(&path_scene(&case(0))));
        assert!(!fits(&path_scene(&case(1))));
        assert!(fits(&scene(&case(1))));
    }
}
