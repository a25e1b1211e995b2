//! `dicephys paper`: the main job. Reproduces the paper end to end and writes a report.

use super::args::parse_engine;
use super::error::Result;
use super::study;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::sim::roll::DEFAULT_MAX_STEPS;
use dicephys::studies::paper::PaperConfig;
use std::path::PathBuf;

/// `dicephys paper`'s arguments.
#[derive(Args, Debug)]
pub struct PaperArgs {
    /// Rolls per simulated cell (block × engine × 2D/3D); 100000 is the paper's own scale.
    #[arg(long, default_value_t = 10000)]
    pub rolls: u64,
    /// Seed of the keyed throws.
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    /// Engines to simulate with (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "bullet,rapier", value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Fixed time step, s.
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = DEFAULT_MAX_STEPS)]
    pub max_steps: u64,
    /// Output directory [default: paper-out].
    #[arg(long, value_name = "OUT")]
    pub out: Option<PathBuf>,
    /// DicePhys exactly as the paper ran it (its rest rule, every flight step stepped) instead
    /// of the exact early stop and closed-form flight.
    #[arg(long)]
    pub faithful: bool,
    /// Print results.json to stdout too (and no progress bar).
    #[arg(long)]
    pub json: bool,
}

impl PaperArgs {
    /// The study's configuration.
    pub fn config(&self) -> PaperConfig {
        let mut engines = self.engines.clone();
        engines.dedup();
        PaperConfig {
            rolls: self.rolls,
            seed: self.seed,
            engines,
            dt: self.dt,
            max_steps: self.max_steps,
            faithful: self.faithful,
        }
    }
}

/// Runs `dicephys paper`.
pub fn run(a: &PaperArgs) -> Result<()> {
    let cfg = a.config();
    cfg.validate()?;
    let out = a.out.clone().unwrap_or_else(|| "paper-out".into());
    study::paper(&cfg, &study::local(&out, a.threads, a.json)?)
}
