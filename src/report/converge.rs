//! `converge`'s results and report: the ratio against dt per block, engine and mode, each
//! cell's departure from the finest dt, and the paper's claim (the study: `studies::converge`).

use crate::error::Result;
use crate::report::figures::sweeps as fig;
use crate::report::figures::{group, Point};
use crate::report::text::{dt_label, left, right, Columns};
use serde::Serialize;
use std::path::Path;

/// One cell: a block, an engine, 2D or 3D, a dt.
#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    /// The block, `LxBxW` in mm.
    pub block: String,
    /// The engine's name.
    pub engine: String,
    /// "3d" or "2d".
    pub mode: String,
    /// The time step, s.
    pub dt: f64,
    /// Rolls made.
    pub rolls: u64,
    /// N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// Simulated steps per roll.
    pub steps_per_roll: f64,
    /// Process CPU seconds per roll, all threads.
    pub cpu_s_per_roll: f64,
    /// Rolls not at rest at the step cap.
    pub unconverged: u64,
    /// Rolls that failed, for any reason.
    pub failed: u64,
    /// Rolls in which the engine injected energy.
    pub energy_gain: u64,
    /// ratio / ratio at the finest dt − 1.
    pub departure: f64,
    /// Its error (with `--precision`: paired on the shared throws).
    pub departure_err: f64,
    /// With `--precision`: 2σ of the departure (of the finest dt: of its own ratio, to half
    /// the precision) is within the precision.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolved: Option<bool>,
}

/// The paper's claim for one block × engine × mode.
#[derive(Clone, Debug, Serialize)]
pub struct Claim {
    /// The block, `LxBxW` in mm.
    pub block: String,
    /// The engine's name.
    pub engine: String,
    /// "3d" or "2d".
    pub mode: String,
    /// The dt the claim is about (`CLAIM_DT`), s.
    pub dt: f64,
    /// The finest dt of the run, the reference, s.
    pub dt_finest: f64,
    /// The ratio at `dt` over the ratio at `dt_finest`, − 1.
    pub departure: f64,
    /// Its error.
    pub departure_err: f64,
    /// 2σ of the departure is at most 1 %.
    pub resolved: bool,
    /// The claim decided at 2σ (`decide`): yes if resolved and |departure| ≤ 1 %; no if
    /// resolved and beyond 1 %, or if even |departure| − 2σ > 1 %; else open.
    pub within_one_percent: Option<bool>,
    /// Rolls per cell for 2σ = 1 % (with `--precision`: both cells at that count, on the
    /// same throws).
    pub rolls_needed: Option<u64>,
    /// Rolls at `dt` and at `dt_finest` (equal without `--precision`).
    pub rolls: (u64, u64),
}

/// The convergence test's results.
#[derive(Clone, Debug, Serialize)]
pub struct Converge {
    /// How rolls end, in words.
    pub settle: String,
    /// Rolls per cell.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The time steps run, coarse to fine, s.
    pub dts: Vec<f64>,
    /// The step cap per roll.
    pub max_steps: u64,
    /// Every cell: by block, engine, 3D then 2D, then dt.
    pub cells: Vec<Cell>,
    /// The paper's claim per block × engine × mode; none without dt = 0.001 s and a finer one.
    pub claims: Vec<Claim>,
    /// Every claim resolved.
    pub resolved: bool,
    /// Plain words: does the run resolve the paper's claim, and if not, what would.
    pub verdict: String,
}

/// The column heads of the log's cell lines (`format_cell`).
pub fn header() -> String {
    TABLE.header()
}

/// One cell as a line of the log, under `header`.
pub fn format_cell(c: &Cell) -> String {
    TABLE.row(&[
        c.block.clone(),
        c.engine.to_string(),
        c.mode.to_string(),
        dt_label(c.dt),
        format!("{:.4} ± {:.4}", c.ratio, c.ratio_err),
        format!("{:.0}", c.steps_per_roll),
        format!("{:.5}", c.cpu_s_per_roll),
        format!(
            "{:+.1} ± {:.1} %",
            100.0 * c.departure,
            100.0 * c.departure_err
        ),
        c.unconverged.to_string(),
        c.failed.to_string(),
        c.energy_gain.to_string(),
    ])
}

/// The columns of the log and of report.md.
const TABLE: Columns = Columns(&[
    left("block", 10),
    left("engine", 13),
    right("mode", 4),
    right("dt", 8),
    right("ratio", 17),
    right("steps", 8),
    right("CPU s/roll", 10),
    right("vs finest dt", 18),
    right("unconv", 6),
    right("failed", 6),
    right("gain", 5),
]);

/// report.md: how the cells were rolled, the table, the verdict and the figures. `precision`
/// is the study's (`--precision`), if it rolled to one.
fn markdown(res: &Converge, precision: Option<f64>, figures: &[&str]) -> String {
    let mut md = format!(
        "# Convergence in dt\n\n{}, seed {}, rolls ended by {}.\n\n```\n{}\n",
        match precision {
            Some(p) => format!(
                "Every cell rolled until 2σ of its departure from the finest dt is at most {:.2} % \
                 or its budget spent",
                100.0 * p
            ),
            None => format!("{} rolls per cell", res.rolls),
        },
        res.seed,
        res.settle,
        header()
    );
    for c in &res.cells {
        md += &format_cell(c);
        md.push('\n');
    }
    md += "```\n\n";
    md += &format!("{}\n\n", res.verdict);
    for f in figures {
        md += &format!("![ratio against dt]({f}.svg)\n");
    }
    md
}

/// Draws the ratio against dt, a line per block, engine and mode, into `dir`; returns its stem.
fn write_figures(dir: &Path, res: &Converge, precision: Option<f64>) -> Result<Vec<&'static str>> {
    let lines: Vec<fig::Line> = group(&res.cells, |c| {
        format!("{} {} {}", c.block, c.engine, c.mode)
    })
    .into_iter()
    .map(|(label, cells)| fig::Line {
        label,
        points: cells
            .iter()
            .map(|c| Point {
                x: c.dt,
                y: c.ratio,
                y_err: c.ratio_err,
            })
            .collect(),
    })
    .collect();
    fig::convergence(
        dir,
        "converge",
        &match precision {
            Some(p) => format!(
                "Ratio against dt (each departure resolved to ±{:.2} % at 2σ, or marked)",
                100.0 * p
            ),
            None => format!("Ratio against dt ({} rolls per point)", res.rolls),
        },
        &lines,
    )?;
    Ok(vec!["converge"])
}

/// The convergence test's report: its results and the precision the study rolled to
/// (`--precision`), which the results do not carry.
pub struct ConvergeReport<'a> {
    /// The results.
    pub res: &'a Converge,
    /// The study's precision, if it rolled to one.
    pub precision: Option<f64>,
}

impl super::Report for ConvergeReport<'_> {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        Ok(super::owned(write_figures(dir, self.res, self.precision)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown(self.res, self.precision, &super::stems(stems))
    }
}
