//! `dicephys paper`: the paper end to end. Every row of its table with theory, measurement and
//! the no-bounce prediction; for the five rows it simulated (printed blocks on MDF, μ = 0.29,
//! e = 0.5) our simulations in 3D and 2D on each engine, with z-scores against experiment and
//! theory.

use crate::block::Block;
use crate::checkpoint;
use crate::cli::theory::{table_report, TableReport};
use crate::cputime::process_cpu_seconds;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::roll::{Rule, Settle};
use crate::scene::{Mode, Scene};
use crate::stats::{self, Ratio};
use crate::summary::RunSummary;
use crate::throws::{ThrowKind, ThrowRanges, Throws};
use serde::Serialize;
use std::time::Instant;

/// What to simulate.
#[derive(Clone, Debug, Serialize)]
pub struct PaperConfig {
    pub rolls: u64,
    pub seed: u64,
    pub engines: Vec<EngineKind>,
    pub dt: f64,
    pub threads: usize,
    pub max_steps: u64,
    /// DicePhys's rest rule and stepped flight, instead of the early stop and fast flight.
    pub faithful: bool,
}

/// One simulated cell: a block of the table, an engine, 2D or 3D.
#[derive(Clone, Debug, Serialize)]
pub struct SimCell {
    pub row: usize,
    pub label: String,
    pub engine: String,
    pub mode: String,
    pub ratio: Ratio,
    /// (simulation − experiment) / combined error.
    pub z_experiment: f64,
    /// (simulation − theory) / combined error.
    pub z_theory: f64,
    pub run: RunSummary,
}

#[derive(Clone, Debug, Serialize)]
pub struct Provenance {
    pub command_line: String,
    pub dicephys_version: String,
    pub engines: Vec<String>,
    /// The engines' short names, as in `simulations[].engine`.
    pub engines_short: Vec<String>,
    pub preset: String,
    pub dt: f64,
    pub seed: u64,
    pub rolls_per_cell: u64,
    pub date_utc: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct PaperResults {
    /// Stopped by Ctrl-C: only the cells in `simulations` were (wholly or partly) rolled.
    pub partial: bool,
    pub provenance: Provenance,
    pub table: TableReport,
    pub simulations: Vec<SimCell>,
    pub wall_s: f64,
    pub cpu_s: f64,
    /// Surfaces whose μ and e the paper did not measure: not simulated, and why.
    pub not_simulated: String,
}

/// The blocks the paper simulated: the table rows marked `simulated`.
pub fn simulated_rows(table: &TableReport) -> Vec<(usize, String, Block)> {
    table
        .rows
        .iter()
        .filter(|r| r.simulated)
        .filter_map(|r| {
            Block::from_mm(r.length_mm, r.breadth_mm, r.width_mm)
                .ok()
                .map(|b| (r.row, r.label.clone(), b))
        })
        .collect()
}

/// The number of rolls `run` will make, for a progress bar.
pub fn total_rolls(cfg: &PaperConfig) -> Result<u64> {
    let table = table_report()?;
    Ok(simulated_rows(&table).len() as u64 * cfg.engines.len() as u64 * 2 * cfg.rolls)
}

/// Runs every simulated cell. `progress` gets the rolls finished so far.
pub fn run(
    cfg: &PaperConfig,
    command_line: String,
    checkpoint_dir: Option<&std::path::Path>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<PaperResults> {
    let mut partial = false;
    let table = table_report()?;
    let wall = Instant::now();
    let cpu0 = process_cpu_seconds();
    let ranges = ThrowRanges::default();
    let throws = Throws::new(ThrowKind::Keyed, cfg.seed, ranges, 0);
    let settle = Settle {
        max_steps: cfg.max_steps,
        // The early stop only where it is audited exact (`roll::EARLY_STOP_MAX_DT`).
        rule: if cfg.faithful || !crate::roll::early_stop_exact(cfg.dt) {
            Rule::Dicephys
        } else {
            Rule::Certificate
        },
        fast_flight: !cfg.faithful,
        ..Settle::default()
    };
    let mut done_before = 0u64;
    let mut simulations = Vec::new();
    'cells: for (row, label, block) in simulated_rows(&table) {
        let t = table.rows.iter().find(|r| r.row == row).expect("row");
        for &engine in &cfg.engines {
            for mode in [Mode::ThreeD, Mode::TwoD] {
                if partial {
                    break 'cells;
                }
                let mut scene = Scene::paper(block, mode);
                scene.dt = cfg.dt;
                let cell_wall = Instant::now();
                let cell_cpu = process_cpu_seconds();
                let base = done_before;
                let dir =
                    checkpoint_dir.map(|d| d.join(format!("row{row}-{engine}-{}", mode.name())));
                if let Some(d) = &dir {
                    std::fs::create_dir_all(d)
                        .map_err(|e| Error::Run(format!("{}: {e}", d.display())))?;
                }
                let done = checkpoint::run(
                    engine,
                    &scene,
                    &throws,
                    &settle,
                    checkpoint::Indices::all(cfg.rolls),
                    cfg.threads,
                    dir.as_deref(),
                    &|n| progress(base + n),
                    &mut |_| Ok(()),
                )
                .map_err(Error::Run)?;
                done_before += cfg.rolls;
                let tally = done.tally;
                if !done.complete {
                    partial = true;
                }
                let run = RunSummary::new(
                    engine,
                    &scene,
                    cfg.seed,
                    ThrowKind::Keyed,
                    &ranges,
                    &settle,
                    &tally,
                    cell_wall.elapsed().as_secs_f64(),
                    process_cpu_seconds() - cell_cpu,
                    cfg.threads,
                );
                let ratio = stats::ratio(tally.counts.breadth, tally.counts.width);
                simulations.push(SimCell {
                    row,
                    label: label.clone(),
                    engine: engine.name().into(),
                    mode: mode.name().into(),
                    ratio,
                    z_experiment: stats::z_score(
                        ratio.value,
                        ratio.err,
                        t.measured_ratio.value,
                        t.measured_ratio.err,
                    ),
                    z_theory: stats::z_score(
                        ratio.value,
                        ratio.err,
                        t.theory_ratio.value,
                        t.theory_ratio.err,
                    ),
                    run,
                });
            }
        }
    }
    Ok(PaperResults {
        partial,
        provenance: Provenance {
            command_line,
            dicephys_version: env!("CARGO_PKG_VERSION").into(),
            engines: cfg.engines.iter().map(|e| e.version()).collect(),
            engines_short: cfg.engines.iter().map(|e| e.name().to_string()).collect(),
            preset: crate::scene::Preset::Dicephys281.name().into(),
            dt: cfg.dt,
            seed: cfg.seed,
            rolls_per_cell: cfg.rolls,
            date_utc: utc_now(),
        },
        table,
        simulations,
        wall_s: wall.elapsed().as_secs_f64(),
        cpu_s: process_cpu_seconds() - cpu0,
        not_simulated: "Pine blocks on carpet and towel, and printed blocks on tough carpet: the \
                        paper measured μ and e only for printed blocks on MDF, so these rows \
                        are not simulated rather than simulated with invented coefficients."
            .into(),
    })
}

/// The current UTC date and time, ISO 8601, from the system clock.
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + if m <= 2 { 1 } else { 0 };
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

fn fmt_z(z: f64) -> String {
    if z.is_finite() {
        format!("{z:+.1}")
    } else {
        "–".into()
    }
}

/// The cell for (row, engine, mode), if simulated.
pub fn cell<'a>(
    res: &'a PaperResults,
    row: usize,
    engine: &str,
    mode: &str,
) -> Option<&'a SimCell> {
    res.simulations
        .iter()
        .find(|c| c.row == row && c.engine == engine && c.mode == mode)
}

/// report.md: the table formatted like the paper's, the simulation columns, and a reading.
pub fn report_markdown(res: &PaperResults, figures: &[&str]) -> String {
    let p = &res.provenance;
    let engines: Vec<String> = {
        let mut v: Vec<String> = res.simulations.iter().map(|c| c.engine.clone()).collect();
        v.dedup();
        let mut seen = Vec::new();
        for e in v {
            if !seen.contains(&e) {
                seen.push(e);
            }
        }
        seen
    };
    let mut s = String::new();
    s += "# Pender & Uhrin (2014) reproduced by dicephys\n\n";
    if res.partial {
        s += "**PARTIAL**: stopped before every cell was simulated; run the same command again \
              to continue from the checkpoint.\n\n";
    }
    s += &format!(
        "Command: `{}`  \nDate: {}  \ndicephys {}; engines: {}; preset {}; dt {} s; seed {}; \
         {} rolls per simulated cell (keyed throws, the paper's ranges); wall {:.0} s, CPU {:.0} s.\n\n",
        p.command_line,
        p.date_utc,
        p.dicephys_version,
        p.engines.join(", "),
        p.preset,
        p.dt,
        p.seed,
        p.rolls_per_cell,
        res.wall_s,
        res.cpu_s
    );
    // Statistical resolution bought by this many rolls.
    let errs: Vec<f64> = res.simulations.iter().map(|c| c.ratio.err).collect();
    if !errs.is_empty() {
        let lo = errs.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = errs.iter().cloned().fold(0.0, f64::max);
        s += &format!(
            "Statistical resolution: a simulated ratio's binomial error is {lo:.4}–{hi:.4} at \
             {} rolls (it falls as 1/√rolls; `--rolls 100000` is the paper's own scale).\n\n",
            p.rolls_per_cell
        );
    }
    s += "## The paper's table, with our simulations\n\n";
    s += "Ratio = N(breadth vertical)/N(width vertical). Theory: eq. (MasterEqu), ± from the \
          printed side errors. Measured: the paper's counts, ± binomial. No bounce: eq. (InElasK). \
          Simulated cells: ratio ± binomial error, then z against experiment / against theory.\n\n";
    let mut head = String::from(
        "| row | L × B × W (mm) | R | theory | surface | throws | L | B | W | measured | z | no bounce |",
    );
    let mut rule = String::from("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for e in &engines {
        for m in ["3D", "2D"] {
            head += &format!(" {e} {m} (z exp / z th) |");
            rule += "---|";
        }
    }
    s += &head;
    s += "\n";
    s += &rule;
    s += "\n";
    for r in &res.table.rows {
        s += &format!(
            "| {}{} | {}×{}×{} | {:.3} ± {:.3} | {:.3} ± {:.3} | {} | {} | {} | {} | {} | {:.3} ± {:.3} | {} | {:.3} |",
            r.row,
            if r.simulated { "*" } else { "" },
            r.length_mm,
            r.breadth_mm,
            r.width_mm,
            r.r.value,
            r.r.err,
            r.theory_ratio.value,
            r.theory_ratio.err,
            r.surface.name(),
            r.throws,
            r.length_vertical,
            r.breadth_vertical,
            r.width_vertical,
            r.measured_ratio.value,
            r.measured_ratio.err,
            fmt_z(r.z),
            r.no_bounce_ratio
        );
        for e in &engines {
            for m in ["3d", "2d"] {
                match cell(res, r.row, e, m) {
                    Some(c) => {
                        s += &format!(
                            " {:.4} ± {:.4} ({} / {}) |",
                            c.ratio.value,
                            c.ratio.err,
                            fmt_z(c.z_experiment),
                            fmt_z(c.z_theory)
                        )
                    }
                    None => s += " |",
                }
            }
        }
        s += "\n";
    }
    s += "\n\\* simulated (printed blocks on MDF, μ = 0.29, e = 0.5).\n\n";
    s += &format!("Not simulated: {}\n\n", res.not_simulated);
    if !res.table.discrepancies.is_empty() {
        s += "Data check: ";
        let d: Vec<String> = res
            .table
            .discrepancies
            .iter()
            .map(|f| f.message.clone())
            .collect();
        s += &d.join("; ");
        s += ".\n\n";
    }
    s += "## Reading\n\n";
    for e in &engines {
        for (m, name) in [("3d", "3D"), ("2d", "2D")] {
            let cells: Vec<&SimCell> = res
                .simulations
                .iter()
                .filter(|c| &c.engine == e && c.mode == m)
                .collect();
            if cells.is_empty() {
                continue;
            }
            let within = |k: f64| cells.iter().filter(|c| c.z_experiment.abs() <= k).count();
            let outside: Vec<String> = cells
                .iter()
                .filter(|c| c.z_experiment.abs() > 1.0)
                .map(|c| format!("{} ({})", c.label, fmt_z(c.z_experiment)))
                .collect();
            s += &format!(
                "- {e} {name}: {} of {} blocks within 1 experimental standard error (combined), \
                 {} within 2{}.\n",
                within(1.0),
                cells.len(),
                within(2.0),
                if outside.is_empty() {
                    String::new()
                } else {
                    format!("; outside 1σ: {}", outside.join(", "))
                }
            );
        }
    }
    s +=
        "\nThe paper: all its 3D simulations agree with experiment within error; its 2D line lies \
          outside two of the five experimental error bars.\n\n";
    if !figures.is_empty() {
        s += "## Figures\n\n";
        for f in figures {
            s += &format!("![{f}]({f}.svg)\n\n");
        }
    }
    s
}

/// results.csv: one row per simulated cell.
pub fn results_csv(res: &PaperResults) -> String {
    let mut s = String::from(
        "row,block,engine,mode,rolls,breadth,width,length,unknown,unconverged,failed,ratio,ratio_err,\
         measured_ratio,measured_err,theory_ratio,theory_err,z_experiment,z_theory,steps_mean,cpu_ms_per_roll\n",
    );
    for c in &res.simulations {
        let t = res.table.rows.iter().find(|r| r.row == c.row);
        let (mr, me, tr, te) = t
            .map(|t| {
                (
                    t.measured_ratio.value,
                    t.measured_ratio.err,
                    t.theory_ratio.value,
                    t.theory_ratio.err,
                )
            })
            .unwrap_or((f64::NAN, f64::NAN, f64::NAN, f64::NAN));
        let k = &c.run.counts;
        s += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.3},{:.3},{:.1},{:.4}\n",
            c.row,
            c.label.split(' ').next().unwrap_or(""),
            c.engine,
            c.mode,
            c.run.rolls,
            k.breadth,
            k.width,
            k.length,
            k.unknown,
            c.run.unconverged,
            c.run.failed_total,
            c.ratio.value,
            c.ratio.err,
            mr,
            me,
            tr,
            te,
            c.z_experiment,
            c.z_theory,
            c.run.steps_mean,
            c.run.cpu_ms_per_roll
        );
    }
    s
}

/// The paper's figures, drawn from the results; returns their names (each has .svg and .png).
pub fn write_figures(dir: &std::path::Path, res: &PaperResults) -> Result<Vec<&'static str>> {
    use crate::figures::{self, Point, SimSeries};
    let mut sims = Vec::new();
    for engine in &res.provenance.engines_short {
        for (mode, name) in [("2d", "2D"), ("3d", "3D")] {
            let mut points: Vec<Point> = res
                .simulations
                .iter()
                .filter(|c| &c.engine == engine && c.mode == mode)
                .filter_map(|c| {
                    let row = res.table.rows.iter().find(|r| r.row == c.row)?;
                    Some(Point {
                        x: row.r.value,
                        y: c.ratio.value,
                        y_err: c.ratio.err,
                    })
                })
                .collect();
            points.sort_by(|a, b| a.x.total_cmp(&b.x));
            sims.push(SimSeries {
                label: format!("{} {name} simulation", engine_label(engine)),
                two_d: mode == "2d",
                points,
            });
        }
    }
    let run = |r: std::result::Result<(), String>| r.map_err(Error::Run);
    run(figures::master_graph(
        dir,
        "master_graph",
        &figures::paper_experiment_points(),
        &sims,
    ))?;
    run(figures::prob_2d(dir, "prob_2d"))?;
    run(figures::len_graph(
        dir,
        "len_graph",
        &figures::paper_length_groups(),
    ))?;
    run(figures::dreidel(dir, "dreidel", 0.1))?;
    Ok(vec!["master_graph", "prob_2d", "len_graph", "dreidel"])
}

fn engine_label(name: &str) -> String {
    match name {
        "bullet" => "Bullet".into(),
        "rapier" => "Rapier".into(),
        "rapier-locked" => "Rapier (locked 3D)".into(),
        other => other.into(),
    }
}
