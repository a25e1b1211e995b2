//! `dicephys stability`: where engines break. Around the paper's scene (140x24x20, μ = 0.29,
//! e = 0.5, dt = 1 ms) one grid over the two most telling axes, dt × restitution, and two
//! lines, friction and the block's aspect ratio, per engine, 2D and 3D. Per cell the fractions
//! of rolls that end unconverged at the step cap, unknown (resting on an edge), failed
//! non-finite, tunnelled through the floor (`roll::Dip::through`), and, as flags, that gained
//! energy (`roll::EnergyWatch`) or dipped into the floor and came back (`roll::Dip`). Rolls
//! end by DicePhys's rule, every step stepped, capped at `max_steps`. Each fraction carries
//! its binomial standard error (`Cell::err`); the default rolls per cell make a 0 mean below
//! 1 % at 95 %.

use super::study::{Progress, Study};
use super::sweep::{cell_spec, check_rolls_and_steps, measure, nonempty};
use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::block::Block;
use crate::model::scene::{Mode, Scene, DICEPHYS_FLOOR_THICKNESS};
use crate::report::stability::{format_cell, Cell, Stability, Sweep, KINDS};
use crate::sim::roll::{Failure, RollConfig, Rule};
use serde::{Deserialize, Serialize};

/// What the stability sweeps run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The engines.
    pub engines: Vec<EngineKind>,
    /// The grid's time steps, s.
    pub dts: Vec<f64>,
    /// The grid's restitutions e.
    pub restitutions: Vec<f64>,
    /// The friction line's μ (at dt = 1 ms, e = 0.5).
    pub frictions: Vec<f64>,
    /// The aspect line's blocks (at dt = 1 ms, e = 0.5, μ = 0.29).
    pub blocks: Vec<Block>,
    /// Rolls per cell.
    pub rolls: u64,
    /// The throws' seed (keyed throws, the same in every cell).
    pub seed: u64,
    /// The step cap per roll.
    pub max_steps: u64,
    /// The box floor's thickness, m: DicePhys's 100 m, or a table top (2 cm) that a die can
    /// really pass through.
    pub floor_thickness: f64,
}

impl Default for Config {
    /// `dicephys stability` with no flags: the dt × restitution grid from 1 ms to 1/30 s, the
    /// friction line, the aspect line's five blocks, 300 rolls a cell (a fraction's standard
    /// error at most 2.9 %), DicePhys's floor.
    fn default() -> Config {
        let b = |s: &str| s.parse::<Block>().expect("a valid block");
        Config {
            engines: crate::studies::paper::DEFAULT_ENGINES.to_vec(),
            dts: vec![1.0 / 1000.0, 1.0 / 240.0, 1.0 / 60.0, 1.0 / 30.0],
            restitutions: vec![0.0, 0.5, 0.8, 0.95],
            frictions: vec![0.0, 0.29, 0.8, 1.5],
            blocks: [
                "140x24x20",
                "140x40x20",
                "140x100x20",
                "200x200x20",
                "24x24x20",
            ]
            .map(b)
            .to_vec(),
            rolls: 300,
            seed: crate::model::throws::DEFAULT_SEED,
            max_steps: 20_000,
            floor_thickness: DICEPHYS_FLOOR_THICKNESS,
        }
    }
}

impl Config {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        nonempty(&self.engines, Field::Engines)?;
        nonempty(&self.dts, Field::Dts)?;
        nonempty(&self.restitutions, Field::Restitutions)?;
        if let Some(e) = self
            .restitutions
            .iter()
            .find(|e| !(e.is_finite() && (0.0..1.0).contains(*e)))
        {
            return Err(Error::field(
                Field::Restitutions,
                e,
                "must be in [0, 1): at e = 1 nothing is lost at a bounce and no roll ever rests",
            ));
        }
        if let Some(m) = self
            .frictions
            .iter()
            .find(|m| !(m.is_finite() && **m >= 0.0))
        {
            return Err(Error::field(Field::Frictions, m, "must be finite and >= 0"));
        }
        if !(0.001..=DICEPHYS_FLOOR_THICKNESS).contains(&self.floor_thickness) {
            return Err(Error::field(
                Field::FloorThickness,
                self.floor_thickness,
                "must be in [0.001, 100] m",
            ));
        }
        check_rolls_and_steps(self.rolls, self.max_steps)
    }
}

/// The 95 % upper bound of a fraction seen 0 times in n rolls: 1 − 0.05^(1/n) (≈ 3/n).
pub fn zero_below_95(n: u64) -> f64 {
    1.0 - 0.05f64.powf(1.0 / n.max(1) as f64)
}

/// The paper's block and contact, the centre of every line.
fn base_block() -> Block {
    Block::from_mm(140.0, 24.0, 20.0).expect("a valid block")
}

/// The paper's scene for `block` with the step and the contact's e and μ set.
fn scene(block: Block, mode: Mode, dt: f64, e: f64, mu: f64) -> Scene {
    let mut scene = Scene::paper(block, mode);
    scene.dt = dt;
    scene.restitution = e;
    scene.friction = mu;
    scene
}

fn cell(
    cfg: &Config,
    study: &Study,
    sweep: Sweep,
    engine: EngineKind,
    scene: Scene,
) -> Result<Cell> {
    let (block, mode, dt, e, mu) = (
        scene.die.block(),
        scene.mode,
        scene.dt,
        scene.restitution,
        scene.friction,
    );
    let mut scene = scene;
    scene.floor_thickness = cfg.floor_thickness;
    let settle = RollConfig {
        max_steps: cfg.max_steps,
        rule: Rule::Dicephys,
        fast_flight: false,
        ..RollConfig::default()
    };
    let m = measure(
        &cell_spec(engine, scene, settle, cfg.seed, cfg.rolls),
        study,
    )?;
    let r = m.ratio();
    let t = &m.tally;
    let mut c = Cell {
        sweep,
        engine,
        mode,
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
        tunnelled: m.frac(t.failed_of(Failure::Tunnelled)),
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

/// Measures every cell, logging each as it is measured.
pub fn run(
    cfg: &Config,
    study: &Study,
    log: &dyn Fn(&str),
    progress: Progress,
) -> Result<Stability> {
    cfg.validate()?;
    let (dt0, e0, mu0) = (0.001, 0.5, 0.29);
    let per_mode = cfg.dts.len() * cfg.restitutions.len() + cfg.frictions.len() + cfg.blocks.len();
    let total = (cfg.engines.len() * 2 * per_mode) as f64;
    let mut cells = Vec::new();
    let mut push = |c: Cell| {
        log(&format_cell(&c));
        cells.push(c);
        progress(cells.len() as f64, total);
    };
    for &engine in &cfg.engines {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            for &dt in &cfg.dts {
                for &e in &cfg.restitutions {
                    let s = scene(base_block(), mode, dt, e, mu0);
                    push(cell(cfg, study, Sweep::DtRestitution, engine, s)?);
                }
            }
            for &mu in &cfg.frictions {
                let s = scene(base_block(), mode, dt0, e0, mu);
                push(cell(cfg, study, Sweep::Friction, engine, s)?);
            }
            for &b in &cfg.blocks {
                let s = scene(b, mode, dt0, e0, mu0);
                push(cell(cfg, study, Sweep::Aspect, engine, s)?);
            }
        }
    }
    let findings = findings(&cells);
    Ok(Stability {
        rolls: cfg.rolls,
        seed: cfg.seed,
        max_steps: cfg.max_steps,
        energy_gain_tolerance: crate::sim::roll::ENERGY_GAIN_TOLERANCE,
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
    match c.sweep {
        Sweep::Friction => format!("{} {} μ {}", c.engine, c.mode, c.friction),
        Sweep::Aspect => format!("{} {} block {}", c.engine, c.mode, c.block),
        _ => format!(
            "{} {} dt {} e {}",
            c.engine,
            c.mode,
            crate::report::text::dt_label(c.dt),
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
