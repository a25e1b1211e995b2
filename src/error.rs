//! The two kinds of error a command can end with, and their exit codes.

use std::fmt;

#[derive(Debug)]
pub enum Error {
    /// Bad input: exit code 2, one line naming what is wrong.
    Usage(String),
    /// A failure while running (I/O, an engine that cannot start): exit code 1.
    Run(String),
    /// Stopped by Ctrl-C before the end, with what was done kept: exit code 130.
    Interrupted(String),
}

impl Error {
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

impl std::error::Error for Error {}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        Error::Run(e.to_string())
    }
}

pub type Result<T> = std::result::Result<T, Error>;
