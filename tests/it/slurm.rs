//! `dicephys slurm` against a real scheduler: the one-node cluster of
//! `scripts/slurm-local.sh start` (`.ci/run` starts it). Without `sbatch`, or with no cluster
//! answering, each test says why on stderr and passes without running. The scripts `slurm`
//! writes are also run by hand, as Slurm runs them, with no scheduler: a directory's name
//! quoted for the shell and sbatch or refused, and `slurm finish` naming a damaged shard or
//! chunk whose task, rerun, replaces it.

use super::helpers::json;
use super::helpers::{bin, edit_rolls, scratch, stderr, walk, Scratch};
use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The cluster has two cores: one Slurm test at a time.
static CLUSTER: Mutex<()> = Mutex::new(());

/// Runs a command with a time limit; its stdout if it succeeded.
fn run_for(cmd: &mut Command, limit: Duration) -> Option<String> {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => {
                let out = child.wait_with_output().ok()?;
                return status
                    .success()
                    .then(|| String::from_utf8_lossy(&out.stdout).into_owned());
            }
            Ok(None) if start.elapsed() < limit => std::thread::sleep(Duration::from_millis(100)),
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                return None;
            }
        }
    }
}

/// A Slurm test that cannot run: under CI (`CI` set, where `.ci/run` starts a cluster, so a
/// missing one is a fault) it fails; elsewhere it says so on a line of the test run's own
/// output (written past the harness's capture, so that it shows beside "ok"), never a
/// silent pass.
fn skipped<T>(test: &str, why: &str) -> Option<T> {
    if std::env::var_os("CI").is_some() {
        panic!("{test}: {why}, and CI is set: .ci/run starts a one-node cluster for these tests");
    }
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "\n{test}: SKIPPED: {why}");
    None
}

/// Some(guard) when a cluster answers; None (with the reason printed) when the test is skipped.
fn cluster(test: &str) -> Option<std::sync::MutexGuard<'static, ()>> {
    let guard = CLUSTER.lock().unwrap_or_else(|e| e.into_inner());
    let on_path = std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join("sbatch").is_file()));
    if !on_path {
        return skipped(test, "no sbatch here (apt-get install slurm-wlm munge)");
    }
    match run_for(
        Command::new("sinfo").args(["-h", "-o", "%t"]),
        Duration::from_secs(15),
    ) {
        Some(states) if !states.trim().is_empty() => Some(guard),
        _ => skipped(
            test,
            "no Slurm cluster answers (scripts/slurm-local.sh start)",
        ),
    }
}

fn tmp(name: &str) -> Scratch {
    Scratch::absent(&format!("slurm-{name}"))
}

/// `dicephys slurm COMMAND RUN --tasks N --dir D --submit`: the array's and the finisher's ids.
fn submit(command: &str, run: &[&str], tasks: u64, dir: &Path) -> (String, String) {
    let out = bin()
        .args(["slurm", command])
        .args(run)
        .args(["--tasks", &tasks.to_string(), "--dir"])
        .arg(dir)
        .arg("--submit")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "slurm {command} --submit: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    // "array job A (N tasks), finishing job F"
    let line = text.lines().next().unwrap_or("");
    let words: Vec<&str> = line.split_whitespace().collect();
    assert!(
        words.len() == 8 && words[0] == "array" && words[5] == "finishing",
        "unexpected: {text}"
    );
    (words[2].to_string(), words[7].to_string())
}

/// What the scheduler says about these jobs, and the logs, for a failure message.
fn diagnose(jobs: &[&str], dir: &Path) -> String {
    let sh = |args: &[&str]| {
        Command::new(args[0])
            .args(&args[1..])
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
            .unwrap_or_default()
    };
    let mut s = sh(&["squeue"]);
    for j in jobs {
        s += &sh(&["scontrol", "show", "job", j]);
    }
    if let Ok(d) = std::fs::read_dir(dir.join("logs")) {
        for e in d.flatten() {
            s += &format!(
                "--- {}\n{}",
                e.path().display(),
                std::fs::read_to_string(e.path()).unwrap_or_default()
            );
        }
    }
    s
}

/// Waits until none of `jobs` is queued or running.
fn wait_gone(jobs: &[&str], dir: &Path, limit: Duration) {
    let start = Instant::now();
    let list = jobs.join(",");
    loop {
        let q = Command::new("squeue")
            .args(["-h", "-o", "%i %t", "-j", &list])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&q.stdout);
        if q.status.success() && text.trim().is_empty() {
            return;
        }
        assert!(
            start.elapsed() < limit,
            "jobs {list} still queued after {limit:?}:\n{}",
            diagnose(jobs, dir)
        );
        std::thread::sleep(Duration::from_millis(500));
    }
}

fn result(dir: &Path, jobs: &[&str]) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("result.json"))
        .unwrap_or_else(|e| panic!("no result.json ({e}):\n{}", diagnose(jobs, dir)));
    serde_json::from_str(&text).unwrap()
}

const SMALL: [&str; 6] = ["--block", "140x24x20", "--rolls", "2000", "--threads", "1"];

#[test]
fn a_four_task_roll_through_slurm_merges_to_the_one_machine_counts() {
    let Some(_cluster) = cluster("slurm roll") else {
        return;
    };
    let dir = tmp("roll");
    let (array, fin) = submit("roll", &SMALL, 4, &dir);
    let whole = json(
        &bin()
            .arg("roll")
            .args(SMALL)
            .arg("--json")
            .output()
            .unwrap(),
    );
    wait_gone(&[&array, &fin], &dir, Duration::from_secs(90));
    let merged = result(&dir, &[&array, &fin]);
    assert_eq!(merged["tally"], whole["tally"]);
    assert_eq!(merged["counts"], whole["counts"]);
    assert_eq!(merged["spec"], whole["spec"]);
    // The finishing step is harmless to rerun: the same counts again.
    let again = bin().args(["slurm", "finish"]).arg(&dir).output().unwrap();
    assert!(again.status.success());
    assert_eq!(result(&dir, &[])["tally"], whole["tally"]);
    // With a task's result gone it refuses, naming the task.
    std::fs::remove_file(dir.join("shard-2.json")).unwrap();
    let out = bin().args(["slurm", "finish"]).arg(&dir).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("have not finished: 2 ") && err.contains("--array=2"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A die given as a mesh (`--die FILE.obj`) through Slurm: the tasks read no file (the hull
/// travels in the plan's specification), and the merged faces are the one machine's.
#[test]
fn a_mesh_die_through_slurm_is_the_one_machine_roll() {
    let Some(_cluster) = cluster("slurm roll --die mesh") else {
        return;
    };
    let dir = tmp("roll-mesh");
    let obj = Scratch::new("slurm-mesh-die");
    let file = obj.path().join("irregular.obj");
    std::fs::write(&file, super::shapes::IRREGULAR_OBJ).unwrap();
    let path = file.to_str().unwrap();
    let run = ["--die", path, "--rolls", "600", "--threads", "1"];
    let (array, fin) = submit("roll", &run, 3, &dir);
    let whole = json(&bin().arg("roll").args(run).arg("--json").output().unwrap());
    wait_gone(&[&array, &fin], &dir, Duration::from_secs(90));
    let merged = result(&dir, &[&array, &fin]);
    assert_eq!(merged["faces"], whole["faces"]);
    assert_eq!(merged["shape"], whole["shape"]);
    assert_eq!(merged["spec"], whole["spec"]);
    let _ = std::fs::remove_dir_all(&dir);
    // `slurm fair` judges the merged faces as `fair` does on one machine.
    let dir = tmp("fair-mesh");
    let judged = [&run[..], &["--null", "quasi-static"]].concat();
    let (array, fin) = submit("fair", &judged, 3, &dir);
    let whole = json(
        &bin()
            .arg("fair")
            .args(&judged)
            .arg("--json")
            .output()
            .unwrap(),
    );
    wait_gone(&[&array, &fin], &dir, Duration::from_secs(90));
    let merged = result(&dir, &[&array, &fin]);
    assert_eq!(merged["fairness"], whole["fairness"]);
    assert_eq!(merged["summary"]["spec"], whole["summary"]["spec"]);
    assert_eq!(merged["fairness"]["null"], "quasi-static");
    let text = std::fs::read_to_string(dir.join("result.txt")).unwrap();
    assert!(text.contains("quasi-static"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_task_cancelled_mid_run_and_requeued_resumes_and_the_counts_still_match() {
    let Some(_cluster) = cluster("slurm roll, a task cancelled") else {
        return;
    };
    // DicePhys's rule with every step stepped: ~2 ms a roll, so a task of 1,500 rolls runs
    // a few seconds and checkpoints its first 1,000 before it ends.
    let run = [
        "--block",
        "140x24x20",
        "--rolls",
        "6000",
        "--faithful",
        "--threads",
        "1",
    ];
    let dir = tmp("requeue");
    let (array, fin) = submit("roll", &run, 4, &dir);
    let reference = bin()
        .arg("roll")
        .args(run)
        .arg("--json")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Cancel task 0 once its first chunk is checkpointed and before it has finished.
    let chunk = || crate::helpers::has_chunk(&dir.join("shard-0"));
    let start = Instant::now();
    while !chunk() {
        assert!(
            start.elapsed() < Duration::from_secs(90),
            "task 0 checkpointed nothing in 90 s:\n{}",
            diagnose(&[&array, &fin], &dir)
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let task = format!("{array}_0");
    assert!(
        !dir.join("shard-0.json").exists(),
        "task 0 ended before it could be cancelled"
    );
    let ok = Command::new("scancel").arg(&task).status().unwrap();
    assert!(ok.success(), "scancel {task}");
    // Requeue it (the scheduler may take a moment to record the cancel).
    let start = Instant::now();
    loop {
        let out = Command::new("scontrol")
            .args(["requeue", &task])
            .output()
            .unwrap();
        if out.status.success() {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "scontrol requeue {task}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    wait_gone(&[&array, &fin], &dir, Duration::from_secs(150));
    let whole = json(&reference.wait_with_output().unwrap());
    let merged = result(&dir, &[&array, &fin]);
    assert_eq!(merged["tally"], whole["tally"]);
    assert_eq!(merged["counts"], whole["counts"]);
    let log = std::fs::read_to_string(dir.join("logs/task-0.out")).unwrap();
    assert!(
        log.contains("attempt 2"),
        "task 0 was not run again:\n{log}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A results.csv without its last column, the CPU time per roll (the only column that is
/// measured rather than counted).
fn counted(csv: &Path) -> Vec<String> {
    std::fs::read_to_string(csv)
        .unwrap_or_else(|e| panic!("{}: {e}", csv.display()))
        .lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(head, _)| head).to_string())
        .collect()
}

/// The paper's 20 cells through four tasks, count for count the one machine's. 300 rolls a cell:
/// an equality, as strict at 300 as at 1,000 (which held the cluster for 17 s of the reference's
/// rolling while the other Slurm tests waited for it).
#[test]
fn paper_through_slurm_writes_the_one_machine_results() {
    let Some(_cluster) = cluster("slurm paper") else {
        return;
    };
    let dir = tmp("paper");
    let run = ["--rolls", "300", "--threads", "1"];
    let (array, fin) = submit("paper", &run, 4, &dir);
    let one = tmp("paper-one");
    let status = bin()
        .arg("paper")
        .args(run)
        .arg("--out")
        .arg(&one)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    wait_gone(&[&array, &fin], &dir, Duration::from_secs(600));
    assert!(
        dir.join("results.csv").exists() && dir.join("result.txt").exists(),
        "no results:\n{}",
        diagnose(&[&array, &fin], &dir)
    );
    let (a, b) = (
        counted(&one.join("results.csv")),
        counted(&dir.join("results.csv")),
    );
    assert_eq!(a.len(), 21, "20 cells and a header");
    assert_eq!(
        a, b,
        "the cluster's counts, ratios and z are the one machine's"
    );
    let report = std::fs::read_to_string(dir.join("result.txt")).unwrap();
    assert!(report.contains("140x24x20"), "{report}");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&one);
}

/// The study path without a scheduler: the scripts written, each task run by hand as the array
/// would (`slurm task DIR K`), then the finishing step; its comparison is the one machine's.
#[test]
fn a_crosscheck_split_by_hand_into_tasks_assembles_to_the_one_machine_comparison() {
    let dir = tmp("by-hand");
    let run = [
        "crosscheck",
        "--block",
        "140x22x13",
        "--rolls",
        "2500",
        "--json",
    ];
    let slurm = |args: &[&str]| bin().arg("slurm").args(args).output().unwrap();
    let d = dir.to_str().unwrap();
    let out = slurm(&[&run[..], &["--tasks", "3", "--dir", d]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("slurm task"));
    // Before any task has run, the finishing step names all three.
    let early = slurm(&["finish", d]);
    assert_eq!(early.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&early.stderr).contains("have not finished: 0, 1, 2 "));
    for k in ["0", "1", "2"] {
        let t = slurm(&["task", d, k]);
        assert!(
            t.status.success(),
            "task {k}: {}",
            String::from_utf8_lossy(&t.stderr)
        );
        assert!(t.stdout.is_empty(), "a task reports nothing");
    }
    let assembled = json(&slurm(&["finish", d]));
    let whole = json(&bin().args(run).output().unwrap());
    assert_eq!(assembled["runs"][0]["tally"], whole["runs"][0]["tally"]);
    assert_eq!(assembled["runs"][1]["tally"], whole["runs"][1]["tally"]);
    assert_eq!(assembled["versus"][0]["z"], whole["versus"][0]["z"]);
    assert_eq!(
        assembled["versus"][0]["same_outcome_fraction"],
        whole["versus"][0]["same_outcome_fraction"]
    );
    // A chunk lost after its task was marked done: the finishing step refuses, rolling nothing.
    // The first cell's directory (beside it, dicephys-run.json names the run).
    let cell = std::fs::read_dir(dir.join("checkpoint"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.is_dir())
        .unwrap();
    let chunk = cell.join("chunk-000000001000-1000.json");
    std::fs::rename(&chunk, dir.join("lost.json")).unwrap();
    let lost = slurm(&["finish", d]);
    assert_eq!(lost.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&lost.stderr).contains("were never rolled"));
    std::fs::rename(dir.join("lost.json"), &chunk).unwrap();
    // A task out of range, and a study's own output flag, are refused as bad input.
    assert_eq!(slurm(&["task", d, "3"]).status.code(), Some(2));
    let own = slurm(&["paper", "--out", "x", "--tasks", "2", "--dir", d]);
    assert_eq!(own.status.code(), Some(2));
    // A study's bad input is refused before anything is stored or submitted (a dry run).
    let bad = tmp("by-hand-bad");
    let b = bad.to_str().unwrap();
    let out = slurm(&[
        "tradeoff",
        "--reference-dt",
        "1/100",
        "--preroll",
        "1000",
        "--tasks",
        "2",
        "--dir",
        b,
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--reference-dt"));
    assert!(!bad.join("slurm.json").exists());
    let _ = std::fs::remove_dir_all(&bad);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `tradeoff` decides its rounds from all the rolls so far, which no task sees: its tasks roll
/// ahead (`--preroll`) and the finishing job runs the study itself, reading their chunks back.
/// Its rows are the one machine's, roll for roll.
#[test]
fn a_tradeoff_rolled_ahead_by_tasks_finishes_as_on_one_machine() {
    let dir = tmp("tradeoff");
    let d = dir.to_str().unwrap();
    let study = [
        "--precision",
        "30",
        "--dts",
        "1/250",
        "--rapier-dts",
        "1/250",
        "--reference-dt",
        "1/1000",
        "--ladder",
        "1/2000",
        "--json",
    ];
    let slurm = |args: &[&str]| bin().arg("slurm").args(args).output().unwrap();
    // Without --preroll it is refused, saying why.
    let plain = slurm(&[&["tradeoff"], &study[..], &["--tasks", "2", "--dir", d]].concat());
    assert_eq!(plain.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&plain.stderr).contains("--preroll"));
    let ahead = [
        &["tradeoff"],
        &study[..],
        &["--preroll", "1000", "--tasks", "2", "--dir", d],
    ];
    assert!(slurm(&ahead.concat()).status.success());
    for k in ["0", "1"] {
        assert!(slurm(&["task", d, k]).status.success(), "task {k}");
    }
    let finished = json(&slurm(&["finish", d]));
    let one = tmp("tradeoff-one");
    let whole = json(
        &bin()
            .arg("tradeoff")
            .args(study)
            .arg("--out")
            .arg(&one)
            .output()
            .unwrap(),
    );
    let rows = |v: &serde_json::Value| -> Vec<(String, serde_json::Value, serde_json::Value)> {
        v["modes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| m["rows"].as_array().unwrap().clone())
            .map(|r| {
                (
                    r["method"].to_string(),
                    r["rolls"].clone(),
                    r["ratio"].clone(),
                )
            })
            .collect()
    };
    assert!(!rows(&whole).is_empty());
    assert_eq!(rows(&finished), rows(&whole));
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&one);
}

/// The counts of a small fit (two 2D MDF blocks) and its flags: 20 points × 100 rolls a block.
fn small_fit(dir: &Path) -> Vec<String> {
    let csv = dir.join("counts.csv");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        &csv,
        "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,\
         width_vertical\na,MDF,140,24,20,2d,0,361,639\nb,MDF,140,30,10,2d,0,40,460\n",
    )
    .unwrap();
    // Seed 7: passes 3 and 4 tighten the box, the fourth cuts it, and a fifth widens it: five
    // passes, each rolled (seed 8 did so until the bootstrap rolled the design again).
    let flags = "--free e,mu --points 20 --degree 2 --rolls 100 --dt 1/250 --seed 7 --json";
    let mut v = vec!["--data".to_string(), csv.display().to_string()];
    v.extend(flags.split(' ').map(String::from));
    v
}

/// What makes two fits the same fit: everything but the cost, the command line and the date.
fn same_fit(a: &serde_json::Value, b: &serde_json::Value) {
    for key in [
        "config",
        "estimate",
        "designs",
        "params",
        "first_pass",
        "passes",
    ] {
        assert_eq!(a[key], b[key], "{key} differs");
    }
    assert_eq!(a["cost"]["rolls"], b["cost"]["rolls"]);
}

/// `slurm fit` by hand: the first pass's tasks and finishing step, then the second's (its box
/// narrowed from the first's result); the fit is the one machine's, bit for bit. The second
/// pass before the first has finished is refused, saying why.
#[test]
fn a_fit_split_by_hand_into_two_passes_is_the_one_machine_fit() {
    let dir = tmp("fit-by-hand");
    let (run, one) = (dir.join("run"), dir.join("one"));
    let fit = small_fit(&dir);
    let fit: Vec<&str> = fit.iter().map(String::as_str).collect();
    let slurm = |args: &[&str]| bin().arg("slurm").args(args).output().unwrap();
    let d = run.to_str().unwrap();
    let first = format!("{d}/first-pass");
    let out = slurm(&[&["fit"], &fit[..], &["--tasks", "2", "--dir", d]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("--dependency=afterok:"), "{text}");
    let early = slurm(&["task", d, "0"]);
    assert_eq!(early.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&early.stderr).contains("the first pass has not finished"));
    for k in ["0", "1"] {
        assert!(slurm(&["task", &first, k]).status.success(), "task {k}");
    }
    let first_pass = json(&slurm(&["finish", &first]));
    assert!(first_pass["first_pass"].is_null());
    for k in ["0", "1"] {
        assert!(slurm(&["task", d, k]).status.success(), "task {k}");
    }
    let split = json(&slurm(&["finish", d]));
    let whole = json(
        &bin()
            .arg("fit")
            .args(&fit)
            .arg("--out")
            .arg(&one)
            .output()
            .unwrap(),
    );
    assert!(whole["first_pass"].is_array(), "the default fit refines");
    // The passes after the second tighten e's box until one cuts it, then widen it: the
    // second stage's finishing job rolls them itself.
    let passes = whole["passes"].as_array().unwrap();
    assert!(
        passes.len() > 3 && passes.iter().any(|p| p["cut"].is_array()),
        "{passes:?}"
    );
    assert!(
        passes.iter().all(|p| p["rolls"].as_u64() > Some(0)),
        "{passes:?}"
    );
    same_fit(&split, &whole);
    assert!(run.join("report.md").exists() && run.join("fit_rows.svg").exists());
    // Its own flags are refused: --recover runs on one machine, --out is --dir.
    for (flag, value) in [("--recover", "e=0.5,mu=0.3"), ("--out", "x")] {
        let bad = tmp("fit-by-hand-bad");
        let b = bad.to_str().unwrap();
        let args = [
            &["fit"],
            &fit[..],
            &[flag, value, "--tasks", "2", "--dir", b],
        ];
        let out = slurm(&args.concat());
        assert_eq!(out.status.code(), Some(2), "{flag}");
        assert!(String::from_utf8_lossy(&out.stderr).contains(flag));
        assert!(!bad.exists(), "{flag}: nothing made");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The job ids a two-stage submission prints: "first pass: array job A (2 tasks), finishing
/// job F" and the same for the second pass.
fn two_stage_jobs(stdout: &[u8]) -> Vec<String> {
    let text = String::from_utf8_lossy(stdout);
    text.lines()
        .take(2)
        .flat_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            assert!(w.len() == 10 && w[2] == "array", "unexpected: {text}");
            [w[4].to_string(), w[9].to_string()]
        })
        .collect()
}

/// `slurm fit --submit` on the one-node cluster: four jobs chained (each pass's array and its
/// finishing job, the second pass after the first's); the fit is the one machine's.
#[test]
fn a_fit_through_slurm_is_the_one_machine_fit() {
    let Some(_cluster) = cluster("slurm fit") else {
        return;
    };
    let dir = tmp("fit");
    let run = dir.join("run");
    let fit = small_fit(&dir);
    let out = bin()
        .args(["slurm", "fit"])
        .args(&fit)
        .args(["--tasks", "2", "--dir"])
        .arg(&run)
        .arg("--submit")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let jobs = two_stage_jobs(&out.stdout);
    let jobs: Vec<&str> = jobs.iter().map(String::as_str).collect();
    let whole = json(
        &bin()
            .arg("fit")
            .args(&fit)
            .arg("--out")
            .arg(dir.join("one"))
            .output()
            .unwrap(),
    );
    wait_gone(&jobs, &run, Duration::from_secs(600));
    let text = std::fs::read_to_string(run.join("fit.json"))
        .unwrap_or_else(|e| panic!("no fit.json ({e}):\n{}", diagnose(&jobs, &run)));
    same_fit(&serde_json::from_str(&text).unwrap(), &whole);
    let _ = std::fs::remove_dir_all(&dir);
}

/// What makes two calibrated papers the same: everything but the costs, the command line and
/// the date.
fn same_calibrated(a: &serde_json::Value, b: &serde_json::Value) {
    for key in ["loo", "theory", "models", "decisions", "check", "rolls"] {
        assert_eq!(a[key], b[key], "{key} differs");
    }
    same_fit(&a["fit"], &b["fit"]);
}

/// `slurm paper --calibrated --submit` on the one-node cluster: two chained stages (every
/// model's first pass, then every model's second pass, whose finishing job rolls the widening
/// passes and the method check and runs the leave-one-out fits); the study is the one
/// machine's, bit for bit. At a tiny size (40 points × 10 rolls a block, dt = 1/250 s, no
/// bootstrap, 2 starts, profiles of 5 points): about 40,000 rolls each way, but about five CPU
/// minutes each (the four models' estimates and 76 leave-one-out fits on designs this noisy),
/// which CI's time cannot hold: run it with `cargo test --release -- --ignored` beside the
/// one-node cluster (it passed at the commit that added it).
#[test]
#[ignore = "ten CPU minutes: cargo test --release -- --ignored, with scripts/slurm-local.sh"]
fn the_calibrated_paper_through_slurm_is_the_one_machine_paper() {
    let Some(_cluster) = cluster("slurm paper --calibrated") else {
        return;
    };
    let dir = tmp("calibrated");
    let run = dir.join("run");
    let flags = [
        "--calibrated",
        "--points",
        "40",
        "--point-rolls",
        "10",
        "--check-rolls",
        "10",
        "--dt",
        "1/250",
        "--bootstrap",
        "0",
        "--starts",
        "2",
        "--profile-points",
        "5",
        "--seed",
        "3",
        "--threads",
        "1",
    ];
    let out = bin()
        .args(["slurm", "paper"])
        .args(flags)
        .args(["--tasks", "2", "--dir"])
        .arg(&run)
        .arg("--submit")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let jobs = two_stage_jobs(&out.stdout);
    let jobs: Vec<&str> = jobs.iter().map(String::as_str).collect();
    let one = bin()
        .arg("paper")
        .args(flags)
        .arg("--json")
        .arg("--out")
        .arg(dir.join("one"))
        .output()
        .unwrap();
    let whole = json(&one);
    wait_gone(&jobs, &run, Duration::from_secs(1200));
    let text = std::fs::read_to_string(run.join("calibrated.json"))
        .unwrap_or_else(|e| panic!("no calibrated.json ({e}):\n{}", diagnose(&jobs, &run)));
    same_calibrated(&serde_json::from_str(&text).unwrap(), &whole);
    assert!(run.join("first-pass").join("first-passes.json").exists());
    assert!(run.join("calibrated.md").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// The scripts `slurm` writes, run by hand as Slurm runs them: no scheduler needed.

/// The value of `#SBATCH --NAME=...` in `script`, read as sbatch's own parser reads it
/// (Slurm's `_get_argument`: a backslash escapes the next character, double quotes group, an
/// unescaped `#` ends the line; single quotes are plain characters).
fn sbatch_value(script: &str, name: &str) -> Option<String> {
    let line = script
        .lines()
        .filter_map(|l| l.strip_prefix("#SBATCH "))
        .find(|l| l.trim_start().starts_with(&format!("--{name}=")))?;
    let (mut arg, mut escaped, mut quoted) = (String::new(), false, false);
    for c in line.trim_start().chars() {
        if escaped {
            escaped = false;
            arg.push(c);
        } else if c == '\\' {
            escaped = true;
        } else if c == '"' {
            quoted = !quoted;
        } else if c == '#' || (!quoted && c.is_ascii_whitespace()) {
            break;
        } else {
            arg.push(c);
        }
    }
    assert!(!quoted, "sbatch: unmatched quote in {line}");
    Some(arg.split_once('=').unwrap().1.to_string())
}

/// A binary that records what it was given (in `$FAKE_ARGS`) and prints a result.
fn fake_dicephys(d: &Path) -> std::path::PathBuf {
    let fake = d.join("fake-dicephys");
    std::fs::write(
        &fake,
        "#!/bin/sh\nprintf '%s\\n' \"$@\" >\"$FAKE_ARGS\"\necho '{}'\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    fake
}

/// `slurm roll` of a small 2D run into `dir`, its tasks run by `fake`.
fn slurm_roll(d: &Path, fake: &Path, dir: &Path, extra: &[&str]) -> Output {
    bin()
        .args([
            "slurm",
            "roll",
            "--block",
            "140x22x13",
            "--2d",
            "--rolls",
            "20",
        ])
        .args(["--tasks", "2", "--bin"])
        .arg(fake)
        .arg("--dir")
        .arg(dir)
        .args(extra)
        .current_dir(d)
        .output()
        .unwrap()
}

#[test]
fn a_slurm_dir_name_is_quoted_for_the_shell_and_sbatch() {
    let d = scratch("slurm-names");
    let fake = fake_dicephys(&d);
    let run = |dir: &Path, extra: &[&str]| slurm_roll(&d, &fake, dir, extra);
    // A name with everything the shell or sbatch would read: it is written safely.
    let nasty = d.join("run x#y %j \"q' $(touch pwned) `touch pwned2`");
    let out = run(&nasty, &["--time", "1:00:00"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let array = std::fs::read_to_string(nasty.join("array.sh")).unwrap();
    let real = nasty.canonicalize().unwrap();
    let want = format!(
        "{}/logs/task-%a.out",
        real.to_str().unwrap().replace('%', "%%")
    );
    assert_eq!(
        sbatch_value(&array, "output").as_deref(),
        Some(&*want),
        "{array}"
    );
    assert_eq!(sbatch_value(&array, "time").as_deref(), Some("1:00:00"));
    let fin = std::fs::read_to_string(nasty.join("finish.sh")).unwrap();
    let want = format!(
        "{}/logs/finish.out",
        real.to_str().unwrap().replace('%', "%%")
    );
    assert_eq!(
        sbatch_value(&fin, "output").as_deref(),
        Some(&*want),
        "{fin}"
    );
    let args = d.join("args.txt");
    let task = Command::new("bash")
        .arg(nasty.join("array.sh"))
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_JOB_ID", "7")
        .env("FAKE_ARGS", &args)
        .current_dir(&*d)
        .output()
        .unwrap();
    assert_eq!(task.status.code(), Some(0), "{}", stderr(&task));
    assert!(!d.join("pwned").exists() && !d.join("pwned2").exists());
    let given = std::fs::read_to_string(&args).unwrap();
    let ckpt = format!("{}/shard-1", real.to_str().unwrap());
    assert!(given.lines().any(|l| l == ckpt), "{given}");
    assert!(nasty.join("shard-1.json").exists());
}

#[test]
fn a_slurm_dir_name_or_flag_that_cannot_be_written_safely_is_refused() {
    let d = scratch("slurm-names-refused");
    let fake = fake_dicephys(&d);
    let run = |dir: &Path, extra: &[&str]| slurm_roll(&d, &fake, dir, extra);
    // What cannot be written safely is refused, with one line, before anything is stored.
    for (dir, extra) in [
        (d.join("a\nb"), &[][..]),
        (d.join("a\\b"), &[][..]),
        (d.join("ok1"), &["--account", "a#b"][..]),
        (d.join("ok2"), &["--partition", "p\"q"][..]),
        (d.join("ok3"), &["--time", "1:00 %j"][..]),
        (d.join("ok4"), &["--time", "1'00"][..]),
    ] {
        let out = run(&dir, extra);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{dir:?} {extra:?}: {}",
            stderr(&out)
        );
        assert_eq!(stderr(&out).lines().count(), 1, "{}", stderr(&out));
        assert!(!dir.exists(), "{dir:?}: made although refused");
    }
    // A study refused by its dry run leaves no directory either.
    let st = d.join("st");
    let out = bin()
        .args([
            "slurm",
            "stability",
            "--rolls",
            "0",
            "--tasks",
            "2",
            "--dir",
        ])
        .arg(&st)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!st.exists(), "a refused run left its directory");
}

/// Runs task `k` of the array script in `dir` as Slurm would.
fn array_task(dir: &Path, k: u64) -> Output {
    let out = Command::new("bash")
        .arg(dir.join("array.sh"))
        .env("SLURM_ARRAY_TASK_ID", k.to_string())
        .env("SLURM_JOB_ID", "7")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "task {k}: {}", stderr(&out));
    out
}

fn slurm(args: &[&std::ffi::OsStr]) -> Output {
    bin().arg("slurm").args(args).output().unwrap()
}

#[test]
fn slurm_finish_names_a_damaged_shard_and_rerunning_its_task_replaces_it() {
    let d = scratch("damaged-shard");
    let dir = d.join("run");
    let out = bin()
        .args([
            "slurm",
            "roll",
            "--block",
            "140x22x13",
            "--2d",
            "--rolls",
            "40",
        ])
        .args(["--tasks", "2", "--dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let finish = || slurm(&["finish".as_ref(), dir.as_os_str()]);
    array_task(&dir, 0);
    array_task(&dir, 1);
    assert_eq!(finish().status.code(), Some(0));
    let counts = |p: &Path| {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        v["tally"].clone()
    };
    let truth = counts(&dir.join("result.json"));
    // A count edited in task 1's result, the file still JSON: named, never merged.
    let shard = dir.join("shard-1.json");
    let text = std::fs::read_to_string(&shard).unwrap();
    let w = text.find("\"width\": ").unwrap() + 9;
    std::fs::write(&shard, format!("{}1{}", &text[..w], &text[w..])).unwrap();
    let bad = finish();
    assert_eq!(bad.status.code(), Some(1), "{}", stderr(&bad));
    assert!(stderr(&bad).contains("shard-1.json"), "{}", stderr(&bad));
    assert!(stderr(&bad).contains("--array=1 "), "{}", stderr(&bad));
    // The advice, followed, works: the task writes its result again, and finish merges.
    let rerun = array_task(&dir, 1);
    assert!(
        !String::from_utf8_lossy(&rerun.stdout).contains("there already"),
        "the rerun task kept the damaged result"
    );
    let ok = finish();
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    assert_eq!(counts(&dir.join("result.json")), truth);
}

#[test]
fn slurm_finish_names_a_damaged_study_chunk_and_rerunning_its_task_replaces_it() {
    let d = scratch("damaged-study");
    let dir = d.join("run");
    let out = bin()
        .args([
            "slurm",
            "crosscheck",
            "--block",
            "140x22x13",
            "--rolls",
            "2000",
        ])
        .args(["--json", "--tasks", "2", "--dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let finish = || slurm(&["finish".as_ref(), dir.as_os_str()]);
    array_task(&dir, 0);
    array_task(&dir, 1);
    let first = finish();
    let tallies = |o: &Output| {
        assert_eq!(o.status.code(), Some(0), "{}", stderr(o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        [v["runs"][0]["tally"].clone(), v["runs"][1]["tally"].clone()]
    };
    let truth = tallies(&first);
    // Damage a chunk of each task in turn (the first and the last of the four): finish names
    // it and its task, and rerunning that task (by the array script, which skips a task
    // marked done) rolls it again.
    let mut chunks: Vec<_> = walk(&dir.join("checkpoint"))
        .into_iter()
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("chunk-")
        })
        .collect();
    chunks.sort();
    assert_eq!(chunks.len(), 4);
    for chunk in [&chunks[0], &chunks[3]] {
        let text = std::fs::read_to_string(chunk).unwrap();
        let bad = edit_rolls(&text);
        assert_ne!(bad, text);
        std::fs::write(chunk, bad).unwrap();
        let refused = finish();
        assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
        let e = stderr(&refused);
        assert!(e.contains(&*chunk.to_string_lossy()), "{e}");
        let k = e
            .split("--array=")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|s| s.parse::<u64>().ok())
            .unwrap_or_else(|| panic!("no task named: {e}"));
        let rerun = array_task(&dir, k);
        assert!(
            !String::from_utf8_lossy(&rerun.stdout).contains("done already"),
            "the task's mark kept it from rolling the chunk again"
        );
        assert_eq!(tallies(&finish()), truth);
    }
}
