//! Progress of long work as a person watching it wants it: on a terminal a labelled bar
//! with elapsed time and an estimate of what is left (indicatif); when standard error is
//! not a terminal (CI logs, `nohup`, a pipe), where indicatif draws nothing, one plain
//! line every [`PLAIN_LINE_EVERY`] and a last one when the work ends, so a log still
//! shows that the run is alive and how far it got.
//!
//! The estimate of the whole work is also said once, in words, as soon as a step after
//! the first has been timed (see [`Progress::set`]), so a run that will take many minutes
//! says so before it takes them. The first step is left out of every estimate: it carries
//! the one-off costs (pipeline compilation, the first dispatch), which on a fresh machine
//! made it 100 times slower than the rest (a three-minute run announced as six hours).

use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// How often a plain progress line is printed when standard error is not a terminal.
pub const PLAIN_LINE_EVERY: Duration = Duration::from_secs(15);

/// Work longer than this (estimated after the first step) is announced with its
/// estimated duration.
const ANNOUNCE_FROM: Duration = Duration::from_secs(20);

/// One piece of long work counted in steps (samples per pixel, frames).
pub struct Progress {
    label: String,
    unit: &'static str,
    total: u64,
    position: u64,
    started: Instant,
    last_plain_line: Instant,
    /// When the first step ended and how many steps were done then: the estimates
    /// extrapolate from there.
    warmed: Option<(Instant, u64)>,
    announced: bool,
    bar: Option<indicatif::ProgressBar>,
}

impl Progress {
    /// Starts counting `total` steps of `unit` (e.g. "spp", "frames") for the work
    /// named `label` (e.g. "reference"), drawing a bar when standard error is a terminal.
    pub fn new(label: impl Into<String>, total: u64, unit: &'static str) -> Progress {
        let label = label.into();
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new(total);
            bar.set_style(
                indicatif::ProgressStyle::with_template(&format!(
                    "{{msg}} {{bar:32}} {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, about {{eta}} left"
                ))
                .expect("a valid progress template"),
            );
            bar.set_message(label.clone());
            bar
        });
        let now = Instant::now();
        Progress {
            label,
            unit,
            total,
            position: 0,
            started: now,
            last_plain_line: now,
            warmed: None,
            announced: false,
            bar,
        }
    }

    /// Sets the number of steps done.
    pub fn set(&mut self, position: u64) {
        self.position = position.min(self.total);
        if let Some(bar) = &self.bar {
            bar.set_position(self.position);
        }
        let now = Instant::now();
        let elapsed = now - self.started;
        if self.warmed.is_none() && self.position > 0 {
            self.warmed = Some((now, self.position));
        }
        let left = self.estimated_left(now);
        if let (false, Some(left)) = (self.announced, left) {
            self.announced = true;
            let estimate = elapsed + left;
            if estimate >= ANNOUNCE_FROM {
                self.say(&format!(
                    "{}: {} {} estimated to take {} (from the {} after the first)",
                    self.label,
                    self.total,
                    self.unit,
                    words(estimate),
                    self.unit
                ));
            }
        }
        if self.bar.is_none() && self.last_plain_line.elapsed() >= PLAIN_LINE_EVERY && self.position < self.total {
            self.last_plain_line = now;
            let left = left.map_or_else(|| "an unknown time".to_string(), |l| format!("about {}", words(l)));
            eprintln!(
                "{}: {}/{} {}, {} elapsed, {left} left",
                self.label,
                self.position,
                self.total,
                self.unit,
                words(elapsed)
            );
        }
    }

    /// Adds `steps` to the steps done.
    pub fn inc(&mut self, steps: u64) {
        self.set(self.position + steps);
    }

    /// Ends the bar; a plain line says how long the work took.
    pub fn finish(self) -> Duration {
        let elapsed = self.started.elapsed();
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        if self.bar.is_none() && elapsed >= PLAIN_LINE_EVERY {
            eprintln!("{}: {} {} in {}", self.label, self.position, self.unit, words(elapsed));
        }
        elapsed
    }

    /// The time the steps not yet done will take, at the rate of the steps done after
    /// the first (module documentation); `None` until such a step is done.
    fn estimated_left(&self, now: Instant) -> Option<Duration> {
        let (warm, warm_position) = self.warmed?;
        let timed = self.position.checked_sub(warm_position).filter(|&steps| steps > 0)?;
        Some((now - warm).mul_f64((self.total - self.position) as f64 / timed as f64))
    }

    /// A line that stays above the bar.
    fn say(&self, line: &str) {
        match &self.bar {
            Some(bar) => bar.println(line),
            None => eprintln!("{line}"),
        }
    }
}

/// A duration as a person says it: "42 s", "3 min 5 s", "1 h 12 min".
pub fn words(duration: Duration) -> String {
    let seconds = duration.as_secs_f64().round() as u64;
    match seconds {
        0..60 => format!("{seconds} s"),
        60..3600 => format!("{} min {} s", seconds / 60, seconds % 60),
        _ => format!("{} h {} min", seconds / 3600, seconds % 3600 / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_words() {
        assert_eq!(words(Duration::from_millis(400)), "0 s");
        assert_eq!(words(Duration::from_secs(59)), "59 s");
        assert_eq!(words(Duration::from_secs(185)), "3 min 5 s");
        assert_eq!(words(Duration::from_secs(3600 + 12 * 60 + 5)), "1 h 12 min");
    }

    #[test]
    fn the_estimate_leaves_out_the_first_step() {
        let mut progress = Progress::new("test", 10, "frames");
        let start = progress.started;
        assert_eq!(progress.estimated_left(start + Duration::from_secs(100)), None);
        // The first step took 100 s (compilation); the next two took 1 s each: the
        // seven left take 7 s, not 7 × 34 s.
        progress.position = 1;
        progress.warmed = Some((start + Duration::from_secs(100), 1));
        assert_eq!(progress.estimated_left(start + Duration::from_secs(100)), None);
        progress.position = 3;
        assert_eq!(progress.estimated_left(start + Duration::from_secs(102)), Some(Duration::from_secs(7)));
    }
}
