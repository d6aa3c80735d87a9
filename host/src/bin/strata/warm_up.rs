//! `strata compare`'s warm-up: every kernel the methods use is built and run once at 8x8,
//! with the run's settings, on two more devices while the reference renders. A CPU driver
//! compiles each kernel at its first dispatch (lavapipe compiles a variant for the uniform
//! values it sees, on one core; the two threads took 16 and 20 s for the ReSTIR kernels
//! once each heavy function had one call site per kernel, 41-45 s before), and its shader
//! cache then serves the methods' own first frames (BENCHMARKS "First run on a fresh
//! machine").
//!
//! The warm-up's devices are created and destroyed while no other thread uses Vulkan:
//! Debian 12's validation layer (1.3.239) keeps its per-instance and per-device data in
//! global maps that creating or destroying an instance or device changes without a lock,
//! and `cargo xtask validate` once crashed inside the layer's lookup while the warm-up
//! created its devices during the reference render. So the threads open their devices
//! first, one at a time, while the main thread waits; and they drop them at the join, while
//! the main thread waits again.

use anyhow::Result;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Barrier, Mutex};
use std::thread::JoinHandle;
use strata_kernels::KernelId;
use strata_render::backend_choice::BackendChoice;
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{Method, RestirSettings};
use strata_render::scene::Scene;

/// The warm-up running on its threads.
pub struct WarmUp {
    thread: JoinHandle<()>,
    /// Warm-up threads whose kernels are all built (or which failed).
    done: Arc<AtomicUsize>,
    /// Warm-up threads.
    count: usize,
    /// Passed by the two warm-up threads and the main thread once the threads' work is
    /// done: from then on only the warm-up threads call Vulkan (to destroy their devices).
    finished: Arc<Barrier>,
}

/// The kernels of each warm-up thread: they compile side by side, the candidates (the
/// largest kernel, 16k inlined expressions) with the small passes on one device; the
/// selection, the temporal merge and the spatial pass (11k each) on the other (measured:
/// 20 s and 16 s on a fresh machine with the candidates at 23k, BENCHMARKS).
fn shares() -> [Vec<KernelId>; 2] {
    let histograms = [KernelId::BlockHistogram, KernelId::BlockHistogramSubgroup, KernelId::BlockHistogramRank];
    [
        [
            &[KernelId::RestirCandidates, KernelId::RestirTemporalKeys, KernelId::RestirShade][..],
            &histograms,
            // The temporal-first order's small pass (dispatched only in that order).
            &[KernelId::RestirReservoirKeys],
        ]
        .concat(),
        // The temporal-first order's spatial pass too.
        vec![KernelId::RestirSelect, KernelId::RestirTemporal, KernelId::RestirSpatial],
    ]
}

impl WarmUp {
    /// Starts the warm-up for `methods` with `restir` on devices of `choice`; returns once
    /// its devices exist (anything failing is left for the real run to report). Each
    /// thread renders two frames per method (the first without temporal reuse, the second
    /// with it: lavapipe evidently compiles a kernel for the uniform values it sees, as a
    /// dispatch on zeroed uniforms built nothing the run could reuse).
    pub fn start(choice: BackendChoice, scene: Scene, methods: Vec<Method>, restir: RestirSettings) -> Self {
        let shares = shares();
        // The two threads and this one.
        let opened = Arc::new(Barrier::new(shares.len() + 1));
        let finished = Arc::new(Barrier::new(shares.len() + 1));
        let done = Arc::new(AtomicUsize::new(0));
        let count = shares.len();
        let (opened_here, finished_here, done_here) = (opened.clone(), finished.clone(), done.clone());
        let thread = std::thread::spawn(move || {
            // Device creation and destruction one thread at a time.
            let lifetime = Mutex::new(());
            std::thread::scope(|threads| {
                for share in shares {
                    let (scene, methods, lifetime) = (&scene, &methods, &lifetime);
                    let (opened, finished, done) = (opened.clone(), finished.clone(), done.clone());
                    threads.spawn(move || {
                        let opening = {
                            let _one_at_a_time = lifetime.lock();
                            strata_render::backend_choice::open_backend_quietly(choice)
                        };
                        opened.wait();
                        let mut backend = opening.ok();
                        if let Some(backend) = backend.as_mut() {
                            let _ = render_share(backend.as_mut(), scene, methods, restir, &share);
                        }
                        done.fetch_add(1, Ordering::Release);
                        finished.wait();
                        let _one_at_a_time = lifetime.lock();
                        drop(backend);
                    });
                }
            });
        });
        opened_here.wait();
        Self { thread, done: done_here, count, finished: finished_here }
    }

    /// Whether the warm-up's kernels are all built (`join` will not wait for them).
    pub fn is_finished(&self) -> bool {
        self.done.load(Ordering::Acquire) == self.count
    }

    /// Waits for the warm-up and the destruction of its devices; the caller makes no
    /// Vulkan call meanwhile.
    pub fn join(self) {
        self.finished.wait();
        let _ = self.thread.join();
    }
}

/// Builds and runs the kernels of `share` for every method and regime on `backend`.
fn render_share(
    backend: &mut dyn strata_backends::Backend,
    scene: &Scene,
    methods: &[Method],
    restir: RestirSettings,
    share: &[KernelId],
) -> Result<()> {
    let gpu_scene = GpuScene::build(scene)?;
    let mut render = RenderSettings::for_scene(scene, 8, 8, 1);
    render.seed = 1;
    // Accumulated frames (the other regime) run the paper's passes whatever the order, the
    // selection with its K: built too when the temporal regime runs the temporal-first
    // passes.
    let accumulated = RestirSettings { temporal: false, ..restir };
    let mut variants = vec![restir];
    if restir.temporal && restir.reuse_order == strata_render::restir::ReuseOrder::TemporalFirst {
        variants.push(accumulated);
    }
    for (&method, variant) in methods.iter().flat_map(|m| variants.iter().map(move |v| (m, v))) {
        let settings = RestirSettings { method, ..*variant };
        let mut renderer =
            strata_render::restir::RestirRenderer::new(backend, &gpu_scene, &render, settings, scene.extent())?;
        renderer.dispatch_only(Some(share.to_vec()));
        let frames = (0..2).try_for_each(|_| renderer.render_frame(backend, None).map(drop));
        renderer.destroy(backend)?;
        frames?;
    }
    Ok(())
}
