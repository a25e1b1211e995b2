//! What the integration tests share.

use std::process::Command;

/// The `dicephys` binary cargo built for these tests.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dicephys"))
}

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
