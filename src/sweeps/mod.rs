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
#[derive(serde::Serialize, serde::Deserialize)]
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

/// Where the sweeps keep their checkpoints (`--out/checkpoint`, set by the command line): a
/// finished cell, with the CPU time it took, is not rolled again when the same command is run
/// again after a crash or Ctrl-C. A cell is kept whole or not at all, so its cost stays true.
pub static CHECKPOINT_DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();

/// A cell's checkpoint directory, named by a hash of everything that defines it and holding
/// that definition in `cell.json`; a directory holding another definition is emptied.
fn cell_dir(
    engine: EngineKind,
    scene: &Scene,
    throws_seed: &str,
    settle: &Settle,
    rolls: u64,
) -> Option<std::path::PathBuf> {
    use std::hash::{Hash, Hasher};
    let root = CHECKPOINT_DIR.get()?;
    let key = serde_json::to_string(&(engine, scene, throws_seed, settle, rolls)).ok()?;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key.hash(&mut h);
    let dir = root.join(format!("{engine}-{:016x}", h.finish()));
    let file = dir.join("cell.json");
    if std::fs::read_to_string(&file).ok().as_deref() != Some(key.as_str()) {
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).ok()?;
        checkpoint::write_atomic(&file, key.as_bytes()).ok()?;
    }
    Some(dir)
}

/// Rolls throws 0..rolls; memory stays flat (chunked, records dropped); a finished cell is
/// kept under `CHECKPOINT_DIR` when set.
pub fn measure(
    engine: EngineKind,
    scene: &Scene,
    throws: &Throws,
    settle: &Settle,
    rolls: u64,
    threads: usize,
) -> Result<Measured, String> {
    let cpu = process_cpu_seconds();
    let seed = match throws {
        Throws::Keyed { seed, ranges } => format!("keyed {seed} {ranges:?}"),
        Throws::Dicephys { throws } => format!("dicephys {}", throws.len()),
    };
    let kept = cell_dir(engine, scene, &seed, settle, rolls).map(|d| d.join("result.json"));
    if let Some(m) = kept
        .as_ref()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .and_then(|t| serde_json::from_str::<Measured>(&t).ok())
    {
        return Ok(m);
    }
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
    let m = Measured {
        tally: run.tally,
        cpu_s: process_cpu_seconds() - cpu,
    };
    if let Some(f) = &kept {
        if let Ok(json) = serde_json::to_string(&m) {
            let _ = checkpoint::write_atomic(f, json.as_bytes());
        }
    }
    Ok(m)
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
