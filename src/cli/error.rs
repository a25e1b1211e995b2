//! How a command ends: its exit code and its one line on stderr.

use std::fmt;

/// The ways a command can end badly.
#[derive(Debug)]
pub enum Error {
    /// Bad input: exit code 2, one line naming what is wrong.
    Usage(String),
    /// A failure while running (I/O, an engine that cannot start): exit code 1.
    Run(String),
    /// Stopped by Ctrl-C or SIGTERM before the end, with what was done kept: exit code 130.
    Interrupted(String),
}

impl Error {
    /// The process exit code.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Usage(_) => 2,
            Error::Run(_) => 1,
            Error::Interrupted(_) => 130,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Usage(m) | Error::Run(m) | Error::Interrupted(m) => f.write_str(m),
        }
    }
}

impl From<dicephys::Error> for Error {
    fn from(e: dicephys::Error) -> Error {
        if e.is_input() {
            Error::Usage(e.to_string())
        } else {
            Error::Run(e.to_string())
        }
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        Error::Run(e.to_string())
    }
}

/// A command's result.
pub type Result<T> = std::result::Result<T, Error>;
