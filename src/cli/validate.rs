//! `dicephys validate`: the engines against the limits where a die's probabilities are known in
//! closed form (`dicephys::studies::validate`); writes `validate.json`, `report.md` and the
//! figures into --out.

use super::args::parse_engine;
use super::args::Seed;
use super::error::Result;
use super::study;
use super::study::StudyPlace;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::model::block::Block;
use dicephys::studies::sweep::parse_dt;
use dicephys::studies::validate as v;
use dicephys::studies::StudyConfig;

/// `dicephys validate`'s arguments.
#[derive(Args, Debug)]
pub struct ValidateArgs {
    /// Engines to simulate with (comma-separated): bullet, rapier, rapier-locked.
    #[arg(long, value_delimiter = ',', default_value = super::args::DEFAULT_ENGINES, value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Rolls per limit cell (block × engine × case).
    #[arg(long, default_value_t = v::Config::default().rolls)]
    pub rolls: u64,
    /// Rolls per point of the trend.
    #[arg(long, default_value_t = v::Config::default().trend_rolls)]
    pub trend_rolls: u64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Threads, --out, --json.
    #[command(flatten)]
    pub place: StudyPlace,
    /// The 2D no-bounce case's blocks (several R).
    #[arg(
        long = "blocks-2d",
        value_delimiter = ',',
        default_value = "140x24x24,140x24x20,140x22x13,140x30x10"
    )]
    pub blocks_2d: Vec<Block>,
    /// The 3D quasi-static case's blocks (a cube, a square cuboid, three different sides).
    #[arg(
        long = "blocks-3d",
        value_delimiter = ',',
        default_value = "20x20x20,40x20x20,30x20x10"
    )]
    pub blocks_3d: Vec<Block>,
    /// The trend's block (2D, the paper's throw).
    #[arg(long, default_value = "140x22x13")]
    pub trend_block: Block,
    /// The trend's points, E:MU, bouncier and grippier in turn ("none" skips it).
    #[arg(long, value_delimiter = ',', default_value = "0:0.1,0.2:0.29,0.5:0.5,0.7:1,0.9:1.5", value_parser = parse_point)]
    pub trend: Vec<Option<(f64, f64)>>,
    /// The free flight's time steps.
    #[arg(long, value_delimiter = ',', default_value = "1/60,1/250,1/1000,1/4000", value_parser = parse_dt)]
    pub flight_dts: Vec<f64>,
    /// The departure in probability each limit case should resolve at 3σ; a case whose rolls
    /// cannot says how many would.
    #[arg(long, default_value_t = v::Config::default().resolve)]
    pub resolve: f64,
}

/// `E:MU` (or `none`) as clap reads it.
fn parse_point(s: &str) -> std::result::Result<Option<(f64, f64)>, dicephys::Error> {
    if s.trim() == "none" {
        return Ok(None);
    }
    let bad = || dicephys::Error::Invalid(format!("trend point '{s}' is not E:MU (or none)"));
    let (e, mu) = s.split_once(':').ok_or_else(bad)?;
    Ok(Some((
        e.trim().parse().map_err(|_| bad())?,
        mu.trim().parse().map_err(|_| bad())?,
    )))
}

impl ValidateArgs {
    /// The study's configuration.
    pub fn config(&self) -> v::Config {
        v::Config {
            engines: self.engines.clone(),
            rolls: self.rolls,
            trend_rolls: self.trend_rolls,
            seed: *self.seed,
            blocks_2d: self.blocks_2d.clone(),
            blocks_3d: self.blocks_3d.clone(),
            trend_block: self.trend_block,
            trend: self.trend.iter().flatten().copied().collect(),
            flight_dts: self.flight_dts.clone(),
            resolve: self.resolve,
            ..v::Config::default()
        }
    }
}

/// Runs `dicephys validate`.
pub fn run(a: &ValidateArgs) -> Result<()> {
    let cfg = StudyConfig::Validate(a.config());
    cfg.validate()?;
    study::run(&cfg, &a.place.local("validate", &cfg)?)
}
