//! `dicephys slurm`: a run as a Slurm job array and a finishing job that merges it exactly
//! (the scripts: `dicephys::run::slurm`), and `dicephys slurm finish DIR`, the finishing step.
//! `roll` is split into shards of its throws; the studies (`paper`, `crosscheck`, `converge`,
//! `tradeoff`, `stability`) chunk by chunk, each task running the command itself with its
//! share (`dicephys slurm task DIR K`), and the finishing job running it once more.

use super::crosscheck::CrosscheckArgs;
use super::error::{Error, Result};
use super::outln;
use super::paper::PaperArgs;
use super::roll::RollArgs;
use super::sweeps::{ConvergeArgs, StabilityArgs, TradeoffArgs};
use super::{Cli, Command};
use clap::{Args, Parser, Subcommand};
use dicephys::report::summary::{RunSummary, ShardResult};
use dicephys::run::runner::{Checkpoint, ChunkShare};
use dicephys::run::slurm::{self, Layout, Options, Plan};
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
#[derive(Args, Debug)]
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
    match &a.command {
        SlurmCommand::Roll(r) => roll(r),
        SlurmCommand::Paper(a) => study(&a.job),
        SlurmCommand::Crosscheck(a) => study(&a.job),
        SlurmCommand::Converge(a) => study(&a.job),
        SlurmCommand::Tradeoff(a) => study(&a.job),
        SlurmCommand::Stability(a) => study(&a.job),
        SlurmCommand::Finish(f) => finish(&f.dir),
        SlurmCommand::Task(t) => task(&t.dir, t.k),
    }
}

/// The scheduler's options, which `dicephys slurm` takes and the study does not.
const JOB_OPTIONS: [&str; 6] = [
    "--tasks",
    "--dir",
    "--partition",
    "--time",
    "--account",
    "--bin",
];

/// The study's own command line, from this process's: the words after `slurm`, without the
/// scheduler's options (clap has parsed them all already).
fn study_args() -> Vec<String> {
    let argv: Vec<String> = std::env::args().collect();
    let start = argv
        .iter()
        .position(|w| w == "slurm")
        .map_or(argv.len(), |i| i + 1);
    let mut args = Vec::new();
    let mut words = argv[start..].iter();
    while let Some(w) = words.next() {
        if w == "--submit" {
            continue;
        }
        if JOB_OPTIONS.contains(&w.as_str()) {
            words.next();
            continue;
        }
        if JOB_OPTIONS.iter().any(|o| w.starts_with(&format!("{o}="))) {
            continue;
        }
        args.push(w.clone());
    }
    args
}

/// Parses a study's command line again (as a task or the finishing job does).
fn parse_study(args: &[String]) -> Result<Command> {
    let cli =
        Cli::try_parse_from(std::iter::once("dicephys".to_string()).chain(args.iter().cloned()))
            .map_err(|e| {
                Error::Usage(format!(
                    "slurm: the stored command line does not parse: {}",
                    e.kind()
                ))
            })?;
    Ok(cli.command)
}

/// Points a study at the run's directory and its threads: its outputs (and checkpoints) go to
/// DIR, on every task and in the finishing job alike.
fn place(cmd: &mut Command, lay: &Layout, threads: usize) -> Result<()> {
    match cmd {
        Command::Paper(a) => (a.out, a.threads) = (lay.dir.clone(), threads),
        Command::Converge(a) => (a.out, a.threads) = (lay.dir.clone(), threads),
        Command::Tradeoff(a) => (a.out, a.threads) = (lay.dir.clone(), threads),
        Command::Stability(a) => (a.out, a.threads) = (lay.dir.clone(), threads),
        Command::Crosscheck(a) => (a.checkpoint, a.run.threads) = (Some(lay.cells()), threads),
        _ => return Err(Error::Usage("slurm: not a study this runs".into())),
    }
    Ok(())
}

/// The threads the study asked for (0: one per core).
fn threads_of(cmd: &Command) -> usize {
    match cmd {
        Command::Paper(a) => a.threads,
        Command::Converge(a) => a.threads,
        Command::Tradeoff(a) => a.threads,
        Command::Stability(a) => a.threads,
        Command::Crosscheck(a) => a.run.threads,
        _ => 1,
    }
}

fn study(job: &JobArgs) -> Result<()> {
    let args = study_args();
    let name = args.first().cloned().unwrap_or_default();
    for w in &args {
        for (flag, why) in [
            ("--out", "the study writes its outputs into --dir"),
            ("--checkpoint", "the tasks keep their chunks under --dir"),
        ] {
            if w == flag || w.starts_with(&format!("{flag}=")) {
                return Err(Error::Usage(format!("slurm {name}: {flag}: {why}")));
            }
        }
    }
    let mut cmd = parse_study(&args)?;
    // A precision run decides each round from all the rolls so far, which no task sees whole.
    match &cmd {
        Command::Tradeoff(t) if t.preroll.is_none() => {
            return Err(Error::Usage(
                "slurm tradeoff: give --preroll ROLLS: its rounds are decided from every roll \
                 so far, which no task sees, so the tasks roll the first ROLLS throws of every \
                 stream ahead and the finishing job runs the study, reading them back and \
                 rolling on itself where a method needs more (`tradeoff --plan` prints the rolls \
                 each needs)"
                    .into(),
            ))
        }
        Command::Converge(c) if c.precision.is_some() => {
            return Err(Error::Usage(
                "slurm converge: --precision decides each cell's rounds from all its rolls, \
                 which no task sees; give --rolls N (a --precision run prints the rolls each \
                 cell needs)"
                    .into(),
            ))
        }
        _ => {}
    }
    // A cluster task takes the threads it asks for; "one per core" means one.
    let threads = threads_of(&cmd).max(1);
    super::args::threads(threads)?;
    let plan = plan_of(&args, threads, job);
    // Bad input is refused here, before anything is submitted or stored: the study runs dry,
    // checking its arguments and stopping at its first cell.
    let (lay, opt, bin) = prepare(&plan, job, threads, |lay| {
        place(&mut cmd, lay, threads)?;
        let _ = super::chunks().set(ChunkShare::DryRun);
        match super::dispatch(cmd) {
            Ok(()) | Err(Error::Interrupted(_)) => Ok(()),
            Err(e) => Err(e),
        }
    })?;
    std::fs::create_dir_all(lay.tasks())
        .map_err(|e| Error::Run(format!("{}: {e}", lay.tasks().display())))?;
    emit(&plan, &lay, &opt, &bin, job.submit)
}

fn plan_of(args: &[String], threads: usize, job: &JobArgs) -> Plan {
    Plan::Study {
        args: args.to_vec(),
        threads,
        tasks: job.tasks,
    }
}

/// One array task of a study: the command with this task's share of the chunks, then its mark.
fn task(dir: &Path, k: u64) -> Result<()> {
    let lay = Layout {
        dir: dir.to_path_buf(),
    };
    let Plan::Study {
        args,
        threads,
        tasks,
    } = read_plan(&lay)?
    else {
        return Err(Error::Usage(format!(
            "slurm task: {} is not a study's run",
            dir.display()
        )));
    };
    if k >= tasks {
        return Err(Error::Usage(format!(
            "slurm task {k}: the run has tasks 0 to {}",
            tasks - 1
        )));
    }
    let mut cmd = parse_study(&args)?;
    place(&mut cmd, &lay, threads)?;
    let _ = super::chunks().set(ChunkShare::task(k, tasks));
    super::dispatch(cmd)?;
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
    emit(&plan, &lay, &opt, &bin, a.job.submit)
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
    std::fs::create_dir_all(&job.dir).map_err(|e| {
        Error::Usage(format!(
            "--dir {}: cannot create it ({e})",
            job.dir.display()
        ))
    })?;
    let dir = job
        .dir
        .canonicalize()
        .map_err(|e| Error::Usage(format!("--dir {}: {e}", job.dir.display())))?;
    let lay = Layout { dir };
    check(&lay)?;
    match read_plan(&lay) {
        Ok(stored) if stored == *plan => {}
        Ok(_) => {
            return Err(Error::Usage(format!(
                "--dir {}: it holds another Slurm run ({}); use a new directory",
                lay.dir.display(),
                lay.plan().display()
            )))
        }
        Err(_) if !lay.plan().exists() => {
            let json = serde_json::to_string_pretty(plan).map_err(|e| Error::Run(e.to_string()))?;
            super::output(&lay.plan())?.write(format!("{json}\n").as_bytes())?;
        }
        Err(e) => return Err(e),
    }
    std::fs::create_dir_all(lay.logs())
        .map_err(|e| Error::Run(format!("{}: {e}", lay.logs().display())))?;
    Ok((lay, opt, bin))
}

fn read_plan(lay: &Layout) -> Result<Plan> {
    let p = lay.plan();
    let text = std::fs::read_to_string(&p).map_err(|e| {
        Error::Usage(format!(
            "{}: not a `dicephys slurm` run directory ({}: {e})",
            lay.dir.display(),
            p.display()
        ))
    })?;
    serde_json::from_str(&text)
        .map_err(|e| Error::Usage(format!("{} is damaged ({e})", p.display())))
}

/// Writes both scripts; prints them, or submits them and prints the job ids.
fn emit(plan: &Plan, lay: &Layout, opt: &Options, bin: &Path, submit: bool) -> Result<()> {
    let array = slurm::array_script(plan, lay, opt, bin)?;
    let fin = slurm::finish_script(plan, lay, opt, bin)?;
    super::output(&lay.array_script())?.write(array.as_bytes())?;
    super::output(&lay.finish_script())?.write(fin.as_bytes())?;
    let (a, f) = (lay.array_script(), lay.finish_script());
    if !submit {
        outln!("# {}\n{array}", a.display());
        outln!("# {}\n{fin}", f.display());
        outln!("# submit with:");
        outln!(
            "#   jid=$(sbatch --parsable {})",
            slurm::quote(&a.to_string_lossy())
        );
        outln!(
            "#   sbatch --dependency=afterany:${{jid%%;*}} {}",
            slurm::quote(&f.to_string_lossy())
        );
        outln!("# result: {}", result_of(plan, lay));
        return Ok(());
    }
    let array_id = sbatch(&[a.as_os_str()])?;
    let dep = format!("--dependency=afterany:{array_id}");
    let fin_id = sbatch(&[std::ffi::OsStr::new(&dep), f.as_os_str()])?;
    outln!(
        "array job {array_id} ({} tasks), finishing job {fin_id}",
        plan.tasks()
    );
    outln!("result: {}", result_of(plan, lay));
    outln!("logs: {}", lay.logs().display());
    Ok(())
}

/// Where the finishing job puts the result, for the user.
fn result_of(plan: &Plan, lay: &Layout) -> String {
    match plan {
        Plan::Roll { .. } => lay.result_json().display().to_string(),
        Plan::Study { .. } => format!(
            "{} (the {} outputs; its printed report in {})",
            lay.dir.display(),
            plan.command(),
            lay.stdout().display()
        ),
    }
}

/// Runs `sbatch --parsable ARGS` and returns the job id it prints.
fn sbatch(args: &[&std::ffi::OsStr]) -> Result<String> {
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
    let plan = read_plan(&lay)?;
    match &plan {
        Plan::Study {
            args,
            threads,
            tasks,
        } => {
            let missing: Vec<String> = (0..*tasks)
                .filter(|&k| !lay.task_done(k).exists())
                .map(|k| k.to_string())
                .collect();
            if !missing.is_empty() {
                return Err(not_finished(&lay, *tasks, &missing, "no mark in tasks/"));
            }
            let mut cmd = parse_study(args)?;
            place(&mut cmd, &lay, *threads)?;
            let chunks = match &mut cmd {
                // The tasks rolled ahead; the study itself runs here, reading their chunks
                // back and rolling on where a method needs more.
                Command::Tradeoff(t) => {
                    t.preroll = None;
                    ChunkShare::All
                }
                // Every chunk is on disk: the study reads them all and rolls none.
                _ => ChunkShare::Assemble,
            };
            let _ = super::chunks().set(chunks);
            let _ = super::command_line().set(format!(
                "dicephys {} (through Slurm: {tasks} tasks, {})",
                args.join(" "),
                lay.dir.display()
            ));
            super::dispatch(cmd)?;
        }
        Plan::Roll { spec, tasks } => {
            let mut parts = Vec::new();
            let mut missing = Vec::new();
            let mut why = Vec::new();
            for k in 0..*tasks {
                let p = lay.shard_result(k);
                match read_shard(&p, &Plan::shard_spec(spec, k, *tasks)) {
                    Ok(s) => parts.push(s),
                    Err(e) => {
                        missing.push(k.to_string());
                        why.push(e);
                    }
                }
            }
            if !missing.is_empty() {
                return Err(not_finished(&lay, *tasks, &missing, &why.join("; ")));
            }
            let merged = RunSummary::merge(&parts)?;
            let json =
                serde_json::to_string_pretty(&merged).map_err(|e| Error::Run(e.to_string()))?;
            let text = merged.human();
            let (j, t) = (
                super::output(&lay.result_json())?,
                super::output(&lay.result_text())?,
            );
            j.write(format!("{json}\n").as_bytes())?;
            t.write(text.as_bytes())?;
            super::stdout(&text)?;
            outln!(
                "slurm finish: {tasks} tasks merged into {}",
                lay.result_json().display()
            );
        }
    }
    Ok(())
}

/// The finishing job's refusal: which tasks have not finished, and how to finish them.
fn not_finished(lay: &Layout, tasks: u64, missing: &[String], why: &str) -> Error {
    Error::Run(format!(
        "slurm finish: {} of {tasks} tasks have not finished: {} ({why}); \
         rerun them with `sbatch --array={} {}` (each resumes from its checkpoint), \
         then `sbatch {}`",
        missing.len(),
        missing.join(", "),
        missing.join(","),
        lay.array_script().display(),
        lay.finish_script().display()
    ))
}

/// One task's result, if it is there, whole, and of this task.
fn read_shard(
    p: &Path,
    want: &dicephys::run::spec::RunSpec,
) -> std::result::Result<ShardResult, String> {
    let text = std::fs::read_to_string(p).map_err(|_| format!("no {}", p.display()))?;
    let s: ShardResult =
        serde_json::from_str(&text).map_err(|e| format!("{} is damaged: {e}", p.display()))?;
    if s.spec != *want {
        return Err(format!("{} is of another run", p.display()));
    }
    if s.partial {
        return Err(format!("{} is partial", p.display()));
    }
    Ok(s)
}
