//! The command line: a thin layer over the library. Each subcommand has a module of its own.

use crate::error::{Error, Result};
use clap::{Parser, Subcommand};
use std::path::Path;

pub mod args;
pub mod bench;
pub mod crosscheck;
pub mod merge;
pub mod paper;
pub mod roll;
pub mod runargs;
pub mod sweeps;
pub mod theory;
pub mod trace;

#[derive(Parser, Debug)]
#[command(
    name = "dicephys",
    version,
    about = "With what probability does a thrown cuboid die land on each face? \
             Simulation (Bullet, Rapier) beside the theory and data of Pender & Uhrin (2014)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Speed of each engine and lever against the faithful configuration, side by side.
    Bench(bench::BenchArgs),
    /// The same throws on several engines: counts, ratios, σ apart, per-throw agreement, cost.
    Crosscheck(crosscheck::CrosscheckArgs),
    /// The paper's convergence test: the ratio against dt per block, engine, 2D/3D.
    Converge(sweeps::ConvergeArgs),
    /// Combine the --json outputs of `roll --shard K/N` runs into the unsharded result.
    Merge(merge::MergeArgs),
    /// Where engines fail: unconverged, unknown, non-finite, tunnelled, energy gain by cell.
    Stability(sweeps::StabilityArgs),
    /// Accuracy against cost across methods, with the Pareto front.
    Tradeoff(sweeps::TradeoffArgs),
    /// Reproduce the paper: its table, theory, simulations and figures, into --out.
    Paper(paper::PaperArgs),
    /// The paper's closed-form theory for a block, or its whole experimental table.
    Theory(theory::TheoryArgs),
    /// Roll one block many times on one engine: counts, ratio, theory, cost.
    Roll(roll::RollArgs),
    /// One throw's trajectory as CSV (step, time, position, orientation, velocities, energy).
    Trace(trace::TraceArgs),
}

/// Runs the command line; returns the process exit code (0 ok, 2 bad input, 1 failure).
pub fn main() -> i32 {
    // Ctrl-C: the first asks long runs to stop cleanly between chunks (they keep their
    // checkpoint and print a partial report); a second ends the process at once.
    let _ = ctrlc::set_handler(|| {
        if crate::checkpoint::STOP.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("dicephys: stopping after the current chunk (Ctrl-C again to quit now)");
    });
    let argv = match resume_argv(std::env::args().collect()) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("dicephys: {e}");
            return e.exit_code();
        }
    };
    let _ = runargs::EFFECTIVE.set(argv.clone());
    let cli = match Cli::try_parse_from(argv) {
        Ok(cli) => cli,
        Err(e) => return clap_error(e),
    };
    let result = match cli.command {
        Command::Bench(a) => bench::run(&a),
        Command::Converge(a) => sweeps::converge(&a),
        Command::Crosscheck(a) => crosscheck::run(&a),
        Command::Stability(a) => sweeps::stability(&a),
        Command::Tradeoff(a) => sweeps::tradeoff(&a),
        Command::Merge(a) => merge::run(&a),
        Command::Paper(a) => paper::run(&a),
        Command::Theory(a) => theory::run(&a),
        Command::Roll(a) => roll::run(&a),
        Command::Trace(a) => trace::run(&a),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("dicephys: {e}");
            e.exit_code()
        }
    }
}

/// Help and version go to stdout as clap prints them; any other parse error becomes one
/// line on stderr and exit code 2.
fn clap_error(e: clap::Error) -> i32 {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            0
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            2
        }
        _ => {
            // clap's message is its first paragraph (some, like a missing argument, span two
            // lines); join it into one line and leave out the usage and help hints after it.
            let text = e.render().to_string();
            let paragraph: Vec<&str> = text
                .lines()
                .map(str::trim)
                .skip_while(|l| l.is_empty())
                .take_while(|l| !l.is_empty())
                .collect();
            let line = paragraph.join(" ");
            let line = line.trim_start_matches("error: ");
            let line = if line.is_empty() {
                "bad command line"
            } else {
                line
            };
            eprintln!("dicephys: {line}");
            2
        }
    }
}

/// Fails early, before any simulation, if `path` cannot be written.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(Error::Usage(format!(
            "{}: directory {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    let probe = dir.join(format!(".dicephys-probe-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| Error::Usage(format!("{}: cannot write there ({e})", path.display())))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// Writes a whole file or nothing: a temporary file beside it, then a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::checkpoint::write_atomic(path, bytes)
        .map_err(|e| Error::Run(format!("{}: {e}", path.display())))
}

/// `dicephys roll --resume DIR [--threads T] [--json]` becomes the stored run's own command
/// line with `--checkpoint DIR`, so a resumed run is configured exactly as it started.
fn resume_argv(argv: Vec<String>) -> Result<Vec<String>> {
    let Some(pos) = argv
        .iter()
        .position(|a| a == "--resume" || a.starts_with("--resume="))
    else {
        return Ok(argv);
    };
    if argv.get(1).map(String::as_str) != Some("roll") {
        return Err(Error::Usage(
            "--resume: only `dicephys roll --resume DIR` resumes".into(),
        ));
    }
    let dir = match argv[pos].split_once('=') {
        Some((_, d)) => d.to_string(),
        None => argv
            .get(pos + 1)
            .cloned()
            .ok_or_else(|| Error::Usage("--resume: name the checkpoint directory".into()))?,
    };
    let file = Path::new(&dir).join("args.json");
    let text = std::fs::read_to_string(&file).map_err(|e| {
        Error::Usage(format!(
            "--resume {dir}: no checkpoint there ({}: {e})",
            file.display()
        ))
    })?;
    let stored: Vec<String> = serde_json::from_str(&text).map_err(|e| {
        Error::Usage(format!(
            "--resume {dir}: {} is damaged ({e})",
            file.display()
        ))
    })?;
    let extra = runargs::without(&argv[2..], &[("--resume", true)]);
    let allowed = runargs::without(
        &extra,
        &[("--threads", true), ("--json", false), ("--per-roll", true)],
    );
    if !allowed.is_empty() {
        return Err(Error::Usage(format!(
            "--resume takes only --threads, --json and --per-roll besides, not {}",
            allowed.join(" ")
        )));
    }
    let mut out = vec![argv[0].clone(), "roll".to_string()];
    out.extend(stored);
    out.extend(extra);
    out.push("--checkpoint".into());
    out.push(dir);
    Ok(out)
}
