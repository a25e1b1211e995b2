//! One roll: reset the world to a throw, step until the die is at rest (or the step cap, or a
//! failure), and say how it came out. Shared by every engine.

use crate::engine::Engine;
use crate::error::Field;
use crate::model::die::DieBody;
use crate::model::faces::Outcome;
use crate::model::scene::Scene;
use crate::model::state::BodyState;
use crate::model::throws::Throw;
use crate::sim::certificate::Certificate;
use crate::sim::flight::Flight;
use crate::sim::rest::{RestDetector, REST_WINDOW};
use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

/// DicePhys's cap: a roll not at rest after this many steps is unconverged.
pub const DEFAULT_MAX_STEPS: u64 = 20_000_000;

/// The cap for a die of any shape unless one is given: 200,000 steps (200 s at the paper's
/// step). A cylinder rolling on its side (a thick coin) keeps rolling on a floor without
/// rolling resistance, and neither engine here has any; such a roll ends unconverged, its face
/// at the cap recorded, in a fraction of a second rather than hours.
pub const SHAPE_MAX_STEPS: u64 = 200_000;

/// The step cap of a roll of `scene` when none is given: [`SHAPE_MAX_STEPS`] for a die of any
/// shape, else DicePhys's [`DEFAULT_MAX_STEPS`]. Every command that rolls a die takes its
/// default cap from here (`roll`, `fair` and `crosscheck` through `EndRequest`, and `trace`),
/// so that the same die is capped alike.
pub fn default_max_steps(scene: &Scene) -> u64 {
    if scene.die.as_shape().is_some() {
        SHAPE_MAX_STEPS
    } else {
        DEFAULT_MAX_STEPS
    }
}

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
    /// Tunnelled: the die has really gone through the floor. See `Dip::through` for what
    /// counts: passed wholly below the floor's bottom face, or its centre held below the top
    /// face for more than `MAX_DIP_STEPS` steps in a row, or at rest there. A dip the engine
    /// pushes back out of is not a failure: it is counted apart (`Dip`).
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
    /// At rest; the face it rests on (`faces::Outcome`), or none.
    Settled(Outcome),
    /// Still moving at the step cap; its face at that moment, for the record only.
    Unconverged(Outcome),
    /// The roll failed, and why.
    Failed(Failure),
}

impl Fate {
    /// A cuboid's roll as the paper sees it: the side standing vertical where it came to rest
    /// (`Outcome::side`); `None` for a roll that did not.
    pub fn settled_side(self) -> Option<crate::model::block::Side> {
        match self {
            Fate::Settled(o) => Some(o.side()),
            _ => None,
        }
    }
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
    /// certificate held, and the face it certified (under the certificate rule, the step
    /// the roll ended).
    pub certified: Option<(u64, Outcome)>,
    /// The engine injected energy: the die's kinetic + potential energy rose above its lowest
    /// value so far by more than `ENERGY_GAIN_TOLERANCE` of its starting energy. A flag, not a
    /// failure: the roll goes on and may still settle.
    #[serde(default)]
    pub energy_gain: bool,
    /// The die's dips into the floor (`DipWatch`): a flag, not a failure.
    #[serde(default)]
    pub dip: Dip,
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

/// The certificate's default margin: measured to be never wrong (docs/method.md, "The
/// certificate").
pub const DEFAULT_MARGIN: f64 = 0.1;

/// The coarsest time step at which the early stop is on by default, s (1/250). Audited with
/// the default margin on 20,000 throws of each MDF block, 2D and 3D: never wrong at 1/1000,
/// 1/500 and 1/250; wrong on 23 of 200,000 rolls at 1/120 and 712 at 1/60, where a contact
/// step can inject more energy than the margin (docs/results/coarse-steps.md).
pub const EARLY_STOP_MAX_DT: f64 = 0.004;

/// True if the early stop is audited exact at this time step (`EARLY_STOP_MAX_DT`).
pub fn early_stop_exact(dt: f64) -> bool {
    dt <= EARLY_STOP_MAX_DT * (1.0 + 1e-9)
}

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

    /// The roll at time step `dt`, ended by `settle` (default: the early stop where it is
    /// audited exact, [`early_stop_exact`], else DicePhys's rule), its flight `fast` or
    /// stepped; `faithful` is DicePhys as the paper ran it (its rule, every step stepped) and
    /// an audit settles fully, so both take DicePhys's rule. Checked.
    pub fn chosen(
        dt: f64,
        settle: Option<Rule>,
        fast: bool,
        faithful: bool,
        audit: bool,
        max_steps: u64,
        margin: f64,
    ) -> crate::Result<RollConfig> {
        if settle == Some(Rule::Certificate) && (faithful || audit) {
            let who = if audit {
                "an audit"
            } else {
                "the faithful run"
            };
            return Err(crate::Error::field(
                Field::Settle,
                "certificate",
                crate::text![
                    format!(
                        "{who} settles by DicePhys's rule (an audit watches the certificate \
                         without stopping); leave out "
                    ),
                    Field::Settle,
                    format!(" or `{}`", if audit { "audit" } else { "faithful" })
                ],
            ));
        }
        let certificate = settle.map_or(early_stop_exact(dt), |r| r == Rule::Certificate);
        let cfg = RollConfig {
            max_steps,
            rule: if certificate && !faithful && !audit {
                Rule::Certificate
            } else {
                Rule::Dicephys
            },
            margin,
            audit,
            fast_flight: fast && !faithful,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// Checks every value before anything runs.
    pub fn validate(&self) -> crate::Result<()> {
        use crate::Error;
        if self.max_steps == 0 {
            return Err(Error::field(Field::MaxSteps, 0, "need at least one step"));
        }
        if !(self.margin.is_finite() && (0.0..1.0).contains(&self.margin)) {
            return Err(Error::field(
                Field::Margin,
                self.margin,
                "must be in [0, 1)",
            ));
        }
        if self.audit && self.rule == Rule::Certificate {
            return Err(Error::Invalid(
                "an audit settles fully: it needs the dicephys rule".into(),
            ));
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
/// kinetic plus potential energy (`DieBody::energy`) above its lowest value so far by more than this
/// fraction of the starting energy is the engine injecting energy: at a contact (restitution
/// above 1, a penetration pushed out too hard) or between contacts.
pub const ENERGY_GAIN_TOLERANCE: f64 = 0.01;

/// Checks a state for failure: non-finite, or through the floor (`Dip::through`, with the
/// roll's dips so far, this state's included).
#[inline]
pub fn check(s: &BodyState, die: &DieBody, dip: &Dip, floor_bottom: f64) -> Option<Failure> {
    if !s.is_finite() {
        Some(Failure::NonFinite)
    } else if dip.through(die, s, floor_bottom) {
        Some(Failure::Tunnelled)
    } else {
        None
    }
}

/// The longest a die's centre may stay below the floor's top face, in steps in a row, before
/// the roll counts as gone through. An engine pushes a die out of the floor over some steps:
/// Bullet's split impulse takes a fifth of the penetration a step while gravity pulls the die
/// back by g·dt² (1.1 cm a step at 1/30 s), so a thin block landing flat at a coarse step can
/// sit with its centre under the top face for a while and still come out. Measured
/// (docs/results/coarse-steps.md): the longest dip that recovered was 19 steps at dt = 1/60
/// and 39 at 1/30 (Bullet, e = 0, 140x30x10), 74 in a 5 m/s drop at dt = 0.1; Rapier's, 8.
/// One that did not lasted 19,912 steps, to the cap.
/// A die that stays under longer than this is held inside the floor or falling beneath it.
pub const MAX_DIP_STEPS: u64 = 100;

/// How far the die went into the floor over a roll. At a coarse step a die landing flat
/// moves a centimetre or more in one step, so its centre can end the step below the floor's
/// top face; the engine pushes it back out over the next steps and the roll goes on. That is
/// a dip: counted, like the energy gain, never a failure by itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Dip {
    /// Steps at whose end the die's centre was below the floor's top face.
    pub steps: u64,
    /// The longest run of such steps in a row.
    pub longest: u64,
    /// The deepest any point of the die went below the floor's top face, m (0: never).
    pub penetration: f64,
    #[serde(skip)]
    run: u64,
}

impl Dip {
    /// A dip as stored: its steps, its longest run, its depth (m).
    pub fn of(steps: u64, longest: u64, penetration: f64) -> Dip {
        Dip {
            steps,
            longest,
            penetration,
            run: 0,
        }
    }

    /// Records one step's state. Inlined into the roll's loop, as `through` and `check`
    /// (each is called every step; left to LLVM they were outlined, one or another, as other
    /// modules changed the crate's layout: +4.6 M to +8.3 M instructions on the callgrind
    /// referee; inlined, 983.1 M).
    #[inline]
    pub fn push(&mut self, die: &DieBody, s: &BodyState) {
        let depth = -die.lowest_point(s);
        // max() keeps the old value if depth is NaN (a non-finite state fails in `check`).
        self.penetration = self.penetration.max(depth);
        if s.position.y < 0.0 {
            self.steps += 1;
            self.run += 1;
            self.longest = self.longest.max(self.run);
        } else {
            self.run = 0;
        }
    }

    /// The centre went below the floor's top face at least once.
    pub fn dipped(&self) -> bool {
        self.steps > 0
    }

    /// The die has really gone through the floor, as of state `s` (already pushed):
    /// - wholly below the floor's bottom face (`floor_bottom`; a table top's, 2 cm down, or
    ///   the default box's, 100 m down): passed through, nothing is left to push it back;
    /// - or its centre below the top face for more than `MAX_DIP_STEPS` steps in a row: held
    ///   inside the floor or falling beneath it, where no engine's push-out takes that long.
    ///
    /// Wholly below the *top* face is not enough: at dt = 1/60 a thin block landing flat
    /// falls 4-5 cm in one step, ends it entirely inside DicePhys's box floor, and Bullet
    /// pushes it back out (8,947 of 20,000 rolls of 140x27x13 in 2D;
    /// docs/results/coarse-steps.md).
    /// A die at rest with its centre below the top face is a failure too (`run_from`).
    /// - or, a die of any shape, its centre deeper below the top face than the die is thick
    ///   (a 0.1 mm coin sank 45 times its thickness at 1 ms and was counted: on its edge 3.5
    ///   times as often as the theory). The cuboid keeps the two rules above, which the
    ///   coarse steps' study measured.
    #[inline]
    pub fn through(&self, die: &DieBody, s: &BodyState, floor_bottom: f64) -> bool {
        let reach = s.position.y - die.lowest_point(s);
        s.position.y + reach < floor_bottom
            || self.run > MAX_DIP_STEPS
            || die
                .convex
                .as_ref()
                .is_some_and(|c| -s.position.y > c.thickness)
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
    pub fn new(die: &DieBody, start: &BodyState) -> EnergyWatch {
        let e0 = die.energy(start);
        EnergyWatch {
            lowest: e0,
            allowance: ENERGY_GAIN_TOLERANCE * e0.abs(),
            gained: false,
        }
    }

    /// Takes one state's energy: flags a gain, keeps the lowest value so far. On a soft table
    /// a die pressed into it holds energy in its springs that kinetic plus potential leave
    /// out, and gets it back: only states clear of the table are compared.
    pub fn push(&mut self, die: &DieBody, s: &BodyState) {
        if die.spring > 0.0 && die.lowest_point(s) < 0.0 {
            return;
        }
        let e = die.energy(s);
        if e > self.lowest + self.allowance {
            self.gained = true;
        }
        self.lowest = self.lowest.min(e);
    }
}

/// Rolls one throw to its end. `observe` sees every step's state (for `trace`), so free flight
/// is walked step by step, never jumped (`Flight::jump`); the roll is the same either way.
pub fn roll_observed(
    engine: &mut dyn Engine,
    scene: &Scene,
    throw: &Throw,
    cfg: &RollConfig,
    observe: impl FnMut(u64, &BodyState),
) -> RollRecord {
    roll_observed_or_abandon(engine, scene, throw, cfg, observe, &|| false)
        .expect("never abandoned")
}

/// [`roll_observed`], abandoned (`None`) when `abandon` says so, asked every 4,096 steps as
/// [`roll_or_abandon`] asks it (`trace` stopped mid-roll).
pub fn roll_observed_or_abandon(
    engine: &mut dyn Engine,
    scene: &Scene,
    throw: &Throw,
    cfg: &RollConfig,
    observe: impl FnMut(u64, &BodyState),
    abandon: &dyn Fn() -> bool,
) -> Option<RollRecord> {
    let end = run(
        engine,
        scene,
        &throw.start(scene),
        cfg,
        observe,
        false,
        abandon,
    )?;
    Some(record_of(throw, end))
}

/// A roll's record: its throw and how it ended.
fn record_of(throw: &Throw, end: End) -> RollRecord {
    RollRecord {
        throw: *throw,
        fate: end.fate,
        steps: end.steps,
        engine_steps: end.engine_steps,
        certified: end.certified,
        energy_gain: end.energy_gain,
        dip: end.dip,
    }
}

/// How many steps of free flight from `s` the certificate cannot fire on: its energy height
/// (E/mg) is above `ceiling` (`Certificate::energy_ceiling`) and falls by exactly ½g·dt² a
/// step in flight (symplectic Euler: ½(v − g dt)² − ½v² + g(v − g dt)dt = −½g²dt², per unit
/// mass, over g), while the bound `DieBody::energy_height_at_least` keeps its rotational
/// part constant. Room is left for rounding.
fn quiet_steps(die: &DieBody, s: &BodyState, ceiling: f64, f: &Flight) -> u64 {
    if ceiling == f64::NEG_INFINITY {
        return u64::MAX;
    }
    let above = die.energy_height_at_least(s) - ceiling;
    let per_step = 0.5 * f.gravity * f.dt * f.dt * (1.0 + 1e-6) + 1e-15;
    if above > 0.0 {
        // Steps 1..=k are above the ceiling while above − k·per_step > 0.
        ((above / per_step).floor() as u64).saturating_sub(1)
    } else {
        0
    }
}

/// `quiet_steps` for an engine's own flight (Rapier): its substepped symplectic Euler loses
/// ½g·h² of energy height per substep, n·½g(dt/n)² = ½g·dt²/n a step, less than the ½g·dt²
/// taken off here; its gyroscopic pass changes |ω|, so the rotational energy is left out of
/// the bound (it is never negative). Damping takes energy faster: then nothing is jumped.
fn quiet_steps_own(s: &BodyState, ceiling: f64, scene: &Scene) -> u64 {
    if ceiling == f64::NEG_INFINITY {
        return u64::MAX;
    }
    if scene.damped() {
        return 0;
    }
    let g = scene.gravity;
    let height = s.position.y + 0.5 * s.linear_velocity.norm_squared() / g - 1e-9;
    let above = height - ceiling;
    let per_step = 0.5 * g * scene.dt * scene.dt * (1.0 + 1e-6) + 1e-15;
    if above > 0.0 {
        ((above / per_step).floor() as u64).saturating_sub(1)
    } else {
        0
    }
}

/// `Flight::jump` for an engine's own flight: takes the flown steps `step` gives from `s`, at
/// most `max`, leaving `s` at the last and the rest rule's window as if each state had been
/// pushed (every flown step keeps the die moving, so the rule cannot fire). Each flown state
/// ends clear of the floor, so no check but the certificate (bounded by `max`) can fire.
fn jump_own(
    s: &mut BodyState,
    max: u64,
    rest: &mut RestDetector,
    mut step: impl FnMut(&BodyState) -> Option<BodyState>,
) -> u64 {
    let mut last = [*s; REST_WINDOW];
    let mut n = 0u64;
    while n < max {
        let Some(next) = step(s) else {
            break;
        };
        *s = next;
        last[(n % REST_WINDOW as u64) as usize] = next;
        n += 1;
    }
    let first = n.saturating_sub(REST_WINDOW as u64);
    rest.skip(first);
    for k in first..n {
        rest.record(&last[(k % REST_WINDOW as u64) as usize]);
    }
    n
}

/// Whether the roll is flying the die itself this step, and how.
#[derive(Clone, Copy, Debug)]
enum Flying {
    /// The engine steps.
    No,
    /// Bullet's ballistic flight (`flight::Flight`), with the rotation one step applies.
    Ballistic(UnitQuaternion<f64>),
    /// The engine's own flight, redone outside it (`Engine::own_flight_step`: Rapier).
    Own,
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
    /// held, and the face it certified.
    pub certified: Option<(u64, Outcome)>,
    /// See `RollRecord::energy_gain`.
    pub energy_gain: bool,
    /// See `RollRecord::dip`.
    pub dip: Dip,
}

/// Steps the die from `start` until it is at rest (or certain), reaches the step cap, or
/// fails. `observe` sees every step's state.
pub fn run_from(
    engine: &mut dyn Engine,
    scene: &Scene,
    start: &BodyState,
    cfg: &RollConfig,
    observe: impl FnMut(u64, &BodyState),
) -> End {
    run(engine, scene, start, cfg, observe, false, &|| false).expect("never abandoned")
}

/// The checks every step's state goes through, and what they keep between steps.
struct Watch {
    die: DieBody,
    certificate: Certificate,
    /// The certificate ends the roll (`Rule::Certificate`).
    stop_early: bool,
    /// The certificate is checked at all (to stop, or for an audit).
    watch: bool,
    floor_bottom: f64,
    /// What a jumped state must be above for the certificate to be out of reach (when it is
    /// checked at all).
    ceiling: f64,
    energy: EnergyWatch,
    rest: RestDetector,
}

impl Watch {
    fn new(scene: &Scene, start: &BodyState, cfg: &RollConfig) -> Watch {
        let die = DieBody::of(scene);
        let certificate = Certificate { margin: cfg.margin };
        let stop_early = cfg.rule == Rule::Certificate;
        let watch = stop_early || cfg.audit;
        let ceiling = if watch {
            certificate.energy_ceiling(&die)
        } else {
            f64::NEG_INFINITY
        };
        Watch {
            energy: EnergyWatch::new(&die, start),
            die,
            certificate,
            stop_early,
            watch,
            floor_bottom: scene.floor_bottom(),
            ceiling,
            rest: RestDetector::default(),
        }
    }

    /// Judges a step's state (`end.steps` already counts it): true when the roll has ended,
    /// with `end.fate` said. `energy` is false for a ballistic flown step, which has no
    /// contact to gain energy at.
    // Every step of every roll passes here: kept inline in the loop as it was written before
    // the split (callgrind, 1,000 paper rolls: 1.9 % more instructions without; 0.8 % with).
    #[inline(always)]
    fn judge(&mut self, end: &mut End, state: &BodyState, energy: bool) -> bool {
        let die = &self.die;
        end.dip.push(die, state);
        if let Some(f) = check(state, die, &end.dip, self.floor_bottom) {
            end.fate = Fate::Failed(f);
            return true;
        }
        if energy {
            self.energy.push(die, state);
            end.energy_gain = self.energy.gained;
        }
        // A die whose centre is under the floor's top face is mid-dip (or through): no
        // outcome is certain until the engine has pushed it back out, and at rest there it
        // has failed.
        let under = state.position.y < 0.0;
        if self.watch && end.certified.is_none() && !under {
            let certain = match &die.convex {
                // A box: the face of its side's region (`labelled`: the end of the axis up).
                None => self
                    .certificate
                    .certain(die, state)
                    .map(|side| die.labelled(side, state)),
                // A die of any shape: the face of the region it cannot leave.
                Some(c) => self
                    .certificate
                    .certain_convex(c, die, state)
                    .map(Outcome::Face),
            };
            if let Some(o) = certain {
                end.certified = Some((end.steps, o));
                if self.stop_early {
                    // Certain of its face: the die cannot leave the face region it is in
                    // (the barrier it cannot climb is the edge between).
                    end.fate = Fate::Settled(o);
                    return true;
                }
            }
        }
        if self.rest.push(state) {
            end.fate = if under {
                Fate::Failed(Failure::Tunnelled)
            } else {
                Fate::Settled(self.die.outcome(state))
            };
            return true;
        }
        false
    }
}

/// A roll's free flight: in flight the roll steps the die itself (`Flying`), and the engine
/// is behind until the state is handed back.
struct Flier {
    /// Bullet's ballistic flight, where the engine's flight is ballistic and flight is fast.
    flight: Option<Flight>,
    /// An engine that flies the die itself (Rapier) does so bit for bit as its own steps, so
    /// every check is walked over its flown steps as over its own, the energy watch too.
    own: bool,
    flying: Flying,
    /// The engine has not stepped the last flown states.
    behind: bool,
    /// The body state a ballistic flight flies: the engine's own (`Engine::body_state`), the
    /// die's state turned back from it at each step (`Flight::to_die`).
    body: BodyState,
    /// Flown steps in a row so far.
    in_a_row: u64,
    /// A jump may still take steps in this flight: false once one took none. In flight the
    /// energy only falls, so a state at or below the certificate's ceiling is followed by
    /// others at or below it, and a flight whose next step must be walked ends there: asking
    /// again at every walked step (most of a low bounce's) would cost a call each and find
    /// nothing. Not asking changes nothing: a walked step is the jumped step (`run`).
    jumpable: bool,
}

impl Flier {
    fn new(
        engine: &dyn Engine,
        scene: &Scene,
        die: DieBody,
        start: &BodyState,
        cfg: &RollConfig,
    ) -> Flier {
        let flight =
            (cfg.fast_flight && engine.ballistic_flight()).then(|| Flight::of_die(scene, die));
        Flier {
            own: cfg.fast_flight && flight.is_none() && engine.own_flight(),
            flight,
            flying: Flying::No,
            behind: false,
            body: *start,
            in_a_row: 0,
            jumpable: true,
        }
    }

    /// Starts a flight if the die, in `state`, may fly.
    #[inline(always)]
    fn start(&mut self, engine: &mut dyn Engine, state: &BodyState) {
        self.jumpable = true;
        self.flying = if self.own {
            if engine.own_flight_start(state) {
                Flying::Own
            } else {
                Flying::No
            }
        } else {
            match &self.flight {
                Some(f) if f.may_start(state, || engine.contact_free()) => {
                    self.body = engine.body_state();
                    Flying::Ballistic(f.step_rotation(&state.angular_velocity))
                }
                _ => Flying::No,
            }
        };
    }

    /// Jumps the flown steps on which no check can fire, at most `left`, leaving `state` at
    /// the last; returns how many. Once the rest rule's window holds flown steps only it
    /// cannot fire in flight (every flown step keeps the die awake: its ω is the same every
    /// step, or its speed is above 0.8 m/s with the vertical velocity of one sign, so neither
    /// sum of ten is near 0). The certificate cannot fire while the energy is above its
    /// ceiling, and a state clear of the floor fails no check. So those steps are jumped,
    /// the rest rule's window kept filled, and the walk takes over where a check could fire
    /// or the die reaches the floor.
    fn jump(
        &mut self,
        engine: &mut dyn Engine,
        w: &mut Watch,
        state: &mut BodyState,
        left: u64,
        scene: &Scene,
    ) -> u64 {
        let n = match (&self.flying, &self.flight) {
            (Flying::Ballistic(dq), Some(f)) => {
                let max = quiet_steps(&w.die, state, w.ceiling, f).min(left);
                let n = f.jump(&mut self.body, dq, max, &mut w.rest);
                if n > 0 {
                    *state = f.to_die(&self.body);
                }
                n
            }
            _ => {
                let max = quiet_steps_own(state, w.ceiling, scene).min(left);
                let (die, energy) = (&w.die, &mut w.energy);
                jump_own(state, max, &mut w.rest, |s| {
                    let next = engine.own_flight_step(s)?;
                    energy.push(die, &next);
                    Some(next)
                })
            }
        };
        if n > 0 {
            self.in_a_row += n;
            self.behind = true;
        } else {
            self.jumpable = false;
        }
        n
    }

    /// Flies `state` on to the next flown state: true if it did, false where the flight
    /// ends, the engine then given the state back (an `Err` if it refused it). The state is
    /// advanced in place, not returned: most walked steps of a flight are flown, and an
    /// `Option<BodyState>` handed on was copied three times over on each (callgrind: 1.2 %
    /// of a plain roll's instructions).
    #[inline(always)]
    fn next(&mut self, engine: &mut dyn Engine, state: &mut BodyState) -> Result<bool, ()> {
        let flown = match (&self.flying, &self.flight) {
            (Flying::Ballistic(dq), Some(f)) => match f.next(&self.body, dq) {
                Some(b) => {
                    self.body = b;
                    *state = f.to_die(&b);
                    true
                }
                None => false,
            },
            _ => match engine.own_flight_step(state) {
                Some(s) => {
                    *state = s;
                    true
                }
                None => false,
            },
        };
        if !flown {
            if self.behind {
                let handed = match self.flying {
                    Flying::Ballistic(_) => engine.set_body_state(&self.body),
                    _ => engine.set_state(state),
                };
                if handed.is_err() {
                    return Err(());
                }
            }
            self.flying = Flying::No;
            self.behind = false;
        } else {
            self.behind = true;
        }
        Ok(flown)
    }
}

/// `run_from`; with `jump`, stretches of free flight on which no check can fire are jumped
/// (`Flier::jump`) and `observe` does not see their states.
fn run(
    engine: &mut dyn Engine,
    scene: &Scene,
    start: &BodyState,
    cfg: &RollConfig,
    mut observe: impl FnMut(u64, &BodyState),
    jump: bool,
    abandon: &dyn Fn() -> bool,
) -> Option<End> {
    let mut end = End {
        fate: Fate::Failed(Failure::Engine),
        steps: 0,
        engine_steps: 0,
        certified: None,
        energy_gain: false,
        dip: Dip::default(),
    };
    if engine.reset(start).is_err() {
        return Some(end);
    }
    let mut w = Watch::new(scene, start, cfg);
    let mut fly = Flier::new(engine, scene, w.die.clone(), start, cfg);
    observe(0, &engine.state());
    let mut state = *start;
    while end.steps < cfg.max_steps {
        let mut flown = false;
        if matches!(fly.flying, Flying::No) {
            fly.start(engine, &state);
        }
        if !matches!(fly.flying, Flying::No) {
            if jump && fly.jumpable && fly.in_a_row >= REST_WINDOW as u64 {
                let n = fly.jump(engine, &mut w, &mut state, cfg.max_steps - end.steps, scene);
                if n > 0 {
                    end.steps += n;
                    end.energy_gain = w.energy.gained;
                    // What the jumped states did to the dip record: the centre above the
                    // floor ends any run of dips (their depths, negative, change nothing).
                    end.dip.push(&w.die, &state);
                    if end.steps >= cfg.max_steps {
                        break;
                    }
                }
            }
            match fly.next(engine, &mut state) {
                Ok(f) => flown = f,
                Err(()) => return Some(end),
            }
        }
        fly.in_a_row = if flown { fly.in_a_row + 1 } else { 0 };
        if !flown {
            if engine.step().is_err() {
                return Some(end);
            }
            end.engine_steps += 1;
            state = engine.state();
        }
        end.steps += 1;
        // A roll that runs long (a die that never settles, to the step cap) asks every 4,096
        // steps whether it is to be abandoned, so that a stop ends it within a second.
        if end.steps & 0xfff == 0 && abandon() {
            return None;
        }
        // Every step's state, flown or stepped, goes through the same checks.
        observe(end.steps, &state);
        if w.judge(&mut end, &state, !flown || fly.own) {
            return Some(end);
        }
    }
    end.fate = Fate::Unconverged(w.die.outcome(&state));
    Some(end)
}

/// Rolls one throw to its end: `roll_observed` watching nothing, with free flight jumped
/// where no check can fire (`Flight::jump`), which leaves the record bit for bit the same.
pub fn roll(engine: &mut dyn Engine, scene: &Scene, throw: &Throw, cfg: &RollConfig) -> RollRecord {
    roll_or_abandon(engine, scene, throw, cfg, &|| false).expect("never abandoned")
}

/// [`roll`], abandoned (`None`) when `abandon` says so: it is asked every 4,096 steps (a stop
/// request, which must end even a roll that runs to the step cap within a second).
pub fn roll_or_abandon(
    engine: &mut dyn Engine,
    scene: &Scene,
    throw: &Throw,
    cfg: &RollConfig,
    abandon: &dyn Fn() -> bool,
) -> Option<RollRecord> {
    let end = run(
        engine,
        scene,
        &throw.start(scene),
        cfg,
        |_, _| {},
        true,
        abandon,
    )?;
    Some(record_of(throw, end))
}
