//! Accuracy against cost, and where methods fail: three sweeps over the same roll code.
//!
//! * [`converge`]: the paper's convergence test (its appendix): the ratio against dt for
//!   several blocks, engines, 2D and 3D, and whether dt = 0.001 s is within 1 % of the finest;
//! * [`tradeoff`]: CPU cost against departure from the reference (the finest-dt faithful
//!   result) across methods, and the Pareto front;
//! * [`stability`]: the fractions of rolls that end unconverged, unknown, non-finite or
//!   tunnelled, or that gain energy, across dt, restitution, friction and aspect ratio.
//!
//! Every cell rolls the same keyed throws (seed, index), so cells differ only in the method.

pub mod converge;
pub mod stability;
pub mod tradeoff;

use crate::batch::Tally;
use crate::checkpoint::{self, Indices};
use crate::cputime::process_cpu_seconds;
use crate::engine::EngineKind;
use crate::roll::Settle;
use crate::scene::Scene;
use crate::stats;
use crate::throws::{ThrowKind, ThrowRanges, Throws};

/// The relative departure asked of a method: the paper's "within 1 %".
pub const ONE_PERCENT: f64 = 0.01;

/// One measured cell: the exact tally and the CPU seconds (all threads) it took.
pub struct Measured {
    pub tally: Tally,
    pub cpu_s: f64,
}

impl Measured {
    pub fn ratio(&self) -> stats::Ratio {
        stats::ratio(self.tally.counts.breadth, self.tally.counts.width)
    }
    pub fn cpu_s_per_roll(&self) -> f64 {
        self.cpu_s / self.tally.rolls.max(1) as f64
    }
    pub fn steps_per_roll(&self) -> f64 {
        self.tally.steps as f64 / self.tally.rolls.max(1) as f64
    }
    /// A count as a fraction of the rolls.
    pub fn frac(&self, n: u64) -> f64 {
        n as f64 / self.tally.rolls.max(1) as f64
    }
}

/// The paper's throws (keyed, the table's ranges) from `seed`.
pub fn throws(seed: u64) -> Throws {
    Throws::new(ThrowKind::Keyed, seed, ThrowRanges::default(), 0)
}

/// Rolls throws 0..rolls; memory stays flat (chunked, records dropped).
pub fn measure(
    engine: EngineKind,
    scene: &Scene,
    throws: &Throws,
    settle: &Settle,
    rolls: u64,
    threads: usize,
) -> Result<Measured, String> {
    let cpu = process_cpu_seconds();
    let run = checkpoint::run(
        engine,
        scene,
        throws,
        settle,
        Indices::all(rolls),
        threads,
        None,
        &|_| {},
        &mut |_| Ok(()),
    )?;
    if !run.complete {
        return Err("stopped before the end (Ctrl-C)".into());
    }
    Ok(Measured {
        tally: run.tally,
        cpu_s: process_cpu_seconds() - cpu,
    })
}

/// A ratio's relative departure from a reference, r/ref − 1, with its error (the two taken as
/// independent: at another dt or engine the same throws soon follow other paths).
pub fn departure(r: stats::Ratio, reference: stats::Ratio) -> (f64, f64) {
    let q = r.value / reference.value;
    let err = q * ((r.err / r.value).powi(2) + (reference.err / reference.value).powi(2)).sqrt();
    (q - 1.0, err)
}

/// Rolls per cell needed for a departure's error to resolve 1 % at 2σ (σ ≤ 0.5 %), from one
/// measured at `rolls` per cell: the error falls as 1/√rolls.
pub fn rolls_to_resolve(err: f64, rolls: u64) -> Option<u64> {
    (err.is_finite() && err > 0.0)
        .then(|| (rolls as f64 * (err / (0.5 * ONE_PERCENT)).powi(2)).ceil() as u64)
}

/// Parses a time step: seconds (0.001) or a fraction (1/1000).
pub fn parse_dt(s: &str) -> Result<f64, String> {
    let v = match s.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) = (
                a.trim().parse().map_err(|_| format!("bad dt '{s}'"))?,
                b.trim().parse().map_err(|_| format!("bad dt '{s}'"))?,
            );
            a / b
        }
        None => s.trim().parse().map_err(|_| format!("bad dt '{s}'"))?,
    };
    if v.is_finite() && v > 0.0 && v <= 0.1 {
        Ok(v)
    } else {
        Err(format!("dt '{s}' must be in (0, 0.1] s"))
    }
}

/// A time step as people write it: 1/1000 for 0.001.
pub fn dt_label(dt: f64) -> String {
    let n = 1.0 / dt;
    if (n - n.round()).abs() < 1e-6 * n {
        format!("1/{}", n.round())
    } else {
        format!("{dt}")
    }
}
