//! One roll: reset the world to a throw, step until the die is at rest (or the step cap, or a
//! failure), and say how it came out. Shared by every engine.

use crate::engine::Engine;
use crate::model::block::Outcome;
use crate::model::die::DieShape;
use crate::model::scene::Scene;
use crate::model::state::BodyState;
use crate::model::throws::Throw;
use crate::sim::certificate::Certificate;
use crate::sim::flight::Flight;
use crate::sim::rest::{classify, RestDetector};
use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

/// DicePhys's cap: a roll not at rest after this many steps is unconverged.
pub const DEFAULT_MAX_STEPS: u64 = 20_000_000;

/// Why a roll failed: the engine's state stopped making sense.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    PartialOrd,
    Ord,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Failure {
    /// Position, orientation or a velocity became NaN or infinite.
    NonFinite,
    /// Tunnelled through the floor: the die's centre went below the floor's top face. A
    /// corner sinking deep for a step or two is not counted: Bullet pushes it back out, and
    /// counting it would fail thin blocks' ordinary rolls at the paper's dt (measured: 2 of
    /// 200 of 140x30x10 in 3D).
    #[serde(alias = "fell_through")]
    Tunnelled,
    /// The engine reported an error (a C++ exception, or a panic inside the engine).
    #[serde(rename = "engine_error")]
    #[strum(serialize = "engine_error")]
    Engine,
}

impl Failure {
    /// Every failure, in the order reports list them.
    pub const ALL: [Failure; 3] = [Failure::NonFinite, Failure::Tunnelled, Failure::Engine];
    /// The failure's name in reports, JSON and CSV.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// How a roll ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fate {
    /// At rest; the side standing vertical.
    Settled(Outcome),
    /// Still moving at the step cap; the side vertical at that moment, for the record only.
    Unconverged(Outcome),
    /// The roll failed, and why.
    Failed(Failure),
}

/// One roll: its throw, how it ended, and how many steps it took.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RollRecord {
    /// The throw rolled.
    pub throw: Throw,
    /// How the roll ended.
    pub fate: Fate,
    /// Simulated steps, flown or by the engine (time = steps × dt).
    pub steps: u64,
    /// Steps the engine itself took (fewer than `steps` where free flight was coasted).
    pub engine_steps: u64,
    /// With `RollConfig::audit` or the certificate rule: the first step at which the energy
    /// certificate held, and the outcome it certified (under the certificate rule, the step
    /// the roll ended).
    pub certified: Option<(u64, Outcome)>,
    /// The engine injected energy: the die's kinetic + potential energy rose above its lowest
    /// value so far by more than `ENERGY_GAIN_TOLERANCE` of its starting energy. A flag, not a
    /// failure: the roll goes on and may still settle.
    #[serde(default)]
    pub energy_gain: bool,
}

impl RollRecord {
    /// The roll's simulated time, s, at time step `dt` (s).
    pub fn sim_time(&self, dt: f64) -> f64 {
        self.steps as f64 * dt
    }
}

/// The rule that ends a roll.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Rule {
    /// DicePhys's: at rest by the vector sums of the last 10 steps' velocities.
    Dicephys,
    /// The exact early stop: the energy is below the barrier out of the current face
    /// (`sim::certificate::Certificate`); falls back to DicePhys's rule if that comes first.
    Certificate,
}

/// How a roll is carried out and what stops it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RollConfig {
    /// A roll not at rest after this many steps is unconverged.
    pub max_steps: u64,
    /// The rule that ends the roll.
    pub rule: Rule,
    /// The certificate's reserve, a fraction of the barrier (`sim::certificate::Certificate`).
    pub margin: f64,
    /// Record when the certificate would first have stopped the roll, without stopping it.
    pub audit: bool,
    /// Jump over free flight in closed form (`flight::Flight`) where the engine's flight is
    /// ballistic.
    pub fast_flight: bool,
}

/// The certificate's default margin: measured to be never wrong (see README, "Speed").
pub const DEFAULT_MARGIN: f64 = 0.1;

impl RollConfig {
    /// DicePhys exactly as the paper ran it: its rest rule, every step by the engine.
    pub fn faithful() -> RollConfig {
        RollConfig::default()
    }

    /// The fast defaults: the exact early stop and the closed-form free flight.
    pub fn fast() -> RollConfig {
        RollConfig {
            rule: Rule::Certificate,
            fast_flight: true,
            ..RollConfig::default()
        }
    }

    /// Checks every value before anything runs.
    pub fn validate(&self) -> crate::Result<()> {
        let bad = |m: String| Err(crate::Error::Invalid(m));
        if self.max_steps == 0 {
            return bad("--max-steps 0: need at least one step".into());
        }
        if !(self.margin.is_finite() && (0.0..1.0).contains(&self.margin)) {
            return bad(format!("--margin {}: must be in [0, 1)", self.margin));
        }
        if self.audit && self.rule == Rule::Certificate {
            return bad("an audit settles fully: it needs the dicephys rule".into());
        }
        Ok(())
    }
}

impl Default for RollConfig {
    fn default() -> Self {
        RollConfig {
            max_steps: DEFAULT_MAX_STEPS,
            rule: Rule::Dicephys,
            margin: DEFAULT_MARGIN,
            audit: false,
            fast_flight: false,
        }
    }
}

/// Energy gain: a real roll never gains mechanical energy (contacts only dissipate; free flight
/// keeps it, and the engines' symplectic Euler loses ½mg²dt² a step). So a rise of the
/// kinetic plus potential energy (`DieShape::energy`) above its lowest value so far by more than this
/// fraction of the starting energy is the engine injecting energy: at a contact (restitution
/// above 1, a penetration pushed out too hard) or between contacts.
pub const ENERGY_GAIN_TOLERANCE: f64 = 0.01;

/// Checks a state for failure: non-finite, or the centre below the floor.
pub fn check(s: &BodyState) -> Option<Failure> {
    if !s.is_finite() {
        Some(Failure::NonFinite)
    } else if s.position.y < 0.0 {
        Some(Failure::Tunnelled)
    } else {
        None
    }
}

/// Watches a roll's energy for gains (`ENERGY_GAIN_TOLERANCE`).
#[derive(Clone, Copy, Debug)]
pub struct EnergyWatch {
    lowest: f64,
    allowance: f64,
    /// True once the energy has risen above its lowest value so far by more than the allowance.
    pub gained: bool,
}

impl EnergyWatch {
    /// A watch from `start`'s energy; the allowance is `ENERGY_GAIN_TOLERANCE` of it.
    pub fn new(die: &DieShape, start: &BodyState) -> EnergyWatch {
        let e0 = die.energy(start);
        EnergyWatch {
            lowest: e0,
            allowance: ENERGY_GAIN_TOLERANCE * e0.abs(),
            gained: false,
        }
    }

    /// Takes one state's energy: flags a gain, keeps the lowest value so far.
    pub fn push(&mut self, die: &DieShape, s: &BodyState) {
        let e = die.energy(s);
        if e > self.lowest + self.allowance {
            self.gained = true;
        }
        self.lowest = self.lowest.min(e);
    }
}

/// Rolls one throw to its end. `observe` sees every step's state (for `trace`).
pub fn roll_observed(
    engine: &mut dyn Engine,
    scene: &Scene,
    throw: &Throw,
    cfg: &RollConfig,
    observe: impl FnMut(u64, &BodyState),
) -> RollRecord {
    let end = run_from(engine, scene, &throw.start(scene), cfg, observe);
    RollRecord {
        throw: *throw,
        fate: end.fate,
        steps: end.steps,
        engine_steps: end.engine_steps,
        certified: end.certified,
        energy_gain: end.energy_gain,
    }
}

/// How a roll from a start state ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct End {
    /// How the roll ended.
    pub fate: Fate,
    /// Simulated steps (time = steps × dt).
    pub steps: u64,
    /// Steps the engine took.
    pub engine_steps: u64,
    /// With an audit or the certificate rule: the first step at which the energy certificate
    /// held, and the outcome it certified.
    pub certified: Option<(u64, Outcome)>,
    /// See `RollRecord::energy_gain`.
    pub energy_gain: bool,
}

/// Steps the die from `start` until it is at rest (or certain), reaches the step cap, or
/// fails.
pub fn run_from(
    engine: &mut dyn Engine,
    scene: &Scene,
    start: &BodyState,
    cfg: &RollConfig,
    mut observe: impl FnMut(u64, &BodyState),
) -> End {
    let die = DieShape::of(scene);
    let certificate = Certificate { margin: cfg.margin };
    let stop_early = cfg.rule == Rule::Certificate;
    let watch = stop_early || cfg.audit;
    let flight = (cfg.fast_flight && engine.ballistic_flight()).then(|| Flight::of(scene));
    let mut end = End {
        fate: Fate::Failed(Failure::Engine),
        steps: 0,
        engine_steps: 0,
        certified: None,
        energy_gain: false,
    };
    if engine.reset(start).is_err() {
        return end;
    }
    let mut energy = EnergyWatch::new(&die, start);
    observe(0, &engine.state());
    let mut rest = RestDetector::default();
    let mut state = *start;
    // In free flight (`flight::Flight`) the roll steps the die itself: `flying` holds the
    // step's rotation, and the engine is behind until the state is handed back.
    let mut flying: Option<UnitQuaternion<f64>> = None;
    let mut behind = false;
    while end.steps < cfg.max_steps {
        let mut next = None;
        if let Some(f) = &flight {
            if flying.is_none() && f.may_start(&state, || engine.contact_free()) {
                flying = Some(f.step_rotation(&state.angular_velocity));
            }
            if let Some(dq) = &flying {
                next = f.next(&state, dq);
                if next.is_none() {
                    flying = None;
                    if behind && engine.set_state(&state).is_err() {
                        return end;
                    }
                    behind = false;
                } else {
                    behind = true;
                }
            }
        }
        let flown = next.is_some();
        state = match next {
            Some(s) => s,
            None => {
                if engine.step().is_err() {
                    return end;
                }
                end.engine_steps += 1;
                engine.state()
            }
        };
        end.steps += 1;
        // Every step's state, flown or stepped, goes through the same checks, but for the
        // energy watch: a flown step has no contact to gain energy at.
        observe(end.steps, &state);
        if let Some(f) = check(&state) {
            end.fate = Fate::Failed(f);
            return end;
        }
        if !flown {
            energy.push(&die, &state);
            end.energy_gain = energy.gained;
        }
        if watch && end.certified.is_none() {
            if let Some(o) = certificate.certain(&die, &state) {
                end.certified = Some((end.steps, o));
                if stop_early {
                    end.fate = Fate::Settled(o);
                    return end;
                }
            }
        }
        if rest.push(&state) {
            end.fate = Fate::Settled(classify(&state));
            return end;
        }
    }
    end.fate = Fate::Unconverged(classify(&state));
    end
}

/// Rolls one throw to its end (`roll_observed`, watching nothing).
pub fn roll(engine: &mut dyn Engine, scene: &Scene, throw: &Throw, cfg: &RollConfig) -> RollRecord {
    roll_observed(engine, scene, throw, cfg, |_, _| {})
}
