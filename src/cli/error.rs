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
    /// Standard output was closed by its reader (`| head -1`): the command ends quietly.
    Closed,
}

impl Error {
    /// The process exit code.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Usage(_) => 2,
            Error::Run(_) => 1,
            Error::Interrupted(_) => 130,
            Error::Closed => 0,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Usage(m) | Error::Run(m) | Error::Interrupted(m) => f.write_str(m),
            Error::Closed => f.write_str("standard output closed"),
        }
    }
}

impl From<dicephys::Error> for Error {
    fn from(e: dicephys::Error) -> Error {
        if matches!(e, dicephys::Error::Stopped) {
            Error::Interrupted(
                "interrupted; the finished work is kept: run the same command to continue".into(),
            )
        } else if let dicephys::Error::Field { field, value, why } = &e {
            let line = if value.is_empty() {
                format!("{}: {}", flag(field), flags_in(why))
            } else {
                format!("{} {value}: {}", flag(field), flags_in(why))
            };
            Error::Usage(line)
        } else if e.is_input() {
            Error::Usage(e.to_string())
        } else if let dicephys::Error::Failed(m) = &e {
            // A failure may name what to change, as a field in backquotes.
            Error::Run(flags_in(m))
        } else {
            Error::Run(e.to_string())
        }
    }
}

/// The flag that sets a field of the library's configurations: most are the field's name,
/// `--` and kebab case; these few are spelt otherwise.
fn flag(field: &str) -> String {
    match field {
        "style" => "--throw".into(),
        "kind" => "--source".into(),
        "budget_s" => "--budget".into(),
        "reference_budget_s" => "--reference-budget".into(),
        "preroll_chunks" => "--preroll".into(),
        "plan_only" => "--plan".into(),
        f => format!("--{}", f.replace('_', "-")),
    }
}

/// A library message with each field it names in backquotes, `like_this`, named by its flag.
pub fn flags_in(why: &str) -> String {
    let mut out = String::new();
    for (i, part) in why.split('`').enumerate() {
        if i % 2 == 1 {
            out += &flag(part);
        } else {
            out += part;
        }
    }
    out
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            Error::Closed
        } else {
            Error::Run(format!("standard output: {e}"))
        }
    }
}

/// A command's result.
pub type Result<T> = std::result::Result<T, Error>;
