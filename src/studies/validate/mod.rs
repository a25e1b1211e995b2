//! `dicephys validate`: the engines against the limits where a die's probabilities are known in
//! closed form (the paper ends: "This problem may also have wider relevance in the testing of
//! physics engines").
//!
//! * **2D, no bounce** ([`Case::NoBounce2d`]): the block released at rest at a uniformly random
//!   angle about z with its lowest edge touching the floor, e = 0, high friction and heavy
//!   damping, rolls downhill onto the face whose angle it started over: P(breadth vertical) =
//!   (2/π) arctan R, eq. (InElasK). Then [`Case::Momentum2d`], the same with the damping lifted.
//! * **3D, quasi-static** ([`Case::QuasiStatic3d`]): the same release in a uniformly random
//!   orientation (Haar measure): each pair of faces with the probability of the solid angle it
//!   subtends at the centre, Simpson's P(i vertical) = (2/π) arctan(w_j w_k / (w_i |w|))
//!   (`theory::simpson_3d`, the paper's unnumbered equation after (InElasK)).
//! * **Free flight** ([`Case::FreeFlight`], [`flight`]): a long tumbling flight against the
//!   exact motion: the translational energy against symplectic Euler's known loss, and the
//!   rotational energy and angular momentum against their conservation, at several dt.
//! * **The trend** ([`Case::Trend`]): the paper's throw in 2D as e and μ rise together; the
//!   paper expects the ratio to move from near the no-bounce ratio towards eq. (MasterEqu).
//!   A curve, not a verdict.
//!
//! Why these limits are exact (README, "Validation"): a die at rest on a corner, moving so
//! slowly that it carries no momentum, follows the steepest descent of its centre's height
//! h(u) = Σ sᵢ|uᵢ| over the directions u of gravity in body axes (with isotropic damping about
//! the contact point, ω ∝ u × ∇h, so du/dt ∝ −(∇h − (u·∇h)u)). The planes uᵢ/sᵢ = uⱼ/sⱼ that
//! bound the solid angle of each face are invariant under that flow (its component along their
//! normal vanishes on them), so a die ends on the face whose solid angle it started in.
//!
//! A roll of a limit case ends by DicePhys's rest rule with the engine's sleeping off (nothing
//! freezes a slow die mid-fall) and the certificate audited (`sim::certificate`). A die still
//! moving at the step cap but certified in a face region (its energy below the barrier out of
//! it) is counted on that face and reported apart, as "moving at the cap": such dice creep or
//! rock on their face for ever (Bullet; README).

pub mod flight;

use super::sweep::{cell_spec, measure, Study};
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::model::block::{Block, Outcome};
use crate::model::scene::{Mode, Scene, MAX_DAMPING};
use crate::model::throws::ThrowStyle;
use crate::report::text::{left, right, Columns};
use crate::run::cputime::process_cpu_seconds;
use crate::run::io::write_atomic;
use crate::run::runner::Checkpoint;
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::run::tally::Tally;
use crate::sim::roll::{Fate, RollConfig, RollRecord, Rule};
use crate::studies::sweep::dt_label;
use crate::theory;
use flight::{FlightRun, Integrator};
use serde::{Deserialize, Serialize};

/// A verdict's bound: |z| at most this many standard errors.
pub const Z_PASS: f64 = 3.0;

/// The limit cases' damping, 1/s, linear and angular: the most Bullet can hold
/// (`scene::MAX_DAMPING`).
pub const LIMIT_DAMPING: f64 = MAX_DAMPING;

/// The limit cases' friction μ: high, so that the die pivots on its corner rather than slides.
pub const LIMIT_FRICTION: f64 = 1.0;

/// The limit cases' step cap: 5 s of 1 ms steps. A die released at rest comes to rest within
/// 2 s (Rapier's slowest of 1,000 rolls: 1.6 s), or never: Bullet lets 26-28 % of 3D dice creep
/// on their face past 20 s with sleeping off, and 0.1-1.7 % of rolls meet the rest rule only
/// between 5 and 20 s; counted at the cap on the face region they are certified in, they land
/// where they would have, at a quarter of the cost.
pub const LIMIT_MAX_STEPS: u64 = 5_000;

/// A conserved quantity passes if it drifts by at most this fraction over the flight at
/// dt = 1 ms and its drift falls as dt does.
pub const DRIFT_PASS: f64 = 0.01;

/// Symplectic Euler's loss is matched if measured/predicted is within this of 1 (rounding).
pub const LOSS_TOLERANCE: f64 = 1e-6;

/// What `validate` runs.
#[derive(Clone, Debug, Serialize)]
pub struct Config {
    /// The engines (Bullet brings its presets and the fast flight to the free-flight case).
    pub engines: Vec<EngineKind>,
    /// Rolls per limit cell (block × engine × case).
    pub rolls: u64,
    /// Rolls per point of the trend.
    pub trend_rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The 2D blocks, for several R.
    pub blocks_2d: Vec<Block>,
    /// The 3D blocks: a cube, a square cuboid, three different sides.
    pub blocks_3d: Vec<Block>,
    /// The trend's block (2D).
    pub trend_block: Block,
    /// The trend's (e, μ) points, bouncier and grippier in turn.
    pub trend: Vec<(f64, f64)>,
    /// The free flight's time steps, s.
    pub flight_dts: Vec<f64>,
    /// The free flight's length, s.
    pub flight_time: f64,
    /// The free flight's spin, rad/s.
    pub flight_spin: f64,
    /// The limit cases' damping rate, 1/s.
    pub damping: f64,
    /// The limit cases' μ.
    pub friction: f64,
    /// The limit cases' step cap.
    pub max_steps: u64,
    /// The trend's step cap.
    pub trend_max_steps: u64,
    /// The departure in probability each limit case should resolve at 3σ; a case that
    /// cannot says how many rolls would.
    pub resolve: f64,
}

impl Default for Config {
    fn default() -> Config {
        let b = |s: &str| s.parse::<Block>().expect("a valid block");
        Config {
            engines: vec![EngineKind::Bullet, EngineKind::Rapier],
            rolls: 6000,
            trend_rolls: 1000,
            seed: 2385,
            blocks_2d: vec![
                b("140x24x24"),
                b("140x24x20"),
                b("140x22x13"),
                b("140x30x10"),
            ],
            blocks_3d: vec![b("20x20x20"), b("40x20x20"), b("30x20x10")],
            trend_block: b("140x22x13"),
            trend: vec![(0.0, 0.1), (0.2, 0.29), (0.5, 0.5), (0.7, 1.0), (0.9, 1.5)],
            flight_dts: vec![1.0 / 60.0, 1.0 / 250.0, 1.0 / 1000.0, 1.0 / 4000.0],
            flight_time: 2.0,
            flight_spin: 40.0,
            damping: LIMIT_DAMPING,
            friction: LIMIT_FRICTION,
            max_steps: LIMIT_MAX_STEPS,
            trend_max_steps: 200_000,
            resolve: 0.02,
        }
    }
}

impl Config {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::Invalid(m));
        if self.engines.is_empty() {
            return bad("--engines: name at least one engine".into());
        }
        for (name, r) in [("--rolls", self.rolls), ("--trend-rolls", self.trend_rolls)] {
            if r == 0 || r > crate::run::spec::MAX_ROLLS {
                return bad(format!("{name} {r}: must be in 1..=1e9"));
            }
        }
        if !(self.resolve.is_finite() && self.resolve > 0.0 && self.resolve < 1.0) {
            return bad(format!("--resolve {}: must be in (0, 1)", self.resolve));
        }
        if !(self.flight_time.is_finite() && self.flight_time > 0.0 && self.flight_time <= 100.0) {
            return bad(format!(
                "--flight-time {}: must be in (0, 100] s",
                self.flight_time
            ));
        }
        if self.trend.is_empty() && self.blocks_2d.is_empty() && self.blocks_3d.is_empty() {
            return bad("nothing to validate: give blocks or trend points".into());
        }
        for &(e, mu) in &self.trend {
            if !(e.is_finite() && (0.0..=1.0).contains(&e) && mu.is_finite() && mu >= 0.0) {
                return bad(format!(
                    "--trend {e}:{mu}: each point is E:MU with e in [0, 1] and μ >= 0"
                ));
            }
        }
        for &dt in &self.flight_dts {
            if !(dt.is_finite() && dt > 0.0 && dt <= 0.1) {
                return bad(format!("--flight-dts {dt}: must be in (0, 0.1] s"));
            }
        }
        let scene = limit_scene(self, self.trend_block, Mode::ThreeD, true);
        scene.validate(false)?;
        for &(e, mu) in &self.trend {
            trend_scene(self, e, mu).validate(false)?;
        }
        RunSpec {
            engine: self.engines[0],
            scene,
            throws: ThrowSpec::keyed_style(self.seed, ThrowStyle::Rest),
            roll: limit_roll(self.max_steps),
            rolls: self.rolls,
            shard: None,
        }
        .validate(false)?;
        limit_roll(self.trend_max_steps).validate()
    }
}

/// The cases.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::Display, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Case {
    /// 2D, released at rest, over-damped: eq. (InElasK).
    #[serde(rename = "2d_no_bounce")]
    #[strum(serialize = "2d_no_bounce")]
    NoBounce2d,
    /// 2D, released at rest, the damping lifted: how far momentum alone moves it.
    #[serde(rename = "2d_momentum")]
    #[strum(serialize = "2d_momentum")]
    Momentum2d,
    /// 3D, released at rest in a Haar-random orientation, over-damped: the solid angles.
    #[serde(rename = "3d_quasi_static")]
    #[strum(serialize = "3d_quasi_static")]
    QuasiStatic3d,
    /// A long tumbling flight: energy and angular momentum against dt.
    FreeFlight,
    /// The paper's throw in 2D as e and μ rise: towards eq. (MasterEqu).
    Trend,
}

/// A row's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::Display)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Verdict {
    /// Within the bound (|z| ≤ 3, or a deterministic tolerance).
    Pass,
    /// Outside it; the row's note says why.
    Fail,
    /// A point of a curve, shown and not judged.
    Curve,
}

/// One line of the table: a quantity with its closed form, its measurement and a verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The case.
    pub case: Case,
    /// The engine (or, in free flight, the integrator).
    pub engine: String,
    /// The block (`LxBxW` mm, with R in 2D) or, in free flight, the time step.
    pub subject: String,
    /// What is compared, e.g. `P(breadth vertical)`.
    pub quantity: String,
    /// The closed form's value.
    pub closed_form: f64,
    /// The measured value.
    pub measured: f64,
    /// Its standard error: binomial, from the closed form's p (null where deterministic).
    pub err: f64,
    /// Rolls counted (dice that ended on a face), or steps flown.
    pub n: u64,
    /// (measured − closed form)/err; null where deterministic.
    pub z: f64,
    /// Pass, fail, or a curve's point.
    pub verdict: Verdict,
    /// What else the reader needs: dice moving at the cap, why a row fails.
    pub note: String,
    /// Where 3σ is wider than `Config::resolve`: the rolls that would resolve it.
    pub rolls_to_resolve: Option<u64>,
}

/// Dice counted by face.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Faces {
    /// Breadth vertical.
    pub breadth: u64,
    /// Width vertical.
    pub width: u64,
    /// Length vertical.
    pub length: u64,
}

impl Faces {
    fn add(&mut self, o: Outcome) {
        match o {
            Outcome::Breadth => self.breadth += 1,
            Outcome::Width => self.width += 1,
            Outcome::Length => self.length += 1,
            Outcome::Unknown => {}
        }
    }

    /// All three.
    pub fn total(&self) -> u64 {
        self.breadth + self.width + self.length
    }

    /// The count of one face.
    pub fn of(&self, o: Outcome) -> u64 {
        match o {
            Outcome::Breadth => self.breadth,
            Outcome::Width => self.width,
            Outcome::Length => self.length,
            Outcome::Unknown => 0,
        }
    }
}

/// One limit cell as rolled: how its dice ended, kept under the study's checkpoint.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LimitCell {
    /// The engine.
    pub engine: EngineKind,
    /// 2D or 3D.
    pub mode: Mode,
    /// The block, `LxBxW` mm.
    pub block: String,
    /// The damping rate, 1/s (0: lifted).
    pub damping: f64,
    /// The run's exact tally (DicePhys's rest rule, the certificate audited).
    pub tally: Tally,
    /// Dice at rest on a face.
    pub at_rest: Faces,
    /// Dice still moving at the cap, certified in a face region they cannot leave (creeping
    /// or rocking on that face).
    pub moving_at_cap: Faces,
    /// Dice at rest on no face, or moving at the cap and not certified.
    pub unknown: u64,
    /// Failed rolls.
    pub failed: u64,
    /// Dice that ended on a face (at rest or moving at the cap) and, of those, the ones that
    /// ended on the face whose solid angle they started in (`start_face`): all of them, in the
    /// quasi-static limit.
    pub ended_on_a_face: u64,
    /// See `ended_on_a_face`.
    pub ended_where_started: u64,
    /// Each throw's face, in index order: b, w, l, ? for none, x for failed (kept with the
    /// cell's checkpoint, not written to `validate.json`).
    #[serde(skip)]
    pub outcomes: String,
    /// Process CPU seconds the cell took.
    pub cpu_s: f64,
}

impl LimitCell {
    fn empty(spec: &RunSpec) -> LimitCell {
        LimitCell {
            engine: spec.engine,
            mode: spec.scene.mode,
            block: spec.scene.block.to_string(),
            damping: spec.scene.linear_damping,
            tally: Tally::default(),
            at_rest: Faces::default(),
            moving_at_cap: Faces::default(),
            unknown: 0,
            failed: 0,
            ended_on_a_face: 0,
            ended_where_started: 0,
            outcomes: String::new(),
            cpu_s: 0.0,
        }
    }

    fn add(&mut self, scene: &Scene, r: &RollRecord) {
        self.tally.add(r);
        let face = match r.fate {
            Fate::Settled(o) => {
                self.at_rest.add(o);
                o
            }
            Fate::Unconverged(_) => match r.certified {
                Some((_, o)) => {
                    self.moving_at_cap.add(o);
                    o
                }
                None => Outcome::Unknown,
            },
            Fate::Failed(_) => {
                self.failed += 1;
                self.outcomes.push('x');
                return;
            }
        };
        if face == Outcome::Unknown {
            self.unknown += 1;
        } else {
            self.ended_on_a_face += 1;
            self.ended_where_started += (face == start_face(scene, &r.throw.start(scene))) as u64;
        }
        self.outcomes.push(match face {
            Outcome::Breadth => 'b',
            Outcome::Width => 'w',
            Outcome::Length => 'l',
            Outcome::Unknown => '?',
        });
    }

    /// Dice on each face, at rest or moving at the cap.
    pub fn faces(&self) -> Faces {
        Faces {
            breadth: self.at_rest.breadth + self.moving_at_cap.breadth,
            width: self.at_rest.width + self.moving_at_cap.width,
            length: self.at_rest.length + self.moving_at_cap.length,
        }
    }

    /// The fraction of throws that ended on the same face in both cells (of the same throws).
    pub fn same_outcome(&self, other: &LimitCell) -> f64 {
        let n = self.outcomes.len().min(other.outcomes.len());
        let same = self
            .outcomes
            .bytes()
            .zip(other.outcomes.bytes())
            .filter(|(a, b)| a == b && *a != b'?' && *a != b'x')
            .count();
        same as f64 / n.max(1) as f64
    }
}

/// One point of the trend.
#[derive(Clone, Debug, Serialize)]
pub struct TrendPoint {
    /// The engine.
    pub engine: EngineKind,
    /// The block, `LxBxW` mm.
    pub block: String,
    /// e.
    pub restitution: f64,
    /// μ.
    pub friction: f64,
    /// Rolls.
    pub rolls: u64,
    /// N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// Eq. (MasterEqu).
    pub theory: f64,
    /// Eq. (InElasK)'s ratio, no bounce.
    pub no_bounce: f64,
    /// Where the ratio lies from theory (0) to no bounce (1).
    pub towards_no_bounce: f64,
    /// P(breadth vertical) = N(breadth)/(N(breadth) + N(width)).
    pub p_breadth: f64,
    /// Its binomial error.
    pub p_breadth_err: f64,
    /// Rolls still moving at the cap.
    pub unconverged: u64,
    /// Rolls flagged with an energy gain.
    pub energy_gain: u64,
}

/// `validate`'s results.
#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    /// What was run.
    pub config: Config,
    /// Every judged (or plotted) quantity.
    pub rows: Vec<Row>,
    /// The limit cells as rolled.
    pub cells: Vec<LimitCell>,
    /// The free flights.
    pub flights: Vec<FlightRun>,
    /// The trend's points.
    pub trend: Vec<TrendPoint>,
    /// Rows passed, failed.
    pub passed: usize,
    /// Rows failed.
    pub failed: usize,
    /// A sentence per finding.
    pub findings: Vec<String>,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Process CPU seconds, all threads.
    pub cpu_s: f64,
}

/// The limit cases' scene: the paper's, released on a floor with e = 0, the config's μ, its
/// damping (or none), and the engine's sleeping off.
pub fn limit_scene(cfg: &Config, block: Block, mode: Mode, damped: bool) -> Scene {
    let mut s = Scene::paper(block, mode);
    s.restitution = 0.0;
    s.friction = cfg.friction;
    let d = if damped { cfg.damping } else { 0.0 };
    s.linear_damping = d;
    s.angular_damping = d;
    s.sleeping = false;
    s
}

/// The limit cases' rolls: DicePhys's rest rule, every step stepped, the certificate audited
/// (it names the face region of a die still moving at the cap).
pub fn limit_roll(max_steps: u64) -> RollConfig {
    RollConfig {
        max_steps,
        rule: Rule::Dicephys,
        audit: true,
        fast_flight: false,
        ..RollConfig::default()
    }
}

/// The trend's scene: the paper's 2D scene for its block, with e and μ.
pub fn trend_scene(cfg: &Config, e: f64, mu: f64) -> Scene {
    let mut s = Scene::paper(cfg.trend_block, Mode::TwoD);
    s.restitution = e;
    s.friction = mu;
    s
}

/// A limit cell as kept under the study's checkpoint, with its per-throw faces.
#[derive(Serialize, Deserialize)]
struct Kept {
    cell: LimitCell,
    outcomes: String,
}

/// Rolls a limit cell, or reads it back from the study's checkpoint.
pub fn measure_limit(spec: &RunSpec, study: &Study) -> Result<LimitCell> {
    let cpu = process_cpu_seconds();
    let dir = study
        .checkpoint
        .as_ref()
        .map(|root| root.join(format!("validate-{}-{}", spec.engine, spec.key())));
    let kept = dir.as_ref().map(|d| d.join("limit.json"));
    if let Some(k) = kept
        .as_ref()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .and_then(|t| serde_json::from_str::<Kept>(&t).ok())
    {
        return Ok(LimitCell {
            outcomes: k.outcomes,
            ..k.cell
        });
    }
    let ck = match &dir {
        Some(d) => Some(Checkpoint::open_fresh(d, spec)?),
        None => None,
    };
    let mut cell = LimitCell::empty(spec);
    let run = study.runner.run(spec, ck.as_ref(), &mut |recs| {
        recs.iter().for_each(|r| cell.add(&spec.scene, r));
        Ok(())
    })?;
    if !run.complete {
        return Err(Error::Stopped);
    }
    cell.cpu_s = process_cpu_seconds() - cpu + run.resumed_cpu_s;
    if let Some(f) = &kept {
        let k = Kept {
            cell: cell.clone(),
            outcomes: cell.outcomes.clone(),
        };
        let json = serde_json::to_string(&k).map_err(|e| Error::Failed(e.to_string()))?;
        write_atomic(f, json.as_bytes())?;
    }
    Ok(cell)
}

/// The face whose solid angle the downward vertical from the centre passes through in state
/// `s`: the body axis i (of x, y in 2D) with the largest |uᵢ|/sᵢ, u the vertical in body axes
/// and sᵢ the half sides; the face a die released there at rest, without momentum, ends on.
pub fn start_face(scene: &Scene, s: &crate::model::state::BodyState) -> Outcome {
    let die = crate::model::die::DieShape::of(scene);
    let up = crate::model::die::up_in_body(&s.rotation);
    let n = if scene.mode == Mode::TwoD { 2 } else { 3 };
    let i = (0..n)
        .max_by(|&p, &q| (up[p].abs() / die.half[p]).total_cmp(&(up[q].abs() / die.half[q])))
        .unwrap_or(0);
    [Outcome::Breadth, Outcome::Width, Outcome::Length][i]
}

/// A probability measured as k of n against the closed form p: the row, with z from the
/// closed form's binomial error √(p(1−p)/n).
fn probability_row(
    cfg: &Config,
    case: Case,
    engine: EngineKind,
    subject: String,
    quantity: &str,
    p: f64,
    (k, n): (u64, u64),
) -> Row {
    let measured = k as f64 / n.max(1) as f64;
    let err = crate::theory::stats::binomial_err(p, n.max(1));
    let z = if n == 0 {
        f64::NAN
    } else {
        (measured - p) / err
    };
    let verdict = if z.abs() <= Z_PASS {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
    Row {
        case,
        engine: engine.name().into(),
        subject,
        quantity: quantity.into(),
        closed_form: p,
        measured,
        err,
        n,
        z,
        verdict,
        note: String::new(),
        rolls_to_resolve: rolls_to_resolve(p, n, cfg.resolve),
    }
}

/// Rolls for 3σ of a proportion near p to be at most `resolve`, if n does not already make it.
pub fn rolls_to_resolve(p: f64, n: u64, resolve: f64) -> Option<u64> {
    let need = (9.0 * p * (1.0 - p) / (resolve * resolve)).ceil() as u64;
    (need > n).then_some(need)
}

/// What a limit cell's dice did besides coming to rest on a face, for its rows' notes.
fn cell_note(c: &LimitCell, max_steps: u64) -> String {
    let mut v = vec![format!(
        "{} of {} on the face they started over",
        c.ended_where_started, c.ended_on_a_face
    )];
    let moving = c.moving_at_cap.total();
    if moving > 0 {
        v.push(format!(
            "{moving} of {} still moving on a face at the {} s cap (counted on it)",
            c.tally.rolls,
            max_steps as f64 * 0.001
        ));
    }
    if c.unknown > 0 {
        v.push(format!("{} on no face", c.unknown));
    }
    if c.failed > 0 {
        v.push(format!("{} failed", c.failed));
    }
    if c.tally.certified_wrong > 0 {
        v.push(format!(
            "{} left the region they were certified in",
            c.tally.certified_wrong
        ));
    }
    v.join("; ")
}

fn subject_2d(block: &Block) -> String {
    format!("{block} (R {:.3})", block.r())
}

const SIDES: [(Outcome, &str); 3] = [
    (Outcome::Breadth, "P(breadth vertical)"),
    (Outcome::Width, "P(width vertical)"),
    (Outcome::Length, "P(length vertical)"),
];

/// Runs every case, logging each row as it is measured.
pub fn run(cfg: &Config, study: &Study, log: &dyn Fn(&str)) -> Result<Validation> {
    cfg.validate()?;
    let wall = std::time::Instant::now();
    let cpu0 = process_cpu_seconds();
    let mut rows: Vec<Row> = Vec::new();
    let mut cells = Vec::new();
    let push = |r: Row, rows: &mut Vec<Row>| {
        log(&format_row(&r));
        rows.push(r);
    };
    let spec = |engine, scene: Scene| RunSpec {
        engine,
        scene,
        throws: ThrowSpec::keyed_style(cfg.seed, ThrowStyle::Rest),
        roll: limit_roll(cfg.max_steps),
        rolls: cfg.rolls,
        shard: None,
    };
    // 2D: over-damped, then the damping lifted, on the same throws.
    for &engine in &cfg.engines {
        for block in &cfg.blocks_2d {
            let p = theory::no_bounce_2d(block.r()).breadth_vertical;
            let damped = measure_limit(
                &spec(engine, limit_scene(cfg, *block, Mode::TwoD, true)),
                study,
            )?;
            let free = measure_limit(
                &spec(engine, limit_scene(cfg, *block, Mode::TwoD, false)),
                study,
            )?;
            for (case, c) in [(Case::NoBounce2d, &damped), (Case::Momentum2d, &free)] {
                let f = c.faces();
                let mut r = probability_row(
                    cfg,
                    case,
                    engine,
                    subject_2d(block),
                    "P(breadth vertical)",
                    p,
                    (f.breadth, f.total()),
                );
                r.note = cell_note(c, cfg.max_steps);
                if case == Case::Momentum2d {
                    let same = format!(
                        "same face as over-damped for {:.1} % of throws",
                        100.0 * c.same_outcome(&damped)
                    );
                    r.note = [same, r.note]
                        .into_iter()
                        .filter(|s| !s.is_empty())
                        .collect::<Vec<_>>()
                        .join("; ");
                }
                push(r, &mut rows);
            }
            cells.push(damped);
            cells.push(free);
        }
    }
    // 3D: over-damped, Haar-random orientations.
    for &engine in &cfg.engines {
        for block in &cfg.blocks_3d {
            let (p, _) = theory::simpson_3d(block);
            let c = measure_limit(
                &spec(engine, limit_scene(cfg, *block, Mode::ThreeD, true)),
                study,
            )?;
            let f = c.faces();
            for (o, q) in SIDES {
                let want = match o {
                    Outcome::Breadth => p.breadth_vertical,
                    Outcome::Width => p.width_vertical,
                    _ => p.length_vertical,
                };
                let mut r = probability_row(
                    cfg,
                    Case::QuasiStatic3d,
                    engine,
                    block.to_string(),
                    q,
                    want,
                    (f.of(o), f.total()),
                );
                r.note = cell_note(&c, cfg.max_steps);
                push(r, &mut rows);
            }
            cells.push(c);
        }
    }
    // Free flight.
    let mut flights = Vec::new();
    let flight_block = Block::from_mm(140.0, 24.0, 20.0)?;
    for integrator in Integrator::for_engines(&cfg.engines) {
        let runs: Vec<FlightRun> = cfg
            .flight_dts
            .iter()
            .map(|&dt| {
                flight::fly(
                    integrator,
                    flight_block,
                    dt,
                    cfg.flight_time,
                    cfg.flight_spin,
                )
            })
            .collect::<Result<_>>()?;
        for r in flight_rows(cfg, integrator, &runs) {
            push(r, &mut rows);
        }
        flights.extend(runs);
    }
    // The trend.
    let mut trend = Vec::new();
    for &engine in &cfg.engines {
        for &(e, mu) in &cfg.trend {
            let roll = RollConfig {
                max_steps: cfg.trend_max_steps,
                rule: Rule::Dicephys,
                fast_flight: true,
                ..RollConfig::default()
            };
            let m = measure(
                &cell_spec(
                    engine,
                    trend_scene(cfg, e, mu),
                    roll,
                    cfg.seed,
                    cfg.trend_rolls,
                ),
                study,
            )?;
            let r = m.ratio();
            let p = crate::theory::stats::probability(m.tally.counts.breadth, m.tally.counts.width);
            let big_r = cfg.trend_block.r();
            let (t, nb) = (theory::ratio_from_r(big_r), theory::no_bounce_ratio(big_r));
            let point = TrendPoint {
                engine,
                block: cfg.trend_block.to_string(),
                restitution: e,
                friction: mu,
                rolls: m.tally.rolls,
                ratio: r.value,
                ratio_err: r.err,
                theory: t,
                no_bounce: nb,
                towards_no_bounce: (r.value - t) / (nb - t),
                p_breadth: p.value,
                p_breadth_err: p.err,
                unconverged: m.tally.unconverged,
                energy_gain: m.tally.energy_gain,
            };
            let z = (r.value - t) / r.err;
            push(
                Row {
                    case: Case::Trend,
                    engine: engine.name().into(),
                    subject: format!("{} e {e} μ {mu}", cfg.trend_block),
                    quantity: "ratio b/w vs (MasterEqu)".into(),
                    closed_form: t,
                    measured: r.value,
                    err: r.err,
                    n: m.tally.counts.breadth + m.tally.counts.width,
                    z,
                    verdict: Verdict::Curve,
                    note: format!(
                        "{:.0} % of the way from (MasterEqu) {t:.3} to no bounce {nb:.3}{}{}",
                        100.0 * point.towards_no_bounce,
                        if m.tally.unconverged > 0 {
                            format!("; {} unconverged", m.tally.unconverged)
                        } else {
                            String::new()
                        },
                        if m.tally.energy_gain > 0 {
                            format!(
                                "; {} of {} rolls gained energy",
                                m.tally.energy_gain, m.tally.rolls
                            )
                        } else {
                            String::new()
                        }
                    ),
                    rolls_to_resolve: None,
                },
                &mut rows,
            );
            trend.push(point);
        }
    }
    let passed = rows.iter().filter(|r| r.verdict == Verdict::Pass).count();
    let failed = rows.iter().filter(|r| r.verdict == Verdict::Fail).count();
    let findings = findings(cfg, &rows, &cells, &flights, &trend);
    Ok(Validation {
        config: cfg.clone(),
        rows,
        cells,
        flights,
        trend,
        passed,
        failed,
        findings,
        wall_s: wall.elapsed().as_secs_f64(),
        cpu_s: process_cpu_seconds() - cpu0,
    })
}

/// The flight's measured order of convergence between the two finest time steps: log(drift
/// ratio)/log(dt ratio); NaN if not measurable.
pub fn order(runs: &[FlightRun], drift: impl Fn(&FlightRun) -> f64) -> f64 {
    let mut v: Vec<&FlightRun> = runs.iter().collect();
    v.sort_by(|a, b| a.dt.total_cmp(&b.dt));
    match v.as_slice() {
        [a, b, ..] if drift(a) > 0.0 && drift(b) > 0.0 => {
            (drift(b) / drift(a)).ln() / (b.dt / a.dt).ln()
        }
        _ => f64::NAN,
    }
}

/// The run at the time step closest to 1 ms (on a log scale).
fn at_one_ms(runs: &[FlightRun]) -> Option<&FlightRun> {
    runs.iter().min_by(|a, b| {
        (a.dt / 1e-3)
            .ln()
            .abs()
            .total_cmp(&(b.dt / 1e-3).ln().abs())
    })
}

/// The free-flight rows of one integrator: symplectic Euler's loss (every dt), and the
/// rotational energy and angular momentum at 1 ms with their order in dt.
fn flight_rows(cfg: &Config, integrator: Integrator, runs: &[FlightRun]) -> Vec<Row> {
    let Some(ref_run) = at_one_ms(runs) else {
        return Vec::new();
    };
    let name = integrator.name().to_string();
    let worst = runs
        .iter()
        .map(|r| r.loss_ratio())
        .max_by(|a, b| (a - 1.0).abs().total_cmp(&(b - 1.0).abs()))
        .unwrap_or(f64::NAN);
    let dts: Vec<String> = runs.iter().map(|r| dt_label(r.dt)).collect();
    let mut rows = vec![Row {
        case: Case::FreeFlight,
        engine: name.clone(),
        subject: format!("dt {}", dts.join(", ")),
        quantity: format!(
            "energy lost / ½mg²dt·T{}",
            if ref_run.substeps > 1 {
                format!(" ÷ {} substeps", ref_run.substeps)
            } else {
                String::new()
            }
        ),
        closed_form: 1.0,
        measured: worst,
        err: f64::NAN,
        n: runs.iter().map(|r| r.steps).sum(),
        z: f64::NAN,
        verdict: if (worst - 1.0).abs() <= LOSS_TOLERANCE {
            Verdict::Pass
        } else {
            Verdict::Fail
        },
        note: format!(
            "symplectic Euler's known loss over {} s, the worst of {} time steps",
            cfg.flight_time,
            runs.len()
        ),
        rolls_to_resolve: None,
    }];
    for (quantity, drift) in [
        (
            "rotational energy drift",
            (|r: &FlightRun| r.rotational_energy_drift) as fn(&FlightRun) -> f64,
        ),
        ("angular momentum drift", |r: &FlightRun| {
            r.angular_momentum_drift
        }),
    ] {
        let d = drift(ref_run);
        let p = order(runs, drift);
        // Conserved to rounding at every step, or small at 1 ms and falling with dt.
        let exact = runs.iter().all(|r| drift(r) < 1e-9);
        let pass = exact || (d <= DRIFT_PASS && p > 0.5);
        let note = if exact {
            "conserved to rounding at every dt".to_string()
        } else if !integrator.gyroscopic() && quantity.starts_with("angular") {
            "no gyroscopic term: ω is held constant in world axes, so the die turns about a \
             fixed axis and L turns with it, the same at every dt (it does not fall with dt); \
             exact only for a spin about a principal axis, as in the paper's throw"
                .to_string()
        } else {
            format!("max over {} s; order {p:.2} in dt", cfg.flight_time)
        };
        rows.push(Row {
            case: Case::FreeFlight,
            engine: name.clone(),
            subject: format!("dt {}", dt_label(ref_run.dt)),
            quantity: quantity.into(),
            closed_form: 0.0,
            measured: d,
            err: f64::NAN,
            n: ref_run.steps,
            z: f64::NAN,
            verdict: if pass { Verdict::Pass } else { Verdict::Fail },
            note,
            rolls_to_resolve: None,
        });
    }
    rows
}

/// A sentence per finding: what passed and failed per engine, what the dice did at the cap,
/// the trend.
fn findings(
    cfg: &Config,
    rows: &[Row],
    cells: &[LimitCell],
    flights: &[FlightRun],
    trend: &[TrendPoint],
) -> Vec<String> {
    let mut out = Vec::new();
    for &engine in &cfg.engines {
        let mine: Vec<&Row> = rows
            .iter()
            .filter(|r| {
                r.engine == engine.name()
                    && matches!(
                        r.case,
                        Case::NoBounce2d | Case::Momentum2d | Case::QuasiStatic3d
                    )
            })
            .collect();
        let fails: Vec<String> = mine
            .iter()
            .filter(|r| r.verdict == Verdict::Fail)
            .map(|r| format!("{} {} {} (z {:+.1})", r.case, r.subject, r.quantity, r.z))
            .collect();
        out.push(format!(
            "{engine}: {} of {} limit rows pass at |z| ≤ {Z_PASS}{}.",
            mine.len() - fails.len(),
            mine.len(),
            if fails.is_empty() {
                String::new()
            } else {
                format!("; fail: {}", fails.join(", "))
            }
        ));
        let mut where_started = Vec::new();
        for mode in [Mode::TwoD, Mode::ThreeD] {
            let (mut k, mut n) = (0, 0);
            for c in cells
                .iter()
                .filter(|c| c.engine == engine && c.mode == mode)
            {
                k += c.ended_where_started;
                n += c.ended_on_a_face;
            }
            if n > 0 {
                where_started.push(format!("{k} of {n} in {mode}"));
            }
        }
        if !where_started.is_empty() {
            out.push(format!(
                "{engine}: dice released at rest that ended on the face whose solid angle they \
                 started in (the quasi-static flow's exact answer, throw by throw): {}.",
                where_started.join(", ")
            ));
        }
        let moving: Vec<String> = cells
            .iter()
            .filter(|c| c.engine == engine && c.moving_at_cap.total() > 0)
            .map(|c| {
                format!(
                    "{} {} {}: {} of {}",
                    c.mode,
                    c.block,
                    if c.damping > 0.0 {
                        "damped"
                    } else {
                        "undamped"
                    },
                    c.moving_at_cap.total(),
                    c.tally.rolls
                )
            })
            .collect();
        if !moving.is_empty() {
            out.push(format!(
                "{engine}: dice never at rest by DicePhys's rule within {} s with sleeping off \
                 (creeping or rocking on a face; counted on it): {}.",
                cfg.max_steps as f64 * 0.001,
                moving.join("; ")
            ));
        }
    }
    let mut integrators: Vec<Integrator> = flights.iter().map(|f| f.integrator).collect();
    integrators.dedup();
    for i in integrators {
        let runs: Vec<FlightRun> = flights
            .iter()
            .filter(|f| f.integrator == i)
            .cloned()
            .collect();
        let Some(f) = at_one_ms(&runs) else { continue };
        let verdicts: Vec<String> = rows
            .iter()
            .filter(|r| r.case == Case::FreeFlight && r.engine == i.name())
            .map(|r| format!("{} {}", r.quantity, r.verdict))
            .collect();
        out.push(format!(
            "free flight, {} at dt {}: energy lost {:.4e} J (symplectic Euler: {:.4e}), \
             rotational energy drift {:.2e}, angular momentum drift {:.2e} ({}).",
            i.name(),
            dt_label(f.dt),
            f.translational_loss_j,
            f.symplectic_loss_j,
            f.rotational_energy_drift,
            f.angular_momentum_drift,
            verdicts.join(", ")
        ));
    }
    for &engine in &cfg.engines {
        let pts: Vec<String> = trend
            .iter()
            .filter(|p| p.engine == engine)
            .map(|p| {
                format!(
                    "e {} μ {}: {:.3} ± {:.3} ({:.0} %)",
                    p.restitution,
                    p.friction,
                    p.ratio,
                    p.ratio_err,
                    100.0 * p.towards_no_bounce
                )
            })
            .collect();
        if !pts.is_empty() {
            out.push(format!(
                "trend, {engine}, {} in 2D (theory {:.3}, no bounce {:.3}; in brackets the \
                 way from theory to no bounce): {}.",
                cfg.trend_block,
                theory::ratio_from_r(cfg.trend_block.r()),
                theory::no_bounce_ratio(cfg.trend_block.r()),
                pts.join("; ")
            ));
        }
    }
    out
}

const TABLE: Columns = Columns(&[
    left("case", 15),
    left("engine", 23),
    left("subject", 24),
    left("quantity", 26),
    right("closed form", 11),
    right("measured ± err", 18),
    right("n", 7),
    right("z", 6),
    left("verdict", 7),
]);

/// The table's header.
pub fn header() -> String {
    TABLE.header()
}

fn num(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e4) {
        format!("{v:.2e}")
    } else {
        format!("{v:.4}")
    }
}

/// The Markdown table of the rows, as the README quotes it.
pub fn markdown_table(res: &Validation) -> String {
    let mut s = String::from(
        "| case | engine | subject | quantity | closed form | measured ± err | n | z | verdict | note |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &res.rows {
        let measured = if r.err.is_finite() {
            format!("{} ± {:.4}", num(r.measured), r.err)
        } else {
            num(r.measured)
        };
        let z = if r.z.is_finite() {
            format!("{:+.1}", r.z)
        } else {
            "–".into()
        };
        let mut note = r.note.clone();
        if let Some(n) = r.rolls_to_resolve {
            if !note.is_empty() {
                note += "; ";
            }
            note += &format!("{n} rolls would resolve ±{}", res.config.resolve);
        }
        let verdict = match r.verdict {
            Verdict::Fail => "**fail**".to_string(),
            v => v.to_string(),
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.case,
            r.engine,
            r.subject,
            r.quantity,
            num(r.closed_form),
            measured,
            r.n,
            z,
            verdict,
            note
        );
    }
    s
}

/// One row as text; its note, and the rolls that would resolve it, after it.
pub fn format_row(r: &Row) -> String {
    let measured = if r.err.is_finite() {
        format!("{} ± {:.4}", num(r.measured), r.err)
    } else {
        num(r.measured)
    };
    let z = if r.z.is_finite() {
        format!("{:+.1}", r.z)
    } else {
        "–".into()
    };
    let mut s = TABLE.row(&[
        r.case.to_string(),
        r.engine.clone(),
        r.subject.clone(),
        r.quantity.clone(),
        num(r.closed_form),
        measured,
        r.n.to_string(),
        z,
        r.verdict.to_string(),
    ]);
    let mut extra = Vec::new();
    if !r.note.is_empty() {
        extra.push(r.note.clone());
    }
    if let Some(n) = r.rolls_to_resolve {
        extra.push(format!("{n} rolls would resolve the asked departure at 3σ"));
    }
    if !extra.is_empty() {
        s += &format!("\n{:>16}{}", "", extra.join("; "));
    }
    s
}
