//! One method's rolls as a keyed throw stream: the first N throws of one run whose `rolls`
//! is a fixed cap ([`STREAM_ROLLS`]), so its key and checkpoint stay put as rounds are added,
//! extended chunk range by chunk range (`Runner::run_range`), with each throw's outcome kept
//! for the paired error of a departure (`super::departure`).

use super::study::Study;
use super::sweep::{cell_spec, Measured};
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::model::block::Side;
use crate::model::scene::Scene;
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::CHUNK_ROLLS;
use crate::run::spec::RunSpec;
use crate::run::tally::Tally;
use crate::sim::roll::{Fate, RollConfig, RollRecord};

/// The `rolls` of a stream's specification: a fixed cap, never rolled whole. A method's rolls
/// are a prefix of this one keyed throw stream, so its checkpoint's key stays the same however
/// many rounds are added, and a cluster could roll chunks ahead of the rounds.
pub const STREAM_ROLLS: u64 = crate::run::spec::MAX_ROLLS;

/// A roll's outcome as the ratio sees it: 1 breadth vertical, 2 width vertical, 0 anything
/// else (length vertical, unknown, unconverged, failed).
fn class(r: &RollRecord) -> u8 {
    match r.fate {
        Fate::Settled(o) => match o.side() {
            Side::Breadth => 1,
            Side::Width => 2,
            _ => 0,
        },
        _ => 0,
    }
}

/// One method's rolls: the first `rolls()` throws of its keyed stream, with each throw's
/// outcome (for the paired error of a departure), the exact tally and the CPU seconds they
/// took (read back with the chunks on a resumed run, so costs stay true).
pub struct Stream {
    /// The specification, its `rolls` the cap `STREAM_ROLLS`.
    pub spec: RunSpec,
    /// Each throw's `class`, in index order.
    pub outcomes: Vec<u8>,
    /// The exact counts of the rolls made.
    pub tally: Tally,
    /// Process CPU seconds they took, all threads.
    pub cpu_s: f64,
}

impl Stream {
    /// The stream of `rolls: STREAM_ROLLS` keyed throws of this method; nothing rolled yet.
    pub fn new(engine: EngineKind, scene: Scene, roll: RollConfig, seed: u64) -> Stream {
        Stream {
            spec: cell_spec(engine, scene, roll, seed, STREAM_ROLLS),
            outcomes: Vec::new(),
            tally: Tally::default(),
            cpu_s: 0.0,
        }
    }

    /// Rolls made.
    pub fn rolls(&self) -> u64 {
        self.outcomes.len() as u64
    }

    /// The cell's measurement so far.
    pub fn measured(&self) -> Measured {
        Measured {
            tally: self.tally.clone(),
            cpu_s: self.cpu_s,
        }
    }

    /// CPU seconds per roll so far (NaN before any roll).
    pub fn cpu_s_per_roll(&self) -> f64 {
        self.cpu_s / self.rolls() as f64
    }

    /// Rolls the stream on to its first `chunks` chunks (a no-op if it has them), reading
    /// chunks already in the study's checkpoint back instead of rolling them. `progress`
    /// hears the rolls made in this call. A stop request is `Error::Stopped`; every whole
    /// chunk rolled is kept for the next run.
    pub fn extend(
        &mut self,
        chunks: u64,
        study: &Study,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<()> {
        let have = self.rolls() / CHUNK_ROLLS;
        if chunks <= have {
            return Ok(());
        }
        let ck = match &study.checkpoint {
            Some(root) => {
                let dir = root.join(format!("{}-{}", self.spec.engine, self.spec.key()));
                Some(study.runner.open_cell(&dir, &self.spec)?)
            }
            None => None,
        };
        let cpu = process_cpu_seconds();
        let mut outcomes = Vec::new();
        let mut tally = Tally::default();
        let run = study.runner.with_progress(progress).run_range(
            &self.spec,
            ck.as_ref(),
            have..chunks,
            &mut |recs| {
                outcomes.extend(recs.iter().map(class));
                recs.iter().try_for_each(|r| tally.add(r, true))
            },
        )?;
        if !run.complete {
            return Err(Error::Stopped);
        }
        self.outcomes.extend(outcomes);
        self.tally.merge(&tally)?;
        // A chunk read back costs what it cost when rolled (stored with it), not the reading.
        let rolled_now = run.tally.rolls > run.resumed;
        self.cpu_s += run.resumed_cpu_s
            + if rolled_now {
                process_cpu_seconds() - cpu
            } else {
                0.0
            };
        Ok(())
    }

    /// The ratio's per-throw influence on ln(ratio): a_i = [breadth]/p_b − [width]/p_w, whose
    /// mean is 0 and whose variance, 1/p_b + 1/p_w, over N rolls is the ratio's relative
    /// variance (err/ratio)². `None` while either outcome is missing.
    pub(crate) fn influence(&self) -> Option<[f64; 3]> {
        let n = self.rolls() as f64;
        let (b, w) = (
            self.tally.counts.breadth as f64,
            self.tally.counts.width as f64,
        );
        (b > 0.0 && w > 0.0).then(|| [0.0, n / b, -n / w])
    }
}
