//! `dicephys tradeoff`: accuracy against cost. A method is an engine, a time step, a settling
//! rule (DicePhys's rest rule with every step stepped, or the exact early stop with closed-form
//! flight) and a scene variant (box floor or plane; in 2D also Rapier's locked 3D body against
//! its true 2D one). Cost: CPU seconds per 1,000 rolls. Accuracy: the ratio's departure from
//! the reference, the faithful scene (Bullet, box floor, DicePhys's rule, stepped) at the finest
//! dt, in standard errors and per cent. Each mode (2D, 3D) has its own reference and front.

use super::{departure, dt_label, measure, rolls_to_resolve, throws, ONE_PERCENT};
use crate::block::Block;
use crate::engine::EngineKind;
use crate::roll::{Rule, Settle};
use crate::scene::{Floor, Mode, Scene};
use serde::Serialize;

pub struct Config {
    pub block: Block,
    pub dts: Vec<f64>,
    /// The reference's dt (finer than every method's).
    pub reference_dt: f64,
    pub rolls: u64,
    pub seed: u64,
    pub threads: usize,
    pub max_steps: u64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub method: String,
    pub engine: String,
    pub mode: String,
    pub dt: f64,
    /// `faithful` (DicePhys's rule, stepped flight) or `fast` (the defaults: closed-form flight,
    /// and the early stop where it is exact, dt <= 1/250).
    pub rule: String,
    pub floor: String,
    pub rolls: u64,
    pub ratio: f64,
    pub ratio_err: f64,
    pub cpu_s_per_1000: f64,
    pub steps_per_roll: f64,
    /// Relative departure from the reference, its error, and in standard errors.
    pub error: f64,
    pub error_err: f64,
    pub error_sigma: f64,
    pub unconverged: u64,
    pub failed: u64,
    pub energy_gain: u64,
    /// Rolls whose die's centre went under the floor's top face at a step (not failures).
    #[serde(default)]
    pub dipped: u64,
    pub reference: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct ModeResult {
    pub mode: String,
    pub reference: Row,
    pub rows: Vec<Row>,
    /// Methods no other is both cheaper and closer to the reference than, cheapest first
    /// (among methods failing or unconverged on at most 1 % of rolls).
    pub pareto_front: Vec<String>,
    /// The cheapest method whose departure is within 1 % at 2σ (|error| + 2σ ≤ 1 %), if any.
    pub cheapest_within_one_percent: Option<String>,
    pub note: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct Tradeoff {
    pub block: String,
    pub rolls: u64,
    pub seed: u64,
    pub reference_dt: f64,
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
    mode: Mode,
    m: &Method,
    reference: Option<&Row>,
) -> Result<Row, String> {
    let mut scene = Scene::paper(cfg.block, mode);
    scene.dt = m.dt;
    scene.floor = m.floor;
    let settle = Settle {
        max_steps: cfg.max_steps,
        // `fast` is the defaults: the early stop only where it is audited exact.
        rule: if m.faithful || !crate::roll::early_stop_exact(m.dt) {
            Rule::Dicephys
        } else {
            Rule::Certificate
        },
        fast_flight: !m.faithful,
        ..Settle::default()
    };
    let res = measure(
        m.engine,
        &scene,
        &throws(cfg.seed),
        &settle,
        cfg.rolls,
        cfg.threads,
    )?;
    let r = res.ratio();
    let (error, error_err) = match reference {
        Some(rf) => departure(
            r,
            crate::stats::Ratio {
                value: rf.ratio,
                err: rf.ratio_err,
            },
        ),
        None => (0.0, 0.0),
    };
    Ok(Row {
        method: m.name(mode),
        engine: m.engine.name().into(),
        mode: mode.name().into(),
        dt: m.dt,
        rule: if m.faithful { "faithful" } else { "fast" }.into(),
        floor: format!("{:?}", m.floor).to_lowercase(),
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

pub fn run(cfg: &Config, log: &dyn Fn(&str)) -> Result<Tradeoff, String> {
    let mut modes = Vec::new();
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let faithful = Method {
            engine: EngineKind::Bullet,
            dt: cfg.reference_dt,
            faithful: true,
            floor: Floor::Box,
        };
        let reference = roll_method(cfg, mode, &faithful, None)?;
        log(&format_row(&reference));
        let mut rows = Vec::new();
        for m in methods(mode, &cfg.dts) {
            let row = roll_method(cfg, mode, &m, Some(&reference))?;
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
            mode: mode.name().into(),
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

pub fn header() -> String {
    format!(
        "{:<38} {:>17} {:>12} {:>8} {:>18} {:>6} {:>6} {:>6}",
        "method", "ratio", "CPU s/1000", "steps", "error", "σ", "failed", "dipped"
    )
}

pub fn format_row(r: &Row) -> String {
    format!(
        "{:<38} {:>8.4} ± {:.4} {:>12.3} {:>8.0} {:>+7.1} ± {:>4.1} % {:>+6.1} {:>6} {:>6}",
        r.method,
        r.ratio,
        r.ratio_err,
        r.cpu_s_per_1000,
        r.steps_per_roll,
        100.0 * r.error,
        100.0 * r.error_err,
        r.error_sigma,
        r.failed + r.unconverged,
        r.dipped
    )
}
