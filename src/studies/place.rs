//! Where a study runs and what it tells its caller: the output directory and cells, its
//! threads and share of the chunks (`Place`), its log, progress and stop flag (`Hooks`), and
//! what the caller prints when it is done (`Done`). Every study's outputs (`studies::outputs`,
//! `studies::fit::outputs`) are written against these, which import neither.

use super::study::{Progress, Study};
use crate::error::{Error, Field, Result};
use crate::run::io::Output;
use crate::run::runner::{ChunkShare, Runner};
use crate::run::slurm::Layout;
use crate::run::stop::Stop;
use serde::Serialize;
use std::path::PathBuf;

/// Where and how a study runs: its threads, its share of the chunks, where its outputs and
/// cells go, what it prints.
#[derive(Clone, Debug)]
pub struct Place {
    /// The output directory. `crosscheck` writes none.
    pub out: PathBuf,
    /// Where the cells are kept (a directory per cell), if anywhere.
    pub checkpoint: Option<PathBuf>,
    /// Worker threads, at least 1.
    pub threads: usize,
    /// All the chunks; a cluster task's share; none (the finishing job, or a dry run).
    pub share: ChunkShare,
    /// Print the JSON result instead of the report.
    pub json: bool,
    /// The command line the report names as its own.
    pub command_line: String,
}

/// What the caller hears while a study runs: its log lines, its progress (done and in all, in
/// the unit `Hooks::unit` gives), and the stop flag it is stopped by.
pub struct Hooks<'a> {
    /// A line of the log (a cell, a row, the plan).
    pub log: &'a (dyn Fn(&str) + Sync),
    /// A line of the result, printed as it is made (on the command line's stdout): `bench`'s
    /// rows, each a measurement minutes apart. Every other study's result is its `Done`.
    pub print: &'a (dyn Fn(&str) + Sync),
    /// Progress: done and in all.
    pub progress: Progress<'a>,
    /// Checked before every roll.
    pub stop: Stop,
}

/// What a study's caller prints when it is done.
#[derive(Debug, Default)]
pub struct Done {
    /// For stdout: the report, or the JSON result.
    pub stdout: String,
    /// For stderr: what was written where (a field it names typed, as in `Error::Field`).
    pub note: Option<crate::error::Text>,
    /// Stopped before the end, and what was kept: the caller ends with its own exit code.
    pub interrupted: Option<String>,
    /// Ended, its result printed, but failed (a die none of whose rolls came to rest on a
    /// face): the caller prints its output, then ends as a failed run, saying this.
    pub failed: Option<String>,
}

impl Place {
    /// Where a study of a cluster run writes, on every task and in the finishing job alike:
    /// its outputs into the run's directory, its cells under its `checkpoint/`.
    pub fn cluster(
        lay: &Layout,
        threads: usize,
        json: bool,
        share: ChunkShare,
        command_line: &str,
    ) -> Place {
        Place {
            out: lay.dir.clone(),
            checkpoint: Some(lay.cells()),
            threads,
            share,
            json,
            command_line: command_line.to_string(),
        }
    }

    /// A cluster task's share or a dry run: its tallies are partial, for no report.
    pub(crate) fn partial(&self) -> bool {
        self.share.is_partial()
    }

    /// How the study's cells run: these threads, its share, stopped by `stop`, telling
    /// `progress` the rolls made in the current run.
    pub(crate) fn study<'a>(&self, stop: &Stop, progress: &'a (dyn Fn(u64) + Sync)) -> Study<'a> {
        Study {
            runner: Runner::new(self.threads, stop.clone())
                .with_share(self.share.clone())
                .with_progress(progress),
            checkpoint: self.checkpoint.clone(),
        }
    }

    /// Creates the output directory and checks that `files` can be written in it.
    pub(crate) fn outputs(&self, files: &[&'static str]) -> Result<Outputs> {
        std::fs::create_dir_all(&self.out).map_err(|e| {
            Error::field(
                Field::Out,
                self.out.display(),
                format!("cannot create it ({e})"),
            )
        })?;
        // A report.md is read in a browser too: report.html beside it (`report::html`).
        let html = files.contains(&"report.md").then_some("report.html");
        files
            .iter()
            .chain(html.iter())
            .map(|f| Ok((*f, Output::check(&self.out.join(f))?)))
            .collect::<Result<_>>()
            .map(Outputs)
    }

    /// What a study stopped before its end says (every study alike, [`interrupted`]): its
    /// cells are kept in its checkpoint.
    pub(crate) fn interrupted(&self) -> Done {
        interrupted(self.checkpoint.as_deref())
    }

    /// The JSON, or the report, to print; the note that says what was written.
    pub(crate) fn done(&self, json: &str, report: &str, file: &str) -> Done {
        Done {
            stdout: format!("{}\n", if self.json { json } else { report }),
            note: (!self.json).then(|| {
                format!("wrote {}/{file}, report.md and figures", self.out.display()).into()
            }),
            ..Done::default()
        }
    }
}

/// What a study stopped before its end says, every study alike: where what was rolled is kept
/// (`kept`), to be continued by the same command, or that nothing was written.
pub(crate) fn interrupted(kept: Option<&std::path::Path>) -> Done {
    Done {
        interrupted: Some(crate::run::stop::interrupted(&match kept {
            Some(d) => crate::run::stop::Kept::Dir(d),
            None => crate::run::stop::Kept::Nothing(None),
        })),
        ..Done::default()
    }
}

/// A stop request met where no roll is kept (a fit's estimate) ends the study as one met
/// between rolls does: with nothing.
pub(crate) fn unless_stopped<T>(r: Result<Option<T>>) -> Result<Option<T>> {
    match r {
        Err(Error::Stopped) => Ok(None),
        r => r,
    }
}

/// A study's output files, checked writable before it rolls, each written by its name.
pub(crate) struct Outputs(Vec<(&'static str, Output)>);

impl Outputs {
    /// Writes `bytes` as the file `name` (one the study declared), whole or not at all; a
    /// `report.md` also as `report.html`, its figures (written before it) inlined.
    pub(crate) fn write(&self, name: &str, bytes: &[u8]) -> Result<()> {
        let out = self.output(name)?;
        out.write(bytes)?;
        if name == "report.md" {
            let dir = out.path.parent().unwrap_or(std::path::Path::new("."));
            let html = crate::report::html::page(&String::from_utf8_lossy(bytes), dir);
            self.output("report.html")?.write(html.as_bytes())?;
        }
        Ok(())
    }

    fn output(&self, name: &str) -> Result<&Output> {
        self.0
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, o)| o)
            .ok_or_else(|| Error::failed(format!("{name}: not among the study's outputs")))
    }
}

pub(crate) fn to_json<T: Serialize>(v: &T) -> Result<String> {
    serde_json::to_string_pretty(v).map_err(|e| Error::failed(e.to_string()))
}

/// Whether a claim refuses a Slurm run's directory (its tasks and finishing job write there).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Claimant {
    /// A command run here, which has not yet looked: a Slurm run's directory is refused.
    Here,
    /// Settled by the caller: the Slurm run itself, or a run here whose [`Place`] was made
    /// only after its maker refused a Slurm run's directory (`cli::study::local`).
    Checked,
}

/// Claims `dir` for `command` run with `identity` (`run::owner`): refused if another command
/// or another run owns it (and, for a run here, if a Slurm run does). The one place a
/// directory is claimed, for every command that writes an `--out`.
pub fn claim<T: Serialize + ?Sized>(
    dir: &std::path::Path,
    command: &str,
    identity: &T,
    by: Claimant,
) -> Result<()> {
    let identity = serde_json::to_value(identity).map_err(|e| Error::failed(e.to_string()))?;
    if by == Claimant::Here {
        crate::run::owner::refuse_cluster_run(dir)?;
    }
    crate::run::owner::claim(dir, command, &identity)
}
