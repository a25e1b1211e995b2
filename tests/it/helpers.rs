//! What the integration tests share.

use std::process::Command;

/// The `dicephys` binary cargo built for these tests.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dicephys"))
}
