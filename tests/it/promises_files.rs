//! The promises about files and directories (docs/guide.md, "What dicephys promises"):
//! outputs whole, with their mode, under long names and links; temporary files cleaned up;
//! damaged chunks named and rolled again; a Slurm directory's name quoted or refused; paths
//! not UTF-8; a run's directory its own; a chunk's size. Each probe, at a small size, failed
//! on the build before its fix.

use super::helpers::{bin, Scratch};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Output};

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("red3-{name}"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A short 2D roll (fast) with these extra arguments.
fn roll(extra: &[&str]) -> Command {
    let mut c = bin();
    c.args(["roll", "--block", "140x22x13", "--2d", "--rolls", "20"])
        .args(extra);
    c
}

fn mode(p: &Path) -> u32 {
    std::fs::metadata(p).unwrap().permissions().mode() & 0o777
}

// Outputs: where they go, with what mode and name.

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

/// Reliability round 5, class D: a `--die` file is read through the capped reader and named:
/// missing, a directory, not text, endless (/dev/zero) or a pipe no one writes to.
#[test]
fn a_die_file_is_read_capped_and_named() {
    let d = scratch("die-read");
    let refused = |die: &std::path::Path, says: &str| {
        let o = bin()
            .args(["roll", "--rolls", "1", "--block", "16x16x16", "--die"])
            .arg(die)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{}: {e}", die.display());
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
        assert!(
            e.contains("--die") && e.contains(says),
            "{}: {e}",
            die.display()
        );
    };
    refused(&d.join("missing.toml"), "No such file");
    refused(&d, "directory");
    std::fs::write(d.join("binary.toml"), [0xff, 0xfe, 0x00, 0x80]).unwrap();
    refused(&d.join("binary.toml"), "not a text file");
    refused(Path::new("/dev/zero"), "larger than 1 MiB");
    // A named pipe with no writer: SIGTERM ends the wait (exit 130).
    let fifo = d.join("die.toml");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let mut child = bin()
        .args(["roll", "--block", "16x16x16", "--die"])
        .arg(&fifo)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(500));
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let status = exit_within(&mut child, 5, "a --die pipe held off SIGTERM");
    assert_eq!(status.code(), Some(130));
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

// Counts.

/// Shard `k` of `n` of a small 2D run, as `roll --shard K/N --json` writes it, parsed.
fn shard_json(k: u64, n: u64) -> serde_json::Value {
    let s = format!("{k}/{n}");
    let out = roll(&["--json", "--shard", &s]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn merge_refuses_a_sum_past_2_to_the_64_rather_than_wrapping() {
    let d = scratch("overflow");
    let mut a = shard_json(0, 2);
    let b = shard_json(1, 2);
    a["tally"]["steps"] = u64::MAX.into();
    // Sealed again: a shard whose checksum holds, and whose counts overflow.
    let a = dicephys::run::seal::sealed(&a).unwrap();
    let files = [(d.join("a.json"), a), (d.join("b.json"), b)];
    for (f, v) in &files {
        std::fs::write(f, v.to_string()).unwrap();
    }
    let out = bin()
        .arg("merge")
        .args(files.iter().map(|(f, _)| f))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("overflow"), "{}", stderr(&out));
}

// Generated Slurm scripts.

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

// Checksums on what is stored.

/// The run's tally as `roll --json` prints it.
fn tally_of(out: &Output) -> serde_json::Value {
    assert_eq!(out.status.code(), Some(0), "{}", stderr(out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["tally"].clone()
}

#[test]
fn a_damaged_chunk_is_named_and_rolled_again_on_resume() {
    let d = scratch("damaged-chunk");
    let ck = d.join("ck");
    let run = |flag: &str| {
        let mut c = bin();
        c.args(["roll", "--json", flag]).arg(&ck);
        if flag == "--checkpoint" {
            c.args(["--block", "140x22x13", "--2d", "--rolls", "2500"]);
        }
        c.output().unwrap()
    };
    let truth = tally_of(&run("--checkpoint"));
    let chunk = ck.join("chunk-000000001000-1000.json");
    let good = std::fs::read(&chunk).unwrap();
    let text = String::from_utf8(good.clone()).unwrap();
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 0x04;
    let damages: [(&str, Vec<u8>); 4] = [
        (
            "a roll edited, still JSON and base64",
            edit_rolls(&text).into_bytes(),
        ),
        (
            "a field renamed",
            text.replacen("\"wall_s\"", "\"wall_t\"", 1).into_bytes(),
        ),
        ("a bit flipped", flipped),
        (
            "no checksum (an older dicephys's chunk)",
            text.replacen("\"checksum\":", "\"checksun\":", 1)
                .into_bytes(),
        ),
    ];
    for (what, bytes) in damages {
        assert_ne!(bytes, good, "{what}: the damage changed nothing");
        std::fs::write(&chunk, &bytes).unwrap();
        let out = run("--resume");
        assert_eq!(tally_of(&out), truth, "{what}: a damaged chunk was counted");
        assert!(
            stderr(&out).contains("chunk-000000001000-1000.json")
                && stderr(&out).contains("rolling its throws again"),
            "{what}: {}",
            stderr(&out)
        );
        // Replaced by a whole chunk: the next resume reads it quietly.
        let again = run("--resume");
        assert_eq!(tally_of(&again), truth);
        assert!(!stderr(&again).contains("damaged"), "{}", stderr(&again));
    }
}

/// A chunk's text with one character of its packed rolls changed for another base64 one: the
/// file is still JSON and its rolls still base64.
fn edit_rolls(text: &str) -> String {
    let at = text.find("\"rolls\":\"").expect("packed rolls") + 9 + 12;
    let c = text.as_bytes()[at];
    let to = if c == b'A' { "B" } else { "A" };
    format!("{}{to}{}", &text[..at], &text[at + 1..])
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

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

// Paths that are not UTF-8.

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

// Interrupts and floors.

#[test]
fn validate_stops_on_ctrl_c_in_its_free_flight_stage() {
    let d = scratch("validate-int");
    let out = d.join("out");
    let log = d.join("stderr.txt");
    let mut child = bin()
        .args([
            "validate",
            "--engines",
            "bullet",
            "--blocks-2d",
            "140x24x20",
        ])
        .args([
            "--blocks-3d",
            "20x20x20",
            "--trend",
            "none",
            "--rolls",
            "10",
        ])
        .args(["--threads", "1", "--flight-dts", "1e-6", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    // The limit cases done (three 3D rows logged), the free flight has begun: 2 s at 1 µs,
    // two million steps an integrator.
    let t = std::time::Instant::now();
    while std::fs::read_to_string(&log)
        .unwrap_or_default()
        .matches("3d_quasi_static")
        .count()
        < 3
    {
        assert!(t.elapsed().as_secs() < 120, "the limit cases never ended");
        assert!(child.try_wait().unwrap().is_none(), "validate ended early");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let status = exit_within(
        &mut child,
        5,
        "validate ignored Ctrl-C in its free-flight stage",
    );
    assert_eq!(status.code(), Some(130));
    assert!(
        !out.join("validate.json").exists(),
        "a stopped run wrote its outputs"
    );
}

#[test]
fn time_steps_below_the_floor_and_other_endless_values_are_refused() {
    let cases: [&[&str]; 9] = [
        &["validate", "--flight-dts", "1e-12"],
        &["roll", "--block", "140x24x20", "--dt", "1e-9"],
        &["converge", "--dts", "1/1000,1e-8"],
        &["stability", "--dts", "1e-7"],
        &["roll", "--block", "140x24x20", "--density", "1e-300"],
        &["stability", "--restitutions", "1"],
        &["tradeoff", "--preroll", "1000000001"],
        &[
            "slurm",
            "stability",
            "--rolls",
            "0",
            "--tasks",
            "2",
            "--dir",
            "/nonexistent/x",
        ],
        &["merge", "/dev/zero"],
    ];
    // Run in a scratch directory, each given a minute: a value let through may never end.
    let d = scratch("floors");
    for args in cases {
        let child = bin()
            .args(args)
            .current_dir(&*d)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let id = child.id();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(child.wait_with_output().unwrap()));
        let Ok(out) = rx.recv_timeout(std::time::Duration::from_secs(60)) else {
            unsafe { libc::kill(id as i32, libc::SIGKILL) };
            panic!("{args:?}: accepted, and still running after a minute");
        };
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).lines().count(),
            1,
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

#[test]
fn help_and_version_into_a_full_stdout_fail() {
    for arg in ["--help", "--version"] {
        let out = bin()
            .arg(arg)
            .stdout(
                std::fs::OpenOptions::new()
                    .write(true)
                    .open("/dev/full")
                    .unwrap(),
            )
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{arg}: {}", stderr(&out));
    }
    // Into a pipe it succeeds.
    let out = bin().arg("--help").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn bench_and_trace_stop_on_ctrl_c() {
    // Each run is long by construction: bench at its cap of rolls on one thread; trace at
    // 1 µs a step, every step a line (over a million lines) into a pipe this test does not
    // read until it has signalled, so the run cannot end before the signal on any machine.
    for args in [
        &["bench", "--rolls", "10000000", "--threads", "1"][..],
        &[
            "trace",
            "--block",
            "140x24x20",
            "--dt",
            "1e-6",
            "--max-steps",
            "20000000",
            "--flight",
            "stepped",
        ][..],
    ] {
        stops_on_ctrl_c(args);
    }
}

/// Starts `args`, waits for its first line on stdout (its handler is installed by then and its
/// run begun), sends SIGINT, then drains stdout and expects exit 130 within a bound a slow
/// machine also meets.
fn stops_on_ctrl_c(args: &[&str]) {
    use std::io::BufRead;
    let mut child = bin()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut out = std::io::BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    assert!(!first.is_empty(), "{args:?} wrote nothing");
    assert!(
        child.try_wait().unwrap().is_none(),
        "{args:?} ended before its signal"
    );
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let drain = std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    let status = exit_within(&mut child, 5, format!("{args:?} ignored Ctrl-C"));
    let _ = drain.join();
    assert_eq!(status.code(), Some(130), "{args:?}");
}

// Who owns a directory.

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
fn a_chunk_takes_at_most_32_bytes_a_roll() {
    let d = scratch("compact");
    for (name, extra) in [("2d", &["--2d"][..]), ("3d", &[][..])] {
        let ck = d.join(name);
        let out = bin()
            .args([
                "roll",
                "--block",
                "140x22x13",
                "--rolls",
                "1000",
                "--checkpoint",
            ])
            .arg(&ck)
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let chunk = ck.join("chunk-000000000000-1000.json");
        let bytes = std::fs::metadata(&chunk).unwrap().len();
        assert!(bytes <= 32 * 1000, "{name}: {bytes} bytes for 1000 rolls");
    }
}

/// `child`'s exit status once it ends, at most `secs` seconds from now (a bound a slow machine
/// also meets); past it the child is killed and the test fails with `what`.
fn exit_within(
    child: &mut std::process::Child,
    secs: u64,
    what: impl std::fmt::Display,
) -> std::process::ExitStatus {
    let t = std::time::Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if t.elapsed().as_secs() > secs {
            let _ = child.kill();
            panic!("{what}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}
