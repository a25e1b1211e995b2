//! What the integration tests share.

use std::path::Path;
use std::process::Command;

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
