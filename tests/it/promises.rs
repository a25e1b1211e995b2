//! The promises of the README's "What dicephys promises" (docs/guide.md, "What dicephys
//! promises") about stopping, streams and bad input: Ctrl-C and SIGTERM in every kind of run,
//! a full or closed stdout, outputs onto links, FIFOs and directories, `merge`'s inputs, and
//! a resumed run's rows. Each probe, at a small size, failed once before its fix.

use super::helpers::{bin, signal_running, Scratch, ENDLESS_ROLLS};
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};
use std::time::Duration;

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("red-{name}"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn roll(args: &[&str]) -> Output {
    bin()
        .args(["roll", "--block", "140x24x20"])
        .args(args)
        .output()
        .unwrap()
}

/// No file of ours beside `dir`'s own entries: no `NAME.tmp-PID`, no `.NAME.*.tmp`.
fn no_temp_files(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let n = e.file_name().to_string_lossy().into_owned();
        assert!(!n.contains(".tmp"), "temporary file left behind: {n}");
    }
}

// 1. Output paths are written, not replaced.

#[test]
fn per_roll_onto_a_symlink_writes_its_target_and_keeps_the_link() {
    let d = scratch("symlink");
    let target = d.join("target.csv");
    std::fs::write(&target, "old").unwrap();
    let link = d.join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let out = roll(&["--rolls", "20", "--per-roll", link.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let text = std::fs::read_to_string(&target).unwrap();
    assert_eq!(
        text.lines().count(),
        21,
        "header and 20 rows in the link's target"
    );
    no_temp_files(&d);
}

#[test]
fn per_roll_onto_a_fifo_streams_into_it_and_leaves_it_a_fifo() {
    let d = scratch("fifo");
    let fifo = d.join("rows.csv");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = roll(&["--rolls", "20", "--per-roll", fifo.to_str().unwrap()]);
    // Should dicephys never have opened the FIFO, its reader would wait for ever: open and
    // close it once without blocking, which ends a waiting reader and does nothing otherwise.
    {
        use std::os::unix::fs::OpenOptionsExt;
        let _ = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(&fifo);
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(reader.join().unwrap().lines().count(), 21);
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

#[test]
fn an_output_that_is_a_directory_is_refused_before_anything_runs() {
    let d = scratch("dir-out");
    let out = roll(&["--rolls", "100000", "--per-roll", d.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(stderr(&out).trim_end().lines().count(), 1);
    assert!(out.stdout.is_empty(), "it ran before refusing");
    no_temp_files(&d);
}

// 2. merge reads its own output.

fn shard(args: &[&str], k: u64, n: u64, dir: &Path) -> PathBuf {
    let s = format!("{k}/{n}");
    let mut all = args.to_vec();
    all.extend(["--json", "--shard", &s]);
    let out = roll(&all);
    assert!(out.status.success(), "{}", stderr(&out));
    let f = dir.join(format!("s{k}.json"));
    std::fs::write(&f, &out.stdout).unwrap();
    f
}

#[test]
fn merge_reads_shards_whose_ratio_is_not_a_number() {
    let d = scratch("nan");
    // 4 rolls in 4 shards: a shard with no width outcome has no ratio (null in JSON).
    let files: Vec<PathBuf> = (0..4).map(|k| shard(&["--rolls", "4"], k, 4, &d)).collect();
    let out = bin()
        .arg("merge")
        .args(&files)
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    // Shards whose every roll is unconverged (a cap of 1 step).
    let files: Vec<PathBuf> = (0..2)
        .map(|k| shard(&["--rolls", "6", "--max-steps", "1"], k, 2, &d))
        .collect();
    let out = bin()
        .arg("merge")
        .args(&files)
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn merge_refuses_a_bad_shard_number_and_a_tally_that_does_not_add_up() {
    let d = scratch("bad-shard");
    let f = shard(&["--rolls", "10"], 0, 2, &d);
    let g = shard(&["--rolls", "10"], 1, 2, &d);
    let text = std::fs::read_to_string(&g).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["spec"]["shard"]["k"] = 5.into();
    // Sealed again (checksum recomputed): refused for its shard number, not its checksum.
    let v = dicephys::run::seal::sealed(&v).unwrap();
    std::fs::write(&g, v.to_string()).unwrap();
    let out = bin().arg("merge").arg(&f).arg(&g).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["tally"]["counts"]["width"] = 1000.into();
    let v = dicephys::run::seal::sealed(&v).unwrap();
    std::fs::write(&g, v.to_string()).unwrap();
    let out = bin().arg("merge").arg(&f).arg(&g).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!stderr(&out).contains("checksum"), "{}", stderr(&out));
}

// 3. A checkpoint holds one run's chunks: see reliability::a_checkpoint_directory_holds_one_run.

// 4. Every command stops the same way.

/// `args` run and sent `signal` after `after_ms`; the run must be long by construction
/// (`ENDLESS_ROLLS`), or it is refused as a test of nothing.
fn interrupted(args: &[&str], signal: i32, after_ms: u64) -> Output {
    let mut child = bin()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Its output is small until the end (a partial report), so an unread pipe cannot block it.
    signal_running(&mut child, signal, after_ms);
    child.wait_with_output().unwrap()
}

#[test]
fn sigterm_stops_a_roll_like_ctrl_c() {
    let d = scratch("sigterm");
    let ck = d.join("ck");
    let out = interrupted(
        &[
            "roll",
            "--block",
            "140x24x20",
            "--rolls",
            ENDLESS_ROLLS,
            "--json",
            "--checkpoint",
        ]
        .iter()
        .copied()
        .chain([ck.to_str().unwrap()])
        .collect::<Vec<_>>(),
        libc::SIGTERM,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["partial"], true);
    no_temp_files(&ck);
}

#[test]
fn a_slow_run_stops_within_a_roll_not_a_chunk() {
    // At dt = 1e-5 s a faithful 3D roll takes ~150,000 steps: a chunk takes minutes.
    let out = interrupted(
        &[
            "roll",
            "--block",
            "140x24x20",
            "--rolls",
            "1000",
            "--dt",
            "0.00001",
            "--faithful",
            "--threads",
            "1",
            "--json",
        ],
        libc::SIGINT,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
}

#[test]
fn crosscheck_stops_when_asked() {
    let out = interrupted(
        &[
            "crosscheck",
            "--block",
            "140x24x20",
            "--rolls",
            ENDLESS_ROLLS,
        ],
        libc::SIGINT,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
}

#[test]
fn paper_interrupted_leaves_the_complete_outputs_alone() {
    let d = scratch("paper");
    let o = d.to_str().unwrap();
    let full = bin()
        .args(["paper", "--rolls", "20", "--engines", "bullet", "--out", o])
        .output()
        .unwrap();
    assert!(full.status.success(), "{}", stderr(&full));
    let before = std::fs::read(d.join("results.json")).unwrap();
    let png = std::fs::read(d.join("prob_2d.png")).unwrap();
    // The directory is the 20-roll run's: another run is refused there (promises_files), so the
    // complete outputs are copied into a directory of no run's, and the slow run stopped there.
    let e = scratch("paper-again");
    std::fs::write(e.join("results.json"), &before).unwrap();
    std::fs::write(e.join("prob_2d.png"), &png).unwrap();
    let out = interrupted(
        &[
            "paper",
            "--rolls",
            ENDLESS_ROLLS,
            "--engines",
            "bullet",
            "--out",
            e.to_str().unwrap(),
        ],
        libc::SIGINT,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert_eq!(std::fs::read(e.join("results.json")).unwrap(), before);
    assert_eq!(std::fs::read(e.join("prob_2d.png")).unwrap(), png);
    no_temp_files(&e);
    no_temp_files(&d);
}

#[test]
fn a_sweep_stops_with_exit_130() {
    let d = scratch("sweep");
    let out = interrupted(
        &[
            "converge",
            "--blocks",
            "140x24x20",
            "--dts",
            "1/1000",
            "--engines",
            "bullet",
            "--rolls",
            ENDLESS_ROLLS,
            "--out",
            d.to_str().unwrap(),
        ],
        libc::SIGINT,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
}

// 6. Broken stdout.

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    for args in [
        &["roll", "--block", "140x24x20", "--rolls", "10", "--json"][..],
        &["trace", "--block", "140x24x20", "--max-steps", "50"][..],
        &["theory", "--table"][..],
    ] {
        let out = bin()
            .args(args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).trim_end().lines().count(),
            1,
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let mut child = bin()
        .args(["trace", "--block", "140x24x20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(stderr(&out).is_empty(), "{}", stderr(&out));
    assert_ne!(out.status.code(), Some(101), "panicked");
}

// 7. Accepted inputs that crashed.

#[test]
fn inputs_at_the_edges_get_one_line_and_exit_2() {
    for args in [
        &[
            "trace",
            "--block",
            "140x24x20",
            "--throws",
            "dicephys",
            "--index",
            "18446744073709551615",
        ][..],
        &["bench", "--rolls", "18446744073709551615"][..],
        &["roll", "--block", "1e-300x1e-300x1e-300", "--rolls", "10"][..],
        &["paper", "--threads", "5000", "--rolls", "10"][..],
        &["paper", "--rolls", "18446744073709551615"][..],
    ] {
        let out = bin().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).trim_end().lines().count(),
            1,
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

// 8. A resumed run writes what an uninterrupted one writes.

#[test]
fn a_resumed_run_writes_the_same_per_roll_rows_and_counts_its_whole_cost() {
    let d = scratch("resume");
    let args = [
        "roll",
        "--block",
        "140x22x13",
        "--2d",
        "--rolls",
        "8000",
        "--seed",
        "5",
    ];
    let whole_csv = d.join("whole.csv");
    let whole = bin()
        .args(args)
        .args(["--json", "--per-roll", whole_csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(whole.status.success());
    let ck = d.join("ck");
    // Killed with SIGKILL once its first chunk is on disk: on one thread the chunks come one
    // at a time, so seven of eight are still to roll, however many cores the machine has.
    let mut child = bin()
        .args(args)
        .args([
            "--threads",
            "1",
            "--json",
            "--checkpoint",
            ck.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let chunk_written = || {
        std::fs::read_dir(&ck)
            .map(|d| {
                d.flatten()
                    .any(|e| e.file_name().to_string_lossy().starts_with("chunk-"))
            })
            .unwrap_or(false)
    };
    for _ in 0..1200 {
        if chunk_written() {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(chunk_written(), "no chunk was checkpointed before the kill");
    assert_ne!(status.code(), Some(0), "finished before the kill");
    let resumed_csv = d.join("resumed.csv");
    let resumed = bin()
        .args(["roll", "--json", "--resume", ck.to_str().unwrap()])
        .args(["--per-roll", resumed_csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert_eq!(
        std::fs::read(&whole_csv).unwrap(),
        std::fs::read(&resumed_csv).unwrap(),
        "per-roll rows differ after resume"
    );
    let w: serde_json::Value = serde_json::from_slice(&whole.stdout).unwrap();
    let r: serde_json::Value = serde_json::from_slice(&resumed.stdout).unwrap();
    assert_eq!(w["tally"], r["tally"]);
    // The resumed run's cost includes the chunks rolled before the kill.
    let (wc, rc) = (w["cpu_s"].as_f64().unwrap(), r["cpu_s"].as_f64().unwrap());
    assert!(
        rc > 0.5 * wc,
        "resumed cost {rc} s against {wc} s uninterrupted"
    );
}
