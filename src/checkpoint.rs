//! Never lose a run. A long batch is rolled in chunks; with a checkpoint directory each finished
//! chunk's records are written there atomically (a temporary file, then a rename), so a run
//! killed at any moment resumes from its last whole chunk. Every throw is a pure function of
//! (configuration, seed, index), so the resumed result is bit-identical to an uninterrupted
//! one. A stop request (Ctrl-C) is honoured between chunks.

use crate::batch::{self, Tally};
use crate::engine::EngineKind;
use crate::roll::{RollRecord, Settle};
use crate::scene::Scene;
use crate::throws::Throws;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Rolls per chunk: small enough that Ctrl-C answers within a second or two, large enough
/// that a chunk file per chunk costs nothing.
pub const CHUNK: usize = 1000;

/// Set by the Ctrl-C handler; checked between chunks.
pub static STOP: AtomicBool = AtomicBool::new(false);

pub fn stop_requested() -> bool {
    STOP.load(Ordering::SeqCst)
}

/// Writes a whole file or nothing: a temporary file beside it, then a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

fn chunk_path(dir: &Path, first: u64, len: usize) -> PathBuf {
    dir.join(format!("chunk-{first:012}-{len}.json"))
}

/// The throws of a run or of one shard: indices k, k + n, k + 2n, … below `end`, generated
/// chunk by chunk so that a run of any size holds one chunk's indices at a time.
#[derive(Clone, Copy, Debug)]
pub struct Indices {
    pub k: u64,
    pub n: u64,
    pub end: u64,
}

impl Indices {
    pub fn all(end: u64) -> Indices {
        Indices { k: 0, n: 1, end }
    }

    pub fn len(&self) -> u64 {
        if self.k >= self.end {
            0
        } else {
            (self.end - self.k).div_ceil(self.n)
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `c`-th chunk of at most `CHUNK` indices.
    fn chunk(&self, c: u64) -> Vec<u64> {
        let first = c * CHUNK as u64;
        let last = (first + CHUNK as u64).min(self.len());
        (first..last).map(|j| self.k + j * self.n).collect()
    }
}

/// The outcome of a chunked run: the exact tally of the rolls made, and whether all were.
pub struct Chunked {
    pub tally: Tally,
    pub complete: bool,
    /// Rolls taken from the checkpoint rather than rolled now.
    pub resumed: u64,
}

/// Rolls `indices` chunk by chunk, reading finished chunks from `dir` and writing new ones
/// there; each chunk's records go to `sink` in index order and are then dropped, so memory
/// stays flat however many rolls. Stops early (complete = false) if a stop is requested.
#[allow(clippy::too_many_arguments)]
pub fn run(
    engine: EngineKind,
    scene: &Scene,
    throws: &Throws,
    settle: &Settle,
    indices: Indices,
    threads: usize,
    dir: Option<&Path>,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn FnMut(&[RollRecord]) -> Result<(), String>,
) -> Result<Chunked, String> {
    let mut tally = Tally::default();
    let mut resumed = 0;
    for c in 0..indices.len().div_ceil(CHUNK as u64) {
        let chunk = indices.chunk(c);
        let chunk = &chunk[..];
        if stop_requested() {
            return Ok(Chunked {
                tally,
                complete: false,
                resumed,
            });
        }
        let path = dir.map(|d| chunk_path(d, chunk[0], chunk.len()));
        if let Some(p) = path.as_ref().filter(|p| p.exists()) {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            let recs: Vec<RollRecord> = serde_json::from_str(&text)
                .map_err(|e| format!("{}: not a chunk of this run ({e})", p.display()))?;
            let ok = recs.len() == chunk.len()
                && recs.iter().zip(chunk).all(|(r, &i)| r.throw.index == i);
            if !ok {
                return Err(format!("{}: its throws are not this chunk's", p.display()));
            }
            resumed += recs.len() as u64;
            recs.iter().for_each(|r| tally.add(r));
            sink(&recs)?;
            progress(tally.rolls);
            continue;
        }
        let base = tally.rolls;
        let recs = batch::run_indices(engine, scene, throws, settle, chunk, threads, &|n| {
            progress(base + n)
        })?;
        if let Some(p) = &path {
            let json = serde_json::to_string(&recs).map_err(|e| e.to_string())?;
            write_atomic(p, json.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
        }
        recs.iter().for_each(|r| tally.add(r));
        sink(&recs)?;
    }
    Ok(Chunked {
        tally,
        complete: true,
        resumed,
    })
}
