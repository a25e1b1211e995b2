//! `dicephys bench`: speed of every engine and lever against the faithful configuration.

use super::args::{Json, Seed, Threads};
use super::error::{Error, Result};
use super::term::outln;
use clap::Args;
use dicephys::studies::bench;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Rolls per measurement.
    #[arg(long, default_value_t = 2000)]
    pub rolls: u64,
    /// Rolls per made die (a weight, pips, rounded edges, all three) against the sharp
    /// uniform die, a 16 mm cube in a tumble, one thread; a quarter as many on Rapier (0: none).
    #[arg(long, default_value_t = 2000)]
    pub dice_rolls: u64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Worker threads.
    #[command(flatten)]
    pub threads: Threads,
    /// Run each measurement this many times and keep the fastest (the outcomes are the same
    /// every time); for a machine shared with other work.
    #[arg(long, default_value_t = 1)]
    pub repeat: u32,
    /// DicePhys 2.81's binary (built by ../shared/tools/build-dicephys.sh): run it beside the
    /// methods, one process per core, for the ×DicePhys columns; without it they are left
    /// empty.
    #[arg(long, value_name = "PATH")]
    pub dicephys: Option<std::path::PathBuf>,
    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &BenchArgs) -> Result<()> {
    if a.rolls == 0 {
        return Err(Error::Usage("--rolls 0: need at least one roll".into()));
    }
    if a.repeat == 0 {
        return Err(Error::Usage("--repeat 0: need at least one run".into()));
    }
    if a.dice_rolls > 1_000_000 {
        return Err(Error::Usage(format!(
            "--dice-rolls {}: at most 1000000",
            a.dice_rolls
        )));
    }
    if a.rolls > 10_000_000 {
        return Err(Error::Usage(format!(
            "--rolls {}: at most 10000000",
            a.rolls
        )));
    }
    let threads = a.threads.checked()?;
    if let Some(p) = &a.dicephys {
        if !p.is_file() {
            return Err(Error::Usage(format!(
                "--dicephys {}: not a file (DicePhys 2.81's binary)",
                p.display()
            )));
        }
    }
    let quiet = *a.json;
    if !quiet {
        outln!("{}", dicephys::report::bench::header());
    }
    // A progress line that cannot be written (a closed pipe) is dropped; the result is
    // written, or its failure reported, at the end.
    let cfg = bench::Config {
        rolls: a.rolls,
        dice_rolls: a.dice_rolls,
        seed: *a.seed,
        threads,
        repeat: a.repeat,
        dicephys: a.dicephys.clone(),
    };
    let b = bench::run(&cfg, super::term::stop(), &|line| {
        if !quiet {
            let _ = super::term::stdout(&format!("{line}\n"));
        }
    })?;
    if *a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&b).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        outln!("peak RSS {:.1} MB", b.peak_rss_mb);
    }
    Ok(())
}
