//! `dicephys tradeoff`: accuracy against cost. A method is an engine, a time step, a settling
//! rule (DicePhys's rest rule with every step stepped, or the exact early stop with closed-form
//! flight) and a scene variant (box floor or plane; in 2D also Rapier's locked 3D body against
//! its true 2D one). Cost: CPU seconds per 1,000 rolls. Accuracy: the ratio's departure from
//! the reference, the faithful scene (Bullet, box floor, DicePhys's rule, stepped) at the finest
//! dt, in standard errors and per cent. Each mode (2D, 3D) has its own reference and front.

use super::sweep::{cell_spec, departure, dt_label, measure, rolls_to_resolve, Study, ONE_PERCENT};
use crate::engine::EngineKind;
use crate::error::Result;
use crate::model::block::Block;
use crate::model::scene::{Floor, Mode, Scene};
use crate::report::text::{left, right, Columns};
use crate::sim::roll::{RollConfig, Rule};
use serde::Serialize;

/// What the trade-off study runs.
pub struct Config {
    /// The block.
    pub block: Block,
    /// The methods' time steps, s.
    pub dts: Vec<f64>,
    /// The reference's dt (finer than every method's).
    pub reference_dt: f64,
    /// Rolls per method.
    pub rolls: u64,
    /// The throws' seed (keyed throws, the same for every method).
    pub seed: u64,
    /// The step cap per roll.
    pub max_steps: u64,
}

/// One method's measurement (or the reference's).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The method's name: engine, mode, dt, rule, floor.
    pub method: String,
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
    /// Rolls made.
    pub rolls: u64,
    /// N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// Process CPU seconds per 1,000 rolls, all threads.
    pub cpu_s_per_1000: f64,
    /// Simulated steps per roll.
    pub steps_per_roll: f64,
    /// Relative departure from the reference, ratio/reference − 1 (a fraction).
    pub error: f64,
    /// Its error.
    pub error_err: f64,
    /// The departure in standard errors, `error / error_err` (0 unless that error is positive).
    pub error_sigma: f64,
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
    /// The reference: Bullet, box floor, DicePhys's rule, stepped, at the reference dt.
    pub reference: Row,
    /// Every method, in the order run.
    pub rows: Vec<Row>,
    /// Methods no other is both cheaper and closer to the reference than, cheapest first
    /// (among methods failing or unconverged on at most 1 % of rolls).
    pub pareto_front: Vec<String>,
    /// The cheapest method whose departure is within 1 % at 2σ (|error| + 2σ ≤ 1 %), if any.
    pub cheapest_within_one_percent: Option<String>,
    /// Plain words: the cheapest method within 1 %, or how many rolls would resolve 1 %.
    pub note: String,
}

/// The trade-off study's results.
#[derive(Clone, Debug, Serialize)]
pub struct Tradeoff {
    /// The block, `LxBxW` in mm.
    pub block: String,
    /// Rolls per method.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The reference's time step, s.
    pub reference_dt: f64,
    /// 3D, then 2D.
    pub modes: Vec<ModeResult>,
}

struct Method {
    engine: EngineKind,
    dt: f64,
    faithful: bool,
    floor: Floor,
}

impl Method {
    fn name(&self, mode: Mode) -> String {
        format!(
            "{} {} {} {} {}",
            self.engine.name(),
            mode.name(),
            dt_label(self.dt),
            if self.faithful { "faithful" } else { "fast" },
            match self.floor {
                Floor::Box => "box",
                Floor::Plane => "plane",
            }
        )
    }
}

fn methods(mode: Mode, dts: &[f64]) -> Vec<Method> {
    let engines: &[EngineKind] = match mode {
        Mode::ThreeD => &[EngineKind::Bullet, EngineKind::Rapier],
        Mode::TwoD => &[
            EngineKind::Bullet,
            EngineKind::Rapier,
            EngineKind::RapierLocked,
        ],
    };
    let mut out = Vec::new();
    for &engine in engines {
        for &dt in dts {
            for faithful in [true, false] {
                for floor in [Floor::Box, Floor::Plane] {
                    out.push(Method {
                        engine,
                        dt,
                        faithful,
                        floor,
                    });
                }
            }
        }
    }
    out
}

fn roll_method(
    cfg: &Config,
    study: &Study,
    mode: Mode,
    m: &Method,
    reference: Option<&Row>,
) -> Result<Row> {
    let mut scene = Scene::paper(cfg.block, mode);
    scene.dt = m.dt;
    scene.floor = m.floor;
    let settle = RollConfig {
        max_steps: cfg.max_steps,
        // `fast` is the defaults: the early stop only where it is audited exact.
        rule: if m.faithful || !crate::sim::roll::early_stop_exact(m.dt) {
            Rule::Dicephys
        } else {
            Rule::Certificate
        },
        fast_flight: !m.faithful,
        ..RollConfig::default()
    };
    let res = measure(
        &cell_spec(m.engine, scene, settle, cfg.seed, cfg.rolls),
        study,
    )?;
    let r = res.ratio();
    let (error, error_err) = match reference {
        Some(rf) => departure(
            r,
            crate::theory::stats::Ratio {
                value: rf.ratio,
                err: rf.ratio_err,
            },
        ),
        None => (0.0, 0.0),
    };
    Ok(Row {
        method: m.name(mode),
        engine: m.engine,
        mode,
        dt: m.dt,
        rule: if m.faithful { "faithful" } else { "fast" }.into(),
        floor: m.floor,
        rolls: res.tally.rolls,
        ratio: r.value,
        ratio_err: r.err,
        cpu_s_per_1000: 1000.0 * res.cpu_s_per_roll(),
        steps_per_roll: res.steps_per_roll(),
        error,
        error_err,
        error_sigma: if error_err > 0.0 {
            error / error_err
        } else {
            0.0
        },
        unconverged: res.tally.unconverged,
        failed: res.tally.failed_total(),
        energy_gain: res.tally.energy_gain,
        dipped: res.tally.dipped,
        reference: reference.is_none(),
    })
}

/// A method that fails (non-finite, tunnelled, engine error) or does not settle on more than
/// this fraction of its rolls is not a candidate, however close its ratio from the rest.
pub const MAX_BAD_FRACTION: f64 = 0.01;

fn eligible(r: &Row) -> bool {
    r.error.is_finite() && ((r.failed + r.unconverged) as f64) <= MAX_BAD_FRACTION * r.rolls as f64
}

/// The Pareto front in cost and |error| over eligible methods: sorted by cost, each method
/// closer to the reference than every cheaper one.
pub fn pareto(rows: &[Row]) -> Vec<String> {
    let mut sorted: Vec<&Row> = rows.iter().filter(|r| eligible(r)).collect();
    sorted.sort_by(|a, b| a.cpu_s_per_1000.total_cmp(&b.cpu_s_per_1000));
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for r in sorted {
        if r.error.abs() < best {
            best = r.error.abs();
            front.push(r.method.clone());
        }
    }
    front
}

/// Measures every method against the reference, logging each as it is measured.
pub fn run(cfg: &Config, study: &Study, log: &dyn Fn(&str)) -> Result<Tradeoff> {
    let mut modes = Vec::new();
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let faithful = Method {
            engine: EngineKind::Bullet,
            dt: cfg.reference_dt,
            faithful: true,
            floor: Floor::Box,
        };
        let reference = roll_method(cfg, study, mode, &faithful, None)?;
        log(&format_row(&reference));
        let mut rows = Vec::new();
        for m in methods(mode, &cfg.dts) {
            let row = roll_method(cfg, study, mode, &m, Some(&reference))?;
            log(&format_row(&row));
            rows.push(row);
        }
        let pareto_front = pareto(&rows);
        let mut by_cost: Vec<&Row> = rows.iter().collect();
        by_cost.sort_by(|a, b| a.cpu_s_per_1000.total_cmp(&b.cpu_s_per_1000));
        let cheapest = by_cost
            .iter()
            .find(|r| eligible(r) && r.error.abs() + 2.0 * r.error_err <= ONE_PERCENT)
            .map(|r| r.method.clone());
        let typical = rows
            .iter()
            .map(|r| r.error_err)
            .filter(|e| e.is_finite())
            .fold(f64::INFINITY, f64::min);
        let note = match &cheapest {
            Some(m) => format!("{m} is the cheapest method within 1 % of the reference (2σ)."),
            None => format!(
                "None is resolvable within 1 % at {} rolls: the smallest error of a departure is \
                 ±{:.1} % (1σ); about {} rolls per method would make 2σ = 1 %.",
                cfg.rolls,
                100.0 * typical,
                rolls_to_resolve(typical, cfg.rolls).unwrap_or(0)
            ),
        };
        modes.push(ModeResult {
            mode,
            reference,
            rows,
            pareto_front,
            cheapest_within_one_percent: cheapest,
            note,
        });
    }
    Ok(Tradeoff {
        block: cfg.block.to_string(),
        rolls: cfg.rolls,
        seed: cfg.seed,
        reference_dt: cfg.reference_dt,
        modes,
    })
}

/// The column heads of the log's method lines (`format_row`).
pub fn header() -> String {
    TABLE.header()
}

/// One method as a line of the log, under `header`.
pub fn format_row(r: &Row) -> String {
    TABLE.row(&[
        r.method.clone(),
        format!("{:.4} ± {:.4}", r.ratio, r.ratio_err),
        format!("{:.3}", r.cpu_s_per_1000),
        format!("{:.0}", r.steps_per_roll),
        format!("{:+.1} ± {:.1} %", 100.0 * r.error, 100.0 * r.error_err),
        format!("{:+.1}", r.error_sigma),
        (r.failed + r.unconverged).to_string(),
        r.dipped.to_string(),
    ])
}

/// The columns of the log and of report.md.
const TABLE: Columns = Columns(&[
    left("method", 38),
    right("ratio", 17),
    right("CPU s/1000", 12),
    right("steps", 8),
    right("error", 18),
    right("σ", 6),
    right("failed", 6),
    right("dipped", 6),
]);
