//! A run as a Slurm job array. Task K of N rolls its shard (`--shard K/N`) into its own
//! checkpoint directory on the shared file system, then writes its `--json` result; a finishing
//! job, started after every task has ended, checks that all N results are there and whole and
//! merges them into exactly the one-machine result.
//!
//! Everything a task needs is on disk before anything is submitted: `DIR/slurm.json` (the
//! [`Plan`]) and one checkpoint per task, `DIR/shard-K/spec.json`, holding that task's
//! [`RunSpec`]. A task runs `dicephys roll --resume DIR/shard-K`, so a task that is requeued
//! or resubmitted continues from its last whole chunk, and no command line is ever re-parsed.
//!
//! A study of several cells (`paper`, `crosscheck`, `converge`, `tradeoff`, `stability`, `fit`) is
//! split chunk by chunk instead ([`crate::run::runner::ChunkShare`]): the plan holds the
//! study's configuration, serialized; task K runs the study from it with its share of the
//! chunks, into the checkpoint directories under `DIR` that all tasks share, and marks itself
//! done in `DIR/tasks/`; the finishing job runs the very study once more, rolling nothing, and
//! writes its outputs into `DIR` exactly as one machine would.
//!
//! This module writes the scripts; it never calls the scheduler.

use crate::error::{Error, Field, Result};
use crate::run::io::Output;
use crate::run::spec::{RunSpec, Shard};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The most tasks of one array (Slurm's own default `MaxArraySize` is 1001).
pub const MAX_TASKS: u64 = 100_000;

/// What a Slurm run does, stored as `DIR/slurm.json`: the finishing job reads it back.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "command", rename_all = "snake_case")]
pub enum Plan {
    /// `dicephys roll`, its throws split into `tasks` shards.
    Roll {
        /// The whole run (no shard).
        spec: Box<RunSpec>,
        /// Array tasks, one shard each.
        tasks: u64,
        /// `dicephys fair`: the merged faces judged against this null (absent: `roll`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fair: Option<crate::theory::null::Null>,
    },
    /// A study of several cells, its chunks shared among the tasks.
    Study {
        /// The study's configuration, serialized (`studies::StudyConfig`, tagged by the
        /// study's name): each task, and the finishing job, runs the library's study from it.
        config: serde_json::Value,
        /// Print the study's JSON result rather than its report (`--json`).
        json: bool,
        /// The command line it was submitted with, named in the report (never parsed).
        command_line: String,
        /// Threads per task (each task's `--cpus-per-task`).
        threads: usize,
        /// Array tasks.
        tasks: u64,
    },
}

impl Plan {
    /// The array's tasks.
    pub fn tasks(&self) -> u64 {
        match self {
            Plan::Roll { tasks, .. } | Plan::Study { tasks, .. } => *tasks,
        }
    }

    /// The command it runs, for job names and messages.
    pub fn command(&self) -> &str {
        match self {
            Plan::Roll { fair: None, .. } => "roll",
            Plan::Roll { fair: Some(_), .. } => "fair",
            Plan::Study { config, .. } => config
                .get("study")
                .and_then(serde_json::Value::as_str)
                .unwrap_or("study"),
        }
    }

    /// True if `other` is this very run (the command line it was submitted with aside: the
    /// scripts may be printed first, then submitted).
    pub fn same_run(&self, other: &Plan) -> bool {
        let bare = |p: &Plan| match p {
            Plan::Study {
                config,
                json,
                threads,
                tasks,
                ..
            } => Plan::Study {
                config: config.clone(),
                json: *json,
                command_line: String::new(),
                threads: *threads,
                tasks: *tasks,
            },
            roll => roll.clone(),
        };
        bare(self) == bare(other)
    }

    /// Task `k`'s share of a `roll`: the same run with shard k/N.
    pub fn shard_spec(spec: &RunSpec, k: u64, tasks: u64) -> RunSpec {
        RunSpec {
            shard: Some(Shard { k, n: tasks }),
            ..spec.unsharded()
        }
    }

    /// Checks the number of tasks against the work.
    pub fn validate(&self) -> Result<()> {
        let n = self.tasks();
        if n == 0 || n > MAX_TASKS {
            return Err(Error::field(
                Field::Tasks,
                n,
                format!("need 1 to {MAX_TASKS} tasks"),
            ));
        }
        match self {
            Plan::Roll { spec, .. } if n > spec.rolls => Err(Error::field(
                Field::Tasks,
                n,
                format!("more tasks than the run's {} rolls", spec.rolls),
            )),
            _ => Ok(()),
        }
    }
}

/// Where the pieces of a Slurm run live under its directory.
#[derive(Clone, Debug)]
pub struct Layout {
    /// The run's directory (absolute: the scripts run on other nodes).
    pub dir: PathBuf,
}

impl Layout {
    /// The run's directory `dir`, made if need be, by its absolute path (the scripts run on
    /// other nodes).
    /// A directory whose absolute path cannot be written into the scripts safely
    /// ([`script_path`]) is refused before it is made (and, if only its real path is unsafe,
    /// removed again if this call made it).
    pub fn create(dir: &Path) -> Result<Layout> {
        let bad = |e: std::io::Error| Error::field(Field::Dir, format!("{dir:?}"), e.to_string());
        script_path(Field::Dir, &std::path::absolute(dir).map_err(bad)?)?;
        let made = !dir.exists();
        std::fs::create_dir_all(dir).map_err(bad)?;
        let real = dir.canonicalize().map_err(bad)?;
        if let Err(e) = script_path(Field::Dir, &real) {
            if made {
                let _ = std::fs::remove_dir(&real);
            }
            return Err(e);
        }
        Ok(Layout { dir: real })
    }

    /// Writes the two scripts (`array_script`, `finish_script`) whole; returns their text.
    pub fn write_scripts(&self, plan: &Plan, opt: &Options, bin: &Path) -> Result<[String; 2]> {
        let array = array_script(plan, self, opt, bin)?;
        let fin = finish_script(plan, self, opt, bin)?;
        Output::check(&self.array_script())?.write(array.as_bytes())?;
        Output::check(&self.finish_script())?.write(fin.as_bytes())?;
        Ok([array, fin])
    }

    /// Stores `plan` in the run's directory, or checks that the directory holds this very run;
    /// makes the logs' directory.
    pub fn store(&self, plan: &Plan) -> Result<()> {
        std::fs::create_dir_all(self.logs()).map_err(|e| Error::io(&self.logs(), e))?;
        match self.read_plan() {
            Ok(stored) if stored.same_run(plan) => Ok(()),
            Ok(_) => Err(Error::Mismatch(format!(
                "{}: it holds another Slurm run ({}); use a new directory",
                self.dir.display(),
                self.plan().display()
            ))),
            Err(_) if !self.plan().exists() => {
                let json =
                    serde_json::to_string_pretty(plan).map_err(|e| Error::failed(e.to_string()))?;
                Output::check(&self.plan())?.write(format!("{json}\n").as_bytes())
            }
            Err(e) => Err(e),
        }
    }

    /// The plan stored in the run's directory.
    pub fn read_plan(&self) -> Result<Plan> {
        let p = self.plan();
        let text = std::fs::read_to_string(&p).map_err(|e| {
            Error::Invalid(format!(
                "{}: not a `dicephys slurm` run directory ({}: {e})",
                self.dir.display(),
                p.display()
            ))
        })?;
        serde_json::from_str(&text)
            .map_err(|e| Error::Invalid(format!("{} is damaged ({e})", p.display())))
    }

    /// The finishing job's refusal: which of the `tasks` have not finished (`missing`, and
    /// `why`), and how to finish them.
    pub fn not_finished(&self, tasks: u64, missing: &[String], why: &str) -> Error {
        Error::failed(format!(
            "slurm finish: {} of {tasks} tasks have not finished: {} ({why}); \
             rerun them with `sbatch --array={} {}` (each resumes from its checkpoint), \
             then `sbatch {}`",
            missing.len(),
            missing.join(", "),
            missing.join(","),
            self.array_script().display(),
            self.finish_script().display()
        ))
    }

    /// A study's tasks that have not marked themselves done, or the finishing job's refusal.
    pub fn check_marks(&self, tasks: u64) -> Result<()> {
        let missing: Vec<String> = (0..tasks)
            .filter(|&k| !self.task_done(k).exists())
            .map(|k| k.to_string())
            .collect();
        if missing.is_empty() {
            Ok(())
        } else {
            Err(self.not_finished(tasks, &missing, "no mark in tasks/"))
        }
    }

    /// Where the finishing job puts the result, for the user.
    pub fn result_of(&self, plan: &Plan) -> String {
        match plan {
            Plan::Roll { .. } => self.result_json().display().to_string(),
            Plan::Study { .. } => format!(
                "{} (the {} outputs; its printed report in {})",
                self.dir.display(),
                plan.command(),
                self.stdout().display()
            ),
        }
    }

    /// How to submit the scripts of `stages` by hand, as shell comments: each stage's array,
    /// its finishing job once the array has ended, and the next stage's array once that
    /// finishing job has succeeded (a fit's second pass needs its first pass's result).
    pub fn instructions(stages: &[(Plan, Layout)]) -> String {
        let mut s = String::from("# submit with:\n");
        let mut after = String::new();
        for (i, (_, lay)) in stages.iter().enumerate() {
            let a = quote(&lay.array_script().to_string_lossy());
            let f = quote(&lay.finish_script().to_string_lossy());
            s += &format!("#   a{i}=$(sbatch --parsable {after}{a})\n");
            let dep = format!("--dependency=afterany:${{a{i}%%;*}}");
            if i + 1 == stages.len() {
                s += &format!("#   sbatch {dep} {f}\n");
            } else {
                s += &format!("#   f{i}=$(sbatch --parsable {dep} {f})\n");
                after = format!("--kill-on-invalid-dep=yes --dependency=afterok:${{f{i}%%;*}} ");
            }
        }
        if let Some((plan, lay)) = stages.last() {
            s += &format!("# result: {}\n", lay.result_of(plan));
        }
        s
    }

    /// The plan, `slurm.json`.
    pub fn plan(&self) -> PathBuf {
        self.dir.join("slurm.json")
    }
    /// Task k's checkpoint directory.
    pub fn checkpoint(&self, k: u64) -> PathBuf {
        self.dir.join(format!("shard-{k}"))
    }
    /// Task k's result (`roll --json`), written whole when the task ends.
    pub fn shard_result(&self, k: u64) -> PathBuf {
        self.dir.join(format!("shard-{k}.json"))
    }
    /// The job-array script.
    pub fn array_script(&self) -> PathBuf {
        self.dir.join("array.sh")
    }
    /// The finishing job's script.
    pub fn finish_script(&self) -> PathBuf {
        self.dir.join("finish.sh")
    }
    /// Where the tasks of a study mark themselves done.
    pub fn tasks(&self) -> PathBuf {
        self.dir.join("tasks")
    }
    /// Task k's mark: written when its share of a study is rolled.
    pub fn task_done(&self, k: u64) -> PathBuf {
        self.tasks().join(format!("task-{k}.done"))
    }
    /// The checkpoint directory of a study's cells (`crosscheck --checkpoint`; the other
    /// studies keep theirs under their `--out`, which is the run's directory).
    pub fn cells(&self) -> PathBuf {
        self.dir.join("checkpoint")
    }
    /// What the finishing job of a study printed (the command's standard output).
    pub fn stdout(&self) -> PathBuf {
        self.dir.join("result.txt")
    }
    /// The jobs' logs.
    pub fn logs(&self) -> PathBuf {
        self.dir.join("logs")
    }
    /// The merged result, as `roll --json` prints it.
    pub fn result_json(&self) -> PathBuf {
        self.dir.join("result.json")
    }
    /// The merged result, as `roll` prints it.
    pub fn result_text(&self) -> PathBuf {
        self.dir.join("result.txt")
    }
}

/// The scheduler options every job of the run gets.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// `--partition`.
    pub partition: Option<String>,
    /// `--time` (each task's limit; the finishing job's too).
    pub time: Option<String>,
    /// `--account`.
    pub account: Option<String>,
    /// CPUs per array task (its `--threads`).
    pub cpus: usize,
}

impl Options {
    /// Refuses values that cannot go on an `#SBATCH` line as they are: a partition or an
    /// account is letters, digits and `_ . , -` (no `#`, which starts a comment for sbatch,
    /// no quote, no `%`, no space or newline); a time is digits, `:` and `-` (`1:00:00`,
    /// `2-12`), or `UNLIMITED`/`INFINITE`.
    pub fn validate(&self) -> Result<()> {
        fn word(v: &str) -> bool {
            v.chars()
                .all(|c| c.is_ascii_alphanumeric() || "_.,-".contains(c))
        }
        fn time(v: &str) -> bool {
            v.starts_with(|c: char| c.is_ascii_digit())
                && v.chars().all(|c| c.is_ascii_digit() || ":-".contains(c))
                || ["unlimited", "infinite"].contains(&v.to_ascii_lowercase().as_str())
        }
        type Check = fn(&str) -> bool;
        let rules: [(Field, &Option<String>, Check, &str); 3] = [
            (
                Field::Partition,
                &self.partition,
                word,
                "letters, digits and _ . , - only",
            ),
            (
                Field::Account,
                &self.account,
                word,
                "letters, digits and _ . , - only",
            ),
            (
                Field::Time,
                &self.time,
                time,
                "minutes or [D-]HH:MM:SS as sbatch takes it (90, 1:00:00, 2-12), or UNLIMITED",
            ),
        ];
        for (name, v, ok, want) in rules {
            if let Some(v) = v {
                if v.is_empty() || !ok(v) {
                    return Err(Error::field(
                        name,
                        format!("{v:?}"),
                        format!("{want} (it is written on an #SBATCH line)"),
                    ));
                }
            }
        }
        Ok(())
    }

    fn lines(&self) -> String {
        let mut s = String::new();
        for (name, v) in [
            ("partition", &self.partition),
            ("time", &self.time),
            ("account", &self.account),
        ] {
            if let Some(v) = v {
                s += &format!("#SBATCH --{name}={v}\n");
            }
        }
        s
    }
}

/// Quotes a word for the shell (POSIX single quotes).
pub fn quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+=:,@".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// A path written into the scripts, or the refusal of `field`: it must be UTF-8 and hold no
/// control character (a newline would end a script line, and the rest of the name run as
/// shell) and no backslash (sbatch's escape, which in a log name also turns off `%a`).
/// Anything else is quoted where it is written: for the shell ([`quote`]) and for sbatch's
/// own parser ([`sbatch_path`]).
pub fn script_path(field: Field, p: &Path) -> Result<&str> {
    let refuse = |why: &str| Err(Error::field(field, format!("{p:?}"), why));
    match p.to_str() {
        None => refuse("not UTF-8; a Slurm run's path goes into its scripts as text"),
        Some(s) if s.chars().any(char::is_control) => refuse(
            "a control character (a newline?) in the path cannot be written into a script safely",
        ),
        Some(s) if s.contains('\\') => {
            refuse("a backslash in the path cannot be written into an #SBATCH line safely")
        }
        Some(s) => Ok(s),
    }
}

fn path_str(p: &Path) -> Result<&str> {
    script_path(Field::Dir, p)
}

/// A file name for an `#SBATCH` line, as sbatch's own parser reads it: `%` doubled (sbatch
/// expands `%j`, `%a` in a log name), and each space, `"`, `'` and `#` escaped with a
/// backslash (sbatch splits at spaces, pairs double quotes and ends the line at `#`). The
/// name holds no backslash or control character ([`script_path`]). `pattern` (e.g.
/// `task-%a.out`) is appended as it is.
pub fn sbatch_path(dir: &str, pattern: &str) -> String {
    let mut s = String::new();
    for c in dir.chars() {
        if c == '%' {
            s.push('%');
        } else if c.is_ascii_whitespace() || "\"'#".contains(c) {
            s.push('\\');
        }
        s.push(c);
    }
    s + pattern
}

/// The job-array script: task K rolls (or resumes) its shard from `DIR/shard-K` and puts its
/// `--json` result at `DIR/shard-K.json` by a rename, so that the file is whole or absent. A
/// task whose result is already there does nothing (a harmless rerun). `--requeue` lets the
/// scheduler requeue a task on a lost node; `--open-mode=append` keeps each attempt's log.
pub fn array_script(plan: &Plan, lay: &Layout, opt: &Options, bin: &Path) -> Result<String> {
    let dir = path_str(&lay.dir)?;
    let bin = script_path(Field::Bin, bin)?;
    let n = plan.tasks();
    let logs = lay.logs();
    let logs = path_str(&logs)?;
    let body = match plan {
        Plan::Roll { .. } => format!(
            "ckpt={d}/shard-$k\n\
             out={d}/shard-$k.json\n\
             if [ -s \"$out\" ]; then\n  echo \"task $k: $out is there already\"\n  exit 0\nfi\n\
             tmp={d}/.shard-$k.json.$SLURM_JOB_ID\n\
             {b} roll --resume \"$ckpt\" --threads {t} --json >\"$tmp\"\n\
             rc=$?\n\
             if [ $rc -ne 0 ]; then\n  rm -f \"$tmp\"\n  echo \"task $k: dicephys exited $rc; its checkpoint $ckpt is kept\" >&2\n  exit $rc\nfi\n\
             mv -f \"$tmp\" \"$out\"\n",
            d = quote(dir),
            b = quote(bin),
            t = opt.cpus,
        ),
        Plan::Study { .. } => format!(
            "done={d}/tasks/task-$k.done\n\
             if [ -e \"$done\" ]; then\n  echo \"task $k: done already ($done)\"\n  exit 0\nfi\n\
             exec {b} slurm task {d} \"$k\"\n",
            d = quote(dir),
            b = quote(bin),
        ),
    };
    Ok(format!(
        "#!/bin/bash\n\
         # dicephys {cmd}: task K of {n} (K = $SLURM_ARRAY_TASK_ID). Written by `dicephys slurm`.\n\
         #SBATCH --job-name=dicephys-{cmd}\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --requeue\n\
         #SBATCH --open-mode=append\n\
         #SBATCH --output={logs}\n\
         {extra}\
         k=${{SLURM_ARRAY_TASK_ID:?not a Slurm array task}}\n\
         echo \"task $k: job ${{SLURM_JOB_ID:-?}} on $(hostname), attempt $((${{SLURM_RESTART_COUNT:-0}} + 1))\"\n\
         {body}",
        cmd = plan.command(),
        last = n - 1,
        cpus = opt.cpus,
        logs = sbatch_path(logs, "/task-%a.out"),
        extra = opt.lines(),
    ))
}

/// The finishing job's script: `dicephys slurm finish DIR`, which refuses an incomplete run,
/// naming the missing tasks, and otherwise writes the merged result (again, if rerun).
pub fn finish_script(plan: &Plan, lay: &Layout, opt: &Options, bin: &Path) -> Result<String> {
    let d = quote(path_str(&lay.dir)?);
    let b = quote(script_path(Field::Bin, bin)?);
    let logs = lay.logs();
    let logs = path_str(&logs)?;
    Ok(format!(
        "#!/bin/bash\n\
         # dicephys {cmd}: merge the {n} tasks' results. Written by `dicephys slurm`.\n\
         #SBATCH --job-name=dicephys-{cmd}-finish\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --open-mode=append\n\
         #SBATCH --output={logs}\n\
         {extra}\
         {run}",
        run = match plan {
            Plan::Roll { .. } => format!("exec {b} slurm finish {d}\n"),
            // The study's report is its standard output: kept whole in DIR/result.txt.
            Plan::Study { .. } => format!(
                "tmp={d}/.result.txt.${{SLURM_JOB_ID:-$$}}\n\
                 {b} slurm finish {d} >\"$tmp\"\n\
                 rc=$?\n\
                 if [ $rc -ne 0 ]; then\n  rm -f \"$tmp\"\n  exit $rc\nfi\n\
                 mv -f \"$tmp\" {d}/result.txt\n\
                 echo \"dicephys {cmd}: {n} tasks assembled into {d}\"\n",
                cmd = plan.command(),
                n = plan.tasks(),
            ),
        },
        cmd = plan.command(),
        n = plan.tasks(),
        logs = sbatch_path(logs, "/finish.out"),
        extra = opt.lines(),
        cpus = match plan {
            // The finishing jobs of `tradeoff` and of a fit's second stage (its widening
            // passes) may roll on; the others only read and write.
            Plan::Study { threads, .. } => *threads,
            Plan::Roll { .. } => 1,
        },
    ))
}
