//! `dicephys converge`, `tradeoff` and `stability`: the sweeps (`dicephys::studies::sweep`), each writing
//! `<command>.json`, `report.md` and its figures into --out.

use super::args::{parse_block, parse_engine};
use super::error::{Error, Result};
use super::outln;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::model::block::Block;
use dicephys::report;
use dicephys::report::text::dt_label;
use dicephys::studies::sweep::{parse_dt, Study};
use dicephys::studies::{converge, stability, tradeoff};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// Blocks, LENGTHxBREADTHxWIDTH in mm (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "140x24x20,140x22x13,140x30x10", value_parser = parse_block)]
    pub blocks: Vec<Block>,
    /// Time steps, s or 1/N (comma-separated); the paper's full set is
    /// 1/60,1/120,1/240,1/500,1/1000,1/2000,1/5000,1/10000.
    #[arg(long, value_delimiter = ',', default_value = "1/60,1/250,1/1000,1/5000", value_parser = parse_dt)]
    pub dts: Vec<f64>,
    #[arg(long, value_delimiter = ',', default_value = "bullet,rapier", value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Rolls per cell (block × engine × mode × dt).
    #[arg(long, default_value_t = 200)]
    pub rolls: u64,
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = 2_000_000)]
    pub max_steps: u64,
    /// Precision as the input, per cent at 2σ ("1" or "1%"): every cell rolled in rounds of one
    /// keyed stream until its departure from the finest dt is resolved to it (--rolls ignored).
    #[arg(long, value_parser = parse_percent)]
    pub precision: Option<f64>,
    /// With --precision: CPU seconds a cell may spend.
    #[arg(long, default_value_t = 600.0)]
    pub budget: f64,
    /// With --precision: CPU seconds the finest dt's cell may spend.
    #[arg(long, default_value_t = 1800.0)]
    pub reference_budget: f64,
    /// Roll with the exact levers (closed-form flight; the early stop at dt <= 1/250 s), shown
    /// exact at fine steps by `tradeoff`'s levers row, instead of every step stepped.
    #[arg(long)]
    pub fast: bool,
    #[arg(long, default_value = "converge-out")]
    pub out: PathBuf,
    /// Print converge.json to stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct TradeoffArgs {
    #[arg(long, default_value = "140x24x20", value_parser = parse_block)]
    pub block: Block,
    /// Bullet's time steps (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1/100,1/250,1/1000", value_parser = parse_dt)]
    pub dts: Vec<f64>,
    /// Rapier's time steps (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1/250,1/1000", value_parser = parse_dt)]
    pub rapier_dts: Vec<f64>,
    /// The reference's time step (Bullet, box floor, the exact levers).
    #[arg(long, default_value = "1/5000", value_parser = parse_dt)]
    pub reference_dt: f64,
    /// The reference's ladder: other fine steps rolled like the reference, each a departure
    /// from it (comma-separated; "none" for none).
    #[arg(long, value_delimiter = ',', default_value = DEFAULT_LADDER, value_parser = parse_dt_or_none)]
    pub ladder: Vec<Option<f64>>,
    /// The 2σ half-width asked of every departure, in per cent of the ratio ("1" or "1%").
    #[arg(long, default_value = DEFAULT_PRECISION, value_parser = parse_percent)]
    pub precision: f64,
    /// CPU seconds a method may spend before it is left unresolved.
    #[arg(long, default_value_t = 600.0)]
    pub budget: f64,
    /// CPU seconds the reference (each mode's) may spend.
    #[arg(long, default_value_t = 1800.0)]
    pub reference_budget: f64,
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    #[arg(long, default_value_t = 2_000_000)]
    pub max_steps: u64,
    #[arg(long, default_value = "tradeoff-out")]
    pub out: PathBuf,
    /// Roll the pilot (a chunk of every method, kept), print the plan (the CPU the precision
    /// asked costs, and the precision an hour buys) and stop.
    #[arg(long)]
    pub plan: bool,
    /// Roll the first ROLLS throws (in whole 1,000s) of every stream (methods, reference, its
    /// ladder and checks) into --out/checkpoint and stop, deciding nothing: what the tasks of
    /// `dicephys slurm tradeoff` do, before its finishing job runs the study, reading them back.
    #[arg(long, value_name = "ROLLS")]
    pub preroll: Option<u64>,
    #[arg(long)]
    pub json: bool,
}

/// `tradeoff`'s default precision, per cent at 2σ: what about 60 minutes on 2 cores buys at
/// the defaults (README, Speed against accuracy).
pub const DEFAULT_PRECISION: &str = "2";

/// `tradeoff`'s default ladder under the reference.
pub const DEFAULT_LADDER: &str = "1/2000,1/10000";

/// A precision in per cent, "1" or "1%", as a fraction in (0, 100 %).
pub(super) fn parse_percent(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .trim_end_matches('%')
        .trim()
        .parse()
        .map_err(|_| format!("bad precision '{s}': give per cent, e.g. 1 or 1%"))?;
    if v.is_finite() && v > 0.0 && v < 100.0 {
        Ok(v / 100.0)
    } else {
        Err(format!("precision '{s}': must be in (0, 100) %"))
    }
}

fn parse_dt_or_none(s: &str) -> std::result::Result<Option<f64>, String> {
    if s.trim() == "none" {
        Ok(None)
    } else {
        parse_dt(s).map(Some).map_err(|e| e.to_string())
    }
}

/// A progress bar on stderr in estimated CPU seconds (so its ETA weighs dear and cheap rolls
/// right), hidden for --json or when stderr is not a terminal.
pub(super) fn cpu_bar(quiet: bool) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    use std::io::IsTerminal;
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(Some(1), ProgressDrawTarget::stderr());
    b.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{wide_bar}] {percent}% of the planned CPU, ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b
}

#[derive(Args, Debug)]
pub struct StabilityArgs {
    #[arg(long, value_delimiter = ',', default_value = "bullet,rapier", value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Time steps of the dt × restitution grid.
    #[arg(long, value_delimiter = ',', default_value = "1/1000,1/240,1/60,1/30", value_parser = parse_dt)]
    pub dts: Vec<f64>,
    /// Restitutions of the grid (0 to 0.95).
    #[arg(long, value_delimiter = ',', default_value = "0,0.5,0.8,0.95")]
    pub restitutions: Vec<f64>,
    /// Frictions of the friction line (0 to 1.5).
    #[arg(long, value_delimiter = ',', default_value = "0,0.29,0.8,1.5")]
    pub frictions: Vec<f64>,
    /// Blocks of the aspect line: breadth/width up to 10, length/breadth down to 1.
    #[arg(long, value_delimiter = ',', default_value = "140x24x20,140x40x20,140x100x20,200x200x20,24x24x20", value_parser = parse_block)]
    pub blocks: Vec<Block>,
    /// Rolls per cell: 300 make a fraction's standard error at most 2.9 % and a 0 mean below
    /// 1 % at 95 %.
    #[arg(long, default_value_t = 300)]
    pub rolls: u64,
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// The step cap: a roll still moving after it is unconverged.
    #[arg(long, default_value_t = 20_000)]
    pub max_steps: u64,
    /// The box floor's thickness, m (DicePhys's 100); 0.02, a table top, lets a die at a
    /// coarse step really pass through it.
    #[arg(long, default_value_t = dicephys::model::scene::DICEPHYS_FLOOR_THICKNESS)]
    pub floor_thickness: f64,
    #[arg(long, default_value = "stability-out")]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

/// Checks what every sweep takes, creates --out, and sets up how cells are run: on these
/// threads, stopped by Ctrl-C, kept under --out/checkpoint.
pub(super) fn check_common(
    rolls: u64,
    max_steps: u64,
    t: usize,
    out: &Path,
    file: &str,
) -> Result<Study<'static>> {
    if rolls == 0 || rolls > dicephys::run::spec::MAX_ROLLS {
        return Err(Error::Usage(format!("--rolls {rolls}: must be in 1..=1e9")));
    }
    if max_steps == 0 {
        return Err(Error::Usage("--max-steps 0: need at least one step".into()));
    }
    let threads = super::args::threads(t)?;
    std::fs::create_dir_all(out)
        .map_err(|e| Error::Usage(format!("--out {}: cannot create it ({e})", out.display())))?;
    super::output(&out.join(file))?;
    super::output(&out.join("report.md"))?;
    Ok(Study {
        runner: super::runner(threads),
        checkpoint: Some(out.join("checkpoint")),
    })
}

fn nonempty<T>(v: &[T], name: &str) -> Result<()> {
    if v.is_empty() {
        Err(Error::Usage(format!("{name}: give at least one value")))
    } else {
        Ok(())
    }
}

pub(super) fn to_json<T: serde::Serialize>(v: &T) -> Result<String> {
    serde_json::to_string_pretty(v).map_err(|e| Error::Run(e.to_string()))
}

/// Writes the JSON and the report, prints one or the other.
pub(super) fn finish(
    out: &Path,
    file: &str,
    json: &str,
    report: &str,
    print_json: bool,
) -> Result<()> {
    super::output(&out.join(file))?.write(json.as_bytes())?;
    super::output(&out.join("report.md"))?.write(report.as_bytes())?;
    if print_json {
        outln!("{json}");
    } else {
        outln!("{report}");
        eprintln!("wrote {}/{file}, report.md and figures", out.display());
    }
    Ok(())
}

pub fn converge(a: &ConvergeArgs) -> Result<()> {
    nonempty(&a.blocks, "--blocks")?;
    nonempty(&a.dts, "--dts")?;
    nonempty(&a.engines, "--engines")?;
    let study = check_common(a.rolls, a.max_steps, a.threads, &a.out, "converge.json")?;
    let cfg = converge::Config {
        blocks: a.blocks.clone(),
        dts: a.dts.clone(),
        engines: a.engines.clone(),
        rolls: a.rolls,
        seed: a.seed,
        max_steps: a.max_steps,
        precision: a.precision,
        budget_s: (a.budget, a.reference_budget),
        fast: a.fast,
    };
    for (v, name) in [
        (a.budget, "--budget"),
        (a.reference_budget, "--reference-budget"),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::Usage(format!("{name} {v}: CPU seconds, above 0")));
        }
    }
    let bar = cpu_bar(a.json || a.precision.is_none());
    let progress = |done: f64, total: f64| {
        bar.set_length((1000.0 * total) as u64);
        bar.set_position((1000.0 * done.min(total)) as u64);
    };
    let res = logged(a.json, &report::converge::header(), |log| {
        let log = |l: &str| bar.suspend(|| log(l));
        converge::run(&cfg, &study, &log, &progress)
    });
    bar.finish_and_clear();
    let Some(res) = res? else {
        return Ok(());
    };
    let figures = report::converge::write_figures(&a.out, &res, a.precision)?;
    let md = report::converge::markdown(&res, a.precision, &figures);
    finish(&a.out, "converge.json", &to_json(&res)?, &md, a.json)
}

pub fn tradeoff(a: &TradeoffArgs) -> Result<()> {
    nonempty(&a.dts, "--dts")?;
    let ladder: Vec<f64> = a.ladder.iter().flatten().copied().collect();
    let mut all_dts = a.dts.iter().chain(&a.rapier_dts);
    if all_dts.any(|&d| d <= a.reference_dt) {
        return Err(Error::Usage(format!(
            "--reference-dt {}: must be finer than every --dts and --rapier-dts",
            dt_label(a.reference_dt)
        )));
    }
    if ladder.contains(&a.reference_dt) {
        return Err(Error::Usage(
            "--ladder: the reference's dt is not a rung".into(),
        ));
    }
    for (v, name) in [
        (a.budget, "--budget"),
        (a.reference_budget, "--reference-budget"),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::Usage(format!("{name} {v}: CPU seconds, above 0")));
        }
    }
    let study = check_common(1, a.max_steps, a.threads, &a.out, "tradeoff.json")?;
    let cfg = tradeoff::Config {
        block: a.block,
        dts: a.dts.clone(),
        rapier_dts: a.rapier_dts.clone(),
        reference_dt: a.reference_dt,
        ladder,
        precision: a.precision,
        budget_s: a.budget,
        reference_budget_s: a.reference_budget,
        seed: a.seed,
        max_steps: a.max_steps,
        plan_only: a.plan,
        preroll_chunks: a
            .preroll
            .map(|r| r.div_ceil(dicephys::run::runner::CHUNK_ROLLS)),
    };
    if a.preroll == Some(0) {
        return Err(Error::Usage("--preroll 0: give at least 1 roll".into()));
    }
    let bar = cpu_bar(a.json);
    let progress = |done: f64, total: f64| {
        bar.set_length((1000.0 * total) as u64);
        bar.set_position((1000.0 * done.min(total)) as u64);
    };
    let res = logged(a.json, &report::tradeoff::header(), |log| {
        let log = |l: &str| bar.suspend(|| log(l));
        tradeoff::run(&cfg, &study, &log, &progress)
    });
    bar.finish_and_clear();
    let Some(res) = res? else {
        return Ok(());
    };
    if a.plan {
        if a.json {
            outln!("{}", to_json(&res)?);
        }
        return Ok(());
    }
    if let Some(r) = a.preroll {
        eprintln!(
            "rolled the first {r} throws of every stream into {}/checkpoint ({:.0} CPU s); \
             the same command without --preroll reads them back",
            a.out.display(),
            res.cpu_s
        );
        return Ok(());
    }
    let figures = report::tradeoff::write_figures(&a.out, &res, a.block)?;
    let md = report::tradeoff::markdown(&res, &figures);
    finish(&a.out, "tradeoff.json", &to_json(&res)?, &md, a.json)
}

pub fn stability(a: &StabilityArgs) -> Result<()> {
    nonempty(&a.engines, "--engines")?;
    nonempty(&a.dts, "--dts")?;
    nonempty(&a.restitutions, "--restitutions")?;
    if let Some(e) = a
        .restitutions
        .iter()
        .find(|e| !(e.is_finite() && (0.0..=1.0).contains(*e)))
    {
        return Err(Error::Usage(format!(
            "--restitutions {e}: must be in [0, 1]"
        )));
    }
    if let Some(m) = a.frictions.iter().find(|m| !(m.is_finite() && **m >= 0.0)) {
        return Err(Error::Usage(format!(
            "--frictions {m}: must be finite and >= 0"
        )));
    }
    if !(0.001..=dicephys::model::scene::DICEPHYS_FLOOR_THICKNESS).contains(&a.floor_thickness) {
        return Err(Error::Usage(format!(
            "--floor-thickness {}: must be in [0.001, 100] m",
            a.floor_thickness
        )));
    }
    let study = check_common(a.rolls, a.max_steps, a.threads, &a.out, "stability.json")?;
    let cfg = stability::Config {
        engines: a.engines.clone(),
        dts: a.dts.clone(),
        restitutions: a.restitutions.clone(),
        frictions: a.frictions.clone(),
        blocks: a.blocks.clone(),
        rolls: a.rolls,
        seed: a.seed,
        max_steps: a.max_steps,
        floor_thickness: a.floor_thickness,
    };
    let Some(res) = logged(a.json, &report::stability::header(), |log| {
        stability::run(&cfg, &study, log)
    })?
    else {
        return Ok(());
    };
    let figures = report::stability::write_figures(&a.out, &res)?;
    let md = report::stability::markdown(&res, &figures);
    finish(&a.out, "stability.json", &to_json(&res)?, &md, a.json)
}

/// Runs a sweep, logging its header and each cell to stderr unless the output is JSON. In a
/// cluster task it runs silently and gives None: the task's share is for the finishing job to
/// assemble, not to report.
pub(super) fn logged<T>(
    quiet: bool,
    header: &str,
    run: impl FnOnce(&dyn Fn(&str)) -> dicephys::Result<T>,
) -> Result<Option<T>> {
    let task = super::is_task();
    let quiet = quiet || task;
    if !quiet {
        eprintln!("{header}");
    }
    let res = run(&|l| {
        if !quiet {
            eprintln!("{l}")
        }
    })?;
    Ok((!task).then_some(res))
}
