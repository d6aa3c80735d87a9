//! Check of the camera-ray kernel: the default scene's camera and a tilted one, pixel
//! centres and jittered positions, image sizes with partial workgroups. Float outputs
//! within the registry's ULP bound, no outliers allowed.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use strata_backends::Backend;
use strata_kernels::reference::camera_rays::camera_rays as reference_rays;
use strata_kernels::trace_types::{CameraParams, Ray};
use strata_kernels::{KernelId, Registry};
use strata_render::histogram_pass::PassError;
use strata_render::scene::{CameraFrame, default_scene};
use strata_render::trace_pass::camera_rays;

/// Checks [`KernelId::CameraRays`].
pub struct CameraCheck;

fn params(case: &Case) -> CameraParams {
    let mut camera = default_scene().camera;
    if case.family == 1 {
        camera.origin = [100.0, 400.0, -300.0];
        camera.up = [0.2, 1.0, 0.1];
        camera.fov_axis = "x".into();
    }
    let frame = CameraFrame::new(&camera).expect("valid camera");
    frame.params(case.width, case.height, camera.far_clip, case.seed as u32)
}

fn outputs(rays: &[Ray]) -> Vec<Output> {
    let ulp = Registry::shared().ok().and_then(|r| r.get(KernelId::CameraRays).spec.float_ulp_bound).unwrap_or(0);
    vec![Output {
        name: "camera_rays",
        words: bytemuck::cast_slice(rays).to_vec(),
        compare: Compare::Float { ulp, max_outside: 0.0 },
    }]
}

impl KernelCheck for CameraCheck {
    fn kernel(&self) -> KernelId {
        KernelId::CameraRays
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let seeds = if config.full { 20 } else { 3 };
        let sizes: &[(u32, u32)] =
            if config.full { &[(1, 1), (17, 9), (64, 48), (256, 256)] } else { &[(1, 1), (17, 9)] };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            for &(width, height) in sizes {
                cases.push(Case {
                    label: format!("{width}x{height} seed {seed} camera {}", seed % 2),
                    width,
                    height,
                    block_size: 0,
                    seed,
                    family: (seed % 2) as u32,
                });
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        Ok(outputs(&camera_rays(backend, &params(case))?))
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        outputs(&reference_rays(&params(case)))
    }
}
