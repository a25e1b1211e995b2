//! A run put on a Slurm cluster: checked, its directory made and claimed, its plan stored and
//! its scripts written ([`crate::run::slurm`]), then submitted (`sbatch`, chained) or printed;
//! an array task's study with its share, and the finishing step. The command line only turns
//! flags into a [`Job`] and a study's configuration, and runs the studies with its hooks.

use super::fit::Stage;
use super::outputs::{self, Hooks, Place};
use super::StudyConfig;
use crate::error::{Error, Field, Result};
use crate::report::summary::{RunSummary, ShardResult};
use crate::run::io::Output;
use crate::run::runner::{Checkpoint, ChunkShare};
use crate::run::slurm::{script_path, Layout, Options, Plan};
use crate::run::spec::RunSpec;
use crate::run::stop::Stop;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The scheduler's side of a run: how many tasks, where, which queue, which binary.
#[derive(Clone, Debug)]
pub struct Job {
    /// Array tasks.
    pub tasks: u64,
    /// The run's directory, on a file system every node shares.
    pub dir: PathBuf,
    /// Partition, time limit and account (`cpus` is set from the study's threads).
    pub options: Options,
    /// The dicephys binary the jobs run, as the nodes see it (None: this process's own).
    pub bin: Option<PathBuf>,
}

/// A study ready to run on a cluster: its configuration, each task's threads, whether it prints
/// JSON, and the command line it was submitted with (named in its report, never parsed).
pub struct Submitted<'a> {
    /// The study.
    pub config: StudyConfig,
    /// Threads per task, at least 1.
    pub threads: usize,
    /// `--json`.
    pub json: bool,
    /// The command line.
    pub command_line: &'a str,
}

/// A stage of a cluster run: its plan, in its directory.
pub type Staged = (Plan, Layout);

/// `s` as a stage; `dry`: run it dry first (a stage that cannot run yet, a fit's second pass,
/// only claims its directory).
fn stage(s: &Submitted, job: &Job, dry: bool) -> Result<Staged> {
    let cfg = &s.config;
    cfg.validate()?;
    // A study that decides its rounds from all the rolls so far cannot be split.
    cfg.check_splittable()?;
    let plan = Plan::Study {
        config: serde_json::to_value(cfg).map_err(|e| Error::failed(e.to_string()))?,
        json: s.json,
        command_line: s.command_line.to_string(),
        threads: s.threads,
        tasks: job.tasks,
    };
    let lay = prepare(&plan, job, s.threads, |lay| {
        if !dry {
            return super::place::claim(
                &lay.dir,
                cfg.name(),
                &cfg.identity(),
                super::place::Claimant::Checked,
            );
        }
        let place = Place::cluster(lay, s.threads, s.json, ChunkShare::DryRun, s.command_line);
        let quiet = Hooks {
            log: &|_| {},
            print: &|_| {},
            progress: &|_, _| {},
            stop: Stop::new(),
        };
        match cfg.run(&place, &quiet) {
            Ok(_) | Err(Error::Stopped) => Ok(()),
            Err(e) => Err(e),
        }
    })?;
    std::fs::create_dir_all(lay.tasks()).map_err(|e| Error::io(&lay.tasks(), e))?;
    Ok((plan, lay))
}

/// A study as the runs a cluster makes of it, each checked, run dry (it stops at its first
/// cell, so that bad input is refused here rather than in a failed array), its plan stored,
/// its scripts written. One run; but a refined `fit` or `paper --calibrated` is two: the first
/// passes into `DIR/first-pass` (their estimates, [`FIRST_PASS`](super::fit::FIRST_PASS) or
/// [`FIRST_PASSES`](super::calibrated::FIRST_PASSES)), the
/// second into `DIR`, its boxes narrowed from the first's results, so that it can only start
/// when the first has finished ([`submit`] chains them).
pub fn stages(s: &Submitted, job: &Job) -> Result<Vec<Staged>> {
    let Some((first_cfg, file)) = s.config.at_stage(Stage::First) else {
        return stage(s, job, true).map(|one| vec![one]);
    };
    let pass = |config| Submitted {
        config,
        command_line: s.command_line,
        ..*s
    };
    let made = !job.dir.exists();
    let first_job = Job {
        dir: job.dir.join("first-pass"),
        ..job.clone()
    };
    let staged = stage(&pass(first_cfg), &first_job, true).and_then(|first| {
        let from = first.1.dir.join(file);
        let (second_cfg, _) = s
            .config
            .at_stage(Stage::Second { first: from })
            .expect("a study of two stages");
        let second = stage(&pass(second_cfg), job, false)?;
        Ok(vec![first, second])
    });
    if staged.is_err() && made {
        let _ = std::fs::remove_dir_all(&job.dir);
    }
    staged
}

/// `roll` as a run of `job.tasks` shards, each with its checkpoint made.
pub fn roll(
    spec: &RunSpec,
    fair: Option<crate::theory::null::Null>,
    threads: usize,
    job: &Job,
) -> Result<Staged> {
    let plan = Plan::Roll {
        spec: Box::new(spec.clone()),
        tasks: job.tasks,
        fair,
    };
    let lay = prepare(&plan, job, threads, |_| Ok(()))?;
    for k in 0..job.tasks {
        Checkpoint::open(&lay.checkpoint(k), &Plan::shard_spec(spec, k, job.tasks))?;
    }
    Ok((plan, lay))
}

/// Checks the job's options, makes the directory, runs `check` on it, stores the plan in it
/// (or checks that it holds this very plan), and writes the scripts.
fn prepare(
    plan: &Plan,
    job: &Job,
    cpus: usize,
    check: impl FnOnce(&Layout) -> Result<()>,
) -> Result<Layout> {
    plan.validate()?;
    let opt = Options {
        cpus,
        ..job.options.clone()
    };
    opt.validate()?;
    let bin = match &job.bin {
        Some(b) if b.is_absolute() => b.clone(),
        Some(b) => {
            return Err(Error::field(
                Field::Bin,
                b.display(),
                "give the absolute path the nodes see",
            ))
        }
        None => std::env::current_exe()
            .and_then(|p| p.canonicalize())
            .map_err(|e| Error::failed(format!("cannot find this binary's path ({e})")))?,
    };
    script_path(Field::Bin, &bin)?;
    // A run refused by its dry run leaves no directory behind that this call made.
    let made = !job.dir.exists();
    let lay = Layout::create(&job.dir)?;
    let stored = check(&lay).and_then(|()| lay.store(plan));
    if let Err(e) = stored {
        if made {
            let _ = std::fs::remove_dir_all(&lay.dir);
        }
        return Err(e);
    }
    lay.write_scripts(plan, &opt, &bin)?;
    Ok(lay)
}

/// The stages' scripts, and how to submit them by hand (for printing).
pub fn scripts(stages: &[Staged]) -> Result<String> {
    let mut s = String::new();
    for (_, lay) in stages {
        for p in [lay.array_script(), lay.finish_script()] {
            let text = std::fs::read_to_string(&p).map_err(|e| Error::io(&p, e))?;
            s += &format!("# {}\n{text}\n", p.display());
        }
    }
    Ok(s + &Layout::instructions(stages))
}

/// Submits the stages with `sbatch`: each stage's array, its finishing job once the array has
/// ended, and a later stage's array once the earlier stage's finishing job has succeeded (or
/// cancelled if it failed). Returns what to print: the job ids, the result, the logs.
pub fn submit(stages: &[Staged]) -> Result<String> {
    let mut out = String::new();
    let mut after: Option<String> = None;
    for (i, (plan, lay)) in stages.iter().enumerate() {
        let mut args: Vec<OsString> = Vec::new();
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
        out += &format!(
            "{pass}array job {array_id} ({} tasks), finishing job {fin_id}\n",
            plan.tasks()
        );
        after = Some(fin_id);
    }
    if let Some((plan, lay)) = stages.last() {
        out += &format!(
            "result: {}\nlogs: {}\n",
            lay.result_of(plan),
            lay.logs().display()
        );
    }
    Ok(out)
}

/// Runs `sbatch --parsable ARGS` and returns the job id it prints.
fn sbatch(args: &[OsString]) -> Result<String> {
    let out = std::process::Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .output()
        .map_err(|e| Error::failed(format!("sbatch: {e} (is Slurm installed here?)")))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(Error::failed(format!(
            "sbatch failed: {}",
            stderr.trim().replace('\n', "; ")
        )));
    }
    // --parsable prints "id" or "id;cluster".
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::failed(format!(
            "sbatch printed no job id: {}",
            stdout.trim()
        )));
    }
    Ok(id)
}

/// Array task `k` of the study run in `dir`: the study and where it runs, with this task's
/// share of the chunks (the caller runs it, then [`mark`]s the task done).
pub fn task(dir: &Path, k: u64) -> Result<(StudyConfig, Place)> {
    let lay = Layout {
        dir: dir.to_path_buf(),
    };
    let (cfg, place, tasks) = outputs::planned(&lay)?;
    if k >= tasks {
        return Err(Error::Invalid(format!(
            "slurm task {k}: the run has tasks 0 to {}",
            tasks - 1
        )));
    }
    let share = ChunkShare::task(k, tasks);
    Ok((cfg, Place { share, ..place }))
}

/// Marks task `k` of the run in `dir` done; returns the line to log.
pub fn mark(dir: &Path, k: u64, tasks: u64) -> Result<String> {
    let done = Layout {
        dir: dir.to_path_buf(),
    }
    .task_done(k);
    crate::run::io::Output::check(&done)?.write(format!("task {k} of {tasks}\n").as_bytes())?;
    Ok(format!(
        "task {k}: its share is rolled ({})",
        done.display()
    ))
}

/// What the finishing step of the run in `dir` does.
pub enum Finishing {
    /// Run the study once more (the caller, with its hooks), reading every chunk; then
    /// [`finished`].
    Study(Box<StudyConfig>, Place, u64),
    /// A `roll`'s shards merged: the text to print (the JSON and the text are written).
    Roll(String),
}

/// The finishing step: every task marked done, then the study to assemble, or the shards of a
/// `roll` merged (rerunning it rewrites the same result).
pub fn finishing(dir: &Path) -> Result<Finishing> {
    let lay = Layout {
        dir: dir.to_path_buf(),
    };
    match lay.read_plan()? {
        Plan::Study { tasks, .. } => {
            lay.check_marks(tasks)?;
            // Every chunk is on disk: the study reads them all and rolls none (but tradeoff,
            // whose tasks rolled ahead, runs here, rolling on where a method needs more).
            let (cfg, place, _) = outputs::planned(&lay)?;
            let (cfg, share) = cfg.finishing(tasks);
            Ok(Finishing::Study(
                Box::new(cfg),
                Place { share, ..place },
                tasks,
            ))
        }
        Plan::Roll { spec, tasks, fair } => {
            let merged = merge_shards(&lay, &spec, tasks)?;
            // What the one machine's `roll --json` (or `fair --json`) prints, and its text.
            let (json, text) = super::roll::RollStudy::new(*spec, fair).render(&merged)?;
            let (j, t) = (
                Output::check(&lay.result_json())?,
                Output::check(&lay.result_text())?,
            );
            j.write(format!("{json}\n").as_bytes())?;
            t.write(text.as_bytes())?;
            Ok(Finishing::Roll(format!(
                "{text}slurm finish: {tasks} tasks merged into {}\n",
                lay.result_json().display()
            )))
        }
    }
}

/// The shards of a `roll` through Slurm merged: every task's result there, whole and of its
/// shard (a damaged one moved aside, so that its task, rerun, writes it again).
fn merge_shards(lay: &Layout, spec: &RunSpec, tasks: u64) -> Result<RunSummary> {
    let (mut parts, mut missing, mut why) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..tasks {
        let p = lay.shard_result(k);
        match ShardResult::read(&p, &Plan::shard_spec(spec, k, tasks)) {
            Ok(s) => parts.push(s),
            Err(e) => {
                missing.push(k.to_string());
                // A result there but not usable is moved aside, so that the task, rerun,
                // writes it again rather than finding it there already.
                let aside = p.with_extension("json.damaged");
                why.push(match p.exists() && std::fs::rename(&p, &aside).is_ok() {
                    true => format!("{e}; moved to {}", aside.display()),
                    false => e,
                });
            }
        }
    }
    if !missing.is_empty() {
        return Err(lay.not_finished(tasks, &missing, &why.join("; ")));
    }
    RunSummary::merge(&parts)
}

/// After the finishing step's study ran and `failed`: a chunk missing or damaged after its
/// task's mark removes the mark, so that the task, rerun, rolls it again, and says so.
pub fn finished(dir: &Path, place: &Place, tasks: u64, failed: bool) -> Result<()> {
    let (true, Some((k, why))) = (failed, place.share.lacking()) else {
        return Ok(());
    };
    let lay = Layout {
        dir: dir.to_path_buf(),
    };
    let mark = lay.task_done(k);
    if let Err(e) = std::fs::remove_file(&mark) {
        if e.kind() != std::io::ErrorKind::NotFound {
            return Err(Error::io(&mark, e));
        }
    }
    let why = format!("{why}; its mark {} removed", mark.display());
    Err(lay.not_finished(tasks, &[k.to_string()], &why))
}
