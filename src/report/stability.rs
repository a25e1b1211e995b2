//! `stability`'s results and report: where engines break, the fraction of rolls of each
//! failure kind per cell of the dt × restitution grid and the friction and aspect lines (the
//! study: `studies::stability`).

use crate::engine::EngineKind;
use crate::error::Result;
use crate::model::scene::{Mode, DICEPHYS_FLOOR_THICKNESS};
use crate::report::figures::group;
use crate::report::figures::sweeps as fig;
use crate::report::text::{dt_label, left, right, Columns};
use serde::Serialize;
use std::path::Path;

/// The failure kinds, in the order of the figures and tables.
pub const KINDS: [&str; 6] = [
    "unconverged",
    "unknown",
    "non_finite",
    "tunnelled",
    "energy_gain",
    "dipped",
];

/// Which sweep a cell belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::Display, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Sweep {
    /// The grid of time step against restitution.
    DtRestitution,
    /// The line over friction.
    Friction,
    /// The line over the block's aspect ratios.
    Aspect,
}

/// One measured cell.
#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    /// The grid or line the cell is on.
    pub sweep: Sweep,
    /// The engine.
    pub engine: EngineKind,
    /// 2D or 3D.
    pub mode: Mode,
    /// The block, `LxBxW` in mm.
    pub block: String,
    /// breadth/width.
    pub breadth_over_width: f64,
    /// length/breadth.
    pub length_over_breadth: f64,
    /// The time step, s.
    pub dt: f64,
    /// The contact's restitution e.
    pub restitution: f64,
    /// The contact's friction μ.
    pub friction: f64,
    /// Rolls made.
    pub rolls: u64,
    /// Fraction of rolls not at rest at the step cap.
    pub unconverged: f64,
    /// Fraction of rolls at rest with no side vertical.
    pub unknown: f64,
    /// Fraction of rolls failed non-finite.
    pub non_finite: f64,
    /// Fraction of rolls failed tunnelled through the floor.
    pub tunnelled: f64,
    /// Fraction of rolls failed by an engine error.
    pub engine_error: f64,
    /// Fraction of rolls in which the engine injected energy.
    pub energy_gain: f64,
    /// Rolls whose centre went under the floor's top face at a step (a flag, not a failure).
    #[serde(default)]
    pub dipped: f64,
    /// The largest binomial standard error of this cell's fractions, √(f(1−f)/rolls).
    #[serde(default)]
    pub fraction_err_max: f64,
    /// A fraction measured as 0 is below this at 95 % confidence: 1 − 0.05^(1/rolls).
    #[serde(default)]
    pub zero_below_95: f64,
    /// N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// Simulated steps per roll.
    pub steps_per_roll: f64,
}

impl Cell {
    /// The fraction of failure kind `k` (one of `KINDS`); NaN for any other name.
    pub fn kind(&self, k: &str) -> f64 {
        match k {
            "unconverged" => self.unconverged,
            "unknown" => self.unknown,
            "non_finite" => self.non_finite,
            "tunnelled" => self.tunnelled,
            "energy_gain" => self.energy_gain,
            "dipped" => self.dipped,
            _ => f64::NAN,
        }
    }

    /// The binomial standard error of a fraction `f` of this cell's rolls.
    pub fn err(&self, f: f64) -> f64 {
        crate::theory::stats::binomial_err(f, self.rolls.max(1))
    }
}

/// The stability sweeps' results.
#[derive(Clone, Debug, Serialize)]
pub struct Stability {
    /// Rolls per cell.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The step cap per roll.
    pub max_steps: u64,
    /// The energy gain flagged, a fraction of the starting energy (`ENERGY_GAIN_TOLERANCE`).
    pub energy_gain_tolerance: f64,
    /// The box floor's thickness, m (DicePhys's: 100).
    pub floor_thickness: f64,
    /// Per cell: a fraction's standard error is at most 0.5/√rolls; a 0 is below
    /// `zero_below_95` at 95 %.
    pub fraction_err_max: f64,
    /// A fraction measured as 0 is below this at 95 % confidence.
    pub zero_below_95: f64,
    /// The grid's time steps, s.
    pub dts: Vec<f64>,
    /// The grid's restitutions.
    pub restitutions: Vec<f64>,
    /// The friction line's μ.
    pub frictions: Vec<f64>,
    /// The aspect line's blocks, `LxBxW` in mm.
    pub blocks: Vec<String>,
    /// Every cell: per engine, 3D then 2D, the grid, then the friction line, then the aspect line.
    pub cells: Vec<Cell>,
    /// One sentence per failure kind: where it happens most.
    pub findings: Vec<String>,
}

/// The column heads of the log's cell lines (`format_cell`).
pub fn header() -> String {
    TABLE.header()
}

/// One cell as a line of the log, under `header`.
pub fn format_cell(c: &Cell) -> String {
    let pc = |v: f64| format!("{:.1}%", 100.0 * v);
    TABLE.row(&[
        c.sweep.to_string(),
        c.engine.to_string(),
        c.mode.to_string(),
        c.block.clone(),
        crate::report::text::dt_label(c.dt),
        c.restitution.to_string(),
        c.friction.to_string(),
        pc(c.unconverged),
        pc(c.unknown),
        pc(c.non_finite),
        pc(c.tunnelled),
        pc(c.energy_gain),
        pc(c.dipped),
        pc(c.fraction_err_max),
        format!("{:.0}", c.steps_per_roll),
    ])
}

/// The columns of the log and of report.md.
const TABLE: Columns = Columns(&[
    left("sweep", 15),
    left("engine", 13),
    right("mode", 4),
    left("block", 11),
    right("dt", 8),
    right("e", 5),
    right("μ", 5),
    right("unconv", 7),
    right("unknown", 7),
    right("nonfin", 7),
    right("tunnel", 7),
    right("gain", 7),
    right("dipped", 7),
    right("±max", 6),
    right("steps", 7),
]);

/// The floor, where it is not DicePhys's.
fn floor_note(thickness: f64) -> String {
    if thickness == DICEPHYS_FLOOR_THICKNESS {
        String::new()
    } else {
        format!(", floor {} m thick", thickness)
    }
}

/// Draws a heat map per failure kind (a panel per engine and mode over the dt × restitution
/// grid) into `dir`; returns their stems.
fn write_figures(dir: &Path, res: &Stability) -> Result<Vec<String>> {
    let mut figures = Vec::new();
    for kind in KINDS {
        let panels: Vec<fig::Panel> = group(
            &res.cells
                .iter()
                .filter(|c| c.sweep == Sweep::DtRestitution)
                .collect::<Vec<_>>(),
            |c| format!("{} {}", c.engine, c.mode),
        )
        .into_iter()
        .map(|(title, cells)| fig::Panel {
            title,
            x_desc: "dt, s".into(),
            y_desc: "restitution e".into(),
            x_labels: res.dts.iter().map(|&d| dt_label(d)).collect(),
            y_labels: res.restitutions.iter().map(|e| e.to_string()).collect(),
            values: res
                .restitutions
                .iter()
                .map(|&e| {
                    res.dts
                        .iter()
                        .map(|&d| {
                            cells
                                .iter()
                                .find(|c| c.dt == d && c.restitution == e)
                                .map_or(f64::NAN, |c| c.kind(kind))
                        })
                        .collect()
                })
                .collect(),
        })
        .collect();
        let stem = format!("stability_{kind}");
        fig::heatmap(
            dir,
            &stem,
            &format!(
                "Fraction of rolls {kind} ({} rolls per cell: ± ≤ {:.1} %, 0 < {:.1} %; μ 0.29, 140x24x20{})",
                res.rolls,
                100.0 * res.fraction_err_max,
                100.0 * res.zero_below_95,
                floor_note(res.floor_thickness)
            ),
            &panels,
        )?;
        figures.push(stem);
    }
    Ok(figures)
}

/// report.md: the settings, every cell, the findings and the figures.
fn markdown(res: &Stability, figures: &[String]) -> String {
    let mut md = format!(
        "# Where methods fail\n\n{} rolls per cell, seed {}, cap {} steps, energy-gain tolerance \
         {} % of the starting energy{}. Each fraction f carries a binomial standard error \
         √(f(1−f)/{}), at most {:.1} % (column ±max: the largest in the row); a 0 means below \
         {:.1} % at 95 % confidence.\n\n```\n{}\n",
        res.rolls,
        res.seed,
        res.max_steps,
        100.0 * res.energy_gain_tolerance,
        floor_note(res.floor_thickness),
        res.rolls,
        100.0 * res.fraction_err_max,
        100.0 * res.zero_below_95,
        header()
    );
    for c in &res.cells {
        md += &format_cell(c);
        md.push('\n');
    }
    md += "```\n\n";
    for f in &res.findings {
        md += &format!("- {f}\n");
    }
    md.push('\n');
    for f in figures {
        md += &format!("![{f}]({f}.svg)\n");
    }
    md
}

impl super::Report for Stability {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        write_figures(dir, self)
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown(self, stems)
    }
}
