//! `dicephys slurm`: a run as a Slurm job array and a finishing job that merges it exactly
//! (the scripts: `dicephys::run::slurm`), and `dicephys slurm finish DIR`, the finishing step.
//! `roll` is split into shards of its throws; the studies (`paper`, `crosscheck`, `converge`,
//! `tradeoff`, `stability`, `fit`) chunk by chunk: the plan stores the study's configuration, each
//! task runs the library's study from it with its share (`dicephys slurm task DIR K`), and the
//! finishing job runs it once more. A fit of two passes is two such runs, chained.

use super::crosscheck::CrosscheckArgs;
use super::error::{Error, Result};
use super::fit::FitArgs;
use super::paper::PaperArgs;
use super::roll::RollArgs;
use super::study;
use super::study::StudyPlace;
use super::sweeps::{ConvergeArgs, StabilityArgs, TradeoffArgs};
use super::term::out;
use clap::{Args, Subcommand};
use dicephys::run::slurm::Options;
use dicephys::studies::calibrated::CalibratedStudy;
use dicephys::studies::cluster::{self, Finishing, Job, Staged, Submitted};
use dicephys::studies::fit::{FitStudy, Stage};
use dicephys::studies::StudyConfig;
use std::path::PathBuf;

/// `dicephys slurm`'s arguments.
#[derive(Args, Debug)]
pub struct SlurmArgs {
    #[command(subcommand)]
    pub command: SlurmCommand,
}

/// What `dicephys slurm` runs.
#[derive(Subcommand, Debug)]
pub enum SlurmCommand {
    /// `roll` as a job array: task K of N rolls shard K/N; the finishing job merges them.
    Roll(Box<SlurmRollArgs>),
    /// `fair` as a job array: task K of N rolls shard K/N; the finishing job merges them and
    /// judges the faces (DIR/result.json is `fair --json`'s document, DIR/result.txt its text).
    Fair(Box<SlurmFairArgs>),
    /// `paper` as a job array: the tasks share the cells' chunks; the finishing job writes
    /// the report into --dir. `paper --calibrated` as two chained arrays: every model's first
    /// pass into --dir/first-pass, then every model's second pass into --dir, whose finishing
    /// job rolls any widening passes and the method check and writes calibrated.md.
    // Its --out is --dir on a cluster: refused if given, so not shown.
    #[command(mut_arg("out", |a| a.hide(true)))]
    Paper(Box<SlurmStudyArgs<PaperArgs>>),
    /// `crosscheck` as a job array; the finishing job's comparison is DIR/result.txt.
    Crosscheck(Box<SlurmStudyArgs<CrosscheckArgs>>),
    /// `converge` as a job array; the finishing job writes the study into --dir.
    // Its --out is --dir on a cluster: refused if given, so not shown.
    #[command(mut_arg("out", |a| a.hide(true)))]
    Converge(Box<SlurmStudyArgs<ConvergeArgs>>),
    /// `tradeoff` as a job array; the finishing job writes the study into --dir.
    // Its --out is --dir on a cluster: refused if given, so not shown.
    #[command(mut_arg("out", |a| a.hide(true)))]
    Tradeoff(Box<SlurmStudyArgs<TradeoffArgs>>),
    /// `stability` as a job array; the finishing job writes the study into --dir.
    // Its --out is --dir on a cluster: refused if given, so not shown.
    #[command(mut_arg("out", |a| a.hide(true)))]
    Stability(Box<SlurmStudyArgs<StabilityArgs>>),
    /// `fit` as job arrays: the first pass into --dir/first-pass, then (its box narrowed from
    /// that result) the second into --dir; one array with --no-refine.
    // Its --out is --dir on a cluster: refused if given, so not shown.
    #[command(mut_arg("out", |a| a.hide(true)))]
    Fit(Box<SlurmStudyArgs<FitArgs>>),
    /// The finishing job: check that every task has finished, then merge (roll) or assemble
    /// (the studies) into DIR.
    Finish(FinishArgs),
    /// One array task of a study: its share of the chunks (run by the array script).
    #[command(hide = true)]
    Task(TaskArgs),
}

/// `dicephys slurm <study>`'s arguments: the study's and the job's.
#[derive(Args, Debug)]
pub struct SlurmStudyArgs<T: Args> {
    #[command(flatten)]
    pub study: T,
    #[command(flatten)]
    pub job: JobArgs,
}

/// `dicephys slurm task`'s arguments.
#[derive(Args, Debug)]
pub struct TaskArgs {
    /// The run's directory.
    pub dir: PathBuf,
    /// This task, 0 ≤ K < the run's tasks.
    pub k: u64,
}

/// The scheduler's side: how many tasks, where, which queue.
#[derive(Args, Clone, Debug)]
pub struct JobArgs {
    /// Array tasks (each takes --threads cores, default 1).
    #[arg(long)]
    pub tasks: u64,
    /// The run's directory, on a file system every node shares: scripts, checkpoints,
    /// each task's result, logs, and the merged result.
    #[arg(long, value_name = "DIR")]
    pub dir: PathBuf,
    /// Slurm partition.
    #[arg(long)]
    pub partition: Option<String>,
    /// Each job's time limit, as sbatch takes it (e.g. 1:00:00).
    #[arg(long)]
    pub time: Option<String>,
    /// Slurm account.
    #[arg(long)]
    pub account: Option<String>,
    /// Submit the jobs with sbatch and print their ids (without it: print the scripts).
    #[arg(long)]
    pub submit: bool,
    /// The dicephys binary the jobs run (default: this one), as the nodes see it.
    #[arg(long, value_name = "PATH")]
    pub bin: Option<PathBuf>,
}

/// `dicephys slurm roll`'s arguments: `roll`'s and the job's.
#[derive(Args, Debug)]
pub struct SlurmRollArgs {
    #[command(flatten)]
    pub roll: RollArgs,
    #[command(flatten)]
    pub job: JobArgs,
}

/// `dicephys slurm fair`'s arguments: `roll`'s, the null, and the job's.
#[derive(Args, Debug)]
pub struct SlurmFairArgs {
    #[command(flatten)]
    pub roll: RollArgs,
    /// What fair means, as `fair --null` (uniform, quasi-static, or a target LABEL=P,…).
    #[arg(long, default_value = "uniform", value_parser = super::args::parse_null)]
    pub null: dicephys::studies::fair::Null,
    #[command(flatten)]
    pub job: JobArgs,
}

/// `dicephys slurm finish`'s arguments.
#[derive(Args, Debug)]
pub struct FinishArgs {
    /// The run's directory (as given to `dicephys slurm ... --dir`).
    pub dir: PathBuf,
}

/// Runs `dicephys slurm`.
pub fn run(a: &SlurmArgs) -> Result<()> {
    let (stages, job) = match &a.command {
        SlurmCommand::Finish(f) => return finish(&f.dir),
        SlurmCommand::Task(t) => {
            let (cfg, place) = cluster::task(&t.dir, t.k)?;
            study::run(&cfg, &place)?;
            let tasks = place.share.tasks();
            eprintln!("{}", cluster::mark(&t.dir, t.k, tasks)?);
            return Ok(());
        }
        SlurmCommand::Roll(r) => (vec![roll("roll", &r.roll, None, &r.job)?], &r.job),
        SlurmCommand::Fair(f) => (
            vec![roll("fair", &f.roll, Some(f.null.clone()), &f.job)?],
            &f.job,
        ),
        c => {
            let (cfg, threads, json, given, job) = study_of(c)?;
            if let Some(flag) = given {
                return Err(Error::Usage(format!(
                    "slurm {}: {flag}: the study writes into --dir (its outputs, and its chunks \
                     under --dir/checkpoint)",
                    cfg.name()
                )));
            }
            // A cluster task takes the threads it asks for; "one per core" means one.
            let threads = threads.max(1);
            super::args::threads(threads)?;
            let line = super::term::command_line();
            let s = Submitted {
                config: cfg,
                threads,
                json,
                command_line: &line,
            };
            (cluster::stages(&s, &job.job())?, job)
        }
    };
    if job.submit {
        out!("{}", cluster::submit(&stages)?);
    } else {
        out!("{}", cluster::scripts(&stages)?);
    }
    Ok(())
}

impl JobArgs {
    fn job(&self) -> Job {
        Job {
            tasks: self.tasks,
            dir: self.dir.clone(),
            options: Options {
                partition: self.partition.clone(),
                time: self.time.clone(),
                account: self.account.clone(),
                cpus: 1,
            },
            bin: self.bin.clone(),
        }
    }
}

/// A study's configuration from its flags, and what a cluster run takes of them: its threads,
/// `--json`, the output flag a cluster run sets itself if it was given, and the job.
type Flags<'a> = (StudyConfig, usize, bool, Option<&'static str>, &'a JobArgs);

fn study_of(c: &SlurmCommand) -> Result<Flags<'_>> {
    // A study that runs in a place: its threads, --json, and --out where it was given.
    let placed = |cfg, p: &StudyPlace, job| {
        (
            cfg,
            *p.threads,
            *p.json,
            p.out.is_some().then_some("--out"),
            job,
        )
    };
    let refuse = |flag: &str, why: &str| Err(Error::Usage(format!("slurm {flag}: {why}")));
    Ok(match c {
        SlurmCommand::Paper(a) => {
            let s = &a.study;
            let cfg = if s.calibrated {
                StudyConfig::Calibrated(CalibratedStudy {
                    config: s.calibrated_config(),
                    stage: Stage::Whole,
                })
            } else {
                StudyConfig::Paper(s.config())
            };
            placed(cfg, &s.place, &a.job)
        }
        SlurmCommand::Crosscheck(a) => {
            let s = &a.study;
            if s.run.precision.is_some() {
                return refuse(
                    "crosscheck: --precision",
                    "tasks split a fixed number of rolls; give --rolls (crosscheck \
                     --precision on one machine)",
                );
            }
            let cfg = StudyConfig::Crosscheck(s.config()?);
            let given = s.checkpoint.is_some().then_some("--checkpoint");
            (cfg, *s.run.threads, *s.json, given, &a.job)
        }
        SlurmCommand::Converge(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Converge(s.config());
            placed(cfg, &s.place, &a.job)
        }
        SlurmCommand::Tradeoff(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Tradeoff(s.config()?);
            placed(cfg, &s.place, &a.job)
        }
        SlurmCommand::Stability(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Stability(s.config());
            placed(cfg, &s.place, &a.job)
        }
        SlurmCommand::Fit(a) => {
            let s = &a.study;
            if s.recover.is_some() {
                return refuse(
                    "fit: --recover",
                    "not available through Slurm (fit --recover on one machine)",
                );
            }
            let cfg = StudyConfig::Fit(FitStudy {
                config: s.config()?,
                stage: Stage::Whole,
            });
            placed(cfg, &s.place, &a.job)
        }
        _ => unreachable!("not a study"),
    })
}

/// `slurm roll` (or `slurm fair`, judged against `fair`): its own flags refused, its shards
/// made.
fn roll(
    command: &str,
    r: &RollArgs,
    fair: Option<dicephys::studies::fair::Null>,
    job: &JobArgs,
) -> Result<Staged> {
    let own = |flag: &str, why: &str| Err(Error::Usage(format!("slurm {command}: {flag}: {why}")));
    if r.shard.is_some() {
        return own("--shard", "the tasks are the shards (--tasks N)");
    }
    if r.run.precision.is_some() {
        return own(
            "--precision",
            "tasks split a fixed number of rolls; give --rolls (--precision on one machine)",
        );
    }
    if r.checkpoint.is_some() || r.resume.is_some() {
        return own(
            "--checkpoint/--resume",
            "each task keeps its checkpoint under --dir",
        );
    }
    if r.per_roll.is_some() {
        return own("--per-roll", "not available through Slurm");
    }
    if *r.json {
        return own(
            "--json",
            "the finishing job writes both DIR/result.json and DIR/result.txt",
        );
    }
    let threads = r.run.threads.max(1);
    super::args::threads(threads)?;
    // `fair` throws in a tumble unless told otherwise, as on one machine.
    let spec = match &fair {
        None => r.spec()?,
        Some(_) => r.spec_or(dicephys::model::throws::ThrowStyle::Tumble)?,
    };
    if fair == Some(dicephys::studies::fair::Null::QuasiStatic)
        && spec.scene.mode == dicephys::model::scene::Mode::TwoD
    {
        return own(
            "--null quasi-static (solid-angle)",
            "the quasi-static theory is 3D; in 2D give uniform",
        );
    }
    Ok(cluster::roll(&spec, fair, threads, &job.job())?)
}

/// The finishing step: every task's result present and whole, then the merged result, written
/// whole (rerunning it rewrites the same result).
fn finish(dir: &std::path::Path) -> Result<()> {
    match cluster::finishing(dir)? {
        Finishing::Study(cfg, place, tasks) => {
            let ran = study::run(&cfg, &place);
            cluster::finished(dir, &place, tasks, ran.is_err())?;
            ran
        }
        Finishing::Roll(text) => super::term::stdout(&text),
    }
}
