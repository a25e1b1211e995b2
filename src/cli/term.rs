//! The process's side of the command line, which every command's module takes from here:
//! its stdout (a closed pipe ends quietly), the `out!`/`outln!` macros, an output path
//! checked before a run, the command line as given, and the stop flag.

use super::error;
use dicephys::run::stop::Stop;

/// The process's stop flag, raised by Ctrl-C or SIGTERM.
pub fn stop() -> &'static Stop {
    Stop::global()
}

/// Writes `text` to stdout and flushes it. A closed pipe (`| head -1`) ends the command
/// quietly; any other failure (a full disk) is an error, never a panic.
pub fn stdout(text: &str) -> error::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()?;
    Ok(())
}

/// `println!` to [`stdout`], returning its error.
macro_rules! outln {
    ($($t:tt)*) => {
        $crate::cli::term::stdout(&format!("{}\n", format_args!($($t)*)))?
    };
}
/// `print!` to [`stdout`], returning its error.
macro_rules! out {
    ($($t:tt)*) => {
        $crate::cli::term::stdout(&format!($($t)*))?
    };
}
pub(crate) use {out, outln};

/// This process's command line, to be named in reports (never parsed): its arguments as
/// given, a byte that is not UTF-8 (in a path, say) shown as U+FFFD rather than a panic.
pub fn command_line() -> String {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}
