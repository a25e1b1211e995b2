//! The paper's report: its results as data, `report.md`, `results.csv` and the figures.

use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::model::scene::{Mode, Preset};
use crate::report::outcomes::{Outcomes3d, Probability};
use crate::report::summary::RunSummary;
use crate::report::table::TableReport;
use crate::run::tally::Counts;
use crate::theory::stats::Ratio;
use serde::Serialize;

/// One simulated cell: a block of the table, an engine, 2D or 3D.
#[derive(Clone, Debug, Serialize)]
pub struct SimCell {
    /// The row of the paper's table, 1-based.
    pub row: usize,
    /// e.g. `140x24x20 MDF`.
    pub label: String,
    /// The engine that rolled it.
    pub engine: EngineKind,
    /// 2D or 3D.
    pub mode: Mode,
    /// Stopped before all its rolls were made: the counts cover the rolls made.
    pub partial: bool,
    /// Simulated N(breadth vertical)/N(width vertical) ± binomial error.
    pub ratio: Ratio,
    /// (simulation − experiment) / combined error.
    pub z_experiment: f64,
    /// (simulation − theory) / combined error.
    pub z_theory: f64,
    /// The cell's run in full: specification, counts and cost.
    pub run: RunSummary,
}

/// Where a paper run's results come from: command, versions, settings, date.
#[derive(Clone, Debug, Serialize)]
pub struct Provenance {
    /// The command line as typed.
    pub command_line: String,
    /// This program's version.
    pub dicephys_version: String,
    /// Each engine's name and version.
    pub engines: Vec<String>,
    /// The engines' short names, as in `simulations[].engine`.
    pub engines_short: Vec<EngineKind>,
    /// Bullet's solver settings (always `dicephys281`, as the paper ran it).
    pub preset: Preset,
    /// The time step, s.
    pub dt: f64,
    /// The throws' seed (keyed throws).
    pub seed: u64,
    /// Rolls per simulated cell.
    pub rolls_per_cell: u64,
    /// When the run ended, UTC, ISO 8601.
    pub date_utc: String,
}

/// `dicephys paper`'s results: the table beside the theory, and the simulated cells.
#[derive(Clone, Debug, Serialize)]
pub struct PaperResults {
    /// Stopped by Ctrl-C: only the cells in `simulations` were (wholly or partly) rolled.
    pub partial: bool,
    /// Where the results come from.
    pub provenance: Provenance,
    /// The paper's table beside the theory, with the data check and χ² per set.
    pub table: TableReport,
    /// The cells simulated, row by row, each engine, 3D then 2D.
    pub simulations: Vec<SimCell>,
    /// Wall-clock seconds the cells took, summed (with a resumed cell's earlier segments; on
    /// a cluster, over every task).
    pub wall_s: f64,
    /// CPU seconds the cells took, all threads, summed likewise.
    pub cpu_s: f64,
    /// Surfaces whose μ and e the paper did not measure: not simulated, and why.
    pub not_simulated: String,
}

/// The current UTC date and time, ISO 8601, from the system clock.
pub fn utc_now() -> String {
    let f = time::macros::format_description!("[year]-[month]-[day]T[hour]:[minute]:[second]Z");
    time::OffsetDateTime::now_utc()
        .format(&f)
        .unwrap_or_else(|_| "unknown".into())
}

fn fmt_z(z: f64) -> String {
    if z.is_finite() {
        format!("{z:+.1}")
    } else {
        "–".into()
    }
}

/// The cell for (row, engine, mode), if simulated.
pub fn cell(res: &PaperResults, row: usize, engine: EngineKind, mode: Mode) -> Option<&SimCell> {
    res.simulations
        .iter()
        .find(|c| c.row == row && c.engine == engine && c.mode == mode)
}

/// report.md: the verdict first (what `paper` prints), then the tables by subject — the theory
/// against the paper's rows, each engine's simulations against experiment, the three
/// outcomes — and the figures.
fn markdown(res: &PaperResults, figures: &[&str]) -> String {
    let engines = engines_of(res);
    let mut s = heading(res);
    s += &format!(
        "## Verdict\n\n```text\n{}```\n\n",
        verdict_body(res, &engines)
    );
    s += &table_markdown(res);
    s += &simulations_markdown(res, &engines);
    s += &outcomes_markdown(res);
    if !figures.is_empty() {
        s += "## Figures\n\n";
        for f in figures {
            s += &format!("![{f}]({f}.svg)\n\n");
        }
    }
    s
}

/// What `paper` prints on the terminal: the verdict first, block by block, in at most 40
/// lines of at most 120 columns; the long report is `report.md` in `out` (issue 50).
pub fn verdict(res: &PaperResults, out: &std::path::Path) -> String {
    let mut s = verdict_body(res, &engines_of(res));
    s += &format!(
        "\nThe whole report (the tables, the three outcomes, the figures), and the results:\n  \
         {d}/report.md, {d}/results.json, {d}/results.csv\n",
        d = out.display()
    );
    s
}

/// The verdict, without where the files are: the terminal's and report.md's opening.
fn verdict_body(res: &PaperResults, engines: &[EngineKind]) -> String {
    let p = &res.provenance;
    let mut s = format!(
        "Pender & Uhrin (2014) reproduced by dicephys {}: {} rolls a simulated block, seed {}\n",
        p.dicephys_version, p.rolls_per_cell, p.seed
    );
    if res.partial {
        s += "PARTIAL: stopped before every block was simulated; the same command continues it\n";
    }
    // The theory against the paper's rows, set by set (as `theory --table` gives it).
    let sets: Vec<String> = res
        .table
        .chi_square
        .iter()
        .map(|c| {
            let p = if c.p_value >= 0.001 {
                format!("{:.3}", c.p_value)
            } else {
                format!("{:.1e}", c.p_value)
            };
            format!("{} {:.1} on {} (p {p})", c.set.name(), c.chi2, c.dof)
        })
        .collect();
    s += &format!(
        "The theory (the paper's eq. 8) against its measured rows, χ² by set:\n  {}\n",
        sets.join("; ")
    );
    s += "\nThe ratio N(breadth)/N(width) on MDF, simulated, against experiment (z: combined σ):\n";
    let mut head = format!("  {:<11} {:>15}", "block", "experiment");
    let columns: Vec<(EngineKind, Mode)> = engines
        .iter()
        .flat_map(|e| [(*e, Mode::ThreeD), (*e, Mode::TwoD)])
        .filter(|(e, m)| {
            res.simulations
                .iter()
                .any(|c| c.engine == *e && c.mode == *m)
        })
        .collect();
    for (e, m) in &columns {
        head += &format!(" {:>20}", format!("{e} {}", m.name()));
    }
    s += &head;
    s += "\n";
    for r in res.table.rows.iter().filter(|r| r.simulated) {
        let mut line = format!(
            "  {:<11} {:>15}",
            format!("{}x{}x{}", r.length_mm, r.breadth_mm, r.width_mm),
            format!(
                "{:.3} ± {:.3}",
                r.measured_ratio.value, r.measured_ratio.err
            )
        );
        for (e, m) in &columns {
            line += &match cell(res, r.row, *e, *m) {
                Some(c) => format!(
                    " {:>20}",
                    format!(
                        "{:.3} ± {:.3} {}",
                        c.ratio.value,
                        c.ratio.err,
                        fmt_z(c.z_experiment)
                    )
                ),
                None => format!(" {:>20}", "–"),
            };
        }
        s += &line;
        s += "\n";
    }
    s += "\n";
    for line in reading(res, engines).lines().skip(2) {
        // Shortened to fit 120 columns with every block outside 1σ named.
        let line = line
            .trim_start_matches("- ")
            .replace(
                " blocks within 1 experimental standard error (combined)",
                " within 1σ",
            )
            .replace(" within 2", " within 2σ")
            .replace(" MDF (", " (")
            .replace("; outside 1σ:", ";\n    outside 1σ:");
        if !line.is_empty() {
            s += &format!("  {line}\n");
        }
    }
    s += "  (the paper: its 3D simulations all within error; its 2D line outside two of five)\n";
    s
}

/// The engines simulated, in the order first met.
fn engines_of(res: &PaperResults) -> Vec<EngineKind> {
    let mut v: Vec<EngineKind> = res.simulations.iter().map(|c| c.engine).collect();
    v.dedup();
    let mut seen = Vec::new();
    for e in v {
        if !seen.contains(&e) {
            seen.push(e);
        }
    }
    seen
}

/// report.md's title, provenance and statistical resolution.
fn heading(res: &PaperResults) -> String {
    let p = &res.provenance;
    let mut s = String::new();
    s += "# Pender & Uhrin (2014) reproduced by dicephys\n\n";
    if res.partial {
        s += "**PARTIAL**: stopped before every cell was simulated; run the same command again \
              to continue from the checkpoint.\n\n";
    }
    s += &format!(
        "Command: `{}`  \nDate: {}  \ndicephys {}; engines: {}; preset {}; dt {} s; seed {}; \
         {} rolls per simulated cell (the paper's throw and ranges); wall {:.0} s, CPU {:.0} s.\n\n",
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
    s
}

/// The paper's table: every row's measurement against the theory (no simulation columns).
fn table_markdown(res: &PaperResults) -> String {
    let mut s = String::new();
    s += "## The theory against the paper's rows\n\n";
    s += "Ratio = N(breadth vertical)/N(width vertical). Theory: the paper's eq. 8, ± from the \
          printed side errors; no bounce: its eq. 1. Measured: the paper's counts (length, \
          breadth, width vertical), ± binomial; z of measured against theory.\n\n";
    s += "| row | L×B×W (mm) | surface | R | counts L / B / W | measured | theory | z | no bounce |\n";
    s += "|---|---|---|---|---|---|---|---|---|\n";
    for r in &res.table.rows {
        s += &format!(
            "| {}{} | {}×{}×{} | {} | {:.3} ± {:.3} | {} / {} / {} | {:.3} ± {:.3} | {:.3} ± {:.3} | {} | {:.3} |\n",
            r.row,
            if r.simulated { "*" } else { "" },
            r.length_mm,
            r.breadth_mm,
            r.width_mm,
            r.surface.name(),
            r.r.value,
            r.r.err,
            r.length_vertical,
            r.breadth_vertical,
            r.width_vertical,
            r.measured_ratio.value,
            r.measured_ratio.err,
            r.theory_ratio.value,
            r.theory_ratio.err,
            fmt_z(r.z),
            r.no_bounce_ratio
        );
    }
    s += "\n\\* simulated below (printed blocks on MDF, μ = 0.29, e = 0.5).\n\n";
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
    s
}

/// Each engine's simulated blocks against experiment and theory, a table an engine.
fn simulations_markdown(res: &PaperResults, engines: &[EngineKind]) -> String {
    let mut s = String::new();
    for e in engines {
        s += &format!(
            "## {} against experiment\n\nEach simulated ratio ± its binomial error, and its z \
             against the measurement and against the theory (combined σ).\n\n",
            engine_label(*e)
        );
        s += "| block | measured | 3D | z exp | z theory | 2D | z exp | z theory |\n";
        s += "|---|---|---|---|---|---|---|---|\n";
        for r in res.table.rows.iter().filter(|r| r.simulated) {
            s += &format!(
                "| {}×{}×{} | {:.3} ± {:.3} |",
                r.length_mm, r.breadth_mm, r.width_mm, r.measured_ratio.value, r.measured_ratio.err
            );
            for m in [Mode::ThreeD, Mode::TwoD] {
                s += &match cell(res, r.row, *e, m) {
                    Some(c) => format!(
                        " {:.4} ± {:.4} | {} | {} |",
                        c.ratio.value,
                        c.ratio.err,
                        fmt_z(c.z_experiment),
                        fmt_z(c.z_theory)
                    ),
                    None => " – | | |".to_string(),
                };
            }
            s += "\n";
        }
        s += "\n";
    }
    s
}

/// How many blocks each engine and mode puts within 1σ and 2σ of experiment.
fn reading(res: &PaperResults, engines: &[EngineKind]) -> String {
    let mut s = String::new();
    s += "## Reading\n\n";
    for e in engines {
        for (m, name) in [("3d", "3D"), ("2d", "2D")] {
            let cells: Vec<&SimCell> = res
                .simulations
                .iter()
                .filter(|c| c.engine == *e && c.mode.name() == m)
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
    s
}

/// `paper`'s report: for each block simulated in 3D, the three outcomes of the experiment (the
/// paper's counts) and of each engine, beside the solid angles.
fn outcomes_markdown(res: &PaperResults) -> String {
    let cells: Vec<_> = res
        .simulations
        .iter()
        .filter(|c| c.run.outcomes.is_some())
        .collect();
    if cells.is_empty() {
        return String::new();
    }
    let cell = |p: &Probability| {
        format!(
            "{:.4} ± {:.4} ({:.4}, {:+.1} σ)",
            p.p, p.err, p.solid_angle, p.z
        )
    };
    let mut s = String::from(
        "## The three outcomes in 3D\n\n\
         Each probability over the dice that came to rest on a face, ± its binomial error; in \
         brackets the solid-angle (Simpson) prediction, (2/π) arctan(w_j w_k / (w_i |w|)), and how \
         many of its standard errors apart. The paper expects bouncing dice to favour the \
         low-energy faces over Simpson's.\n\n\
         | row | block | source | n | P(breadth vertical) | P(width vertical) | P(length vertical) |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let mut rows: Vec<usize> = cells.iter().map(|c| c.row).collect();
    rows.dedup();
    for row in rows {
        let here: Vec<_> = cells.iter().filter(|c| c.row == row).collect();
        let label = &here[0].label;
        if let Some(t) = res.table.rows.iter().find(|t| t.row == row) {
            let counts = Counts {
                breadth: t.breadth_vertical,
                width: t.width_vertical,
                length: t.length_vertical,
                unknown: 0,
                face: 0,
            };
            if let Some(o) = Block::from_mm(t.length_mm, t.breadth_mm, t.width_mm)
                .ok()
                .and_then(|b| Outcomes3d::of(&b, &counts))
            {
                s += &format!(
                    "| {row} | {label} | experiment | {} | {} | {} | {} |\n",
                    o.n,
                    cell(&o.breadth),
                    cell(&o.width),
                    cell(&o.length)
                );
            }
        }
        for c in here {
            if let Some(o) = &c.run.outcomes {
                s += &format!(
                    "| {row} | {label} | {} | {} | {} | {} | {} |\n",
                    c.engine,
                    o.n,
                    cell(&o.breadth),
                    cell(&o.width),
                    cell(&o.length)
                );
            }
        }
    }
    s.push('\n');
    s
}

/// results.csv: one row per simulated cell.
pub fn results_csv(res: &PaperResults) -> Result<String> {
    /// One simulated cell; decimals fixed per column.
    #[derive(Serialize)]
    struct Row<'a> {
        row: usize,
        block: &'a str,
        engine: EngineKind,
        mode: Mode,
        rolls: u64,
        breadth: u64,
        width: u64,
        length: u64,
        unknown: u64,
        unconverged: u64,
        failed: u64,
        ratio: String,
        ratio_err: String,
        measured_ratio: String,
        measured_err: String,
        theory_ratio: String,
        theory_err: String,
        z_experiment: String,
        z_theory: String,
        steps_mean: String,
        cpu_ms_per_roll: String,
    }
    let mut csv = csv::Writer::from_writer(Vec::new());
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
        let f6 = |v: f64| format!("{v:.6}");
        let row = Row {
            row: c.row,
            block: c.label.split(' ').next().unwrap_or(""),
            engine: c.engine,
            mode: c.mode,
            rolls: c.run.rolls,
            breadth: k.breadth,
            width: k.width,
            length: k.length,
            unknown: k.unknown,
            unconverged: c.run.unconverged,
            failed: c.run.failed_total,
            ratio: f6(c.ratio.value),
            ratio_err: f6(c.ratio.err),
            measured_ratio: f6(mr),
            measured_err: f6(me),
            theory_ratio: f6(tr),
            theory_err: f6(te),
            z_experiment: format!("{:.3}", c.z_experiment),
            z_theory: format!("{:.3}", c.z_theory),
            steps_mean: format!("{:.1}", c.run.steps_mean),
            cpu_ms_per_roll: format!("{:.4}", c.run.cpu_ms_per_roll),
        };
        csv.serialize(row)
            .map_err(|e| Error::failed(format!("results.csv: {e}")))?;
    }
    let bytes = csv
        .into_inner()
        .map_err(|e| Error::failed(format!("results.csv: {}", e.error())))?;
    String::from_utf8(bytes).map_err(|e| Error::failed(format!("results.csv: {e}")))
}

/// The paper's figures, drawn from the results; returns their names (each has .svg and .png).
fn write_figures(dir: &std::path::Path, res: &PaperResults) -> Result<Vec<&'static str>> {
    use crate::report::figures::{paper as figures, Point, SimSeries};
    let mut sims = Vec::new();
    for engine in &res.provenance.engines_short {
        for (mode, name) in [("2d", "2D"), ("3d", "3D")] {
            let mut points: Vec<Point> = res
                .simulations
                .iter()
                .filter(|c| c.engine == *engine && c.mode.name() == mode)
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
                label: format!("{} {name} simulation", engine_label(*engine)),
                two_d: mode == "2d",
                points,
            });
        }
    }
    figures::master_graph(
        dir,
        "master_graph",
        &figures::paper_experiment_points(),
        &sims,
    )?;
    figures::prob_2d(dir, "prob_2d")?;
    figures::len_graph(dir, "len_graph", &figures::paper_length_groups())?;
    figures::dreidel(dir, "dreidel", 0.1)?;
    Ok(vec!["master_graph", "prob_2d", "len_graph", "dreidel"])
}

fn engine_label(engine: EngineKind) -> &'static str {
    match engine {
        EngineKind::Bullet => "Bullet",
        EngineKind::Rapier => "Rapier",
        EngineKind::RapierLocked => "Rapier (locked 3D)",
        EngineKind::Moreau => "Moreau–Jean",
    }
}

impl super::Report for PaperResults {
    fn write_figures(&self, dir: &std::path::Path) -> Result<Vec<String>> {
        Ok(super::owned(write_figures(dir, self)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown(self, &super::stems(stems))
    }
}
