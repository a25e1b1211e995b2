//! One roll: reset the world to a throw, step until the die is at rest (or the step cap, or a
//! failure), and say how it came out. Shared by every engine.

use crate::block::Outcome;
use crate::engine::{BodyState, Engine};
use crate::scene::Scene;
use crate::settle::{classify, Certificate, DieShape, RestDetector};
use crate::throws::Throw;
use serde::Serialize;

/// DicePhys's cap: a roll not at rest after this many steps is unconverged.
pub const DEFAULT_MAX_STEPS: u64 = 20_000_000;

/// Why a roll failed: the engine's state stopped making sense.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum Failure {
    /// Position, orientation or a velocity became NaN or infinite.
    NonFinite,
    /// The die's centre went below the floor's top face: it tunnelled through.
    FellThrough,
    /// The engine reported an error (a C++ exception, or a panic inside the engine).
    Engine,
}

impl Failure {
    pub const ALL: [Failure; 3] = [Failure::NonFinite, Failure::FellThrough, Failure::Engine];
    pub fn name(self) -> &'static str {
        match self {
            Failure::NonFinite => "non_finite",
            Failure::FellThrough => "fell_through",
            Failure::Engine => "engine_error",
        }
    }
}

/// How a roll ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fate {
    /// At rest; the side standing vertical.
    Settled(Outcome),
    /// Still moving at the step cap; the side vertical at that moment, for the record only.
    Unconverged(Outcome),
    Failed(Failure),
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RollRecord {
    pub throw: Throw,
    pub fate: Fate,
    pub steps: u64,
    /// With `Settle::audit`: the first step at which the energy certificate held, and the
    /// outcome it certified.
    pub certified: Option<(u64, Outcome)>,
}

impl RollRecord {
    pub fn sim_time(&self, dt: f64) -> f64 {
        self.steps as f64 * dt
    }
}

/// The rule that ends a roll.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Rule {
    /// DicePhys's: at rest by the vector sums of the last 10 steps' velocities.
    Dicephys,
    /// The exact early stop: the energy is below the barrier out of the current face
    /// (`settle::Certificate`); falls back to DicePhys's rule if that comes first.
    Certificate,
}

/// What stops a roll.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Settle {
    pub max_steps: u64,
    pub rule: Rule,
    /// The certificate's reserve, a fraction of the barrier (`settle::Certificate`).
    pub margin: f64,
    /// Record when the certificate would first have stopped the roll, without stopping it.
    pub audit: bool,
}

/// The certificate's default margin: measured to be never wrong (see README, "Speed").
pub const DEFAULT_MARGIN: f64 = 0.1;

impl Default for Settle {
    fn default() -> Self {
        Settle {
            max_steps: DEFAULT_MAX_STEPS,
            rule: Rule::Dicephys,
            margin: DEFAULT_MARGIN,
            audit: false,
        }
    }
}

/// Checks a state for failure.
pub fn check(s: &BodyState) -> Option<Failure> {
    if !s.is_finite() {
        Some(Failure::NonFinite)
    } else if s.position.y < 0.0 {
        Some(Failure::FellThrough)
    } else {
        None
    }
}

/// Rolls one throw to its end. `observe` sees every step's state (for `trace`).
pub fn roll_observed(
    engine: &mut dyn Engine,
    scene: &Scene,
    throw: &Throw,
    settle: &Settle,
    observe: impl FnMut(u64, &BodyState),
) -> RollRecord {
    let (fate, steps, certified) = run_from(engine, scene, &throw.start(scene), settle, observe);
    RollRecord {
        throw: *throw,
        fate,
        steps,
        certified,
    }
}

/// Steps the die from `start` until it is at rest (or certain), reaches the step cap, or
/// fails; returns how it ended, the number of steps taken, and (auditing) when the
/// certificate first held.
pub fn run_from(
    engine: &mut dyn Engine,
    scene: &Scene,
    start: &BodyState,
    settle: &Settle,
    mut observe: impl FnMut(u64, &BodyState),
) -> (Fate, u64, Option<(u64, Outcome)>) {
    let die = DieShape::of(scene);
    let certificate = Certificate {
        margin: settle.margin,
    };
    let stop_early = settle.rule == Rule::Certificate;
    let watch = stop_early || settle.audit;
    let mut certified = None;
    if engine.reset(start).is_err() {
        return (Fate::Failed(Failure::Engine), 0, None);
    }
    observe(0, &engine.state());
    let mut rest = RestDetector::default();
    let mut steps = 0;
    let mut state = *start;
    while steps < settle.max_steps {
        if engine.step().is_err() {
            return (Fate::Failed(Failure::Engine), steps, certified);
        }
        steps += 1;
        state = engine.state();
        observe(steps, &state);
        if let Some(f) = check(&state) {
            return (Fate::Failed(f), steps, certified);
        }
        if watch && certified.is_none() {
            if let Some(o) = certificate.certain(&die, &state) {
                certified = Some((steps, o));
                if stop_early {
                    return (Fate::Settled(o), steps, certified);
                }
            }
        }
        if rest.push(&state) {
            return (Fate::Settled(classify(&state)), steps, certified);
        }
    }
    (Fate::Unconverged(classify(&state)), steps, certified)
}

pub fn roll(engine: &mut dyn Engine, scene: &Scene, throw: &Throw, settle: &Settle) -> RollRecord {
    roll_observed(engine, scene, throw, settle, |_, _| {})
}
