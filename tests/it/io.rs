//! Every file a run writes goes through `run::io`: `--per-roll` to `/dev/stdout`, piped or
//! redirected; a new output's mode from the umask and an existing one's kept, a study's claim
//! on its directory included; a 250-byte name; a loop of links refused; the temporary files a
//! killed run left removed by the next run there. (`--per-roll` onto a link, a FIFO or a
//! directory: roll.rs.) Each probe, at a small size, failed on the build before its fix.

use super::helpers::{bin, roll, scratch, stderr};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::Path;

fn mode(p: &Path) -> u32 {
    std::fs::metadata(p).unwrap().permissions().mode() & 0o777
}

#[test]
fn per_roll_to_dev_stdout_piped_or_redirected_keeps_the_rows_and_the_summary() {
    let piped = roll(&["--json", "--per-roll", "/dev/stdout"])
        .output()
        .unwrap();
    assert_eq!(piped.status.code(), Some(0), "{}", stderr(&piped));
    let d = scratch("stdout");
    let file = d.join("out.txt");
    let redirected = roll(&["--json", "--per-roll", "/dev/stdout"])
        .stdout(std::fs::File::create(&file).unwrap())
        .output()
        .unwrap();
    assert_eq!(redirected.status.code(), Some(0), "{}", stderr(&redirected));
    for text in [
        String::from_utf8(piped.stdout).unwrap(),
        std::fs::read_to_string(&file).unwrap(),
    ] {
        let (csv, json) = text.split_at(text.find('{').expect("the JSON summary"));
        assert!(csv.starts_with("index,"), "{text}");
        assert_eq!(csv.lines().count(), 21, "{text}");
        let v: serde_json::Value = serde_json::from_str(json).unwrap();
        assert_eq!(v["tally"]["rolls"], 20);
    }
}

#[test]
fn outputs_honour_the_umask_and_keep_an_existing_files_mode() {
    let d = scratch("umask");
    let csv = d.join("rolls.csv");
    let with_umask = |mask: u32| {
        let mut c = roll(&["--per-roll", csv.to_str().unwrap()]);
        // SAFETY: umask(2) is async-signal-safe.
        unsafe {
            c.pre_exec(move || {
                libc::umask(mask);
                Ok(())
            })
        };
        let out = c.output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    };
    with_umask(0o022);
    assert_eq!(mode(&csv), 0o644, "a new file under umask 022");
    std::fs::set_permissions(&csv, std::fs::Permissions::from_mode(0o640)).unwrap();
    with_umask(0o022);
    assert_eq!(mode(&csv), 0o640, "an existing file keeps its mode");
}

/// Reliability round 5, class L: a study's claim on its directory, `dicephys-run.json`, was
/// always 0600; it honours the umask as every other output.
#[test]
fn a_directorys_claim_honours_the_umask() {
    let d = scratch("claim-umask");
    let out = d.join("out");
    let mut c = bin();
    c.args(["fair", "--rolls", "20", "--threads", "1", "--out"])
        .arg(&out);
    // SAFETY: umask(2) is async-signal-safe.
    unsafe {
        c.pre_exec(|| {
            libc::umask(0o022);
            Ok(())
        })
    };
    let o = c.output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(mode(&out.join("dicephys-run.json")), 0o644);
}

/// Two runs of one command with the same flags in one `--out` at once: the second is refused
/// before it rolls, naming the first's process (a study's cells used to refuse it only at the
/// first cell both rolled, after it had rolled others beside the first; `fair` not at all).
/// The first is long by construction and killed once the second has been refused; the same
/// command then takes the directory up again (the system frees a lock with its holder).
#[test]
fn a_second_run_in_a_directory_a_run_is_using_is_refused_naming_it() {
    use super::helpers::{refused, wait_at_most, ENDLESS_ROLLS};
    let d = scratch("busy-out");
    for (n, command) in [
        ["fair", "--block", "16x16x16"],
        ["paper", "--engines", "bullet"],
    ]
    .iter()
    .enumerate()
    {
        let out = d.join(format!("out-{n}"));
        let run = || {
            let mut c = bin();
            c.args(command)
                .args(["--rolls", ENDLESS_ROLLS, "--threads", "1", "--out"])
                .arg(&out);
            c
        };
        // A run started, once its lock names it.
        let holding = || {
            let mut child = run()
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
                .unwrap();
            let holds = format!("pid {}", child.id());
            let start = std::time::Instant::now();
            while std::fs::read_to_string(out.join("lock")).map_or(true, |t| t.trim() != holds) {
                assert!(child.try_wait().unwrap().is_none(), "{command:?}: it ended");
                assert!(
                    start.elapsed().as_secs() < 120,
                    "{command:?}: no lock taken"
                );
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            (child, holds)
        };
        let kill = |mut child: std::process::Child| {
            unsafe { libc::kill(child.id() as i32, libc::SIGKILL) };
            wait_at_most(&mut child, std::time::Duration::from_secs(60));
        };
        let (first, holds) = holding();
        let second = run().output().unwrap();
        refused(&second, 2, &format!("in use by another run ({holds})"));
        kill(first);
        let (again, _) = holding();
        kill(again);
    }
}

#[test]
fn an_output_name_of_250_bytes_is_written() {
    let d = scratch("long-name");
    let csv = d.join(format!("{}.csv", "r".repeat(246)));
    let out = roll(&["--per-roll", csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(csv.is_file());
}

#[test]
fn a_loop_of_links_as_an_output_is_refused_and_left_a_link() {
    let d = scratch("loop");
    let (a, b) = (d.join("a.csv"), d.join("b.csv"));
    std::os::unix::fs::symlink(&b, &a).unwrap();
    std::os::unix::fs::symlink(&a, &b).unwrap();
    let out = roll(&["--per-roll", a.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("loop"), "{}", stderr(&out));
    assert!(a.symlink_metadata().unwrap().file_type().is_symlink());
}

#[test]
fn the_temporary_files_a_killed_run_left_are_removed_by_the_next_run_there() {
    let d = scratch("leftovers");
    let left = d.join(".report.md.a1B2c3.dicephys.tmp");
    let held = d.join(".report.md.d4E5f6.dicephys.tmp");
    let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
    for p in [&left, &held] {
        let f = std::fs::File::create(p).unwrap();
        f.set_modified(hour_ago).unwrap();
    }
    // A run still writing holds its temporary file locked: it stays.
    let lock = std::fs::File::open(&held).unwrap();
    lock.lock().unwrap();
    let csv = d.join("rolls.csv");
    let out = roll(&["--per-roll", csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(!left.exists(), "a dead run's temporary file was left");
    assert!(held.exists(), "a live run's temporary file was removed");
}
