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
use super::sweeps::{ConvergeArgs, StabilityArgs, TradeoffArgs};
use super::{out, outln};
use clap::{Args, Subcommand};
use dicephys::report::summary::RunSummary;
use dicephys::run::runner::{Checkpoint, ChunkShare};
use dicephys::run::slurm::{Layout, Options, Plan};
use dicephys::studies::fit::{FitStudy, Stage, FIRST_PASS};
use dicephys::studies::outputs::{self, Place};
use dicephys::studies::StudyConfig;
use std::path::{Path, PathBuf};

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
    /// `paper` as a job array: the tasks share the cells' chunks; the finishing job writes
    /// the report into --dir.
    Paper(Box<SlurmStudyArgs<PaperArgs>>),
    /// `crosscheck` as a job array; the finishing job's comparison is DIR/result.txt.
    Crosscheck(Box<SlurmStudyArgs<CrosscheckArgs>>),
    /// `converge` as a job array; the finishing job writes the study into --dir.
    Converge(Box<SlurmStudyArgs<ConvergeArgs>>),
    /// `tradeoff` as a job array; the finishing job writes the study into --dir.
    Tradeoff(Box<SlurmStudyArgs<TradeoffArgs>>),
    /// `stability` as a job array; the finishing job writes the study into --dir.
    Stability(Box<SlurmStudyArgs<StabilityArgs>>),
    /// `fit` as job arrays: the first pass into --dir/first-pass, then (its box narrowed from
    /// that result) the second into --dir; one array with --no-refine.
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

/// `dicephys slurm finish`'s arguments.
#[derive(Args, Debug)]
pub struct FinishArgs {
    /// The run's directory (as given to `dicephys slurm ... --dir`).
    pub dir: PathBuf,
}

/// Runs `dicephys slurm`.
pub fn run(a: &SlurmArgs) -> Result<()> {
    if let Some(flags) = study_of(&a.command)? {
        let submit = flags.4.submit;
        let (plan, lay) = stage(flags, true)?;
        return emit(&[(plan, lay)], submit);
    }
    match &a.command {
        SlurmCommand::Roll(r) => roll(r),
        SlurmCommand::Fit(f) => fit(f),
        SlurmCommand::Finish(f) => finish(&f.dir),
        SlurmCommand::Task(t) => task(&t.dir, t.k),
        _ => Ok(()),
    }
}

/// A study's configuration from its flags, and what a cluster run takes of them: its threads,
/// `--json`, whether it was given the output flag a cluster run sets itself, and the job.
type Flags<'a> = (StudyConfig, usize, bool, Option<&'static str>, &'a JobArgs);

fn study_of(c: &SlurmCommand) -> Result<Option<Flags<'_>>> {
    let out = |given: bool| given.then_some("--out");
    Ok(Some(match c {
        SlurmCommand::Paper(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Paper(s.config());
            (cfg, s.threads, s.json, out(s.out.is_some()), &a.job)
        }
        SlurmCommand::Crosscheck(a) => {
            let s = &a.study;
            if s.run.precision.is_some() {
                return Err(Error::Usage(
                    "slurm crosscheck: --precision: tasks split a fixed number of rolls; give \
                     --rolls (crosscheck --precision on one machine)"
                        .into(),
                ));
            }
            let cfg = StudyConfig::Crosscheck(s.config()?);
            let given = s.checkpoint.is_some().then_some("--checkpoint");
            (cfg, s.run.threads, s.json, given, &a.job)
        }
        SlurmCommand::Converge(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Converge(s.config());
            (cfg, s.threads, s.json, out(s.out.is_some()), &a.job)
        }
        SlurmCommand::Tradeoff(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Tradeoff(s.config()?);
            (cfg, s.threads, s.json, out(s.out.is_some()), &a.job)
        }
        SlurmCommand::Stability(a) => {
            let s = &a.study;
            let cfg = StudyConfig::Stability(s.config());
            (cfg, s.threads, s.json, out(s.out.is_some()), &a.job)
        }
        _ => return Ok(None),
    }))
}

/// `dicephys slurm <study>`: the study checked, run dry (`dry`), its plan stored, the scripts
/// written.
fn stage((cfg, threads, json, given, job): Flags, dry: bool) -> Result<(Plan, Layout)> {
    if let Some(flag) = given {
        return Err(Error::Usage(format!(
            "slurm {}: {flag}: the study writes into --dir (its outputs, and its chunks under \
             --dir/checkpoint)",
            cfg.name()
        )));
    }
    cfg.validate()?;
    // A study that decides its rounds from all the rolls so far cannot be split.
    cfg.check_splittable()?;
    // A cluster task takes the threads it asks for; "one per core" means one.
    let threads = threads.max(1);
    super::args::threads(threads)?;
    let line = super::command_line();
    let plan = Plan::Study {
        config: serde_json::to_value(&cfg).map_err(|e| Error::Run(e.to_string()))?,
        json,
        command_line: line.clone(),
        threads,
        tasks: job.tasks,
    };
    // Bad input is refused here, before anything is submitted or stored: the study runs dry,
    // checking its arguments and stopping at its first cell.
    let (lay, opt, bin) = prepare(&plan, job, threads, |lay| {
        if !dry {
            // A study that cannot run yet (a fit's second pass) only claims the directory.
            return Ok(dicephys::run::owner::claim(
                &lay.dir,
                cfg.name(),
                &cfg.identity(),
            )?);
        }
        let dry = Place::cluster(lay, threads, json, ChunkShare::DryRun, &line);
        match study::run(&cfg, &dry) {
            Ok(()) | Err(Error::Interrupted(_)) => Ok(()),
            Err(e) => Err(e),
        }
    })?;
    std::fs::create_dir_all(lay.tasks())
        .map_err(|e| Error::Run(format!("{}: {e}", lay.tasks().display())))?;
    lay.write_scripts(&plan, &opt, &bin)?;
    Ok((plan, lay))
}

/// `dicephys slurm fit`: one array, or two passes as two: the first pass's tasks, its finishing
/// job (the first pass's estimate, `first-pass.json`), then the second pass's tasks over the box
/// narrowed from it, and its finishing job (the fit). The second pass's box is only known when
/// the first has finished, so its jobs wait for the first's finishing job.
fn fit(a: &SlurmStudyArgs<FitArgs>) -> Result<()> {
    let s = &a.study;
    if s.recover.is_some() {
        return Err(Error::Usage(
            "slurm fit: --recover: not available through Slurm (fit --recover on one machine)"
                .into(),
        ));
    }
    let config = s.config()?;
    let given = s.out.is_some().then_some("--out");
    let flags = |stage, job| {
        let cfg = StudyConfig::Fit(FitStudy {
            config: config.clone(),
            stage,
        });
        (cfg, s.threads, s.json, given, job)
    };
    if !config.design.refine {
        let one = stage(flags(Stage::Whole, &a.job), true)?;
        return emit(&[one], a.job.submit);
    }
    let made = !a.job.dir.exists();
    let first_job = JobArgs {
        dir: a.job.dir.join("first-pass"),
        ..a.job.clone()
    };
    let staged = stage(flags(Stage::First, &first_job), true).and_then(|first| {
        let from = first.1.dir.join(FIRST_PASS);
        let second = stage(flags(Stage::Second { first: from }, &a.job), false)?;
        Ok([first, second])
    });
    match staged {
        Ok(stages) => emit(&stages, a.job.submit),
        Err(e) => {
            if made {
                let _ = std::fs::remove_dir_all(&a.job.dir);
            }
            Err(e)
        }
    }
}

/// One array task of a study: the study with this task's share of the chunks, then its mark.
fn task(dir: &Path, k: u64) -> Result<()> {
    let lay = Layout {
        dir: dir.to_path_buf(),
    };
    let (cfg, place, tasks) = outputs::planned(&lay)?;
    if k >= tasks {
        return Err(Error::Usage(format!(
            "slurm task {k}: the run has tasks 0 to {}",
            tasks - 1
        )));
    }
    let share = ChunkShare::task(k, tasks);
    study::run(&cfg, &Place { share, ..place })?;
    super::output(&lay.task_done(k))?.write(format!("task {k} of {tasks}\n").as_bytes())?;
    eprintln!(
        "task {k}: its share is rolled ({})",
        lay.task_done(k).display()
    );
    Ok(())
}

fn roll(a: &SlurmRollArgs) -> Result<()> {
    let r = &a.roll;
    let own = |flag: &str, why: &str| Err(Error::Usage(format!("slurm roll: {flag}: {why}")));
    if r.shard.is_some() {
        return own("--shard", "the tasks are the shards (--tasks N)");
    }
    if r.run.precision.is_some() {
        return own(
            "--precision",
            "tasks split a fixed number of rolls; give --rolls (roll --precision on one machine)",
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
    if r.json {
        return own(
            "--json",
            "the finishing job writes both DIR/result.json and DIR/result.txt",
        );
    }
    let spec = r.spec()?;
    let plan = Plan::Roll {
        spec: Box::new(spec.clone()),
        tasks: a.job.tasks,
    };
    let threads = r.run.threads.max(1);
    super::args::threads(threads)?;
    let (lay, opt, bin) = prepare(&plan, &a.job, threads, |_| Ok(()))?;
    for k in 0..a.job.tasks {
        Checkpoint::open(&lay.checkpoint(k), &Plan::shard_spec(&spec, k, a.job.tasks))?;
    }
    lay.write_scripts(&plan, &opt, &bin)?;
    emit(&[(plan, lay)], a.job.submit)
}

/// Checks the job options, makes the directory, runs `check` on it, and stores the plan in it
/// (or checks that it holds this very plan).
fn prepare(
    plan: &Plan,
    job: &JobArgs,
    cpus: usize,
    check: impl FnOnce(&Layout) -> Result<()>,
) -> Result<(Layout, Options, PathBuf)> {
    plan.validate()?;
    let opt = Options {
        partition: job.partition.clone(),
        time: job.time.clone(),
        account: job.account.clone(),
        cpus,
    };
    opt.validate()?;
    let bin = match &job.bin {
        Some(b) if b.is_absolute() => b.clone(),
        Some(b) => {
            return Err(Error::Usage(format!(
                "--bin {}: give the absolute path the nodes see",
                b.display()
            )))
        }
        None => std::env::current_exe()
            .and_then(|p| p.canonicalize())
            .map_err(|e| Error::Run(format!("cannot find this binary's path ({e})")))?,
    };
    dicephys::run::slurm::script_path("bin", &bin)?;
    // A run refused by its dry run leaves no directory behind that this call made.
    let made = !job.dir.exists();
    let lay = Layout::create(&job.dir)?;
    if let Err(e) = check(&lay) {
        if made {
            let _ = std::fs::remove_dir_all(&lay.dir);
        }
        return Err(e);
    }
    lay.store(plan).map_err(|e| match e {
        dicephys::Error::Mismatch(m) => Error::Usage(format!("--dir {m}")),
        e => e.into(),
    })?;
    Ok((lay, opt, bin))
}

/// Prints each stage's scripts and how to submit them, or submits them and prints the job ids:
/// each stage's array, then its finishing job once the array has ended; a later stage's array
/// once the earlier stage's finishing job has succeeded.
fn emit(stages: &[(Plan, Layout)], submit: bool) -> Result<()> {
    if !submit {
        for (_, lay) in stages {
            for p in [lay.array_script(), lay.finish_script()] {
                let text = std::fs::read_to_string(&p)
                    .map_err(|e| Error::Run(format!("{}: {e}", p.display())))?;
                outln!("# {}\n{text}", p.display());
            }
        }
        out!("{}", Layout::instructions(stages));
        return Ok(());
    }
    let mut after: Option<String> = None;
    for (i, (plan, lay)) in stages.iter().enumerate() {
        let mut args: Vec<std::ffi::OsString> = Vec::new();
        if let Some(prev) = &after {
            args.push("--kill-on-invalid-dep=yes".into());
            args.push(format!("--dependency=afterok:{prev}").into());
        }
        args.push(lay.array_script().into_os_string());
        let array_id = sbatch(&args)?;
        let dep = format!("--dependency=afterany:{array_id}");
        let fin_id = sbatch(&[dep.into(), lay.finish_script().into_os_string()])?;
        let pass = match (stages.len(), i) {
            (1, _) => "",
            (_, 0) => "first pass: ",
            _ => "second pass: ",
        };
        outln!(
            "{pass}array job {array_id} ({} tasks), finishing job {fin_id}",
            plan.tasks()
        );
        after = Some(fin_id);
    }
    if let Some((plan, lay)) = stages.last() {
        outln!("result: {}", lay.result_of(plan));
        outln!("logs: {}", lay.logs().display());
    }
    Ok(())
}

/// Runs `sbatch --parsable ARGS` and returns the job id it prints.
fn sbatch(args: &[std::ffi::OsString]) -> Result<String> {
    let out = std::process::Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .output()
        .map_err(|e| Error::Run(format!("sbatch: {e} (is Slurm installed here?)")))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(Error::Run(format!(
            "sbatch failed: {}",
            stderr.trim().replace('\n', "; ")
        )));
    }
    // --parsable prints "id" or "id;cluster".
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::Run(format!(
            "sbatch printed no job id: {}",
            stdout.trim()
        )));
    }
    Ok(id)
}

/// The finishing step: every task's result present and whole, then the merged result, written
/// whole (rerunning it rewrites the same result).
fn finish(dir: &Path) -> Result<()> {
    let lay = Layout {
        dir: dir.to_path_buf(),
    };
    let plan = lay.read_plan()?;
    match &plan {
        Plan::Study { tasks, .. } => {
            lay.check_marks(*tasks)?;
            // Every chunk is on disk: the study reads them all and rolls none (but tradeoff,
            // whose tasks rolled ahead, runs here, rolling on where a method needs more).
            let (cfg, place, _) = outputs::planned(&lay)?;
            let (cfg, share) = cfg.finishing(*tasks);
            let ran = study::run(
                &cfg,
                &Place {
                    share: share.clone(),
                    ..place
                },
            );
            // A chunk missing or damaged after its task's mark: the mark goes, so that the
            // task, rerun, rolls it again (a damaged chunk is rolled again and replaced).
            if let (Err(_), Some((k, why))) = (&ran, share.lacking()) {
                let mark = lay.task_done(k);
                if let Err(e) = std::fs::remove_file(&mark) {
                    if e.kind() != std::io::ErrorKind::NotFound {
                        return Err(Error::Run(format!("{}: {e}", mark.display())));
                    }
                }
                let why = format!("{why}; its mark {} removed", mark.display());
                return Err(lay.not_finished(*tasks, &[k.to_string()], &why).into());
            }
            ran?;
        }
        Plan::Roll { spec, tasks } => {
            let text = RunSummary::merge_tasks(&lay, spec, *tasks)?;
            super::stdout(&text)?;
            outln!(
                "slurm finish: {tasks} tasks merged into {}",
                lay.result_json().display()
            );
        }
    }
    Ok(())
}
