//! `cargo xtask fuzz`: runs the loaders' fuzz targets (`strata_check::fuzz`) one after
//! another and prints each campaign's figures; exits non-zero naming the input files of
//! any crash. A hang or a huge allocation ends the process at once (status 2 or 3), after
//! writing the input. The evaluation's reader, which strata-check does not link, is
//! handed in here ([`readers`]).

use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use std::time::Duration;
use strata_check::fuzz::{self, Campaign};

/// One allocation over this many bytes during an input is a finding.
const ALLOCATION_LIMIT: usize = 1 << 30;

/// `cargo xtask fuzz`'s arguments.
#[derive(clap::Args)]
pub struct FuzzArgs {
    /// Only these targets (comma-separated): scene-json, ply, gltf, obj, exr, errors-csv.
    #[arg(long, value_delimiter = ',')]
    target: Vec<String>,
    /// Seconds per target (default 10 when --executions is not given either).
    #[arg(long)]
    seconds: Option<u64>,
    /// Executions per target (the campaign stops at whichever limit comes first).
    #[arg(long)]
    executions: Option<u64>,
    /// Generator seed: the same seed runs the same inputs.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Where findings are written (`DIR/<target>/crash-<hash>`, `hang-`, `huge-`, `contained-`).
    #[arg(long)]
    crash_dir: Option<PathBuf>,
    /// An input running longer than this many milliseconds is a hang.
    #[arg(long, default_value_t = 2000)]
    hang_ms: u64,
    /// Leave out the shared scenes' files as seeds (only seeds written in code).
    #[arg(long)]
    no_shared: bool,
    /// Write each target's distinct outcomes to `DIR/<target>.txt`.
    #[arg(long)]
    outcomes: Option<PathBuf>,
}

/// The readers of the host crate that the harness fuzzes: `errors.csv`'s.
pub fn readers() -> fuzz::Readers {
    fuzz::Readers {
        errors_csv: |text| {
            let rows = strata::evaluation::compare::parse_errors_csv(text)?;
            Ok(rows.iter().map(|e| [e.relmse, e.prelmse, e.mse, e.relmse_luminance.unwrap_or(0.0)]).collect())
        },
    }
}

/// Runs the campaigns of `args`.
pub fn fuzz(args: FuzzArgs) -> Result<()> {
    let targets = fuzz::targets(readers());
    let names: Vec<&str> = targets.iter().map(|t| t.name()).collect();
    if let Some(unknown) = args.target.iter().find(|t| !names.contains(&t.as_str())) {
        bail!("--target {unknown}: no such fuzz target (targets: {})", names.join(", "));
    }
    let seconds = match (args.seconds, args.executions) {
        (None, None) => Some(10),
        (seconds, _) => seconds,
    };
    let campaign = Campaign {
        seed: args.seed,
        executions: args.executions,
        duration: seconds.map(Duration::from_secs),
        crash_dir: args.crash_dir.unwrap_or_else(fuzz::findings_folder),
        hang_after: Duration::from_millis(args.hang_ms),
        allocation_limit: ALLOCATION_LIMIT,
        shared_scenes: if args.no_shared { None } else { fuzz::shared_scenes() },
        progress: Some(Duration::from_secs(30)),
    };
    println!(
        "fuzz: seed {}, {}, seeds from code{}",
        campaign.seed,
        match (campaign.executions, campaign.duration) {
            (Some(n), Some(d)) => format!("{n} executions or {} s per target", d.as_secs()),
            (Some(n), None) => format!("{n} executions per target"),
            (None, Some(d)) => format!("{} s per target", d.as_secs()),
            (None, None) => unreachable!("a limit is always set"),
        },
        match &campaign.shared_scenes {
            Some(folder) => format!(" and {}", folder.display()),
            None => String::new(),
        }
    );
    let mut crashed = Vec::new();
    for target in targets.iter().filter(|t| args.target.is_empty() || args.target.iter().any(|n| n == t.name())) {
        let report = fuzz::run_campaign(target.as_ref(), &campaign);
        println!("{}", report.summary());
        if let Some(folder) = &args.outcomes {
            std::fs::create_dir_all(folder)?;
            let file = folder.join(format!("{}.txt", report.target));
            strata_files::write_whole(&file, (report.outcome_kinds.join("\n") + "\n").as_bytes())
                .with_context(|| format!("{}: cannot write", file.display()))?;
        }
        for finding in &report.contained {
            println!(
                "  contained ×{}: {}: {} ({})",
                finding.count,
                finding.signature,
                finding.message,
                finding.file.display()
            );
        }
        for finding in &report.crashes {
            println!(
                "  CRASH ×{}: {}: {} ({})",
                finding.count,
                finding.signature,
                finding.message,
                finding.file.display()
            );
            crashed.push(finding.file.display().to_string());
        }
    }
    if !crashed.is_empty() {
        bail!("{} crash(es); inputs: {}", crashed.len(), crashed.join(", "));
    }
    Ok(())
}
