//! What the integration tests share.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The `dicephys` binary cargo built for these tests; or, to see a probe fail on an older
/// build, the one `DICEPHYS_TEST_BIN` names (e.g. main's, copied aside before a fix).
pub fn bin() -> Command {
    match std::env::var_os("DICEPHYS_TEST_BIN") {
        Some(b) => Command::new(b),
        None => Command::new(env!("CARGO_BIN_EXE_dicephys")),
    }
}

/// The five MDF blocks the paper simulated, in its order.
pub const MDF_BLOCKS: [&str; 5] = [
    "140x24x20",
    "140x22x13",
    "140x27x13",
    "140x29x11",
    "140x30x10",
];

/// Runs the binary with `args` and waits for it.
pub fn dicephys(args: &[&str]) -> std::process::Output {
    bin().args(args).output().expect("run dicephys")
}

/// A successful run's stdout as one JSON document; a failed run fails the test with its stderr.
pub fn json(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON document")
}

/// A test's scratch directory: unique, under the system's temporary directory, and removed
/// when the test passes. A failing test keeps it, and says where, for a look at what the run
/// left there.
pub struct Scratch(Option<tempfile::TempDir>);

impl Scratch {
    /// A new, empty directory named after `name`.
    pub fn new(name: &str) -> Scratch {
        let dir = tempfile::Builder::new()
            .prefix(&format!("dicephys-{name}-"))
            .tempdir()
            .expect("a scratch directory");
        Scratch(Some(dir))
    }

    /// A path for `dicephys` to create (its name held, nothing there yet): an output or
    /// checkpoint directory whose creation is part of the test.
    pub fn absent(name: &str) -> Scratch {
        let s = Scratch::new(name);
        std::fs::remove_dir(s.path()).expect("the scratch directory, empty");
        s
    }

    /// The directory's path.
    pub fn path(&self) -> &Path {
        self.0.as_ref().expect("scratch directory").path()
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.path()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.path()
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.path().as_os_str()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            if let Some(dir) = self.0.take() {
                eprintln!("kept the failing test's scratch: {}", dir.keep().display());
            }
        }
    }
}

/// Rolls enough that no machine finishes them before a stop test's signal: a stop test's run
/// is long by construction, never by how slow this machine is (the cap, `run::spec::MAX_ROLLS`;
/// at a microsecond a roll it is still a quarter of an hour on one thread).
pub const ENDLESS_ROLLS: &str = "1000000000";

/// Sends `signal` to `child` after `ms`, first checking that it is still running: a run that
/// ended before its signal would test nothing, and says so instead of failing on its exit code.
pub fn signal_running(child: &mut std::process::Child, signal: i32, ms: u64) {
    std::thread::sleep(std::time::Duration::from_millis(ms));
    if let Some(s) = child.try_wait().expect("the child's status") {
        panic!("the run ended ({s}) before its signal: it must be long by construction");
    }
    unsafe { libc::kill(child.id() as i32, signal) };
}

/// A probe's scratch directory, `dicephys-red-NAME-…` (see `Scratch`).
pub fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("red-{name}"))
}

/// A run's stderr, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// One line on stderr and exit code `code`.
pub fn refused(o: &Output, code: i32, says: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "one line: {e}");
    assert!(e.contains(says), "wanted '{says}' in: {e}");
}

/// A short 2D roll (fast) with these extra arguments.
pub fn roll(extra: &[&str]) -> Command {
    let mut c = bin();
    c.args(["roll", "--block", "140x22x13", "--2d", "--rolls", "20"])
        .args(extra);
    c
}

/// Shard `k` of `n` of a small 2D run, as `roll --shard K/N --json` writes it, parsed.
pub fn shard_json(k: u64, n: u64) -> serde_json::Value {
    let s = format!("{k}/{n}");
    let out = roll(&["--json", "--shard", &s]).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// A chunk's text with one character of its packed rolls changed for another base64 one: the
/// file is still JSON and its rolls still base64.
pub fn edit_rolls(text: &str) -> String {
    let at = text.find("\"rolls\":\"").expect("packed rolls") + 9 + 12;
    let c = text.as_bytes()[at];
    let to = if c == b'A' { "B" } else { "A" };
    format!("{}{to}{}", &text[..at], &text[at + 1..])
}

/// Every file under `dir`, at any depth.
pub fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
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

/// `child`'s exit status once it ends, at most `secs` seconds from now (a bound a slow machine
/// also meets); past it the child is killed and the test fails with `what`.
pub fn exit_within(
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

/// Waits for `child`, killing it after `limit` (then its exit code is `None`).
pub fn wait_at_most(child: &mut std::process::Child, limit: Duration) -> Option<i32> {
    let t = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.code();
        }
        if t.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs the binary, killed after `limit` (then its exit code is `None`).
pub fn timed(args: &[&str], limit: Duration) -> (Option<i32>, String, Duration) {
    let mut child = bin()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t = Instant::now();
    let code = wait_at_most(&mut child, limit);
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    (code, err, t.elapsed())
}

/// `args` run and sent `signal` after `after_ms`; the run must be long by construction
/// (`ENDLESS_ROLLS`), or it is refused as a test of nothing.
pub fn interrupted(args: &[&str], signal: i32, after_ms: u64) -> Output {
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

/// No file of ours beside `dir`'s own entries: no `NAME.tmp-PID`, no `.NAME.*.tmp`.
pub fn no_temp_files(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let n = e.file_name().to_string_lossy().into_owned();
        assert!(!n.contains(".tmp"), "temporary file left behind: {n}");
    }
}

/// True once a checkpoint chunk (`chunk-*`) is on disk directly in `dir`.
pub fn has_chunk(dir: &Path) -> bool {
    std::fs::read_dir(dir)
        .map(|d| {
            d.flatten()
                .any(|e| e.file_name().to_string_lossy().starts_with("chunk-"))
        })
        .unwrap_or(false)
}

/// Waits (at most 2 minutes) for a line of `child`'s stderr that contains `stage`, sends it
/// SIGINT, and returns its exit code, its stderr up to that line and how long it took to end:
/// a stop signalled after the stage has said it started, so the run is long by construction.
pub fn interrupt_after(
    mut child: std::process::Child,
    stage: &str,
) -> (Option<i32>, String, Duration) {
    use std::io::BufRead;
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    let t = Instant::now();
    loop {
        let mut line = String::new();
        if err.read_line(&mut line).unwrap() == 0 || t.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("no line '{stage}' before the run ended: {seen}");
        }
        seen.push_str(&line);
        if line.contains(stage) {
            break;
        }
    }
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let stopped = Instant::now();
    // Drain stderr so that the child never blocks on a full pipe.
    std::thread::spawn(move || std::io::copy(&mut err, &mut std::io::sink()));
    let status = child.wait().unwrap();
    (status.code(), seen, stopped.elapsed())
}
