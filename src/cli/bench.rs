//! `dicephys bench`: speed of every engine and lever against the faithful configuration.

use super::args::{Json, Seed, Threads};
use super::error::Result;
use clap::Args;
use dicephys::studies::{bench, StudyConfig};

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
    let cfg = bench::Config {
        rolls: a.rolls,
        dice_rolls: a.dice_rolls,
        seed: *a.seed,
        threads: a.threads.checked()?,
        repeat: a.repeat,
        dicephys: a.dicephys.clone(),
    };
    let place = super::study::here(None, None, cfg.threads, *a.json)?;
    super::study::run(&StudyConfig::Bench(cfg), &place)
}
