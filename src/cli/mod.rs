//! The command line: a thin layer over the library. Each subcommand has a module of its own.

use clap::{Parser, Subcommand};

pub mod theory;

#[derive(Parser, Debug)]
#[command(
    name = "dicephys",
    version,
    about = "With what probability does a thrown cuboid die land on each face? \
             Simulation (Bullet, Rapier) beside the theory and data of Pender & Uhrin (2014)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// The paper's closed-form theory for a block, or its whole experimental table.
    Theory(theory::TheoryArgs),
}

/// Runs the command line; returns the process exit code (0 ok, 2 bad input, 1 failure).
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_error(e),
    };
    let result = match cli.command {
        Command::Theory(a) => theory::run(&a),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("dicephys: {e}");
            e.exit_code()
        }
    }
}

/// Help and version go to stdout as clap prints them; any other parse error becomes one
/// line on stderr and exit code 2.
fn clap_error(e: clap::Error) -> i32 {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            0
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            2
        }
        _ => {
            // clap's message is its first paragraph (some, like a missing argument, span two
            // lines); join it into one line and leave out the usage and help hints after it.
            let text = e.render().to_string();
            let paragraph: Vec<&str> = text
                .lines()
                .map(str::trim)
                .skip_while(|l| l.is_empty())
                .take_while(|l| !l.is_empty())
                .collect();
            let line = paragraph.join(" ");
            let line = line.trim_start_matches("error: ");
            let line = if line.is_empty() {
                "bad command line"
            } else {
                line
            };
            eprintln!("dicephys: {line}");
            2
        }
    }
}
