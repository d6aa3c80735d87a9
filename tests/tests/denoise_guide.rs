//! The renderer's denoiser guide (`restir_guide`) means what `DenoiseGuide` says: with a
//! still camera every motion vector is zero (the sub-pixel jitter is left out), and with a
//! moving one a pixel's motion vector leads to where its surface was: the previous
//! frame's guide there shows the same object at about the same depth, far more often
//! than where the opposite vector leads. On the interpreter, so that it runs anywhere.

use strata_backends::Backend;
use strata_backends::backend::download;
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_kernels::denoise_types::DenoiseGuide;
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{RestirRenderer, RestirSettings};
use strata_render::scene::{CameraPath, default_scene};

const SIZE: u32 = 32;

/// The guides of two consecutive frames along `path`.
fn two_frames(path: &CameraPath) -> (Vec<DenoiseGuide>, Vec<DenoiseGuide>) {
    let mut backend = CpuBackend::new(CpuOptions::default()).unwrap();
    let backend: &mut dyn Backend = &mut backend;
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let render = RenderSettings::for_scene(&scene, SIZE, SIZE, 7);
    let mut renderer =
        RestirRenderer::new(backend, &gpu_scene, &render, RestirSettings::default(), scene.extent()).unwrap();
    renderer.enable_guides(backend).unwrap();
    let mut guides = Vec::new();
    for frame in 0..2 {
        renderer.render_frame(backend, Some(&path.camera_at(&render.camera, frame))).unwrap();
        guides.push(download::<DenoiseGuide>(backend, renderer.denoiser_inputs().unwrap().guides).unwrap());
    }
    renderer.destroy(backend).unwrap();
    let current = guides.pop().unwrap();
    (guides.pop().unwrap(), current)
}

#[test]
fn a_still_camera_has_no_motion() {
    let (_, guides) = two_frames(&CameraPath::Static);
    let surfaces = guides.iter().filter(|g| g.depth > 0.0).count();
    assert!(surfaces > (SIZE * SIZE / 2) as usize, "the default scene fills the image: {surfaces} surfaces");
    for (pixel, g) in guides.iter().enumerate() {
        assert!(g.depth >= 0.0 && g.depth.is_finite(), "pixel {pixel}: depth {}", g.depth);
        if g.depth > 0.0 {
            assert_eq!(g.motion, [0.0, 0.0], "pixel {pixel}");
            let length = (g.normal[0].powi(2) + g.normal[1].powi(2) + g.normal[2].powi(2)).sqrt();
            assert!((length - 1.0).abs() < 1e-3, "pixel {pixel}: normal of length {length}");
        }
    }
}

#[test]
fn motion_vectors_lead_to_where_the_surface_was() {
    let (previous, current) = two_frames(&CameraPath::orbit(&default_scene().camera, 4.0));
    // Where the pixel's motion (times `sign`) leads, the share of surface pixels whose
    // previous guide shows the same object within 10 % of the depth.
    let found = |sign: f32| -> f64 {
        let (mut same, mut surfaces) = (0, 0);
        for y in 0..SIZE {
            for x in 0..SIZE {
                let g = current[(y * SIZE + x) as usize];
                if g.depth <= 0.0 {
                    continue;
                }
                surfaces += 1;
                let (px, py) = (x as f32 + 0.5 + sign * g.motion[0], y as f32 + 0.5 + sign * g.motion[1]);
                if px < 0.0 || py < 0.0 || px >= SIZE as f32 || py >= SIZE as f32 {
                    continue;
                }
                let p = previous[(py as u32 * SIZE + px as u32) as usize];
                if p.mesh == g.mesh && (p.depth - g.depth).abs() <= 0.1 * g.depth {
                    same += 1;
                }
            }
        }
        f64::from(same) / f64::from(surfaces)
    };
    let moving: f64 = current.iter().filter(|g| g.depth > 0.0).map(|g| f64::from(g.motion[0].abs())).sum::<f64>()
        / current.iter().filter(|g| g.depth > 0.0).count() as f64;
    assert!(moving > 1.0, "an orbit of 4 degrees moves the image by {moving} pixels on average");
    let (forwards, backwards) = (found(1.0), found(-1.0));
    assert!(
        forwards > 0.85 && forwards > backwards + 0.1,
        "same surface {forwards} along the motion, {backwards} against it"
    );
}

#[test]
fn guides_enabled_late_are_offered_only_after_a_frame_that_wrote_them() {
    let mut backend = CpuBackend::new(CpuOptions::default()).unwrap();
    let backend: &mut dyn Backend = &mut backend;
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let render = RenderSettings::for_scene(&scene, 8, 8, 1);
    let mut renderer =
        RestirRenderer::new(backend, &gpu_scene, &render, RestirSettings::default(), scene.extent()).unwrap();
    renderer.render_frame(backend, None).unwrap();
    renderer.enable_guides(backend).unwrap();
    assert!(renderer.denoiser_inputs().is_none(), "no frame has written a guide yet");
    renderer.render_frame(backend, None).unwrap();
    let first = renderer.denoiser_inputs().unwrap();
    assert_eq!(first.guides, first.previous_guides, "the first guided frame has no earlier guide");
    renderer.render_frame(backend, None).unwrap();
    let second = renderer.denoiser_inputs().unwrap();
    assert_eq!(second.previous_guides, first.guides);
    assert_ne!(second.guides, second.previous_guides);
    renderer.destroy(backend).unwrap();
}
