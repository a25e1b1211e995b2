//! Many rolls in parallel, and their tally. Each thread keeps one world and reuses it; every
//! throw is a pure function of its index, and the tally is exact integers, so the result is
//! the same for any thread count or order.

use crate::block::Outcome;
use crate::engine::{new_engine, Engine, EngineKind};
use crate::roll::{roll, Failure, Fate, RollRecord, Settle};
use crate::scene::Scene;
use crate::throws::Throws;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

/// Exact counts over a set of rolls.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    /// Settled rolls by the side standing vertical.
    pub counts: Counts,
    pub unconverged: u64,
    pub failed: BTreeMap<String, u64>,
    pub rolls: u64,
    /// Steps simulated over all rolls.
    pub steps: u64,
    /// Steps the engines took (fewer where free flight was coasted).
    pub engine_steps: u64,
    /// Auditing the early stop: rolls the certificate fired on, how many of those came to rest
    /// on another face than it named, how many the full settle left "unknown" (DicePhys's rest
    /// rule stopping a rocking die at the turning point of a swing, still tilted: no face to
    /// disagree with), and the steps at which it fired, summed.
    pub certified: u64,
    pub certified_wrong: u64,
    #[serde(default)]
    pub certified_unknown: u64,
    pub certified_steps: u64,
    /// Rolls in which the engine injected energy (`RollRecord::energy_gain`), whatever their
    /// fate.
    #[serde(default)]
    pub energy_gain: u64,
    /// Rolls whose die's centre went below the floor's top face at some step (`roll::Dip`),
    /// whatever their fate. A flag, like the energy gain.
    #[serde(default)]
    pub dipped: u64,
    /// The deepest any point of a die went below the floor's top face, over all rolls, in
    /// nanometres, rounded up (an integer, so that tallies merge exactly, by the maximum).
    #[serde(default)]
    pub deepest_dip_nm: u64,
}

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    pub breadth: u64,
    pub width: u64,
    pub length: u64,
    pub unknown: u64,
}

impl Counts {
    pub fn add(&mut self, o: Outcome) {
        match o {
            Outcome::Breadth => self.breadth += 1,
            Outcome::Width => self.width += 1,
            Outcome::Length => self.length += 1,
            Outcome::Unknown => self.unknown += 1,
        }
    }
}

impl Tally {
    pub fn add(&mut self, r: &RollRecord) {
        self.rolls += 1;
        self.steps += r.steps;
        self.engine_steps += r.engine_steps;
        self.energy_gain += r.energy_gain as u64;
        self.dipped += r.dip.dipped() as u64;
        self.deepest_dip_nm = self.deepest_dip_nm.max(nanometres(r.dip.penetration));
        if let Some((step, o)) = r.certified {
            self.certified += 1;
            self.certified_steps += step;
            match r.fate {
                Fate::Settled(Outcome::Unknown) | Fate::Unconverged(Outcome::Unknown) => {
                    self.certified_unknown += 1
                }
                Fate::Settled(s) | Fate::Unconverged(s) => self.certified_wrong += (s != o) as u64,
                Fate::Failed(_) => {}
            }
        }
        match r.fate {
            Fate::Settled(o) => self.counts.add(o),
            Fate::Unconverged(_) => self.unconverged += 1,
            Fate::Failed(f) => *self.failed.entry(f.name().to_string()).or_insert(0) += 1,
        }
    }

    pub fn failed_total(&self) -> u64 {
        self.failed.values().sum()
    }

    pub fn failed_of(&self, f: Failure) -> u64 {
        self.failed.get(f.name()).copied().unwrap_or(0)
    }

    pub fn merge(&mut self, o: &Tally) {
        self.counts.breadth += o.counts.breadth;
        self.counts.width += o.counts.width;
        self.counts.length += o.counts.length;
        self.counts.unknown += o.counts.unknown;
        self.unconverged += o.unconverged;
        for (k, v) in &o.failed {
            *self.failed.entry(k.clone()).or_insert(0) += v;
        }
        self.rolls += o.rolls;
        self.steps += o.steps;
        self.engine_steps += o.engine_steps;
        self.certified += o.certified;
        self.certified_wrong += o.certified_wrong;
        self.certified_unknown += o.certified_unknown;
        self.certified_steps += o.certified_steps;
        self.energy_gain += o.energy_gain;
        self.dipped += o.dipped;
        self.deepest_dip_nm = self.deepest_dip_nm.max(o.deepest_dip_nm);
    }

    /// `deepest_dip_nm` in metres.
    pub fn deepest_dip_m(&self) -> f64 {
        self.deepest_dip_nm as f64 * 1e-9
    }

    pub fn of(records: &[RollRecord]) -> Tally {
        let mut t = Tally::default();
        for r in records {
            t.add(r);
        }
        t
    }
}

/// A depth in whole nanometres, rounded up (0 for none; a NaN never reaches here, as a
/// non-finite state fails the roll before its depth is recorded).
fn nanometres(m: f64) -> u64 {
    if m > 0.0 {
        (m * 1e9).ceil().min(u64::MAX as f64) as u64
    } else {
        0
    }
}

/// Rolls throws `indices` with `threads` threads; records in index order.
/// `progress` is called with the number of rolls finished so far, from any thread.
pub fn run(
    engine: EngineKind,
    scene: &Scene,
    throws: &Throws,
    settle: &Settle,
    indices: std::ops::Range<u64>,
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<RollRecord>, String> {
    let list: Vec<u64> = indices.collect();
    run_indices(engine, scene, throws, settle, &list, threads, progress)
}

/// As `run`, for any list of throw indices (a shard, a chunk of a checkpointed run).
pub fn run_indices(
    engine: EngineKind,
    scene: &Scene,
    throws: &Throws,
    settle: &Settle,
    indices: &[u64],
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<RollRecord>, String> {
    // Fail early, once, if the engine cannot be built for this scene.
    new_engine(engine, scene)?;
    let pool = pool(threads)?;
    let done = std::sync::atomic::AtomicU64::new(0);
    let records = pool.install(|| {
        indices
            .par_iter()
            .map(|&i| {
                let throw = throws.get(i);
                let r =
                    WORLD.with(|w| roll_one(&mut w.borrow_mut(), engine, scene, &throw, settle));
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(n);
                r
            })
            .collect()
    });
    Ok(records)
}

/// A pool per thread count, kept for the process: its threads, and the worlds they keep, live
/// from one batch (or chunk) to the next.
fn pool(threads: usize) -> Result<std::sync::Arc<rayon::ThreadPool>, String> {
    static POOLS: Mutex<Vec<(usize, std::sync::Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let mut pools = POOLS.lock().map_err(|e| e.to_string())?;
    if let Some((_, p)) = pools.iter().find(|(t, _)| *t == threads) {
        return Ok(p.clone());
    }
    let p = std::sync::Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?,
    );
    pools.push((threads, p.clone()));
    Ok(p)
}

/// Each worker thread's world, reused while the engine and scene stay the same.
struct World {
    kind: EngineKind,
    scene: Scene,
    engine: Box<dyn Engine>,
}

thread_local! {
    static WORLD: RefCell<Option<World>> = const { RefCell::new(None) };
}

/// One roll that cannot take the batch down: an engine panic is caught, counted as an engine
/// failure, and the thread's world is rebuilt for the next throw.
fn roll_one(
    world: &mut Option<World>,
    kind: EngineKind,
    scene: &Scene,
    throw: &crate::throws::Throw,
    settle: &Settle,
) -> RollRecord {
    if !matches!(world, Some(w) if w.kind == kind && w.scene == *scene) {
        *world = new_engine(kind, scene).ok().map(|engine| World {
            kind,
            scene: scene.clone(),
            engine,
        });
    }
    let failed = RollRecord {
        throw: *throw,
        fate: Fate::Failed(Failure::Engine),
        steps: 0,
        engine_steps: 0,
        certified: None,
        energy_gain: false,
        dip: Default::default(),
    };
    let Some(w) = world.as_mut() else {
        return failed;
    };
    match catch_unwind(AssertUnwindSafe(|| {
        roll(w.engine.as_mut(), scene, throw, settle)
    })) {
        Ok(r) => r,
        Err(_) => {
            *world = None;
            failed
        }
    }
}
