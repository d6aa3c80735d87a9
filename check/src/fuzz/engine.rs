//! The campaign loop: pick a corpus input, mutate it (or generate a fresh one), run the
//! target under `catch_unwind` with a panic hook that sees panics a loader contains
//! itself, watch the clock from another thread, and keep every input that produced an
//! outcome not seen before. Findings are written to `<crash folder>/<target>/`.

use super::mutate::{FuzzRng, mutate_bytes};
use super::{Outcome, Target};
use rand::{Rng, SeedableRng};
use std::cell::RefCell;
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// The longest input a campaign runs (longer mutants are cut).
pub const MAX_INPUT: usize = 1 << 20;
/// Inputs kept beyond the seeds.
const MAX_CORPUS: usize = 4096;

/// How one input fared.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// The loader accepted it (and the result passed the target's checks).
    Accepted,
    /// Accepted with a remark (see [`Outcome::Noted`]).
    Noted(String),
    /// The loader refused it with this message.
    Refused(String),
    /// A panic in a third-party parser that the loader turned into an error (its
    /// `without_panic` guard): reported, not a failure.
    Contained {
        /// Where the panic happened.
        location: String,
        /// The panic's message.
        message: String,
    },
    /// A bug: a panic that escaped, a panic in our own code (contained or not), or a
    /// loaded scene that breaks the oracle.
    Crash {
        /// What kind and where, e.g. `panic at render/src/scene/ply.rs:120`.
        signature: String,
        /// The message.
        message: String,
    },
}

/// A panic seen by the hook.
#[derive(Clone, Debug)]
struct PanicRecord {
    location: String,
    message: String,
}

thread_local! {
    /// Panics of the current input on this thread, while one runs.
    static CAPTURED: RefCell<Option<Vec<PanicRecord>>> = const { RefCell::new(None) };
}

/// Installs (once) the panic hook that records panics while an input runs, and leaves
/// others to the previous hook.
fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let record = PanicRecord {
                location: info.location().map_or_else(|| "(unknown)".into(), |l| format!("{}:{}", l.file(), l.line())),
                message: info
                    .payload()
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| info.payload().downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "(no message)".into()),
            };
            let captured = CAPTURED.with(|c| match c.try_borrow_mut() {
                Ok(mut slot) => slot.as_mut().map(|list| list.push(record)).is_some(),
                Err(_) => false,
            });
            if !captured {
                previous(info);
            }
        }));
    });
}

/// Whether a panic location is in this workspace's code (relative source paths) rather
/// than in a dependency or the standard library (absolute paths).
fn in_our_code(location: &str) -> bool {
    !location.starts_with('/') && !location.starts_with("(unknown)")
}

/// Runs `target` on `input` and judges it (see [`Verdict`]).
pub fn execute(target: &dyn Target, input: &[u8]) -> Verdict {
    install_hook();
    CAPTURED.with(|c| *c.borrow_mut() = Some(Vec::new()));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| target.execute(input)));
    let panics = CAPTURED.with(|c| c.borrow_mut().take()).unwrap_or_default();
    match result {
        Err(_) => {
            let first = panics
                .first()
                .cloned()
                .unwrap_or(PanicRecord { location: "(unknown)".into(), message: "(no message)".into() });
            Verdict::Crash { signature: format!("panic at {}", first.location), message: first.message }
        }
        Ok(outcome) => {
            if let Some(ours) = panics.iter().find(|p| in_our_code(&p.location)) {
                return Verdict::Crash {
                    signature: format!("contained panic at {}", ours.location),
                    message: ours.message.clone(),
                };
            }
            match (outcome, panics.first()) {
                (Outcome::Bug(message), _) => {
                    let kind: String = message.chars().take_while(|c| *c != '[' && !c.is_ascii_digit()).collect();
                    Verdict::Crash { signature: format!("oracle: {}", kind.trim()), message }
                }
                (_, Some(panic)) => {
                    Verdict::Contained { location: panic.location.clone(), message: panic.message.clone() }
                }
                (Outcome::Accepted, None) => Verdict::Accepted,
                (Outcome::Noted(remark), None) => Verdict::Noted(remark),
                (Outcome::Refused(message), None) => Verdict::Refused(message),
            }
        }
    }
}

/// A message with its numbers and odd quoted texts blurred, so that messages differing
/// only in values count as one outcome (the campaign's rough coverage figure).
pub fn outcome_kind(message: &str) -> String {
    let mut out = String::new();
    let mut digits = false;
    for c in message.chars() {
        if c.is_ascii_digit() {
            if !digits {
                out.push('#');
            }
            digits = true;
        } else {
            digits = false;
            out.push(c);
        }
    }
    // The first segment names the file (user data when a mutated scene names it): only
    // its extension is kept.
    let mut blurred = String::new();
    let mut rest = out.as_str();
    if let Some((file, after)) = rest.split_once(": ")
        && !file.starts_with("line")
    {
        let extension = file.rsplit_once('.').map_or("", |(_, e)| e);
        blurred.push_str(&format!("(file).{}: ", if extension.len() <= 4 { extension } else { "" }));
        rest = after;
    }
    // Quoted texts (user data, which may hold quotes itself) collapse: everything from the
    // first quote to the last becomes `…`, except a field path of SceneError's
    // `: field `…`:` (which says where the loader stopped).
    if let Some(rest_of_field) = rest.strip_prefix("field `")
        && let Some((field, after)) = rest_of_field.split_once("`: ")
        && field.len() <= 60
        && field.chars().all(|c| c.is_ascii_alphanumeric() || "._#[]/\\\" ".contains(c))
    {
        blurred.push_str(&format!("field `{field}`: "));
        rest = after;
    }
    match (rest.find(['`', '"']), rest.rfind(['`', '"'])) {
        (Some(first), Some(last)) if first < last => {
            blurred.push_str(&rest[..first]);
            blurred.push_str("`…`");
            blurred.push_str(&rest[last + 1..]);
        }
        (Some(first), _) => {
            blurred.push_str(&rest[..first]);
            blurred.push_str("`…");
        }
        _ => blurred.push_str(rest),
    }
    // Lists of values (`[1.0, NaN, -2]`) become `[…]`.
    let mut listless = String::new();
    let mut depth = 0;
    for c in blurred.chars() {
        match c {
            '[' => {
                if depth == 0 {
                    listless.push_str("[…]");
                }
                depth += 1;
            }
            ']' if depth > 0 => depth -= 1,
            _ if depth == 0 => listless.push(c),
            _ => {}
        }
    }
    listless.chars().take(160).collect()
}

/// FNV-1a of `bytes`, the name of a finding's file.
pub fn fnv64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3))
}

/// What a campaign runs.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// Generator seed: the same seed runs the same inputs.
    pub seed: u64,
    /// Stop after this many executions.
    pub executions: Option<u64>,
    /// Stop after this long.
    pub duration: Option<Duration>,
    /// Findings go to `crash_dir/<target>/`.
    pub crash_dir: PathBuf,
    /// An input running longer than this is a hang.
    pub hang_after: Duration,
    /// One allocation over this many bytes is a finding (0: unchecked); needs the
    /// [`super::GuardedAllocator`] as the process's global allocator.
    pub allocation_limit: usize,
    /// The committed test scenes (`scenes/`), whose small files join the seeds.
    pub shared_scenes: Option<PathBuf>,
    /// Print a progress line this often.
    pub progress: Option<Duration>,
}

/// A finding of a campaign: its kind and where, how often, and the first input's file.
#[derive(Clone, Debug)]
pub struct Finding {
    /// e.g. `panic at render/src/scene/ply.rs:120`, or a contained panic's location.
    pub signature: String,
    /// The first message.
    pub message: String,
    /// Inputs that gave it.
    pub count: u64,
    /// The first input, as written.
    pub file: PathBuf,
}

/// What a campaign did.
#[derive(Clone, Debug)]
pub struct CampaignReport {
    /// Target name.
    pub target: String,
    /// Its seed.
    pub seed: u64,
    /// Inputs run.
    pub executions: u64,
    /// Wall time.
    pub elapsed: Duration,
    /// Inputs accepted.
    pub accepted: u64,
    /// Distinct outcomes ([`outcome_kind`] of each refusal, plus acceptance).
    pub distinct_outcomes: usize,
    /// The distinct outcomes, sorted.
    pub outcome_kinds: Vec<String>,
    /// Seed inputs, and the corpus size at the end.
    pub corpus: (usize, usize),
    /// Bugs (files `crash-<hash>`).
    pub crashes: Vec<Finding>,
    /// Panics in dependencies contained by a loader (files `contained-<hash>`).
    pub contained: Vec<Finding>,
}

impl CampaignReport {
    /// One line: executions, rate, outcomes, findings.
    pub fn summary(&self) -> String {
        let seconds = self.elapsed.as_secs_f64();
        format!(
            "{}: {} executions in {:.1} s ({:.0}/s), {} accepted, {} distinct outcomes, corpus {} → {}, {} crash(es), {} contained third-party panic(s)",
            self.target,
            self.executions,
            seconds,
            self.executions as f64 / seconds.max(1e-9),
            self.accepted,
            self.distinct_outcomes,
            self.corpus.0,
            self.corpus.1,
            self.crashes.len(),
            self.contained.len()
        )
    }
}

/// What the watchdog and the allocation guard need to report the running input.
struct Running {
    input: Vec<u8>,
    folder: PathBuf,
}

/// The running input (written on a hang or a huge allocation).
static RUNNING: Mutex<Option<Running>> = Mutex::new(None);
/// Milliseconds since [`clock`]'s start when the current input started, 0 between inputs.
static STARTED_MS: AtomicU64 = AtomicU64::new(0);
/// One campaign at a time per process (the statics above are shared).
static ONE_CAMPAIGN: Mutex<()> = Mutex::new(());

fn clock() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_millis() as u64 + 1
}

/// Writes `input` as `<folder>/<kind>-<hash>`; returns the path.
fn write_finding(folder: &Path, kind: &str, input: &[u8]) -> PathBuf {
    let path = folder.join(format!("{kind}-{:016x}", fnv64(input)));
    if let Err(error) = std::fs::create_dir_all(folder).and_then(|()| strata_files::write_whole(&path, input)) {
        eprintln!("fuzz: cannot write {}: {error}", path.display());
    }
    path
}

/// Writes the running input as a `kind` finding, says `what`, and exits with `status`.
fn report_running_and_exit(kind: &str, what: String, status: i32) -> ! {
    let written = match RUNNING.try_lock() {
        Ok(guard) => guard.as_ref().map(|r| write_finding(&r.folder, kind, &r.input)),
        Err(_) => None,
    };
    match written {
        Some(path) => eprintln!("fuzz: {what}: input written to {}", path.display()),
        None => eprintln!("fuzz: {what} (the input could not be saved)"),
    }
    std::process::exit(status)
}

/// Called by [`super::GuardedAllocator`] on an allocation over the limit (registered
/// with [`super::alloc::on_huge_allocation`] when a campaign starts).
fn report_huge_allocation(size: usize) {
    let backtrace = std::backtrace::Backtrace::force_capture().to_string();
    let ours: Vec<&str> = backtrace.lines().filter(|l| l.contains(" at ") && !l.contains("/rustc/")).take(8).collect();
    eprintln!("fuzz: where the allocation was made:\n{}", ours.join("\n"));
    report_running_and_exit("huge", format!("one allocation of {size} bytes (over the campaign's limit)"), 3)
}

/// Runs `campaign` on `target` until its execution count or duration is reached. A hang
/// or a huge allocation ends the process (status 2 or 3) after writing the input.
pub fn run_campaign(target: &dyn Target, campaign: &Campaign) -> CampaignReport {
    let _one = ONE_CAMPAIGN.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let folder = campaign.crash_dir.join(target.name());
    let seeds = target.seeds(campaign.shared_scenes.as_deref());
    assert!(!seeds.is_empty(), "{}: no seeds", target.name());
    let mut corpus: Vec<Vec<u8>> = seeds.iter().map(|s| s[..s.len().min(MAX_INPUT)].to_vec()).collect();
    let seed_count = corpus.len();
    let mut rng = FuzzRng::seed_from_u64(campaign.seed ^ fnv64(target.name().as_bytes()));
    let mut outcomes: HashSet<String> = HashSet::new();
    let mut crashes: BTreeMap<String, Finding> = BTreeMap::new();
    let mut contained: BTreeMap<String, Finding> = BTreeMap::new();
    let (mut executions, mut accepted) = (0u64, 0u64);

    *RUNNING.lock().unwrap_or_else(std::sync::PoisonError::into_inner) =
        Some(Running { input: Vec::new(), folder: folder.clone() });
    let stop = AtomicBool::new(false);
    let hang_ms = campaign.hang_after.as_millis() as u64;
    let started = Instant::now();
    super::alloc::on_huge_allocation(report_huge_allocation);
    let previous_limit = super::alloc::set_allocation_limit(0);
    std::thread::scope(|scope| {
        scope.spawn(|| {
            while !stop.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(50));
                let at = STARTED_MS.load(Ordering::SeqCst);
                if at != 0 && clock().saturating_sub(at) > hang_ms {
                    super::alloc::set_allocation_limit(0);
                    report_running_and_exit("hang", format!("an input ran longer than {hang_ms} ms"), 2);
                }
            }
        });
        // Run the seeds first, then mutants.
        let mut next_progress = campaign.progress.map(|p| started + p);
        loop {
            if campaign.executions.is_some_and(|n| executions >= n)
                || campaign.duration.is_some_and(|d| started.elapsed() >= d)
            {
                break;
            }
            let input = if (executions as usize) < seed_count {
                corpus[executions as usize].clone()
            } else {
                next_input(target, &mut rng, &corpus, seed_count)
            };
            {
                let mut running = RUNNING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                if let Some(running) = running.as_mut() {
                    running.input.clear();
                    running.input.extend_from_slice(&input);
                }
            }
            super::alloc::set_allocation_limit(campaign.allocation_limit);
            STARTED_MS.store(clock(), Ordering::SeqCst);
            let verdict = execute(target, &input);
            STARTED_MS.store(0, Ordering::SeqCst);
            super::alloc::set_allocation_limit(0);
            executions += 1;
            let kind = match &verdict {
                Verdict::Accepted => {
                    accepted += 1;
                    "accepted".to_string()
                }
                Verdict::Noted(remark) => {
                    accepted += 1;
                    format!("accepted: {}", outcome_kind(remark))
                }
                Verdict::Refused(message) => outcome_kind(message),
                Verdict::Contained { location, message } => {
                    let finding = contained.entry(location.clone()).or_insert_with(|| Finding {
                        signature: location.clone(),
                        message: message.clone(),
                        count: 0,
                        file: write_finding(&folder, "contained", &input),
                    });
                    finding.count += 1;
                    format!("contained {location}")
                }
                Verdict::Crash { signature, message } => {
                    let finding = crashes.entry(signature.clone()).or_insert_with(|| {
                        let file = write_finding(&folder, "crash", &input);
                        eprintln!(
                            "fuzz: {}: {signature}: {message}: input written to {}",
                            target.name(),
                            file.display()
                        );
                        Finding { signature: signature.clone(), message: message.clone(), count: 0, file }
                    });
                    finding.count += 1;
                    signature.clone()
                }
            };
            // New outcomes join the corpus, and one accepted input in 16 (valid files that
            // differ from the seeds reach deepest).
            let keep = outcomes.insert(kind.clone()) || (kind == "accepted" && rng.random_range(0..16) == 0);
            if keep && (executions as usize) > seed_count {
                if corpus.len() < seed_count + MAX_CORPUS {
                    corpus.push(input);
                } else {
                    let slot = seed_count + rng.random_range(0..MAX_CORPUS);
                    corpus[slot] = input;
                }
            }
            if let Some(at) = next_progress
                && Instant::now() >= at
            {
                eprintln!(
                    "fuzz: {}: {executions} executions, {:.0} s, {} outcomes, {} crash(es)",
                    target.name(),
                    started.elapsed().as_secs_f64(),
                    outcomes.len(),
                    crashes.len()
                );
                next_progress = campaign.progress.map(|p| at + p);
            }
        }
        stop.store(true, Ordering::Relaxed);
    });
    super::alloc::set_allocation_limit(previous_limit);
    *RUNNING.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = None;
    CampaignReport {
        target: target.name().into(),
        seed: campaign.seed,
        executions,
        elapsed: started.elapsed(),
        accepted,
        distinct_outcomes: outcomes.len(),
        outcome_kinds: {
            let mut kinds: Vec<String> = outcomes.into_iter().collect();
            kinds.sort();
            kinds
        },
        corpus: (seed_count, corpus.len()),
        crashes: crashes.into_values().collect(),
        contained: contained.into_values().collect(),
    }
}

/// A fresh input: one generated from random bytes (1 in 16), or a corpus input (a seed
/// one time in four) with one to four stacked mutations, half of them the target's
/// structure-aware ones.
fn next_input(target: &dyn Target, rng: &mut FuzzRng, corpus: &[Vec<u8>], seeds: usize) -> Vec<u8> {
    if rng.random_range(0..16) == 0 {
        let raw: Vec<u8> = (0..rng.random_range(16..4096)).map(|_| rng.random()).collect();
        if let Ok(input) = target.generate(&mut arbitrary::Unstructured::new(&raw)) {
            return input;
        }
    }
    // A seed one time in four (the corpus fills with refused inputs), else any input.
    let pick = if rng.random_range(0..4) == 0 { rng.random_range(0..seeds) } else { rng.random_range(0..corpus.len()) };
    let mut input = corpus[pick].clone();
    let stacked = 1 + rng.random_range(0..4usize).saturating_sub(1);
    for _ in 0..stacked {
        if rng.random_bool(0.5)
            && let Some(mutant) = target.mutate(rng, &input)
        {
            input = mutant;
            continue;
        }
        let other = &corpus[rng.random_range(0..corpus.len())];
        mutate_bytes(rng, &mut input, other);
    }
    input.truncate(MAX_INPUT);
    input
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcome_kinds_blur_values_and_keep_fields() {
        assert_eq!(
            outcome_kind("a.json: field `camera.fov_deg`: 1e39 must lie in (0, 180)"),
            "(file).json: field `camera.fov_deg`: #e# must lie in (#, #)"
        );
        assert_eq!(outcome_kind("unknown variant `x!y`, expected"), "unknown variant `…`, expected");
        assert_eq!(outcome_kind("line 3: unknown method `foo`"), "line #: unknown method `…`");
        assert_eq!(
            outcome_kind("f: field `.`: invalid type: string \"ab\", expected"),
            "(file).: field `.`: invalid type: string `…`, expected"
        );
    }
}
