//! Never lose a run. A run is rolled in chunks; with a checkpoint directory each finished
//! chunk's records are written there atomically, bound to the run by its specification's key,
//! so a run killed at any moment resumes from its last whole chunk, and a chunk of another run
//! is never counted. Every throw is a pure function of (specification, index), so the resumed
//! result is bit-identical to an uninterrupted one. A stop request is honoured before every
//! roll: what was rolled is kept.

use crate::error::{Error, Result};
use crate::run::batch::{self, threads};
use crate::run::cputime::process_cpu_seconds;
use crate::run::io::write_atomic;
use crate::run::lock::lock;
use crate::run::spec::RunSpec;
use crate::run::stop::Stop;
use crate::run::tally::Tally;
use crate::sim::roll::RollRecord;
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Rolls per chunk: a chunk file per 1,000 rolls costs nothing.
pub const CHUNK_ROLLS: u64 = 1000;

/// How runs are carried out: threads, stop requests, progress. Nothing here changes a result.
#[derive(Clone)]
pub struct Runner<'a> {
    /// Worker threads, at least 1.
    pub threads: usize,
    /// Checked before every roll.
    pub stop: Stop,
    /// Called with the rolls finished so far in the current run, from any thread.
    pub progress: &'a (dyn Fn(u64) + Sync),
    /// Which chunks this process rolls: all of them, except on a cluster.
    pub share: ChunkShare,
    /// A stage's line of progress from work that rolls nothing (a fit's estimate).
    pub say: &'a (dyn Fn(&str) + Sync),
}

/// Which of its runs' chunks a process rolls. On one machine, all. On a cluster, a study of
/// several cells (`paper`, the sweeps, `crosscheck`) is split chunk by chunk among the tasks of
/// a job array, all writing into the same checkpoint directories; the finishing job then runs
/// the study once more and finds every chunk there, so its counts are those of one machine.
#[derive(Clone, Debug, Default)]
pub enum ChunkShare {
    /// Roll every chunk not already in the checkpoint.
    #[default]
    All,
    /// Task `k` of `n`: of the chunks this process meets, counted over all its runs in the
    /// order it meets them (a study's order does not depend on its results), the j-th is its
    /// own when j mod n = k; it rolls those and passes over the rest. Its tallies are partial,
    /// for the finishing job to assemble, never to report.
    Task {
        /// This task, 0 ≤ k < n.
        k: u64,
        /// How many tasks.
        n: u64,
        /// Chunks met so far.
        met: Arc<AtomicU64>,
    },
    /// Roll nothing: every chunk must be in the checkpoint already (the finishing job of a
    /// run split among `n` tasks). The first chunk missing or damaged is kept, with the task
    /// that rolls it (counted as [`ChunkShare::Task`] counts), for the finishing job to name.
    Assemble {
        /// How many tasks rolled the chunks.
        n: u64,
        /// Chunks met so far.
        met: Arc<AtomicU64>,
        /// The first chunk missing or damaged: its task, and why.
        lacking: Arc<std::sync::Mutex<Option<(u64, String)>>>,
    },
    /// Roll and read nothing: every run ends at once, incomplete. A study run so checks its
    /// arguments and stops at its first cell (`dicephys slurm` does this before submitting).
    DryRun,
}

impl ChunkShare {
    /// Task `k` of `n`.
    pub fn task(k: u64, n: u64) -> ChunkShare {
        ChunkShare::Task {
            k,
            n,
            met: Arc::new(AtomicU64::new(0)),
        }
    }

    /// The finishing job of a run split among `n` tasks.
    pub fn assemble(n: u64) -> ChunkShare {
        ChunkShare::Assemble {
            n: n.max(1),
            met: Arc::new(AtomicU64::new(0)),
            lacking: Arc::default(),
        }
    }

    /// The tasks the run is split among (1 when it is not split).
    pub fn tasks(&self) -> u64 {
        match self {
            ChunkShare::Task { n, .. } | ChunkShare::Assemble { n, .. } => *n,
            _ => 1,
        }
    }

    /// The finishing job's first chunk missing or damaged: the task that rolls it, and why.
    pub fn lacking(&self) -> Option<(u64, String)> {
        match self {
            ChunkShare::Assemble { lacking, .. } => lacking.lock().ok()?.clone(),
            _ => None,
        }
    }

    /// Whether this process takes the next chunk it meets, and the task that rolls it.
    fn take_next(&self) -> (bool, u64) {
        match self {
            ChunkShare::Task { k, n, met } => {
                let j = met.fetch_add(1, Ordering::Relaxed) % n;
                (j == *k, j)
            }
            ChunkShare::Assemble { n, met, .. } => (true, met.fetch_add(1, Ordering::Relaxed) % n),
            _ => (true, 0),
        }
    }

    /// The finishing job's refusal of a chunk missing or damaged (rolled by task `task`).
    fn lack(&self, task: u64, why: String) -> Error {
        if let ChunkShare::Assemble { lacking, .. } = self {
            if let Ok(mut l) = lacking.lock() {
                l.get_or_insert((task, why.clone()));
            }
        }
        Error::failed(format!("{why} (task {task} rolls it)"))
    }

    /// True for a task's share or a dry run: their tallies are partial by design, for no
    /// report.
    pub fn is_partial(&self) -> bool {
        matches!(self, ChunkShare::Task { .. } | ChunkShare::DryRun)
    }
}

/// What a run rolled: the exact tally of the rolls made, and whether all were.
#[derive(Clone, Debug)]
pub struct Rolled {
    /// The rolls made (or read back from the checkpoint).
    pub tally: Tally,
    /// False if a stop request ended the run early.
    pub complete: bool,
    /// Rolls read back from the checkpoint rather than rolled now.
    pub resumed: u64,
    /// CPU seconds the resumed rolls took when they were rolled (stored with their chunks), so
    /// that a resumed run's cost is the sum over its segments.
    pub resumed_cpu_s: f64,
    /// Wall-clock seconds the resumed rolls took when they were rolled.
    pub resumed_wall_s: f64,
}

/// One chunk file, `chunk-FIRST-LEN.json`: the run's key, what the chunk cost, and its rolls
/// packed ([`crate::run::pack`], format `rolls-v2`, or an older `rolls-v1`, in base64), under a checksum
/// ([`crate::run::seal`]). A chunk of the JSON records an older dicephys wrote has no
/// checksum: it is read as damaged, named, and rolled again.
#[derive(Serialize, Deserialize)]
struct ChunkFile {
    key: String,
    cpu_s: f64,
    wall_s: f64,
    format: String,
    rolls: String,
}

/// A chunk read back: what it cost, and its records.
struct Chunked {
    cpu_s: f64,
    wall_s: f64,
    records: Vec<RollRecord>,
}

impl<'a> Runner<'a> {
    /// A runner on `threads` threads (0: one per core), no progress shown.
    pub fn new(threads_asked: usize, stop: Stop) -> Runner<'static> {
        Runner {
            threads: threads(threads_asked),
            stop,
            progress: &|_| {},
            share: ChunkShare::All,
            say: &|_| {},
        }
    }

    /// The same runner, saying its stages' lines to `say`.
    pub fn with_say(self, say: &'a (dyn Fn(&str) + Sync)) -> Runner<'a> {
        Runner { say, ..self }
    }

    /// What a computation between rolls hears: this runner's stop flag and stage lines.
    pub fn watch(&self) -> crate::run::stop::Watch<'_> {
        crate::run::stop::Watch {
            stop: &self.stop,
            say: self.say,
        }
    }

    /// Runs `f` in this runner's pool of `threads` threads, so that whatever it does in
    /// parallel (a fit's profiles, bootstrap, leave-one-out) uses those threads and no others.
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> Result<R> {
        Ok(crate::run::batch::pool(self.threads)?.install(f))
    }

    /// The same runner, rolling only its share of the chunks.
    pub fn with_share(self, share: ChunkShare) -> Runner<'a> {
        Runner { share, ..self }
    }

    /// Opens a cell's checkpoint directory for `spec` (see [`Checkpoint::open_fresh`]). A
    /// task of a cluster run shares the directory with the other tasks: it takes a lock of its
    /// own, and refuses, rather than empties, a directory holding another run.
    pub fn open_cell(&self, dir: &Path, spec: &RunSpec) -> Result<Checkpoint> {
        match &self.share {
            ChunkShare::Task { k, .. } => Checkpoint::open_as(dir, spec, &format!("lock-task-{k}")),
            _ => Checkpoint::open_fresh(dir, spec),
        }
    }

    /// The same runner, reporting progress to `progress`.
    pub fn with_progress<'b>(&self, progress: &'b (dyn Fn(u64) + Sync)) -> Runner<'b>
    where
        'a: 'b,
    {
        Runner {
            threads: self.threads,
            stop: self.stop.clone(),
            progress,
            share: self.share.clone(),
            say: self.say,
        }
    }

    /// Rolls the run's throws chunk by chunk, reading finished chunks from `checkpoint` and
    /// writing new ones there; each chunk's records go to `sink` in index order and are then
    /// dropped, so memory stays flat however many rolls. Ends early (complete = false) on a
    /// stop request, with every roll made so far counted. A cluster task passes over the
    /// chunks that are not its own (and is complete when its own are done); the finishing
    /// job rolls nothing, and a chunk missing from the checkpoint is an error for it.
    pub fn run(
        &self,
        spec: &RunSpec,
        checkpoint: Option<&Checkpoint>,
        sink: &mut dyn FnMut(&[RollRecord]) -> Result<()>,
    ) -> Result<Rolled> {
        let all = 0..spec.indices().len().div_ceil(CHUNK_ROLLS);
        self.run_range(spec, checkpoint, all, sink)
    }

    /// `run`, over the chunks in `range` only (chunk c holds the run's throws c·CHUNK_ROLLS
    /// onwards): a run whose `rolls` is a large fixed cap is then one keyed throw stream,
    /// rolled a prefix at a time into one checkpoint whose key does not change as the prefix
    /// grows (`studies::stream::Stream`). `complete` means every chunk in `range` was rolled.
    pub fn run_range(
        &self,
        spec: &RunSpec,
        checkpoint: Option<&Checkpoint>,
        range: std::ops::Range<u64>,
        sink: &mut dyn FnMut(&[RollRecord]) -> Result<()>,
    ) -> Result<Rolled> {
        let indices = spec.indices();
        let end = range.end.min(indices.len().div_ceil(CHUNK_ROLLS));
        let throws = spec.throws.source(
            spec.rolls
                .min(end.saturating_mul(CHUNK_ROLLS) * indices.n.max(1)),
        );
        let key = spec.key();
        let sides = spec.scene.die.counts_sides();
        let mut done = Rolled {
            tally: Tally::default(),
            complete: false,
            resumed: 0,
            resumed_cpu_s: 0.0,
            resumed_wall_s: 0.0,
        };
        if let ChunkShare::DryRun = self.share {
            return Ok(done);
        }
        for c in range.start..end {
            let chunk = indices.chunk(c, CHUNK_ROLLS);
            let path = checkpoint.map(|d| d.chunk_path(chunk[0], chunk.len()));
            let (mine, task) = self.share.take_next();
            if !mine {
                continue;
            }
            let assemble = matches!(self.share, ChunkShare::Assemble { .. });
            if let Some(p) = path.as_ref().filter(|p| p.exists()) {
                match read_chunk(p, &key, &chunk, &throws) {
                    Ok(file) => {
                        done.resumed += file.records.len() as u64;
                        done.resumed_cpu_s += file.cpu_s;
                        done.resumed_wall_s += file.wall_s;
                        file.records
                            .iter()
                            .try_for_each(|r| done.tally.add(r, sides))?;
                        sink(&file.records)?;
                        (self.progress)(done.tally.rolls);
                        continue;
                    }
                    // Every throw is a function of (spec, index): a damaged chunk is rolled
                    // again, and replaced, rather than counted.
                    Err(Chunk::Damaged(why)) if !assemble => {
                        eprintln!("dicephys: {}: {why}; rolling its throws again", p.display());
                    }
                    Err(Chunk::Damaged(why)) => {
                        return Err(self.share.lack(task, format!("{}: {why}", p.display())))
                    }
                    Err(Chunk::Refused(e)) => return Err(e),
                }
            } else if assemble {
                let first = chunk[0];
                return Err(self.share.lack(
                    task,
                    format!(
                        "{}: throws {first}.. ({} of them) were never rolled",
                        path.map_or_else(|| "no checkpoint".into(), |p| p.display().to_string()),
                        chunk.len()
                    ),
                ));
            }
            if self.stop.requested() {
                return Ok(done);
            }
            let base = done.tally.rolls;
            let (cpu, wall) = (process_cpu_seconds(), std::time::Instant::now());
            let job = batch::Job {
                engine: spec.engine,
                scene: &spec.scene,
                throws: &throws,
                cfg: &spec.roll,
            };
            let recs = batch::run_indices(&job, &chunk, self.threads, &self.stop, &|n| {
                (self.progress)(base + n)
            })?;
            let whole = recs.len() == chunk.len();
            if let (Some(p), true) = (&path, whole) {
                let file = ChunkFile {
                    key: key.clone(),
                    cpu_s: process_cpu_seconds() - cpu,
                    wall_s: wall.elapsed().as_secs_f64(),
                    format: crate::run::pack::FORMAT.into(),
                    rolls: crate::run::pack::base64(&crate::run::pack::pack(&recs)),
                };
                let json = crate::run::seal::to_string(&file, false)?;
                write_atomic(p, json.as_bytes())?;
                recs.iter().try_for_each(|r| done.tally.add(r, sides))?;
                sink(&recs)?;
            } else {
                recs.iter().try_for_each(|r| done.tally.add(r, sides))?;
                sink(&recs)?;
            }
            if !whole {
                return Ok(done);
            }
        }
        done.complete = true;
        Ok(done)
    }
}

/// Why a stored chunk is not read.
enum Chunk {
    /// Damaged (or of a dicephys before checksums): rolled again where it can be.
    Damaged(String),
    /// Whole, but another run's, or of other throws: an error.
    Refused(Error),
}

/// The chunk at `p` of the run keyed `key`, holding the throws `chunk`: its checksum checked
/// ([`crate::run::seal`]), then its key and throws.
fn read_chunk(
    p: &Path,
    key: &str,
    chunk: &[u64],
    throws: &crate::model::throws::Throws,
) -> std::result::Result<Chunked, Chunk> {
    use crate::run::seal::{open, Broken};
    let text = match std::fs::read(p) {
        Ok(b) => String::from_utf8(b).map_err(|_| Chunk::Damaged("damaged: not UTF-8".into()))?,
        Err(e) => return Err(Chunk::Refused(Error::io(p, e))),
    };
    let file: ChunkFile = open(&text).map_err(|b| match b {
        Broken::Damaged(why) => Chunk::Damaged(why),
        Broken::Shape(why) => Chunk::Refused(Error::Mismatch(format!(
            "{}: not a chunk of this run ({why})",
            p.display()
        ))),
    })?;
    if file.key != key {
        return Err(Chunk::Refused(Error::Mismatch(format!(
            "{}: a chunk of another run (key {}, this run's {key})",
            p.display(),
            file.key
        ))));
    }
    let refuse = |why: String| Chunk::Refused(Error::Mismatch(format!("{}: {why}", p.display())));
    use crate::run::pack::{FORMAT, FORMAT_V1};
    if file.format != FORMAT && file.format != FORMAT_V1 {
        return Err(refuse(format!(
            "format {:?}, not {:?} (a newer dicephys's?)",
            file.format,
            crate::run::pack::FORMAT
        )));
    }
    let records = crate::run::pack::unbase64(&file.rolls)
        .and_then(|b| crate::run::pack::unpack(&b, chunk, throws, &file.format))
        .map_err(|e| refuse(format!("its rolls are not this chunk's ({e})")))?;
    Ok(Chunked {
        cpu_s: file.cpu_s,
        wall_s: file.wall_s,
        records,
    })
}

/// A checkpoint directory, held by one run at a time: `spec.json` names the run, `lock` its
/// holder while it runs, and `chunk-*.json` its finished chunks.
#[derive(Debug)]
pub struct Checkpoint {
    /// The directory.
    pub dir: PathBuf,
    /// Held (an advisory lock the system drops when the process ends, however it ends).
    _lock: File,
}

/// A checkpoint's `spec.json`.
#[derive(Serialize, Deserialize)]
struct Stored {
    key: String,
    spec: RunSpec,
}

impl Checkpoint {
    /// Opens `dir` for `spec`: creates it with the specification in it, or checks that it
    /// holds this very run; and takes its lock, or says who holds it.
    pub fn open(dir: &Path, spec: &RunSpec) -> Result<Checkpoint> {
        Checkpoint::open_as(dir, spec, "lock")
    }

    /// [`Checkpoint::open`] with the lock file `lock_name`: the tasks of a cluster run each
    /// hold their own on a directory they share, writing chunks no other task writes.
    fn open_as(dir: &Path, spec: &RunSpec, lock_name: &str) -> Result<Checkpoint> {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::Invalid(format!(
                "checkpoint {}: cannot create it ({e})",
                dir.display()
            ))
        })?;
        crate::run::owner::check_unowned(dir)?;
        let lock = checkpoint_lock(dir, lock_name)?;
        crate::run::io::clean_temporaries(dir);
        // Written when absent, then read back: tasks of a cluster run that open a new cell at
        // the same moment each write the same whole file (an atomic rename), and the one
        // read back decides.
        let file = dir.join("spec.json");
        if !file.exists() {
            let stored = Stored {
                key: spec.key(),
                spec: spec.clone(),
            };
            let json =
                serde_json::to_string_pretty(&stored).map_err(|e| Error::failed(e.to_string()))?;
            write_atomic(&file, json.as_bytes())?;
        }
        if Checkpoint::spec_in(dir)? != *spec {
            return Err(Error::Mismatch(format!(
                "checkpoint {}: it holds another run; resume that run, or use a new directory",
                dir.display()
            )));
        }
        Ok(Checkpoint {
            dir: dir.to_path_buf(),
            _lock: lock,
        })
    }

    /// Opens `dir` for `spec`, emptying it first if it holds another run (the sweeps' cells,
    /// whose directories are named by their key and rewritten freely).
    /// A directory without a readable `spec.json` (an older version's, or damaged) is emptied
    /// too.
    pub fn open_fresh(dir: &Path, spec: &RunSpec) -> Result<Checkpoint> {
        let ours = Checkpoint::spec_in(dir).is_ok_and(|s| s == *spec);
        if !ours && dir.exists() {
            // Never empty a cell another live process is rolling: its lock says so.
            if dir.join("lock").exists() {
                drop(checkpoint_lock(dir, "lock")?);
            }
            std::fs::remove_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        }
        Checkpoint::open(dir, spec)
    }

    /// The run specification stored in `dir`.
    pub fn spec_in(dir: &Path) -> Result<RunSpec> {
        let file = dir.join("spec.json");
        let text = std::fs::read_to_string(&file).map_err(|e| {
            Error::Invalid(format!(
                "{}: no checkpoint there ({}: {e})",
                dir.display(),
                file.display()
            ))
        })?;
        let stored: Stored = serde_json::from_str(&text)
            .map_err(|e| Error::Invalid(format!("{} is damaged ({e})", file.display())))?;
        Ok(stored.spec)
    }

    fn chunk_path(&self, first: u64, len: usize) -> PathBuf {
        self.dir.join(format!("chunk-{first:012}-{len}.json"))
    }
}

/// The lock file `name` of the checkpoint `dir`, taken (or who holds it, said).
fn checkpoint_lock(dir: &Path, name: &str) -> Result<File> {
    lock(&dir.join(name), &format!("checkpoint {}", dir.display()))
}
