//! Check of the five ReSTIR kernels. Like the path tracer they have no Rust mirror: the
//! reference executor is the CPU interpreter running the same frames. Each case renders
//! two frames (so the temporal merge has a history) of the default scene, or of the same
//! room with a glass box, a rough-metal box and an environment, at a size with partial
//! workgroups and blocks, and each kernel's check compares the buffers that kernel
//! writes. A frame is a chain (candidates feed the histogram, selection, temporal reuse
//! and shading), and paths branch on float results, so a value that diverges on one
//! backend changes what follows: floats are compared within the registry's 4096-ULP
//! bound (Vulkan's atan2/acos precision), and at most 10 % of the values may differ
//! beyond it; integer fields (kinds, lights, object ids, flags) are compared the same
//! way, as words with outliers.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use strata::histogram_pass::PassError;
use strata::render::{GpuScene, RenderSettings};
use strata::restir::{FrameBuffers, Method, RestirRenderer, RestirSettings};
use strata_backends::Backend;
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_kernels::selection::{SamplerVariant, SelectionSettings};
use strata_kernels::{KernelId, Registry};

/// Checks one of the ReSTIR kernels ([`KernelId::RestirCandidates`] and the four after it).
pub struct RestirCheck(pub KernelId);

fn frame(backend: &mut dyn Backend, case: &Case) -> Result<FrameBuffers, PassError> {
    let scene = super::path::scene(case);
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
            sampler: SamplerVariant::ALL[(case.seed / 3 % 5) as usize],
            ..SelectionSettings::default()
        },
        disc_radius: 4.0,
        temporal_candidates,
        ..RestirSettings::default()
    };
    let mut renderer = RestirRenderer::new(backend, &gpu_scene, &render, settings, scene.extent())?;
    let result = (|| {
        renderer.render_frame(backend, None)?;
        renderer.render_frame(backend, None)?;
        renderer.frame_buffers(backend)
    })();
    renderer.destroy(backend)?;
    result
}

fn words<T: bytemuck::Pod>(values: &[T]) -> Vec<u32> {
    bytemuck::cast_slice(values).to_vec()
}

impl RestirCheck {
    fn outputs(&self, buffers: &FrameBuffers) -> Vec<Output> {
        let ulp = Registry::shared().ok().and_then(|r| r.get(self.0).spec.float_ulp_bound).unwrap_or(0);
        let float = Compare::Float { ulp, max_outside: 0.10 };
        let words_with_outliers = Compare::WordsWithOutliers { max_outside: 0.10 };
        match self.0 {
            KernelId::RestirCandidates => {
                let flags: Vec<u32> =
                    buffers.primaries.iter().flat_map(|p| [p.object_id, p.material, p.flags]).collect();
                let kinds: Vec<u32> = buffers.candidates.iter().flat_map(|c| [c.kind, c.light]).collect();
                let floats: Vec<u32> = buffers
                    .candidates
                    .iter()
                    .flat_map(|c| [c.position, c.normal, c.reflected].into_iter().flatten().chain([c.weight]))
                    .map(f32::to_bits)
                    .collect();
                vec![
                    Output { name: "primaries.ids_flags", words: flags, compare: words_with_outliers },
                    Output { name: "candidates.kind_light", words: kinds, compare: words_with_outliers },
                    Output { name: "candidates.values", words: floats, compare: float },
                    Output { name: "histogram_in", words: words(&buffers.histogram_candidates), compare: float },
                    Output { name: "base_radiance", words: words(&buffers.base_radiance), compare: float },
                ]
            }
            KernelId::RestirSelect => {
                let values: Vec<u32> = buffers
                    .selected
                    .iter()
                    .flat_map(|r| [r.weight, r.count, r.target_value])
                    .map(f32::to_bits)
                    .collect();
                vec![Output { name: "reservoirs_out.w_m_target", words: values, compare: float }]
            }
            KernelId::RestirTemporalKeys => vec![
                Output { name: "temporal_keys", words: words(&buffers.temporal_keys), compare: float },
                Output {
                    name: "temporal_sources",
                    words: buffers.temporal_sources.clone(),
                    compare: words_with_outliers,
                },
            ],
            KernelId::RestirTemporal => {
                let values: Vec<u32> = buffers
                    .reservoirs
                    .iter()
                    .flat_map(|r| [r.weight, r.count, r.target_value])
                    .map(f32::to_bits)
                    .collect();
                vec![Output { name: "merged_reservoirs.w_m_target", words: values, compare: float }]
            }
            _ => vec![Output { name: "frame_out", words: words(&buffers.image), compare: float }],
        }
    }
}

impl KernelCheck for RestirCheck {
    fn kernel(&self) -> KernelId {
        self.0
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let seeds = if config.full { 20 } else { 3 };
        let sizes: &[(u32, u32)] = if config.full { &[(1, 1), (13, 9), (40, 24)] } else { &[(13, 9)] };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            for &(width, height) in sizes {
                let family = (seed % 2) as u32;
                let block_size = [4, 8, 16][(seed % 3) as usize];
                cases.push(Case {
                    label: format!(
                        "{width}x{height} seed {seed} B{block_size} {} {}",
                        ["strata T=4", "restir T=0", "restir-disc T=2"][(seed % 3) as usize],
                        ["default scene", "glass, metal, environment"][family as usize]
                    ),
                    width,
                    height,
                    block_size,
                    seed,
                    family,
                });
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        Ok(self.outputs(&frame(backend, case)?))
    }

    fn quick_slots(&self) -> Option<&'static [&'static str]> {
        Some(&["cpu", "wgpu-vulkan", "ash"])
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        let mut interpreter = CpuBackend::new(CpuOptions::default()).expect("the interpreter always opens");
        self.outputs(&frame(&mut interpreter, case).expect("the interpreter runs the ReSTIR frame"))
    }
}
