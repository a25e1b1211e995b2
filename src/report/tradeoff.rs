//! `tradeoff`'s results and report: each method's cost against its departure from the
//! reference, resolved to a precision, with the Pareto front (the study: `studies::tradeoff`).

use crate::engine::EngineKind;
use crate::error::Result;
use crate::model::block::Block;
use crate::model::scene::{Floor, Mode};
use crate::report::figures::tradeoff as fig;
use crate::report::text::{dt_label, left, right, Columns};
use serde::Serialize;
use std::path::Path;

/// What a row is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// A method on the chart.
    Method,
    /// The reference itself.
    Reference,
    /// A rung of the reference's ladder (another fine step, the same levers).
    Ladder,
    /// The reference's scene rolled faithfully (DicePhys's rule, stepped): shows the levers
    /// exact at the reference's step.
    Levers,
}

/// One method's measurement (or the reference's).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The method's name: engine, mode, dt, rule, floor.
    pub method: String,
    /// What the row is.
    pub role: Role,
    /// The engine.
    pub engine: EngineKind,
    /// 2D or 3D.
    pub mode: Mode,
    /// The time step, s.
    pub dt: f64,
    /// `faithful` (DicePhys's rule, stepped flight) or `fast` (the defaults: closed-form flight,
    /// and the early stop where it is exact, dt <= 1/250).
    pub rule: String,
    /// The floor: DicePhys's box, or the plane.
    pub floor: Floor,
    /// Rolls made: the first `rolls` throws of the keyed stream.
    pub rolls: u64,
    /// N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// Process CPU seconds per 1,000 rolls, all threads.
    pub cpu_s_per_1000: f64,
    /// Simulated steps per roll.
    pub steps_per_roll: f64,
    /// Relative departure from the reference, ratio/reference − 1 (a fraction), with the
    /// shared throws as a control variate (`studies::departure::paired_departure`).
    pub error: f64,
    /// Its standard error, paired on the shared throws.
    pub error_err: f64,
    /// The same error had the throws been independent.
    pub error_err_unpaired: f64,
    /// The fraction of shared throws ending alike (breadth, width, other) with the reference.
    pub agreement: f64,
    /// The departure in standard errors, `error / error_err` (0 unless that error is positive).
    pub error_sigma: f64,
    /// 2σ of the departure (for the reference: of its own ratio) is at most the precision.
    pub resolved: bool,
    /// Unresolved: the rolls that would resolve it (the reference as rolled), if any would.
    pub rolls_needed: Option<u64>,
    /// Rolls not at rest at the step cap.
    pub unconverged: u64,
    /// Rolls that failed, for any reason.
    pub failed: u64,
    /// Rolls in which the engine injected energy.
    pub energy_gain: u64,
    /// Rolls whose die's centre went under the floor's top face at a step (not failures).
    #[serde(default)]
    pub dipped: u64,
    /// This row is the reference (its departure 0).
    pub reference: bool,
}

/// One mode's methods against its reference, its Pareto front and its verdict.
#[derive(Clone, Debug, Serialize)]
pub struct ModeResult {
    /// 2D or 3D.
    pub mode: Mode,
    /// The reference: Bullet, box floor, the exact levers, at the reference dt.
    pub reference: Row,
    /// The reference's scene rolled faithfully, and the ladder's rungs.
    pub checks: Vec<Row>,
    /// Every method, in the order run.
    pub rows: Vec<Row>,
    /// Resolved methods no other resolved one is both cheaper and closer to the reference
    /// than, cheapest first (among methods failing or unconverged on at most 1 % of rolls).
    pub pareto_front: Vec<String>,
    /// The cheapest resolved method whose |departure| is at most the precision, if any.
    pub cheapest_within: Option<String>,
    /// Plain words: the cheapest method within the precision, and what is unresolved.
    pub note: String,
}

/// The trade-off study's results.
#[derive(Clone, Debug, Serialize)]
pub struct Tradeoff {
    /// The block, `LxBxW` in mm.
    pub block: String,
    /// The 2σ half-width asked of every departure, a fraction.
    pub precision: f64,
    /// CPU seconds a method may spend.
    pub budget_s: f64,
    /// The throws' seed.
    pub seed: u64,
    /// The reference's time step, s.
    pub reference_dt: f64,
    /// After the pilot: the CPU seconds the whole run was planned to take.
    pub planned_cpu_s: f64,
    /// The same plan at 1 % (no budget): what resolving the paper's 1 % costs.
    pub planned_cpu_s_at_one_percent: f64,
    /// The precision the whole run (pilot included, no budget) would reach in an hour of
    /// all this run's threads, from the pilot's costs and variances.
    pub precision_in_an_hour: f64,
    /// CPU seconds the rolls took (read back with their chunks on a resumed run).
    pub cpu_s: f64,
    /// 3D, then 2D.
    pub modes: Vec<ModeResult>,
}

/// One method across the blocks of a run on several blocks.
#[derive(Clone, Debug, Serialize)]
pub struct MethodAcross {
    /// The method's name, as in each block's rows.
    pub method: String,
    /// Its departure farthest from 0 over the blocks (a fraction; NaN counts as farthest).
    pub worst_error: f64,
    /// That departure's standard error.
    pub worst_error_err: f64,
    /// The block it is on.
    pub worst_block: String,
    /// Blocks on which its departure is resolved (and it fails or stays unconverged on at most
    /// 1 % of rolls).
    pub resolved_on: u64,
    /// Resolved, and its |departure| within the precision, on every block.
    pub within_everywhere: bool,
    /// CPU seconds per 1,000 rolls, the mean over the blocks.
    pub cpu_s_per_1000: f64,
}

/// One mode's methods across the blocks, and the cheapest within the precision on all.
#[derive(Clone, Debug, Serialize)]
pub struct ModeAcross {
    /// 2D or 3D.
    pub mode: Mode,
    /// Every method, in the order run.
    pub methods: Vec<MethodAcross>,
    /// The cheapest method (by mean cost) within the precision on every block, if any.
    pub cheapest_everywhere: Option<String>,
    /// The same in words.
    pub note: String,
}

/// A trade-off study of several blocks: each block's own study, and each method across them.
#[derive(Clone, Debug, Serialize)]
pub struct TradeoffBlocks {
    /// The blocks, `LxBxW` in mm, in the order run.
    pub blocks: Vec<String>,
    /// The 2σ half-width asked of every departure, a fraction.
    pub precision: f64,
    /// CPU seconds a method may spend (on each block).
    pub budget_s: f64,
    /// CPU seconds each reference may spend.
    pub reference_budget_s: f64,
    /// The throws' seed.
    pub seed: u64,
    /// The references' time step, s.
    pub reference_dt: f64,
    /// After the pilot: the CPU seconds the whole run was planned to take.
    pub planned_cpu_s: f64,
    /// The same plan at 1 % (no budget).
    pub planned_cpu_s_at_one_percent: f64,
    /// The precision the whole run would reach in an hour of its threads.
    pub precision_in_an_hour: f64,
    /// CPU seconds the rolls took, all blocks.
    pub cpu_s: f64,
    /// Each mode across the blocks, 3D first.
    pub across: Vec<ModeAcross>,
    /// Each block's study, as a run on that block alone reports it.
    pub per_block: Vec<Tradeoff>,
}

/// The column heads of the log's method lines (`format_row`).
pub fn header() -> String {
    TABLE.header()
}

/// One method as a line of the log, under `header`.
pub fn format_row(r: &Row) -> String {
    TABLE.row(&[
        r.method.clone(),
        r.rolls.to_string(),
        format!("{:.4} ± {:.4}", r.ratio, r.ratio_err),
        format!("{:.3}", r.cpu_s_per_1000),
        format!("{:.0}", r.steps_per_roll),
        format!("{:+.2} ± {:.2} %", 100.0 * r.error, 100.0 * r.error_err),
        if r.resolved { "yes" } else { "no" }.into(),
        format!("{:.3}", r.agreement),
        (r.failed + r.unconverged).to_string(),
        r.dipped.to_string(),
    ])
}

/// The columns of the log and of report.md.
const TABLE: Columns = Columns(&[
    left("method", 38),
    right("rolls", 8),
    right("ratio", 17),
    right("CPU s/1000", 11),
    right("steps", 7),
    right("departure ±1σ", 18),
    right("res.", 4),
    right("agree", 6),
    right("failed", 6),
    right("dipped", 6),
]);

/// report.md: how the methods were rolled, each mode's table, front and verdict, and the
/// figure.
fn markdown(res: &Tradeoff, figures: &[&str]) -> String {
    let mut md = format!(
        "# Accuracy against cost\n\n{}, seed {}; every departure rolled until 2σ ≤ {:.2} % or \
         {:.0} CPU s spent; reference: Bullet, box floor, the exact levers (early stop, fast \
         flight), dt {}, to 2σ ≤ {:.2} % of its own. Planned after the pilot: {:.0} CPU s; \
         spent on rolls: {:.0} CPU s. At ±1 % the plan is {:.0} CPU s.\n\n",
        res.block,
        res.seed,
        100.0 * res.precision,
        res.budget_s,
        dt_label(res.reference_dt),
        50.0 * res.precision,
        res.planned_cpu_s,
        res.cpu_s,
        res.planned_cpu_s_at_one_percent
    );
    md += &modes_markdown(res, "##");
    for f in figures {
        md += &format!("![cost against departure]({f}.svg)\n");
    }
    md
}

/// Each mode of one block: its table (log lines), front and verdict, under `level` headings.
fn modes_markdown(res: &Tradeoff, level: &str) -> String {
    let mut md = String::new();
    for m in &res.modes {
        md += &format!(
            "{level} {}\n\n```\n{}\n{}  (reference)\n",
            m.mode,
            header(),
            format_row(&m.reference)
        );
        for r in &m.checks {
            md += &format!("{}  ({:?})\n", format_row(r), r.role);
        }
        for r in &m.rows {
            md += &format_row(r);
            md.push('\n');
        }
        md += &format!(
            "```\n\nPareto front over resolved methods (cheapest first): {}.\n\n{}\n\n",
            m.pareto_front.join("; "),
            m.note
        );
    }
    md
}

/// A departure ± 2σ in per cent, "(open)" when unresolved.
fn departure_cell(r: &Row) -> String {
    format!(
        "{:+.2} ± {:.2}{}",
        100.0 * r.error,
        200.0 * r.error_err,
        if r.resolved { "" } else { " (open)" }
    )
}

/// report.md of a run on several blocks: per mode, every method's departure on every block
/// (± 2σ) with its worst and its mean cost, the cheapest within the precision on all blocks;
/// then each block's own tables; and the figure.
fn markdown_blocks(res: &TradeoffBlocks, figures: &[&str]) -> String {
    let p = 100.0 * res.precision;
    let mut md = format!(
        "# Accuracy against cost, {} blocks\n\nBlocks {}; seed {}; on each block and mode every \
         departure rolled until 2σ ≤ {p:.2} % or {:.0} CPU s spent; reference: Bullet, box \
         floor, the exact levers (early stop, fast flight), dt {}, to 2σ ≤ {:.2} % of its own \
         or {:.0} CPU s. Planned after the pilot: {:.0} CPU s; spent on rolls: {:.0} CPU s. At \
         ±1 % the plan is {:.0} CPU s.\n\n",
        res.blocks.len(),
        res.blocks.join(", "),
        res.seed,
        res.budget_s,
        dt_label(res.reference_dt),
        p / 2.0,
        res.reference_budget_s,
        res.planned_cpu_s,
        res.cpu_s,
        res.planned_cpu_s_at_one_percent
    );
    for f in figures {
        md += &format!("![cost against departure, a panel per block]({f}.svg)\n\n");
    }
    for a in &res.across {
        let mode_of = |t: &Tradeoff| t.modes.iter().find(|m| m.mode == a.mode).cloned();
        let modes: Vec<Option<ModeResult>> = res.per_block.iter().map(mode_of).collect();
        md += &format!(
            "## {} across the blocks\n\nDepartures from each block's reference, per cent ± 2σ \
             (open: 2σ above ±{p:.2} % within the budget); the worst over the blocks; \
             within: resolved and within ±{p:.2} % on every block; CPU seconds per 1,000 rolls, \
             the mean over the blocks.\n\n| method | {} | worst | within | CPU s/1000 |\n|---|{}---|---|---|\n",
            a.mode,
            res.blocks.join(" | "),
            "---|".repeat(res.blocks.len())
        );
        let cells = |f: &dyn Fn(&ModeResult) -> String| -> String {
            modes
                .iter()
                .map(|m| m.as_ref().map_or("".into(), f))
                .collect::<Vec<_>>()
                .join(" | ")
        };
        md += &format!(
            "| reference ratio ± 2σ (rolls) | {} | | | |\n",
            cells(&|m| format!(
                "{:.4} ± {:.4} ({})",
                m.reference.ratio,
                2.0 * m.reference.ratio_err,
                m.reference.rolls
            ))
        );
        let checks: Vec<String> = modes
            .iter()
            .flatten()
            .next()
            .map(|m| m.checks.iter().map(|r| r.method.clone()).collect())
            .unwrap_or_default();
        for name in checks {
            md += &format!(
                "| {name} (check) | {} | | | |\n",
                cells(&|m| m
                    .checks
                    .iter()
                    .find(|r| r.method == name)
                    .map_or("".into(), departure_cell))
            );
        }
        for x in &a.methods {
            md += &format!(
                "| {} | {} | {:+.2} ± {:.2} ({}) | {} | {:.3} |\n",
                x.method,
                cells(&|m| m
                    .rows
                    .iter()
                    .find(|r| r.method == x.method)
                    .map_or("".into(), departure_cell)),
                100.0 * x.worst_error,
                200.0 * x.worst_error_err,
                x.worst_block,
                if x.within_everywhere { "yes" } else { "no" },
                x.cpu_s_per_1000
            );
        }
        md += &format!("\n{}\n\n", a.note);
    }
    for t in &res.per_block {
        md += &format!("## {}\n\n", t.block);
        md += &modes_markdown(t, "###");
    }
    md
}

/// A method's name without its mode: the figures' key, shared by 3D and 2D.
fn key_name(r: &Row) -> String {
    format!(
        "{} {} {} {}",
        r.engine.name(),
        dt_label(r.dt),
        r.rule,
        match r.floor {
            Floor::Box => "box",
            Floor::Plane => "plane",
        }
    )
}

/// Every method of `studies`, numbered from 1 in the order first met: (number, name).
fn figure_key(studies: &[&Tradeoff]) -> Vec<(String, String)> {
    let mut names: Vec<String> = Vec::new();
    for r in studies.iter().flat_map(|t| &t.modes).flat_map(|m| &m.rows) {
        let n = key_name(r);
        if !names.contains(&n) {
            names.push(n);
        }
    }
    names
        .into_iter()
        .enumerate()
        .map(|(i, n)| ((i + 1).to_string(), n))
        .collect()
}

/// One block's panel: its methods numbered by `key`, the paper's experimental error on the
/// block and Rapier's departure at its finest step as bands, and in its caption the cheapest
/// method within the precision per mode.
fn panel(res: &Tradeoff, key: &[(String, String)], caption: &str) -> fig::Panel {
    let mut methods = Vec::new();
    let mut bands = Vec::new();
    let number = |r: &Row| {
        let n = key_name(r);
        key.iter()
            .find(|(_, name)| *name == n)
            .map_or("?".into(), |(k, _)| k.clone())
    };
    if let Some(m) = res.block.parse::<Block>().ok().and_then(paper_experiment) {
        bands.push(fig::Band {
            lo: 0.0,
            hi: 200.0 * m.err / m.value,
            two_d: None,
        });
    }
    let mut cheapest = Vec::new();
    for m in &res.modes {
        let two_d = m.mode == Mode::TwoD;
        for r in &m.rows {
            methods.push(fig::MethodPoint {
                key: number(r),
                cost: r.cpu_s_per_1000,
                error: 100.0 * r.error.abs(),
                error_err: 100.0 * r.error_err,
                two_d,
                resolved: r.resolved,
                on_front: m.pareto_front.contains(&r.method),
                cheapest: m.cheapest_within.as_ref() == Some(&r.method),
            });
            if m.cheapest_within.as_ref() == Some(&r.method) {
                cheapest.push(format!("{} {}", m.mode.name(), number(r)));
            }
        }
        if let Some(r) = rapier_finest(m) {
            let (d, e) = (100.0 * r.error.abs(), 200.0 * r.error_err);
            bands.push(fig::Band {
                lo: d - e,
                hi: d + e,
                two_d: Some(two_d),
            });
        }
    }
    let cheapest = if cheapest.is_empty() {
        "none within".to_string()
    } else {
        format!("cheapest within: {}", cheapest.join(", "))
    };
    fig::Panel {
        title: format!("{caption}; {cheapest}"),
        methods,
        bands,
    }
}

/// The paper's measured ratio for `block` (a simulated MDF row), if it has one.
fn paper_experiment(block: Block) -> Option<crate::theory::stats::Ratio> {
    crate::theory::paper_data::load().ok().and_then(|t| {
        t.rows
            .into_iter()
            .find(|r| r.simulated && r.block_dims().ok() == Some(block))
            .map(|r| r.measured_ratio())
    })
}

/// Rapier's converged departure: its box floor, exact levers, at its finest step.
fn rapier_finest(m: &ModeResult) -> Option<&Row> {
    m.rows
        .iter()
        .filter(|r| r.engine == EngineKind::Rapier && r.rule == "fast" && r.floor == Floor::Box)
        .min_by(|x, y| x.dt.total_cmp(&y.dt))
}

/// What the bands of the panels are.
fn band_notes() -> Vec<String> {
    vec![
        "grey band: the paper's experiment on the block, 2σ".into(),
        "tinted bands: Rapier (box, fast, finest step)".into(),
        "  against Bullet, |departure| ± 2σ, per mode".into(),
    ]
}

/// Draws cost against departure for one block, every method numbered and keyed, with the
/// paper's experimental error on the block and Rapier's converged departure as yardsticks,
/// into `dir`; returns its stem.
fn write_figures(dir: &Path, res: &Tradeoff) -> Result<Vec<&'static str>> {
    let key = figure_key(&[res]);
    let figure = fig::Figure {
        title: format!(
            "{}: cost against departure from Bullet at {} (±{} % at 2σ asked)",
            res.block,
            dt_label(res.reference_dt),
            100.0 * res.precision
        ),
        panels: vec![panel(res, &key, &res.block)],
        key,
        band_notes: band_notes(),
        precision: 100.0 * res.precision,
    };
    fig::write(dir, "tradeoff", &figure)?;
    Ok(vec!["tradeoff"])
}

/// The figure of a run on several blocks: a panel per block on shared axes, every method
/// numbered the same in every panel and keyed beside them.
fn write_figures_blocks(dir: &Path, res: &TradeoffBlocks) -> Result<Vec<&'static str>> {
    let studies: Vec<&Tradeoff> = res.per_block.iter().collect();
    let key = figure_key(&studies);
    let figure = fig::Figure {
        title: format!(
            "Cost against departure from Bullet at {}, per block (±{} % at 2σ asked)",
            dt_label(res.reference_dt),
            100.0 * res.precision
        ),
        panels: res
            .per_block
            .iter()
            .map(|t| panel(t, &key, &t.block))
            .collect(),
        key,
        band_notes: band_notes(),
        precision: 100.0 * res.precision,
    };
    fig::write(dir, "tradeoff", &figure)?;
    Ok(vec!["tradeoff"])
}

impl super::Report for Tradeoff {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        Ok(super::owned(write_figures(dir, self)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown(self, &super::stems(stems))
    }
}

impl super::Report for TradeoffBlocks {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        Ok(super::owned(write_figures_blocks(dir, self)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown_blocks(self, &super::stems(stems))
    }
}
