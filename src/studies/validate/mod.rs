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
//! Why these limits are exact (docs/method.md; measured: docs/results/validation.md): a die at rest on a corner, moving so
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
//! rock on their face for ever (Bullet; docs/results/validation.md).

mod findings;
pub mod flight;
pub mod limits;
mod rows;
mod trend;

use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::block::Block;
use crate::model::scene::{Mode, MAX_DAMPING};
use crate::model::throws::ThrowStyle;
pub use crate::report::validate::Config;
use crate::report::validate::{Validation, Verdict};
use crate::run::cputime::process_cpu_seconds;
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::studies::study::{Progress, Study};
use limits::{limit_roll, limit_scene};
use rows::Rows;
use trend::trend_scene;

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

impl Default for Config {
    fn default() -> Config {
        let b = |s: &str| s.parse::<Block>().expect("a valid block");
        Config {
            engines: crate::studies::paper::DEFAULT_ENGINES.to_vec(),
            rolls: 6000,
            trend_rolls: 1000,
            seed: crate::model::throws::DEFAULT_SEED,
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
        let bad = |field, v: String, why: &str| Err(Error::field(field, v, why));
        if self.engines.is_empty() {
            return bad(Field::Engines, String::new(), "name at least one engine");
        }
        for (name, r) in [
            (Field::Rolls, self.rolls),
            (Field::TrendRolls, self.trend_rolls),
        ] {
            if r == 0 || r > crate::run::spec::MAX_ROLLS {
                return bad(name, r.to_string(), "must be in 1..=1e9");
            }
        }
        if !(self.resolve.is_finite() && self.resolve > 0.0 && self.resolve < 1.0) {
            return bad(
                Field::Resolve,
                self.resolve.to_string(),
                "must be in (0, 1)",
            );
        }
        if !(self.flight_time.is_finite() && self.flight_time > 0.0 && self.flight_time <= 100.0) {
            let t = self.flight_time.to_string();
            return bad(Field::FlightTime, t, "must be in (0, 100] s");
        }
        if self.trend.is_empty() && self.blocks_2d.is_empty() && self.blocks_3d.is_empty() {
            return Err(Error::Invalid(
                "nothing to validate: give blocks or trend points".into(),
            ));
        }
        for &(e, mu) in &self.trend {
            if !(e.is_finite() && (0.0..=1.0).contains(&e) && mu.is_finite() && mu >= 0.0) {
                return bad(
                    Field::Trend,
                    format!("{e}:{mu}"),
                    "each point is E:MU with e in [0, 1] and μ >= 0",
                );
            }
        }
        for &dt in &self.flight_dts {
            crate::model::scene::check_dt(Field::FlightDts, dt)?;
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

impl Config {
    /// The rows `run` measures: two per 2D block, three per 3D block, three per flight
    /// integrator, one per trend point, for each engine asked.
    pub fn rows(&self) -> usize {
        let flights = flight_integrators(&self.engines);
        self.engines.len()
            * (2 * self.blocks_2d.len() + 3 * self.blocks_3d.len() + self.trend.len())
            + if self.flight_dts.is_empty() {
                0
            } else {
                3 * flights
            }
    }
}

fn flight_integrators(engines: &[EngineKind]) -> usize {
    crate::report::validate::Integrator::for_engines(engines).len()
}

/// Runs every case, logging each row as it is measured.
pub fn run(
    cfg: &Config,
    study: &Study,
    log: &dyn Fn(&str),
    progress: Progress,
) -> Result<Validation> {
    cfg.validate()?;
    let wall = std::time::Instant::now();
    let cpu0 = process_cpu_seconds();
    let mut rows = Rows {
        rows: Vec::new(),
        log,
        progress,
        total: cfg.rows(),
    };
    let mut cells = limits::no_bounce_2d(cfg, study, &mut rows)?;
    cells.extend(limits::quasi_static_3d(cfg, study, &mut rows)?);
    let flights = flight::cases(cfg, &study.runner.stop, &mut rows)?;
    let trend = trend::points(cfg, study, &mut rows)?;
    let rows = rows.rows;
    let passed = rows.iter().filter(|r| r.verdict == Verdict::Pass).count();
    let failed = rows.iter().filter(|r| r.verdict == Verdict::Fail).count();
    let findings = findings::findings(cfg, &rows, &cells, &flights, &trend);
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
