//! Accuracy against cost, and where methods fail: three sweeps over the same roll code.
//!
//! * [`converge`](super::converge): the paper's convergence test (its appendix): the ratio against dt for
//!   several blocks, engines, 2D and 3D, and whether dt = 0.001 s is within 1 % of the finest;
//! * [`tradeoff`](super::tradeoff): CPU cost against departure from the reference (the finest-dt faithful
//!   result) across methods, and the Pareto front;
//! * [`stability`](super::stability): the fractions of rolls that end unconverged, unknown, non-finite or
//!   tunnelled, or that gain energy, across dt, restitution, friction and aspect ratio.
//!
//! Every cell rolls the same keyed throws (seed, index), so cells differ only in the method.
//! This module holds what the sweeps share: how a cell is rolled and kept (`Study`,
//! `measure`), and the time steps as people write them. A sweep that rolls to a precision
//! rolls each method as a [`Stream`](super::stream::Stream), compares it with its reference
//! as a [`Departure`](super::departure::Departure), and rolls in rounds within a budget
//! ([`precision`](super::precision)).

use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::scene::Scene;
use crate::run::cputime::process_cpu_seconds;
use crate::run::io::write_atomic;
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::run::tally::Tally;
use crate::sim::roll::RollConfig;
use crate::studies::study::Study;
use crate::theory::stats;

/// The relative departure asked of a method: the paper's "within 1 %".
pub const ONE_PERCENT: f64 = 0.01;

/// One measured cell: the exact tally and the CPU seconds (all threads) it took.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Measured {
    /// The cell's exact counts.
    pub tally: Tally,
    /// Process CPU seconds the cell took, all threads.
    pub cpu_s: f64,
}

impl Measured {
    /// N(breadth vertical)/N(width vertical) ± binomial error.
    pub fn ratio(&self) -> stats::Ratio {
        stats::ratio(self.tally.counts.breadth, self.tally.counts.width)
    }
    /// Process CPU seconds per roll.
    pub fn cpu_s_per_roll(&self) -> f64 {
        self.cpu_s / self.tally.rolls.max(1) as f64
    }
    /// Simulated steps per roll.
    pub fn steps_per_roll(&self) -> f64 {
        self.tally.steps as f64 / self.tally.rolls.max(1) as f64
    }
    /// A count as a fraction of the rolls.
    pub fn frac(&self, n: u64) -> f64 {
        n as f64 / self.tally.rolls.max(1) as f64
    }
}

/// A sweep cell's run: `rolls` keyed throws of the paper's ranges from `seed`.
pub fn cell_spec(
    engine: EngineKind,
    scene: Scene,
    roll: RollConfig,
    seed: u64,
    rolls: u64,
) -> RunSpec {
    RunSpec {
        engine,
        scene,
        throws: ThrowSpec::keyed(seed),
        roll,
        rolls,
        shard: None,
    }
}

/// Rolls a cell; memory stays flat (chunked, records dropped); a finished cell is kept under
/// the study's checkpoint directory, in a directory named by the cell's key. A stop request
/// is an error here: a sweep's cell is whole or not reported.
pub fn measure(spec: &RunSpec, study: &Study) -> Result<Measured> {
    let cpu = process_cpu_seconds();
    let dir = study
        .checkpoint
        .as_ref()
        .map(|root| root.join(format!("{}-{}", spec.engine, spec.key())));
    // A cluster task's tally is its share only: it neither reads nor keeps a cell's result.
    let task = study.runner.share.is_partial();
    let kept = dir
        .as_ref()
        .filter(|_| !task)
        .map(|d| d.join("result.json"));
    if let Some(m) = kept
        .as_ref()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .and_then(|t| serde_json::from_str::<Measured>(&t).ok())
    {
        return Ok(m);
    }
    let ck = match &dir {
        Some(d) => Some(study.runner.open_cell(d, spec)?),
        None => None,
    };
    let run = study.runner.run(spec, ck.as_ref(), &mut |_| Ok(()))?;
    if !run.complete {
        return Err(Error::Stopped);
    }
    let m = Measured {
        tally: run.tally,
        cpu_s: process_cpu_seconds() - cpu + run.resumed_cpu_s,
    };
    if let Some(f) = &kept {
        let json = serde_json::to_string(&m).map_err(|e| Error::failed(e.to_string()))?;
        write_atomic(f, json.as_bytes())?;
    }
    Ok(m)
}

/// Parses a number of seconds written as a decimal (0.001) or a fraction (1/1000); its range
/// is the caller's to check.
pub fn parse_seconds(s: &str) -> Result<f64> {
    let bad = || Error::Invalid(format!("bad dt '{s}'"));
    Ok(match s.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) = (
                a.trim().parse().map_err(|_| bad())?,
                b.trim().parse().map_err(|_| bad())?,
            );
            a / b
        }
        None => s.trim().parse().map_err(|_| bad())?,
    })
}

/// Parses a time step: seconds (0.001) or a fraction (1/1000), in [1e-6, 0.1] s.
pub fn parse_dt(s: &str) -> Result<f64> {
    use crate::model::scene::{MAX_DT, MIN_DT};
    let v = parse_seconds(s)?;
    if v.is_finite() && (MIN_DT..=MAX_DT).contains(&v) {
        Ok(v)
    } else {
        Err(Error::Invalid(format!(
            "dt '{s}' must be in [{MIN_DT}, {MAX_DT}] s"
        )))
    }
}

/// Checks what every sweep takes: its rolls per cell and its step cap.
pub fn check_rolls_and_steps(rolls: u64, max_steps: u64) -> Result<()> {
    if rolls == 0 || rolls > crate::run::spec::MAX_ROLLS {
        return Err(Error::field(Field::Rolls, rolls, "must be in 1..=1e9"));
    }
    if max_steps == 0 {
        return Err(Error::field(Field::MaxSteps, 0, "need at least one step"));
    }
    Ok(())
}

/// Refuses an empty list: "blocks: give at least one value".
pub fn nonempty<T>(v: &[T], field: Field) -> Result<()> {
    if v.is_empty() {
        Err(Error::field(field, "", "give at least one value"))
    } else {
        Ok(())
    }
}

/// Refuses a CPU budget that is not a positive number of seconds.
pub fn check_budget(v: f64, field: Field) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::field(field, v, "CPU seconds, above 0"))
    }
}
