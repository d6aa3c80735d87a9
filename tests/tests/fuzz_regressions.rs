//! The loaders' fuzz harness under `cargo test`: every committed finding
//! (`tests/data/fuzz/<target>/`) gives an error now, not a panic, a hang or a huge
//! allocation; and a short fixed-seed campaign of every target (from the seeds written in
//! code, so that it runs the same with or without the scene files) finds nothing. The long campaigns
//! are `cargo xtask fuzz`; RELIABILITY.md has their figures.

use std::time::{Duration, Instant};
use strata::evaluation::compare::{FrameError, errors_csv, parse_errors_csv};
use strata_check::fuzz::{self, Campaign, GuardedAllocator, Readers, Verdict};

/// One allocation over the campaign's limit is a finding (the process exits naming it).
#[global_allocator]
static ALLOCATOR: GuardedAllocator = GuardedAllocator;

/// One allocation over this many bytes is a finding.
const ALLOCATION_LIMIT: usize = 1 << 30;

/// The evaluation's reader, which strata-check does not link (as `cargo xtask fuzz` hands
/// it in).
fn readers() -> Readers {
    Readers {
        errors_csv: |text| {
            let rows = parse_errors_csv(text)?;
            Ok(rows.iter().map(|e| [e.relmse, e.prelmse, e.mse, e.relmse_luminance.unwrap_or(0.0)]).collect())
        },
    }
}

/// `errors-csv`'s seeds, written in strata-check as text, are accepted by the reader it is
/// handed, and the complete grid is byte for byte what `strata compare` writes for it.
#[test]
fn errors_csv_seeds_are_what_compare_writes() {
    let target = fuzz::targets(readers()).into_iter().find(|t| t.name() == "errors-csv").unwrap();
    let seeds = target.seeds(None);
    for (index, seed) in seeds.iter().enumerate() {
        assert_eq!(fuzz::execute(target.as_ref(), seed), Verdict::Accepted, "seed {index}");
    }
    let grid = std::str::from_utf8(&seeds[0]).unwrap();
    let rows: Vec<FrameError> = parse_errors_csv(grid).unwrap();
    assert_eq!(errors_csv(&rows), grid);
}

#[test]
fn every_committed_finding_is_now_refused_cleanly() {
    let folder = fuzz::findings_folder();
    let previous = fuzz::set_allocation_limit(ALLOCATION_LIMIT);
    let results = fuzz::replay_findings(&folder, readers(), Duration::from_secs(20)).unwrap();
    fuzz::set_allocation_limit(previous);
    assert!(results.len() >= 20, "{}: only {} findings", folder.display(), results.len());
    let mut failures = Vec::new();
    for (file, verdict) in &results {
        let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        let fine = match verdict {
            Verdict::Accepted | Verdict::Noted(_) | Verdict::Refused(_) => true,
            // A panic inside a dependency that the loader turns into an error: allowed only
            // for the inputs committed as such (debug-build overflow checks in `exr`'s B44
            // decoder); what was a crash must now be refused before the dependency panics.
            Verdict::Contained { .. } => name.starts_with("contained-"),
            Verdict::Crash { .. } => false,
        };
        if !fine {
            failures.push(format!("{}: {verdict:?}", file.display()));
        }
    }
    assert!(failures.is_empty(), "findings that still break a loader:\n{}", failures.join("\n"));
}

#[test]
fn a_short_fixed_seed_campaign_of_every_target_finds_nothing() {
    let crash_dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-fuzz-findings-{}", std::process::id()));
    let started = Instant::now();
    let mut failures = Vec::new();
    for target in fuzz::targets(readers()) {
        // About a second each in a debug build.
        let executions = match target.name() {
            "gltf" => 5000,
            "scene-json" => 6000,
            "exr" => 8000,
            "errors-csv" => 40_000,
            _ => 20_000,
        };
        let campaign = Campaign {
            seed: 20250101,
            executions: Some(executions),
            duration: None,
            crash_dir: crash_dir.clone(),
            hang_after: Duration::from_secs(20),
            allocation_limit: ALLOCATION_LIMIT,
            shared_scenes: None,
            progress: None,
        };
        let report = fuzz::run_campaign(target.as_ref(), &campaign);
        eprintln!("{}", report.summary());
        assert_eq!(report.executions, executions);
        assert!(report.distinct_outcomes > 5, "{}: the mutants reach too little", report.summary());
        for finding in &report.crashes {
            failures.push(format!(
                "{}: {} ×{}: {} (input: {})",
                report.target,
                finding.signature,
                finding.count,
                finding.message,
                finding.file.display()
            ));
        }
    }
    eprintln!("every target: {:.1} s", started.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "the fixed-seed campaign found:\n{}", failures.join("\n"));
    let _ = std::fs::remove_dir_all(&crash_dir);
}

/// The same seed runs the same inputs: two short campaigns agree on every figure.
#[test]
fn a_campaign_is_deterministic_from_its_seed() {
    let target = fuzz::targets(readers()).into_iter().find(|t| t.name() == "ply").unwrap();
    let campaign = |seed| Campaign {
        seed,
        executions: Some(2000),
        duration: None,
        crash_dir: std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("strata-fuzz-determinism-{}", std::process::id())),
        hang_after: Duration::from_secs(20),
        allocation_limit: 0,
        shared_scenes: None,
        progress: None,
    };
    let run = |seed| fuzz::run_campaign(target.as_ref(), &campaign(seed));
    let (a, b, c) = (run(7), run(7), run(8));
    assert_eq!((a.accepted, &a.outcome_kinds, a.corpus), (b.accepted, &b.outcome_kinds, b.corpus));
    assert_ne!(a.outcome_kinds, c.outcome_kinds);
}
