//! `dicephys stability`: where engines break. Around the paper's scene (140x24x20, μ = 0.29,
//! e = 0.5, dt = 1 ms) one grid over the two most telling axes, dt × restitution, and two
//! lines, friction and the block's aspect ratio, per engine, 2D and 3D. Per cell the fractions
//! of rolls that end unconverged at the step cap, unknown (resting on an edge), failed
//! non-finite, tunnelled through the floor (`roll::Dip::through`), and, as flags, that gained
//! energy (`roll::EnergyWatch`) or dipped into the floor and came back (`roll::Dip`). Rolls
//! end by DicePhys's rule, every step stepped, capped at `max_steps`. Each fraction carries
//! its binomial standard error (`Cell::err`); the default rolls per cell make a 0 mean below
//! 1 % at 95 %.

use super::{measure, throws};
use crate::block::Block;
use crate::engine::EngineKind;
use crate::roll::{Failure, Rule, Settle};
use crate::scene::{Mode, Scene};
use serde::Serialize;

pub struct Config {
    pub engines: Vec<EngineKind>,
    pub dts: Vec<f64>,
    pub restitutions: Vec<f64>,
    pub frictions: Vec<f64>,
    pub blocks: Vec<Block>,
    pub rolls: u64,
    pub seed: u64,
    pub threads: usize,
    pub max_steps: u64,
    /// The box floor's thickness, m: DicePhys's 100 m, or a table top (2 cm) that a die can
    /// really pass through.
    pub floor_thickness: f64,
}

/// The failure kinds, in the order of the figures and tables.
pub const KINDS: [&str; 6] = [
    "unconverged",
    "unknown",
    "non_finite",
    "tunnelled",
    "energy_gain",
    "dipped",
];

#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    /// `dt_restitution` (the grid), `friction` or `aspect` (the lines).
    pub sweep: String,
    pub engine: String,
    pub mode: String,
    pub block: String,
    /// breadth/width and length/breadth.
    pub breadth_over_width: f64,
    pub length_over_breadth: f64,
    pub dt: f64,
    pub restitution: f64,
    pub friction: f64,
    pub rolls: u64,
    pub unconverged: f64,
    pub unknown: f64,
    pub non_finite: f64,
    pub tunnelled: f64,
    pub engine_error: f64,
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
    pub ratio: f64,
    pub ratio_err: f64,
    pub steps_per_roll: f64,
}

impl Cell {
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
        fraction_err(f, self.rolls)
    }
}

/// √(f(1−f)/n): the standard error of a fraction of n rolls.
pub fn fraction_err(f: f64, n: u64) -> f64 {
    (f * (1.0 - f) / n.max(1) as f64).sqrt()
}

/// The 95 % upper bound of a fraction seen 0 times in n rolls: 1 − 0.05^(1/n) (≈ 3/n).
pub fn zero_below_95(n: u64) -> f64 {
    1.0 - 0.05f64.powf(1.0 / n.max(1) as f64)
}

#[derive(Clone, Debug, Serialize)]
pub struct Stability {
    pub rolls: u64,
    pub seed: u64,
    pub max_steps: u64,
    pub energy_gain_tolerance: f64,
    /// The box floor's thickness, m (DicePhys's: 100).
    pub floor_thickness: f64,
    /// Per cell: a fraction's standard error is at most 0.5/√rolls; a 0 is below
    /// `zero_below_95` at 95 %.
    pub fraction_err_max: f64,
    pub zero_below_95: f64,
    pub dts: Vec<f64>,
    pub restitutions: Vec<f64>,
    pub frictions: Vec<f64>,
    pub blocks: Vec<String>,
    pub cells: Vec<Cell>,
    /// One sentence per failure kind: where it happens most.
    pub findings: Vec<String>,
}

/// The paper's block and contact, the centre of every line.
fn base_block() -> Block {
    Block::from_mm(140.0, 24.0, 20.0).expect("a valid block")
}

#[allow(clippy::too_many_arguments)]
fn cell(
    cfg: &Config,
    sweep: &str,
    engine: EngineKind,
    mode: Mode,
    block: Block,
    dt: f64,
    e: f64,
    mu: f64,
) -> Result<Cell, String> {
    let mut scene = Scene::paper(block, mode);
    scene.dt = dt;
    scene.restitution = e;
    scene.friction = mu;
    scene.floor_thickness = cfg.floor_thickness;
    let settle = Settle {
        max_steps: cfg.max_steps,
        rule: Rule::Dicephys,
        fast_flight: false,
        ..Settle::default()
    };
    let m = measure(
        engine,
        &scene,
        &throws(cfg.seed),
        &settle,
        cfg.rolls,
        cfg.threads,
    )?;
    let r = m.ratio();
    let t = &m.tally;
    let mut c = Cell {
        sweep: sweep.into(),
        engine: engine.name().into(),
        mode: mode.name().into(),
        block: block.to_string(),
        breadth_over_width: block.breadth / block.width,
        length_over_breadth: block.length / block.breadth,
        dt,
        restitution: e,
        friction: mu,
        rolls: t.rolls,
        unconverged: m.frac(t.unconverged),
        unknown: m.frac(t.counts.unknown),
        non_finite: m.frac(t.failed_of(Failure::NonFinite)),
        tunnelled: m.frac(t.failed_of(Failure::FellThrough)),
        engine_error: m.frac(t.failed_of(Failure::Engine)),
        energy_gain: m.frac(t.energy_gain),
        dipped: m.frac(t.dipped),
        fraction_err_max: 0.0,
        zero_below_95: zero_below_95(t.rolls),
        ratio: r.value,
        ratio_err: r.err,
        steps_per_roll: m.steps_per_roll(),
    };
    c.fraction_err_max = KINDS.iter().map(|k| c.err(c.kind(k))).fold(0.0, f64::max);
    Ok(c)
}

pub fn run(cfg: &Config, log: &dyn Fn(&str)) -> Result<Stability, String> {
    let (dt0, e0, mu0) = (0.001, 0.5, 0.29);
    let mut cells = Vec::new();
    let mut push = |c: Cell| {
        log(&format_cell(&c));
        cells.push(c);
    };
    for &engine in &cfg.engines {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            for &dt in &cfg.dts {
                for &e in &cfg.restitutions {
                    push(cell(
                        cfg,
                        "dt_restitution",
                        engine,
                        mode,
                        base_block(),
                        dt,
                        e,
                        mu0,
                    )?);
                }
            }
            for &mu in &cfg.frictions {
                push(cell(
                    cfg,
                    "friction",
                    engine,
                    mode,
                    base_block(),
                    dt0,
                    e0,
                    mu,
                )?);
            }
            for &b in &cfg.blocks {
                push(cell(cfg, "aspect", engine, mode, b, dt0, e0, mu0)?);
            }
        }
    }
    let findings = findings(&cells);
    Ok(Stability {
        rolls: cfg.rolls,
        seed: cfg.seed,
        max_steps: cfg.max_steps,
        energy_gain_tolerance: crate::roll::ENERGY_GAIN_TOLERANCE,
        floor_thickness: cfg.floor_thickness,
        fraction_err_max: 0.5 / (cfg.rolls.max(1) as f64).sqrt(),
        zero_below_95: zero_below_95(cfg.rolls),
        dts: cfg.dts.clone(),
        restitutions: cfg.restitutions.clone(),
        frictions: cfg.frictions.clone(),
        blocks: cfg.blocks.iter().map(|b| b.to_string()).collect(),
        cells,
        findings,
    })
}

fn describe(c: &Cell) -> String {
    match c.sweep.as_str() {
        "friction" => format!("{} {} μ {}", c.engine, c.mode, c.friction),
        "aspect" => format!("{} {} block {}", c.engine, c.mode, c.block),
        _ => format!(
            "{} {} dt {} e {}",
            c.engine,
            c.mode,
            super::dt_label(c.dt),
            c.restitution
        ),
    }
}

/// Per failure kind: how many cells show it, and the worst.
fn findings(cells: &[Cell]) -> Vec<String> {
    KINDS
        .iter()
        .map(|&k| {
            let hit: Vec<&Cell> = cells.iter().filter(|c| c.kind(k) > 0.0).collect();
            match hit.iter().max_by(|a, b| a.kind(k).total_cmp(&b.kind(k))) {
                None => format!("{k}: none in any of {} cells.", cells.len()),
                Some(w) => {
                    let mut names: Vec<String> = hit.iter().take(6).map(|c| describe(c)).collect();
                    if hit.len() > 6 {
                        names.push("…".into());
                    }
                    format!(
                        "{k}: in {} of {} cells, worst {:.1} ± {:.1} % ({}); cells: {}.",
                        hit.len(),
                        cells.len(),
                        100.0 * w.kind(k),
                        100.0 * w.err(w.kind(k)),
                        describe(w),
                        names.join("; ")
                    )
                }
            }
        })
        .collect()
}

pub fn header() -> String {
    format!(
        "{:<15} {:<13} {:>4} {:<11} {:>8} {:>5} {:>5} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6} {:>7}",
        "sweep",
        "engine",
        "mode",
        "block",
        "dt",
        "e",
        "μ",
        "unconv",
        "unknown",
        "nonfin",
        "tunnel",
        "gain",
        "dipped",
        "±max",
        "steps"
    )
}

pub fn format_cell(c: &Cell) -> String {
    let pc = |v: f64| format!("{:.1}%", 100.0 * v);
    format!(
        "{:<15} {:<13} {:>4} {:<11} {:>8} {:>5} {:>5} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6} {:>7.0}",
        c.sweep,
        c.engine,
        c.mode,
        c.block,
        super::dt_label(c.dt),
        c.restitution,
        c.friction,
        pc(c.unconverged),
        pc(c.unknown),
        pc(c.non_finite),
        pc(c.tunnelled),
        pc(c.energy_gain),
        pc(c.dipped),
        pc(c.fraction_err_max),
        c.steps_per_roll
    )
}
