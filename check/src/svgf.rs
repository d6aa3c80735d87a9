//! Check of the four SVGF kernels (`kernels/wgsl/denoise/`) against the Rust reference
//! (`strata_kernels::reference::svgf`), each pass alone on generated inputs: guides of a
//! few slanted planes (objects with their own normals, depths and textured albedo), a
//! share of sky pixels in some families, motion vectors that land between pixels, off the
//! image, or are NaN, histories of every length, and moments whose variance is not lost
//! to cancellation (`E[l²]` at least 1.1 `E[l]²`, so that a fused multiply-add in one backend
//! cannot turn a 0 into many ULPs). Every output is f32, within the registry's bound.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use strata_backends::backend::{download, upload};
use strata_backends::{Backend, Bind, BufferId};
use strata_kernels::denoise_types::{DenoiseGuide, DenoiseParams};
use strata_kernels::reference::svgf::{self, TemporalInputs};
use strata_kernels::{KernelId, Registry};
use strata_render::histogram_pass::PassError;

/// Checks one SVGF kernel.
pub struct SvgfCheck(pub KernelId);

/// The families of generated inputs (`Case::family`).
const FAMILIES: u32 = 4;

/// Everything any of the four passes reads.
struct Inputs {
    params: DenoiseParams,
    colour: Vec<[f32; 4]>,
    guides: Vec<DenoiseGuide>,
    previous_guides: Vec<DenoiseGuide>,
    history: Vec<[f32; 4]>,
    previous_integrated: Vec<[f32; 4]>,
    previous_moments: Vec<[f32; 2]>,
    /// Integrated illumination and length: the variance pass's input.
    integrated: Vec<[f32; 4]>,
    /// Moments: the variance pass's input.
    moments: Vec<[f32; 2]>,
    /// Illumination and variance: the à-trous pass's input (and the filtered
    /// illumination the modulation reads).
    levels: Vec<[f32; 4]>,
}

fn unit(v: [f32; 3]) -> [f32; 3] {
    let length = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / length)
}

/// One object of a generated guide image: a slanted plane with its own albedo.
#[derive(Clone, Copy)]
struct Plane {
    normal: [f32; 3],
    depth: f32,
    /// Depth change per pixel along x and y.
    slope: [f32; 2],
    albedo: [f32; 3],
}

/// A guide image: up to four objects, each a slanted plane over a region of the image
/// (vertical stripes of random widths), `sky` of the pixels without a surface.
fn guide_image(rng: &mut Pcg32, width: u32, height: u32, sky: f64) -> Vec<DenoiseGuide> {
    let objects = rng.random_range(1..=4u32);
    let planes: Vec<Plane> = (0..objects)
        .map(|_| Plane {
            normal: unit([rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(0.2..1.0)]),
            depth: rng.random_range(0.5..20.0f32),
            slope: [rng.random_range(-0.05..0.05f32), rng.random_range(-0.05..0.05f32)],
            albedo: [rng.random_range(0.0..1.0), rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)],
        })
        .collect();
    let edges: Vec<u32> = (0..objects).map(|_| rng.random_range(0..width.max(1))).collect();
    let mut guides = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let object = edges.iter().filter(|&&e| x >= e).count().min(objects as usize - 1);
            let Plane { normal, depth, slope, albedo } = planes[object];
            if rng.random_bool(sky) {
                guides.push(DenoiseGuide {
                    albedo: [1.0; 3],
                    normal: [0.0, 0.0, 1.0],
                    mesh: u32::MAX,
                    ..Default::default()
                });
                continue;
            }
            // A texture: some pixels darker, some black (not demodulated).
            let texture = match rng.random_range(0..10) {
                0 => 0.0,
                1..3 => 0.5,
                _ => 1.0,
            };
            guides.push(DenoiseGuide {
                albedo: albedo.map(|a| a * texture),
                depth: (depth + slope[0] * x as f32 + slope[1] * y as f32).max(0.1),
                normal,
                mesh: object as u32,
                motion: [0.0; 2],
                _pad: [0; 2],
            });
        }
    }
    guides
}

fn inputs(kernel: KernelId, case: &Case) -> Inputs {
    let mut rng = Pcg32::seed_from_u64(case.seed);
    let (width, height) = (case.width, case.height);
    let pixels = (width * height) as usize;
    let sky = if case.family == 1 { 0.2 } else { 0.0 };
    let mut guides = guide_image(&mut rng, width, height, sky);
    // The previous frame: the same surfaces, some replaced (a disocclusion), depths and
    // normals moved a little.
    let mut previous_guides = guides.clone();
    for g in &mut previous_guides {
        match rng.random_range(0..10) {
            0 => g.mesh = g.mesh.wrapping_add(1),
            1 => g.depth *= 1.3,
            2 => g.normal = unit([g.normal[0] + 0.8, g.normal[1], g.normal[2]]),
            _ => g.depth *= rng.random_range(0.97..1.03f32),
        }
    }
    for g in &mut guides {
        g.motion = match (case.family, rng.random_range(0..20)) {
            (2, 0) => [f32::NAN, 0.5],
            (2, 1) => [-1e30, -1e30],
            (2, 2) => [f32::INFINITY, 0.0],
            (2, 3) => [0.0, 0.0],
            _ => [rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0)],
        };
    }
    let colour_of = |rng: &mut Pcg32| -> [f32; 4] {
        let scale = if rng.random_range(0..8) == 0 { 20.0 } else { 1.0 };
        [rng.random::<f32>() * scale, rng.random::<f32>() * scale, rng.random::<f32>() * scale, 0.0]
    };
    let colour: Vec<[f32; 4]> = (0..pixels).map(|_| colour_of(&mut rng)).collect();
    let history: Vec<[f32; 4]> = (0..pixels).map(|_| colour_of(&mut rng)).collect();
    let lengths = |rng: &mut Pcg32| -> f32 {
        if rng.random_bool(0.5) { rng.random_range(1..4) as f32 } else { rng.random_range(1.0..40.0) }
    };
    let moments_of = |rng: &mut Pcg32| -> [f32; 2] {
        let mean = rng.random_range(0.01..5.0f32);
        [mean, mean * mean * rng.random_range(1.1..4.0f32)]
    };
    let previous_integrated = (0..pixels)
        .map(|_| {
            let c = colour_of(&mut rng);
            [c[0], c[1], c[2], lengths(&mut rng)]
        })
        .collect();
    let previous_moments = (0..pixels).map(|_| moments_of(&mut rng)).collect();
    let integrated = (0..pixels)
        .map(|_| {
            let c = colour_of(&mut rng);
            [c[0], c[1], c[2], lengths(&mut rng)]
        })
        .collect();
    let moments = (0..pixels).map(|_| moments_of(&mut rng)).collect();
    let levels = (0..pixels)
        .map(|_| {
            let c = colour_of(&mut rng);
            [c[0], c[1], c[2], rng.random_range(0.0..2.0)]
        })
        .collect();
    let level = if kernel == KernelId::SvgfAtrous { (case.seed % 5) as u32 } else { 0 };
    // Object edges on for about half the cases (the seed's parity), and the à-trous
    // variance of correlated noise (`svgf-correlated`) in every third.
    let settings = strata_render::denoise::SvgfSettings::default().with_object_edges(case.seed % 2 == 1);
    let mut params = settings.params(width, height, level, case.family != 3);
    if case.seed % 3 == 2 {
        params.svgf.error_correlation = 0.15;
    }
    Inputs {
        params,
        colour,
        guides,
        previous_guides,
        history,
        previous_integrated,
        previous_moments,
        integrated,
        moments,
        levels,
    }
}

fn float_output(name: &'static str, words: Vec<u32>, kernel: KernelId) -> Output {
    let ulp = Registry::shared().ok().and_then(|r| r.get(kernel).spec.float_ulp_bound).unwrap_or(0);
    Output { name, words, compare: Compare::Float { ulp, max_outside: 0.0 } }
}

fn words<T: bytemuck::Pod>(values: &[T]) -> Vec<u32> {
    bytemuck::cast_slice(values).to_vec()
}

impl KernelCheck for SvgfCheck {
    fn kernel(&self) -> KernelId {
        self.0
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let seeds = if config.full { 20 } else { 4 };
        let sizes: &[(u32, u32)] =
            if config.full { &[(1, 1), (13, 9), (40, 24), (128, 128)] } else { &[(1, 1), (13, 9), (40, 24)] };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            for &(width, height) in sizes {
                let family = (seed % u64::from(FAMILIES)) as u32;
                let what = ["planes", "planes and sky", "awkward motion", "no history"][family as usize];
                cases.push(Case {
                    label: format!("{width}x{height} seed {seed} {what}"),
                    width,
                    height,
                    block_size: 0,
                    seed: 0x5f6f ^ seed << 16 ^ u64::from(width),
                    family,
                });
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        let kernel = Registry::shared()?.get(self.0);
        let inputs = inputs(self.0, case);
        let pixels = (case.width * case.height) as usize;
        let mut buffers: Vec<BufferId> = Vec::new();
        let result = (|| {
            let mut binds = Vec::new();
            let mut bind = |backend: &mut dyn Backend, name: &str, words: &[u32]| -> Result<BufferId, PassError> {
                let info = kernel
                    .binding_named(name)
                    .ok_or_else(|| PassError::Input(format!("kernel {}: no binding named {name}", kernel.name())))?;
                let buffer = upload(backend, name, words)?;
                buffers.push(buffer);
                binds.push(Bind::new(info.binding, buffer));
                Ok(buffer)
            };
            bind(backend, "params", &words(&[inputs.params]))?;
            // Outputs start as a pattern no kernel writes, so an unwritten value shows.
            let garbage = |count: usize| vec![0x7fa5_a5a5u32; count];
            let outputs = match self.0 {
                KernelId::SvgfTemporal => {
                    bind(backend, "colour", &words(&inputs.colour))?;
                    bind(backend, "guides", &words(&inputs.guides))?;
                    bind(backend, "previous_guides", &words(&inputs.previous_guides))?;
                    bind(backend, "history", &words(&inputs.history))?;
                    bind(backend, "previous_integrated", &words(&inputs.previous_integrated))?;
                    bind(backend, "previous_moments", &words(&inputs.previous_moments))?;
                    let integrated = bind(backend, "integrated", &garbage(pixels * 4))?;
                    let moments = bind(backend, "moments", &garbage(pixels * 2))?;
                    vec![("integrated", integrated), ("moments", moments)]
                }
                KernelId::SvgfVariance => {
                    bind(backend, "guides", &words(&inputs.guides))?;
                    bind(backend, "integrated", &words(&inputs.integrated))?;
                    bind(backend, "moments", &words(&inputs.moments))?;
                    vec![("illumination_variance", bind(backend, "illumination_variance", &garbage(pixels * 4))?)]
                }
                KernelId::SvgfAtrous => {
                    bind(backend, "guides", &words(&inputs.guides))?;
                    bind(backend, "level_in", &words(&inputs.levels))?;
                    vec![("level_out", bind(backend, "level_out", &garbage(pixels * 4))?)]
                }
                _ => {
                    bind(backend, "colour", &words(&inputs.colour))?;
                    bind(backend, "guides", &words(&inputs.guides))?;
                    bind(backend, "filtered", &words(&inputs.levels))?;
                    vec![("denoised", bind(backend, "denoised", &garbage(pixels * 4))?)]
                }
            };
            backend.dispatch(kernel, &binds, [case.width.div_ceil(8), case.height.div_ceil(8), 1])?;
            outputs
                .into_iter()
                .map(|(name, buffer)| Ok(float_output(name, download::<u32>(backend, buffer)?, self.0)))
                .collect::<Result<Vec<_>, PassError>>()
        })();
        for buffer in buffers {
            backend.destroy_buffer(buffer)?;
        }
        result
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        let i = inputs(self.0, case);
        let p = &i.params;
        match self.0 {
            KernelId::SvgfTemporal => {
                let temporal_inputs = TemporalInputs {
                    colour: &i.colour,
                    guides: &i.guides,
                    previous_guides: &i.previous_guides,
                    history: &i.history,
                    previous_integrated: &i.previous_integrated,
                    previous_moments: &i.previous_moments,
                };
                let (integrated, moments) = svgf::temporal(p, &temporal_inputs);
                vec![
                    float_output("integrated", words(&integrated), self.0),
                    float_output("moments", words(&moments), self.0),
                ]
            }
            KernelId::SvgfVariance => {
                let out = svgf::variance(p, &i.guides, &i.integrated, &i.moments);
                vec![float_output("illumination_variance", words(&out), self.0)]
            }
            KernelId::SvgfAtrous => {
                vec![float_output("level_out", words(&svgf::atrous(p, &i.guides, &i.levels)), self.0)]
            }
            _ => vec![float_output("denoised", words(&svgf::modulate(&i.guides, &i.colour, &i.levels)), self.0)],
        }
    }
}
