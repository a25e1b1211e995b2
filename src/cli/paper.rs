//! `dicephys paper`: the main job. Reproduces the paper end to end and writes a report.

use super::args::parse_engine;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::paper::{self, PaperConfig};
use crate::roll::DEFAULT_MAX_STEPS;
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct PaperArgs {
    /// Rolls per simulated cell (block × engine × 2D/3D); 100000 is the paper's own scale.
    #[arg(long, default_value_t = 10000)]
    pub rolls: u64,
    /// Seed of the keyed throws.
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    /// Engines to simulate with (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "bullet,rapier", value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Fixed time step, s.
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = DEFAULT_MAX_STEPS)]
    pub max_steps: u64,
    /// Output directory.
    #[arg(long, default_value = "paper-out")]
    pub out: PathBuf,
    /// DicePhys exactly as the paper ran it (its rest rule, every flight step stepped) instead
    /// of the exact early stop and closed-form flight.
    #[arg(long)]
    pub faithful: bool,
    /// Print results.json to stdout too (and no progress bar).
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &PaperArgs) -> Result<()> {
    if a.rolls == 0 {
        return Err(Error::Usage("--rolls 0: need at least one roll".into()));
    }
    if !(a.dt.is_finite() && a.dt > 0.0 && a.dt <= 0.1) {
        return Err(Error::Usage(format!(
            "--dt {}: must be in (0, 0.1] s",
            a.dt
        )));
    }
    if a.max_steps == 0 || a.engines.is_empty() {
        return Err(Error::Usage(
            "--max-steps and --engines must not be empty or 0".into(),
        ));
    }
    std::fs::create_dir_all(&a.out)
        .map_err(|e| Error::Usage(format!("--out {}: cannot create it ({e})", a.out.display())))?;
    super::check_writable(&a.out.join("results.json"))?;
    let threads = if a.threads == 0 {
        rayon::current_num_threads()
    } else {
        a.threads
    };
    let mut engines = a.engines.clone();
    engines.dedup();
    let cfg = PaperConfig {
        rolls: a.rolls,
        seed: a.seed,
        engines,
        dt: a.dt,
        threads,
        max_steps: a.max_steps,
        faithful: a.faithful,
    };
    let total = paper::total_rolls(&cfg)?;
    let bar = if a.json || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{wide_bar}] {pos}/{len} rolls, ETA {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    };
    let command_line = std::env::args().collect::<Vec<_>>().join(" ");
    // Cells are rolled in checkpointed chunks under --out/checkpoint: the same command run
    // again (after a crash or Ctrl-C) continues where it stopped.
    let ck = a.out.join("checkpoint");
    let key = serde_json::to_string(&PaperConfig {
        threads: 0,
        ..cfg.clone()
    })
    .map_err(|e| Error::Run(e.to_string()))?;
    let key_file = ck.join("config.json");
    if std::fs::read_to_string(&key_file).ok().as_deref() != Some(key.as_str()) {
        if ck.exists() {
            eprintln!(
                "dicephys: {} held another configuration; starting afresh",
                ck.display()
            );
            std::fs::remove_dir_all(&ck)?;
        }
        std::fs::create_dir_all(&ck)?;
        super::write_atomic(&key_file, key.as_bytes())?;
    }
    let res = paper::run(&cfg, command_line, Some(&ck), &|n| bar.set_position(n))?;
    bar.finish_and_clear();
    let figures = crate::paper::write_figures(&a.out, &res)?;
    let json = serde_json::to_string_pretty(&res).map_err(|e| Error::Run(e.to_string()))?;
    super::write_atomic(&a.out.join("results.json"), json.as_bytes())?;
    super::write_atomic(
        &a.out.join("results.csv"),
        paper::results_csv(&res).as_bytes(),
    )?;
    let md = paper::report_markdown(&res, &figures);
    super::write_atomic(&a.out.join("report.md"), md.as_bytes())?;
    if a.json {
        println!("{json}");
    } else {
        println!("{md}");
        eprintln!(
            "wrote {}/report.md, results.json, results.csv and figures",
            a.out.display()
        );
    }
    Ok(())
}
