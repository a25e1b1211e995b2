//! `paper` and `paper --calibrated` through the binary: a stopped run leaves the complete
//! outputs alone; a run's directory is refused to another command and to another run; an
//! output directory whose name is not UTF-8 is written to (a Slurm run's is refused);
//! `--calibrated`'s own values are checked before anything runs, by their flags.

use super::helpers::{
    bin, interrupted, no_temp_files, roll, scratch, stderr, timed, walk, Scratch, ENDLESS_ROLLS,
};
use std::time::Duration;

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
    // The directory is the 20-roll run's: another run is refused there
    // (paper::a_run_directory_is_refused_to_another_command_and_to_another_run), so the complete
    // outputs are copied into a directory of no run's, and the slow run stopped there.
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
fn a_run_directory_is_refused_to_another_command_and_to_another_run() {
    let d = scratch("owner");
    let out = d.join("out");
    let paper = |rolls: &str| {
        bin()
            .args([
                "paper",
                "--engines",
                "bullet",
                "--threads",
                "1",
                "--rolls",
                rolls,
            ])
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap()
    };
    let first = paper("20");
    assert_eq!(first.status.code(), Some(0), "{}", stderr(&first));
    let report = std::fs::read(out.join("report.md")).unwrap();
    let cells = walk(&out.join("checkpoint"));
    // Another command's outputs there: refused, nothing replaced.
    let other = bin()
        .args(["converge", "--rolls", "5", "--engines", "bullet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(other.status.code(), Some(2), "{}", stderr(&other));
    assert!(stderr(&other).contains("`paper`"), "{}", stderr(&other));
    // The same command with other flags: refused, its cells kept.
    let again = paper("40");
    assert_eq!(again.status.code(), Some(2), "{}", stderr(&again));
    assert_eq!(std::fs::read(out.join("report.md")).unwrap(), report);
    assert_eq!(
        walk(&out.join("checkpoint")),
        cells,
        "cell checkpoints removed"
    );
    // A roll's checkpoint there, and a study into a roll's checkpoint: refused both ways.
    let roll_ck = bin()
        .args([
            "roll",
            "--block",
            "140x22x13",
            "--rolls",
            "5",
            "--checkpoint",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(roll_ck.status.code(), Some(2), "{}", stderr(&roll_ck));
    let ck = d.join("ck");
    let made = roll(&["--checkpoint", ck.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    let into = bin()
        .args(["stability", "--rolls", "5", "--out"])
        .arg(&ck)
        .output()
        .unwrap();
    assert_eq!(into.status.code(), Some(2), "{}", stderr(&into));
    // The same run again continues, whatever its threads.
    let same = bin()
        .args([
            "paper",
            "--engines",
            "bullet",
            "--threads",
            "2",
            "--rolls",
            "20",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(same.status.code(), Some(0), "{}", stderr(&same));
}

#[test]
fn a_path_that_is_not_utf8_is_written_to_or_refused_never_a_panic() {
    use std::os::unix::ffi::OsStrExt;
    let d = scratch("not-utf8");
    let name = |s: &[u8]| d.join(std::ffi::OsStr::from_bytes(s));
    let out_dir = name(b"paper-\xff");
    let out = bin()
        .args([
            "paper",
            "--rolls",
            "10",
            "--engines",
            "bullet",
            "--threads",
            "1",
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(out_dir.join("report.md").exists());
    // A Slurm run's path goes into its scripts as text: refused, one line, nothing made.
    let dir = name(b"slurm-\xfe");
    let out = bin()
        .args(["slurm", "paper", "--rolls", "10", "--tasks", "2", "--dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(stderr(&out).lines().count(), 1, "{}", stderr(&out));
    assert!(!dir.exists());
}

/// Class 6: `paper --calibrated`'s own values are checked before anything runs, by their flags.
#[test]
fn calibrated_values_are_checked_first_by_their_flags() {
    let dir = Scratch::new("promise-cal");
    for (flag, value) in [
        ("--reference-dt", "0"),
        ("--reference-dt", "nan"),
        ("--check-rolls", "0"),
        ("--check-rolls", "2000000000"),
        ("--point-rolls", "0"),
        ("--points", "0"),
        ("--max-steps", "0"),
        // Reliability round 5, class F: parsed and ignored before, now honoured and checked.
        ("--starts", "0"),
        ("--profile-points", "2"),
    ] {
        let out = dir.join(format!("out{}", flag.len()));
        let (code, err, took) = timed(
            &[
                "paper",
                "--calibrated",
                flag,
                value,
                "--out",
                out.to_str().unwrap(),
            ],
            Duration::from_secs(20),
        );
        assert_eq!(code, Some(2), "{flag} {value}: {err}");
        assert!(err.contains(flag), "{flag} {value}: {err}");
        assert!(took < Duration::from_secs(2), "{flag} {value}: {took:?}");
        // Class 11: nothing left behind.
        assert!(!out.exists(), "{flag} {value} left {}", out.display());
    }
}
