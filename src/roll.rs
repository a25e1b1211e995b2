//! One roll: reset the world to a throw, step until the die is at rest (or the step cap, or a
//! failure), and say how it came out. Shared by every engine.

use crate::block::Outcome;
use crate::engine::{BodyState, Engine};
use crate::scene::Scene;
use crate::settle::{classify, RestDetector};
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
}

impl RollRecord {
    pub fn sim_time(&self, dt: f64) -> f64 {
        self.steps as f64 * dt
    }
}

/// What stops a roll.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Settle {
    pub max_steps: u64,
}

impl Default for Settle {
    fn default() -> Self {
        Settle {
            max_steps: DEFAULT_MAX_STEPS,
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
    let (fate, steps) = run_from(engine, &throw.start(scene), settle, observe);
    RollRecord {
        throw: *throw,
        fate,
        steps,
    }
}

/// Steps the die from `start` until it is at rest, reaches the step cap, or fails; returns
/// how it ended and the number of steps taken.
pub fn run_from(
    engine: &mut dyn Engine,
    start: &BodyState,
    settle: &Settle,
    mut observe: impl FnMut(u64, &BodyState),
) -> (Fate, u64) {
    if engine.reset(start).is_err() {
        return (Fate::Failed(Failure::Engine), 0);
    }
    observe(0, &engine.state());
    let mut rest = RestDetector::default();
    let mut steps = 0;
    let mut state = *start;
    while steps < settle.max_steps {
        if engine.step().is_err() {
            return (Fate::Failed(Failure::Engine), steps);
        }
        steps += 1;
        state = engine.state();
        observe(steps, &state);
        if let Some(f) = check(&state) {
            return (Fate::Failed(f), steps);
        }
        if rest.push(&state) {
            return (Fate::Settled(classify(&state)), steps);
        }
    }
    (Fate::Unconverged(classify(&state)), steps)
}

pub fn roll(engine: &mut dyn Engine, scene: &Scene, throw: &Throw, settle: &Settle) -> RollRecord {
    roll_observed(engine, scene, throw, settle, |_, _| {})
}
