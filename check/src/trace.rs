//! Check of the BVH closest-hit kernel: random triangle soups (shared edges, coplanar
//! groups, tiny and large triangles), rays from outside with some axis-aligned
//! directions. Control flow depends on float results, so hits are compared with the
//! registry's ULP bound and a small share (0.1 %) of rays may hit a different triangle
//! at a near-tie.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use strata_backends::Backend;
use strata_kernels::reference::bvh_trace::closest_hit;
use strata_kernels::trace_types::Hit;
use strata_kernels::{KernelId, Registry};
use strata_render::histogram_pass::PassError;
use strata_render::synthetic::{rays_into_cube, triangle_soup};
use strata_render::trace_pass::{SceneBvh, TracePass};

/// Checks [`KernelId::BvhClosestHit`].
pub struct TraceCheck;

fn inputs(case: &Case) -> (SceneBvh, Vec<strata_kernels::trace_types::Ray>) {
    let scene = SceneBvh::build(&triangle_soup(case.width as usize, case.seed)).expect("generated scenes are valid");
    (scene, rays_into_cube(case.height as usize, case.seed ^ 0xa5a5))
}

fn outputs(hits: &[Hit]) -> Vec<Output> {
    let ulp = Registry::shared().ok().and_then(|r| r.get(KernelId::BvhClosestHit).spec.float_ulp_bound).unwrap_or(0);
    let floats: Vec<u32> = hits.iter().flat_map(|h| [h.t.to_bits(), h.u.to_bits(), h.v.to_bits()]).collect();
    vec![
        Output { name: "hits.t_u_v", words: floats, compare: Compare::Float { ulp, max_outside: 0.003 } },
        Output {
            name: "hits.primitive",
            words: hits.iter().map(|h| h.primitive).collect(),
            compare: Compare::WordsWithOutliers { max_outside: 0.001 },
        },
    ]
}

impl KernelCheck for TraceCheck {
    fn kernel(&self) -> KernelId {
        KernelId::BvhClosestHit
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let (seeds, sizes): (u64, &[(u32, u32)]) =
            if config.full { (20, &[(1, 64), (50, 1000), (2000, 4000)]) } else { (3, &[(1, 64), (300, 2000)]) };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            for &(triangles, rays) in sizes {
                cases.push(Case {
                    label: format!("{triangles} triangles, {rays} rays, seed {seed}"),
                    width: triangles,
                    height: rays,
                    block_size: 0,
                    seed: 0xb0b ^ seed << 8 ^ u64::from(triangles),
                    family: 0,
                });
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        let (scene, rays) = inputs(case);
        let pass = TracePass::new(backend, &scene)?;
        let hits = pass.trace(backend, &rays);
        pass.destroy(backend)?;
        Ok(outputs(&hits?))
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        let (scene, rays) = inputs(case);
        let hits: Vec<Hit> =
            rays.iter().map(|ray| closest_hit(&scene.nodes, &scene.primitive_indices, &scene.triangles, ray)).collect();
        outputs(&hits)
    }
}
