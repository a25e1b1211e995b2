//! `dicephys paper`: the main job. Reproduces the paper end to end and writes a report.

use super::args::parse_engine;
use super::error::{Error, Result};
use super::outln;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::paper as report;
use dicephys::sim::roll::DEFAULT_MAX_STEPS;
use dicephys::studies::paper::{self, PaperConfig};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

/// `dicephys paper`'s arguments.
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
    /// Fixed time step, s or 1/N.
    #[arg(long, default_value = "0.001", value_parser = super::args::parse_step)]
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
    /// All 19 rows simulated with e, μ (per surface) and the throw's κ fitted to the counts;
    /// every row predicted by a fit without it, beside the theory; the models compared; the
    /// method checked (calibrated.md, calibrated.json and figures in --out). --dt is the fit's
    /// step; --rolls and --engines are not used.
    #[arg(long)]
    pub calibrated: bool,
    /// With --calibrated: parameter points each block is simulated at, per pass.
    #[arg(long, default_value_t = 64)]
    pub points: usize,
    /// With --calibrated: rolls at each point.
    #[arg(long, default_value_t = 500)]
    pub point_rolls: u64,
    /// With --calibrated: the method check's reference step, s or 1/N.
    #[arg(long, default_value = "1/5000", value_parser = super::args::parse_step)]
    pub reference_dt: f64,
    /// With --calibrated: throws per block in the method check.
    #[arg(long, default_value_t = 4000)]
    pub check_rolls: u64,
}

/// Runs `dicephys paper --calibrated`.
fn calibrated(a: &PaperArgs) -> Result<()> {
    use dicephys::calibration::design::DesignSpec;
    use dicephys::calibration::estimate::Search;
    use dicephys::calibration::params::Method;
    use dicephys::report::fit as fit_report;
    use dicephys::studies::calibrated::{self, CalibratedConfig};
    let cfg = CalibratedConfig {
        method: Method {
            engine: EngineKind::Bullet,
            dt: a.dt,
            max_steps: a.max_steps,
        },
        design: DesignSpec {
            points: a.points,
            rolls: a.point_rolls,
            ..DesignSpec::default()
        },
        search: Search {
            seed: a.seed,
            ..Search::default()
        },
        seed: a.seed,
        check_rolls: a.check_rolls,
        reference_dt: a.reference_dt,
    };
    if a.check_rolls < 2 || a.check_rolls > dicephys::run::spec::MAX_ROLLS {
        return Err(Error::Usage(format!(
            "--check-rolls {}: from 2 to {}",
            a.check_rolls,
            dicephys::run::spec::MAX_ROLLS
        )));
    }
    let threads = super::args::threads(a.threads)?;
    std::fs::create_dir_all(&a.out)
        .map_err(|e| Error::Usage(format!("--out {}: cannot create it ({e})", a.out.display())))?;
    let outputs = [
        super::output(&a.out.join("calibrated.json"))?,
        super::output(&a.out.join("calibrated.md"))?,
    ];
    // Both passes roll about as much as the first.
    let total = 2 * calibrated::first_pass_rolls(&cfg)?;
    let bar = if a.json || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{wide_bar}] {pos}/~{len} rolls, ETA {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    };
    let command_line = std::env::args().collect::<Vec<_>>().join(" ");
    let cells = a.out.join("calibration");
    let progress = |n| bar.set_position(n);
    let runner = super::runner(threads);
    let res = calibrated::run(&cfg, command_line, &runner.with_progress(&progress), Some(&cells))?;
    bar.finish_and_clear();
    let Some(res) = res else {
        return Err(Error::Interrupted(format!(
            "interrupted; {} kept what was rolled: run the same command to continue",
            cells.display()
        )));
    };
    let figures = fit_report::write_calibrated_figures(&a.out, &res)?;
    let md = fit_report::calibrated_markdown(&res, &figures);
    let json = serde_json::to_string_pretty(&res).map_err(|e| Error::Run(e.to_string()))?;
    outputs[0].write(json.as_bytes())?;
    outputs[1].write(md.as_bytes())?;
    if a.json {
        outln!("{json}");
    } else {
        outln!("{md}");
        eprintln!(
            "wrote {}/calibrated.md, calibrated.json and figures",
            a.out.display()
        );
    }
    Ok(())
}

/// Runs `dicephys paper`.
pub fn run(a: &PaperArgs) -> Result<()> {
    if a.calibrated {
        return calibrated(a);
    }
    let mut engines = a.engines.clone();
    engines.dedup();
    let cfg = PaperConfig {
        rolls: a.rolls,
        seed: a.seed,
        engines,
        dt: a.dt,
        max_steps: a.max_steps,
        faithful: a.faithful,
    };
    cfg.validate()?;
    let threads = super::args::threads(a.threads)?;
    std::fs::create_dir_all(&a.out)
        .map_err(|e| Error::Usage(format!("--out {}: cannot create it ({e})", a.out.display())))?;
    let outputs = [
        super::output(&a.out.join("results.json"))?,
        super::output(&a.out.join("results.csv"))?,
        super::output(&a.out.join("report.md"))?,
    ];
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
    let command_line = super::command_line()
        .get_or_init(|| std::env::args().collect::<Vec<_>>().join(" "))
        .clone();
    // Cells are rolled in checkpointed chunks under --out/checkpoint, each cell's directory
    // bound to its run's specification: the same command run again (after a crash or Ctrl-C)
    // continues where it stopped.
    let ck = a.out.join("checkpoint");
    let progress = |n| bar.set_position(n);
    let runner = super::runner(threads);
    let res = paper::run(
        &cfg,
        command_line,
        &runner.with_progress(&progress),
        Some(&ck),
    )?;
    bar.finish_and_clear();
    if super::is_task() {
        // A cluster task's share: its chunks are kept for the finishing job; nothing to report.
        return Ok(());
    }
    let md = report::report_markdown(&res, &["master_graph", "prob_2d", "len_graph", "dreidel"]);
    if res.partial {
        // A partial run leaves the last complete outputs alone: its report goes to stdout.
        outln!("{md}");
        return Err(Error::Interrupted(format!(
            "interrupted; {} kept what was rolled: run the same command to continue",
            ck.display()
        )));
    }
    let figures = report::write_figures(&a.out, &res)?;
    let md = report::report_markdown(&res, &figures);
    let json = serde_json::to_string_pretty(&res).map_err(|e| Error::Run(e.to_string()))?;
    outputs[0].write(json.as_bytes())?;
    outputs[1].write(report::results_csv(&res)?.as_bytes())?;
    outputs[2].write(md.as_bytes())?;
    if a.json {
        outln!("{json}");
    } else {
        outln!("{md}");
        eprintln!(
            "wrote {}/report.md, results.json, results.csv and figures",
            a.out.display()
        );
    }
    Ok(())
}
