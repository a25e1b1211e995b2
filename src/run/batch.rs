//! Many rolls in parallel, and their tally. Each thread keeps one world and reuses it; every
//! throw is a pure function of its index, and the tally is exact integers, so the result is
//! the same for any thread count or order.

use crate::engine::{new_engine, Engine, EngineKind};
use crate::error::{Error, Result};
use crate::model::scene::Scene;
use crate::model::throws::Throws;
use crate::run::stop::Stop;
use crate::sim::roll::{roll_or_abandon, Failure, Fate, RollConfig, RollRecord};
use rayon::prelude::*;
use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

/// What every roll of a batch shares.
#[derive(Clone, Copy)]
pub struct Job<'a> {
    /// The engine.
    pub engine: EngineKind,
    /// The scene.
    pub scene: &'a Scene,
    /// Where the throws come from.
    pub throws: &'a Throws,
    /// How each roll is carried out and ended.
    pub cfg: &'a RollConfig,
}

/// Worker threads: 0 means one per core.
pub fn threads(asked: usize) -> usize {
    if asked == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        asked
    }
}

/// The most worker threads a run takes.
pub const MAX_THREADS: usize = 1024;

/// Worker threads asked (0: one per core), checked and resolved: what every front end calls.
pub fn checked_threads(asked: usize) -> Result<usize> {
    if asked > MAX_THREADS {
        return Err(Error::field(
            crate::error::Field::Threads,
            asked,
            format!("at most {MAX_THREADS}"),
        ));
    }
    Ok(threads(asked))
}

/// Rolls throws `indices` with `threads` threads (0: one per core), no stop; records in index
/// order.
pub fn run(
    engine: EngineKind,
    scene: &Scene,
    throws: &Throws,
    cfg: &RollConfig,
    indices: std::ops::Range<u64>,
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<RollRecord>> {
    let list: Vec<u64> = indices.collect();
    let job = Job {
        engine,
        scene,
        throws,
        cfg,
    };
    let threads = self::threads(threads);
    run_indices(&job, &list, threads, &Stop::new(), progress)
}

/// Rolls throws `indices` with `threads` threads; records in index order. A stop request is
/// checked before each roll: the rolls not yet begun are left out (so fewer records than
/// indices means the batch was stopped). `progress` is called with the number of rolls
/// finished so far, from any thread.
pub fn run_indices(
    job: &Job,
    indices: &[u64],
    threads: usize,
    stop: &Stop,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<RollRecord>> {
    let Job {
        engine,
        scene,
        throws,
        cfg,
    } = *job;
    // Fail early, once, if the engine cannot be built for this scene.
    new_engine(engine, scene)?;
    let pool = pool(threads)?;
    let done = std::sync::atomic::AtomicU64::new(0);
    let records: Vec<Option<RollRecord>> = pool.install(|| {
        indices
            .par_iter()
            .map(|&i| {
                if stop.requested() {
                    return None;
                }
                let throw = throws.get(i);
                let r = WORLD
                    .with(|w| roll_one(&mut w.borrow_mut(), engine, scene, &throw, cfg, stop))?;
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(n);
                Some(r)
            })
            .collect()
    });
    Ok(records.into_iter().flatten().collect())
}

/// A pool per thread count, kept for the process: its threads, and the worlds they keep, live
/// from one batch (or chunk) to the next.
pub(crate) fn pool(threads: usize) -> Result<std::sync::Arc<rayon::ThreadPool>> {
    static POOLS: Mutex<Vec<(usize, std::sync::Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, p)) = pools.iter().find(|(t, _)| *t == threads) {
        return Ok(p.clone());
    }
    let p = std::sync::Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| Error::failed(format!("cannot start {threads} threads ({e})")))?,
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
/// failure, and the thread's world is rebuilt for the next throw. `None`: abandoned midway by a
/// stop request (left out, as a roll not begun is).
fn roll_one(
    world: &mut Option<World>,
    kind: EngineKind,
    scene: &Scene,
    throw: &crate::model::throws::Throw,
    cfg: &RollConfig,
    stop: &Stop,
) -> Option<RollRecord> {
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
        return Some(failed);
    };
    let abandon = || stop.requested();
    match catch_unwind(AssertUnwindSafe(|| {
        roll_or_abandon(w.engine.as_mut(), scene, throw, cfg, &abandon)
    })) {
        Ok(r) => r,
        Err(_) => {
            *world = None;
            Some(failed)
        }
    }
}
