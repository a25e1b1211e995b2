//! The command line: a thin layer over the library. Each subcommand has a module of its own.

use clap::{CommandFactory, Parser, Subcommand};
use error::Error;
use term::{stdout, stop};

pub mod args;
pub mod bench;
pub mod compare;
pub mod crosscheck;
pub mod design;
pub mod error;
pub mod fair;
pub mod fit;
pub mod merge;
pub mod paper;
pub mod roll;
pub mod slurm;
pub mod study;
pub mod sweeps;
pub mod term;
pub mod theory;
pub mod trace;
pub mod validate;

#[derive(Parser, Debug)]
#[command(
    name = "dicephys",
    version,
    about = "With what probability does a thrown die (the paper's cuboid, a d6, any convex \
             shape) land on each face? \
             Simulation (Bullet, Rapier) beside the theory and data of Pender & Uhrin (2014)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Reproduce the paper: its table, theory, simulations and figures, into --out.
    Paper(paper::PaperArgs),
    /// Roll one die many times on one engine: counts, ratio or faces, theory, cost.
    Roll(roll::RollArgs),
    /// Calibrate e, μ and the throw to measured counts (maximum likelihood through a surrogate
    /// of the simulator), or check that a fit recovers known values (--recover).
    Fit(fit::FitArgs),
    /// Predict a block the fit did not see (or many, --blocks-file): its outcome probabilities with
    /// their errors, and a held-out test where they were counted.
    Predict(fit::PredictArgs),
    /// Two fits of the same counts by different models (--free), compared by how well each
    /// predicts the rows it did not see (leave one out): which the data ask for, or unresolved.
    Compare(compare::CompareArgs),
    /// Is this die fair? Roll it (thrown in a tumble by default) and set each face against a
    /// fair die's: its probability and departure in σ, χ², and the throws a tester would need.
    Fair(fair::FairArgs),
    /// Design a die for its throws: the value of one feature (a coin's thickness, a block's
    /// length, the centre of mass, the pips' depth, the edges' radius) that gives the
    /// probabilities you want, found by rolling it and checked at a fresh seed.
    Design(design::DesignArgs),
    /// The paper's closed-form theory for a block, or its whole experimental table.
    Theory(theory::TheoryArgs),
    /// The same throws on several engines: counts, ratios, σ apart, per-throw agreement, cost.
    Crosscheck(crosscheck::CrosscheckArgs),
    /// The paper's convergence test: the ratio against dt per block, engine, 2D/3D.
    Converge(sweeps::ConvergeArgs),
    /// Accuracy against cost across methods, with the Pareto front.
    Tradeoff(sweeps::TradeoffArgs),
    /// Where engines fail: unconverged, unknown, non-finite, tunnelled, energy gain by cell.
    Stability(sweeps::StabilityArgs),
    /// The engines against the limits known in closed form: no bounce (2D), solid angles (3D),
    /// free flight, and the trend towards the paper's theory.
    Validate(validate::ValidateArgs),
    /// Speed of each engine and method (early stop, closed-form flight, floor) against DicePhys's
    /// own way of rolling, side by side.
    Bench(bench::BenchArgs),
    /// One throw's trajectory as CSV (step, time, position, orientation, velocities, energy).
    Trace(trace::TraceArgs),
    /// Combine the --json outputs of `roll --shard K/N` runs into the unsharded result.
    Merge(merge::MergeArgs),
    /// A run as a Slurm job array and a finishing job that merges it into the one-machine result.
    Slurm(slurm::SlurmArgs),
    /// A shell's completions for dicephys, on stdout (e.g. `dicephys completions bash >
    /// ~/.local/share/bash-completion/completions/dicephys`).
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// The manual page, roff on stdout (e.g. `dicephys man > ~/.local/share/man/man1/dicephys.1`).
    Man,
}

/// Runs the command line; returns the process exit code (0 ok, 2 bad input, 1 failure, 130
/// stopped early with what was done kept).
pub fn main() -> i32 {
    // Ctrl-C or SIGTERM: the first asks runs to stop (a roll under way is abandoned within
    // 4,096 steps; they keep their checkpoint and report what was done, as partial); a second
    // ends the process at once.
    let _ = ctrlc::set_handler(|| {
        if stop().request() {
            std::process::exit(130);
        }
        eprintln!("dicephys: stopping (Ctrl-C again to quit now)");
    });
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_error(e),
    };
    let result = dispatch(cli.command);
    match result {
        Ok(()) | Err(Error::Closed) => 0,
        Err(e) => {
            eprintln!("dicephys: {e}");
            e.exit_code()
        }
    }
}

/// Runs one command.
pub fn dispatch(command: Command) -> error::Result<()> {
    match command {
        Command::Bench(a) => bench::run(&a),
        Command::Converge(a) => sweeps::converge(&a),
        Command::Crosscheck(a) => crosscheck::run(&a),
        Command::Stability(a) => sweeps::stability(&a),
        Command::Tradeoff(a) => sweeps::tradeoff(&a),
        Command::Fit(a) => fit::run(&a),
        Command::Compare(a) => compare::run(&a),
        Command::Predict(a) => fit::predict(&a),
        Command::Fair(a) => fair::run(a),
        Command::Design(a) => design::run(&a),
        Command::Merge(a) => merge::run(&a),
        Command::Paper(a) => paper::run(&a),
        Command::Theory(a) => theory::run(&a),
        Command::Roll(a) => roll::run(&a),
        Command::Slurm(a) => slurm::run(&a),
        Command::Trace(a) => trace::run(&a),
        Command::Validate(a) => validate::run(&a),
        Command::Completions { shell } => {
            let mut text = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "dicephys", &mut text);
            stdout(&String::from_utf8_lossy(&text))
        }
        Command::Man => {
            let mut text = Vec::new();
            clap_mangen::Man::new(Cli::command())
                .render(&mut text)
                .map_err(|e| Error::Run(e.to_string()))?;
            stdout(&String::from_utf8_lossy(&text))
        }
    }
}

/// clap's "did you mean" for a misspelt flag or command, kept in the one line: "; did you
/// mean --rolls?" (issue 50: it used to be cut with the usage hints after it).
fn suggestion(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue};
    let named = [ContextKind::SuggestedArg, ContextKind::SuggestedSubcommand]
        .into_iter()
        .find_map(|k| match e.get(k) {
            Some(ContextValue::String(s)) => Some(s.clone()),
            Some(ContextValue::Strings(v)) if !v.is_empty() => Some(v.join(" or ")),
            _ => None,
        });
    named.map_or_else(String::new, |s| format!("; did you mean {s}?"))
}

/// Help and version go to stdout as clap prints them; any other parse error becomes one
/// line on stderr and exit code 2.
fn clap_error(e: clap::Error) -> i32 {
    use clap::error::ErrorKind;
    match e.kind() {
        // Written as every output is: a closed pipe ends quietly, a full disk is an error.
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => match stdout(&e.render().to_string())
        {
            Ok(()) | Err(Error::Closed) => 0,
            Err(e) => {
                eprintln!("dicephys: {e}");
                e.exit_code()
            }
        },
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
            eprintln!("dicephys: {line}{}", suggestion(&e));
            2
        }
    }
}
