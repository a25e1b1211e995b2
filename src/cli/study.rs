//! A study run from the command line: where it writes, its log and progress on stderr, and
//! what it prints. The study, its rendering and its files are the library's
//! (`dicephys::studies::outputs`).

use super::error::{Error, Result};
use super::term::out;
use clap::Args;
use dicephys::report::progress::Progress;
use dicephys::run::runner::ChunkShare;
use dicephys::studies::place::{Done, Hooks, Place};
use dicephys::studies::StudyConfig;
use std::path::Path;
use std::time::Duration;

/// Where a study runs and how it reports: its threads, its directory, JSON or text.
#[derive(Args, Debug, Clone)]
pub struct StudyPlace {
    /// Worker threads.
    #[command(flatten)]
    pub threads: super::args::Threads,
    /// Output directory: the report, its JSON, the figures, and the kept cells the same
    /// command continues from [default: the command's name and -out, e.g. paper-out].
    #[arg(long, value_name = "OUT")]
    pub out: Option<std::path::PathBuf>,
    /// JSON or text.
    #[command(flatten)]
    pub json: super::args::Json,
}

impl StudyPlace {
    /// `cfg` run here, on all its chunks, writing into `--out` or `<command>-out`.
    pub fn local(&self, command: &str, cfg: &StudyConfig) -> Result<Place> {
        let out = self.out.clone();
        let out = out.unwrap_or_else(|| format!("{command}-out").into());
        local(&out, cfg, *self.threads, *self.json)
    }
}

/// `cfg` run here, on all its chunks, writing into `out` (its cells under the directory it
/// names, [`StudyConfig::cells`]). A Slurm run's directory is refused: its tasks and
/// finishing job write there.
pub fn local(out: &Path, cfg: &StudyConfig, threads: usize, json: bool) -> Result<Place> {
    if !out.as_os_str().is_empty() {
        dicephys::run::owner::refuse_cluster_run(out)?;
    }
    Ok(Place {
        out: out.to_path_buf(),
        checkpoint: Some(out.join(cfg.cells())),
        threads: super::args::threads(threads)?,
        share: ChunkShare::All,
        json,
        command_line: super::term::command_line(),
    })
}

/// Where a command run here on all its chunks writes, for a study that keeps no cells of its
/// own: `out` if given (made, and refused if a cluster's run owns it; `fair --out`, `design
/// --out`), else nowhere; its checkpoint, if any (`roll --checkpoint`).
pub fn here(
    out: Option<&Path>,
    checkpoint: Option<std::path::PathBuf>,
    threads: usize,
    json: bool,
) -> Result<Place> {
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::Usage(format!("--out {}: cannot create it ({e})", dir.display()))
        })?;
        dicephys::run::owner::refuse_cluster_run(dir)?;
    }
    Ok(Place {
        out: out.map(Path::to_path_buf).unwrap_or_default(),
        checkpoint,
        threads,
        share: ChunkShare::All,
        json,
        command_line: super::term::command_line(),
    })
}

/// Runs a study, with a bar (or progress lines) and its log on stderr: every command that
/// runs a study, here or as a cluster's task, runs it this way.
pub fn run(cfg: &StudyConfig, place: &Place) -> Result<()> {
    with_hooks(cfg.name(), cfg.unit(), place.json, |hooks| {
        cfg.run(place, hooks)
    })
}

/// How often a command whose stderr is not a terminal says how far it has come:
/// `DICEPHYS_PROGRESS_SECS` seconds, default 30.
pub fn every() -> Duration {
    std::env::var("DICEPHYS_PROGRESS_SECS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .map_or(Duration::from_secs(30), Duration::from_secs_f64)
}

/// Runs a study with its log on stderr (out of the bar's way) and its progress shown, then
/// prints what it says.
fn with_hooks(
    command: &'static str,
    unit: dicephys::report::progress::Unit,
    json: bool,
    run: impl FnOnce(&Hooks) -> dicephys::Result<Done>,
) -> Result<()> {
    let progress = Progress::new(command, unit, true, json, every());
    // A line of the result as it comes (`bench`'s rows, `trace`'s CSV) goes to stdout. The
    // first that cannot be written is kept, and the command ends with it once the study has
    // run (a closed pipe quietly, another failure as one line): no later line is tried, and
    // the log, which would only say what was not printed, falls silent.
    let unwritten: std::sync::Mutex<Option<Error>> = std::sync::Mutex::new(None);
    let failed = || unwritten.lock().map_or(true, |u| u.is_some());
    let log = |l: &str| {
        if !failed() {
            progress.suspend(|| eprintln!("{l}"))
        }
    };
    let set = |done: f64, total: f64| progress.set(done, total);
    let print = |l: &str| {
        if failed() {
            return;
        }
        if let Err(e) = progress.suspend(|| super::term::stdout(&format!("{l}\n"))) {
            if let Ok(mut u) = unwritten.lock() {
                *u = Some(e);
            }
        }
    };
    let done = run(&Hooks {
        log: &log,
        print: &print,
        progress: &set,
        stop: super::term::stop().clone(),
    });
    progress.finish();
    if let Some(e) = unwritten.into_inner().ok().flatten() {
        return Err(e);
    }
    let done = done?;
    out!("{}", done.stdout);
    if let Some(n) = done.note {
        eprintln!("{}", super::error::flags_in(&n));
    }
    match (done.interrupted, done.failed) {
        (Some(m), _) => Err(Error::Interrupted(m)),
        (None, Some(m)) => Err(Error::Run(m)),
        (None, None) => Ok(()),
    }
}
