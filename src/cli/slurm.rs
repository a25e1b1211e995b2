//! `dicephys slurm`: a run as a Slurm job array and a finishing job that merges it exactly
//! (the scripts: `dicephys::run::slurm`), and `dicephys slurm finish DIR`, the finishing step.

use super::error::{Error, Result};
use super::outln;
use super::roll::RollArgs;
use clap::{Args, Subcommand};
use dicephys::report::summary::{RunSummary, ShardResult};
use dicephys::run::runner::Checkpoint;
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
    /// The finishing job: check that every task's result is there, merge, write DIR/result.*.
    Finish(FinishArgs),
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
        SlurmCommand::Finish(f) => finish(&f.dir),
    }
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
        spec: spec.clone(),
        tasks: a.job.tasks,
    };
    let threads = r.run.threads.max(1);
    super::args::threads(threads)?;
    let (lay, opt, bin) = prepare(&plan, &a.job, threads)?;
    for k in 0..a.job.tasks {
        Checkpoint::open(&lay.checkpoint(k), &Plan::shard_spec(&spec, k, a.job.tasks))?;
    }
    emit(&plan, &lay, &opt, &bin, a.job.submit)
}

/// Checks the job options, makes the directory and stores the plan in it (or checks that it
/// holds this very plan).
fn prepare(plan: &Plan, job: &JobArgs, cpus: usize) -> Result<(Layout, Options, PathBuf)> {
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
        outln!("# result: {}", lay.result_json().display());
        return Ok(());
    }
    let array_id = sbatch(&[a.as_os_str()])?;
    let dep = format!("--dependency=afterany:{array_id}");
    let fin_id = sbatch(&[std::ffi::OsStr::new(&dep), f.as_os_str()])?;
    outln!(
        "array job {array_id} ({} tasks), finishing job {fin_id}",
        plan.tasks()
    );
    outln!("result: {}", lay.result_json().display());
    outln!("logs: {}", lay.logs().display());
    Ok(())
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
                return Err(Error::Run(format!(
                    "slurm finish: {} of {tasks} tasks have not finished: {} ({}); \
                     rerun them with `sbatch --array={} {}` (each resumes from its checkpoint), \
                     then `sbatch {}`",
                    missing.len(),
                    missing.join(", "),
                    why.join("; "),
                    missing.join(","),
                    lay.array_script().display(),
                    lay.finish_script().display()
                )));
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
