//! Device time per ReSTIR pass, summed over a benchmark's frames: the per-pass times and
//! shares the `render` and `table1` benches print beside criterion's frame times.

use std::time::Duration;

/// The five passes' names in `FrameStats::pass_times`' order (strata-render's
/// `RestirRenderer`: the temporal entry includes the temporal histogram and merge; in the
/// temporal-first order the histogram includes its keys' pass).
pub const PASS_NAMES: [&str; 5] = ["candidates", "histogram", "select", "temporal", "shade"];

/// Device time per pass summed over a benchmark's frames (warm-up included).
#[derive(Default)]
pub struct PassTimes {
    frames: u32,
    passes: [Duration; 5],
}

impl PassTimes {
    /// Adds one frame's pass times and returns the frame's total.
    pub fn add(&mut self, times: [Duration; 5]) -> Duration {
        self.frames += 1;
        for (total, t) in self.passes.iter_mut().zip(times) {
            *total += t;
        }
        times.iter().sum()
    }

    /// Each pass's mean time per frame, in [`PASS_NAMES`]' order (zero before any frame).
    pub fn means(&self) -> [Duration; 5] {
        self.passes.map(|t| if self.frames == 0 { Duration::ZERO } else { t / self.frames })
    }

    /// Pass `index`'s share of the frame in percent; `None` before any frame or when no
    /// pass took time (a backend without timestamps), so that no NaN is printed.
    pub fn share(&self, index: usize) -> Option<f64> {
        let total: Duration = self.passes.iter().sum();
        (self.frames > 0 && !total.is_zero()).then(|| 100.0 * self.passes[index].as_secs_f64() / total.as_secs_f64())
    }

    /// One line to stderr: each pass's mean time and share of the frame. Nothing when a
    /// filter left the benchmark out (no frames ran) or nothing was timed.
    pub fn print(&self, name: &str) {
        if self.share(0).is_none() {
            return;
        }
        let means = self.means();
        let parts: Vec<String> = PASS_NAMES
            .iter()
            .enumerate()
            .map(|(i, pass)| {
                let ms = 1e3 * means[i].as_secs_f64();
                format!("{pass} {ms:.3} ms ({:.1} %)", self.share(i).unwrap_or(0.0))
            })
            .collect();
        eprintln!("{name}: {} frames, mean per frame: {}", self.frames, parts.join(", "));
    }
}
