//! `dicephys converge`, `tradeoff` and `stability`: the sweeps' flags, turned into the library's
//! configurations (`dicephys::studies::{converge, tradeoff, stability}`); each writes
//! `<command>.json`, `report.md` and its figures into --out (`super::study`).

use super::args::Seed;
use super::args::{parse_engine, parse_percent};
use super::error::{Error, Result};
use super::study;
use super::study::StudyPlace;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::model::block::Block;
use dicephys::model::scene::Mode;
use dicephys::studies::sweep::parse_dt;
use dicephys::studies::{converge, stability, tradeoff, StudyConfig};

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// Blocks, LENGTHxBREADTHxWIDTH in mm (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "140x24x20,140x22x13,140x30x10"
    )]
    pub blocks: Vec<Block>,
    /// Time steps, s or 1/N (comma-separated); the paper's full set is
    /// 1/60,1/120,1/240,1/500,1/1000,1/2000,1/5000,1/10000.
    #[arg(long, value_delimiter = ',', default_value = "1/60,1/250,1/1000,1/5000", value_parser = parse_dt)]
    pub dts: Vec<f64>,
    /// Engines to simulate with (comma-separated): bullet, rapier, rapier-locked.
    #[arg(long, value_delimiter = ',', default_value = super::args::DEFAULT_ENGINES, value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Rolls per cell (block × engine × mode × dt).
    #[arg(long, default_value_t = 200)]
    pub rolls: u64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Threads, --out, --json.
    #[command(flatten)]
    pub place: StudyPlace,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = converge::Config::default().max_steps)]
    pub max_steps: u64,
    /// Precision as the input, per cent at 2σ ("1" or "1%"): every cell rolled in rounds of one
    /// keyed stream until its departure from the finest dt is resolved to it (--rolls ignored).
    #[arg(long, value_parser = parse_percent)]
    pub precision: Option<f64>,
    /// With --precision: CPU seconds a cell may spend.
    #[arg(long, default_value_t = 600.0)]
    pub budget: f64,
    /// With --precision: CPU seconds the finest dt's cell may spend.
    #[arg(long, default_value_t = 1800.0)]
    pub reference_budget: f64,
    /// Roll the fast way (closed-form flight; the exact early stop at dt <= 1/250 s), which
    /// `tradeoff` shows gives the same outcomes at fine steps, instead of every step stepped.
    #[arg(long)]
    pub fast: bool,
}

#[derive(Args, Debug)]
pub struct TradeoffArgs {
    /// The block, LENGTHxBREADTHxWIDTH in mm.
    #[arg(long, default_value = "140x24x20", conflicts_with = "blocks")]
    pub block: Block,
    /// Several blocks (comma-separated), each with its own reference and methods, and a
    /// summary across them.
    #[arg(long, value_delimiter = ',')]
    pub blocks: Vec<Block>,
    /// The modes (comma-separated): 3d, 2d or both.
    #[arg(long, value_delimiter = ',', default_value = "3d,2d")]
    pub modes: Vec<Mode>,
    /// Bullet's time steps (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1/100,1/250,1/1000", value_parser = parse_dt)]
    pub dts: Vec<f64>,
    /// Rapier's time steps (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1/250,1/1000", value_parser = parse_dt)]
    pub rapier_dts: Vec<f64>,
    /// The reference's time step (Bullet, box floor, rolled the fast way).
    #[arg(long, default_value = "1/5000", value_parser = parse_dt)]
    pub reference_dt: f64,
    /// The reference's ladder: other fine steps rolled like the reference, each a departure
    /// from it (comma-separated; "none" for none).
    #[arg(long, value_delimiter = ',', default_value = DEFAULT_LADDER, value_parser = parse_dt_or_none)]
    pub ladder: Vec<Option<f64>>,
    /// The 2σ half-width asked of every departure, in per cent of the ratio ("1" or "1%").
    #[arg(long, default_value = DEFAULT_PRECISION, value_parser = parse_percent)]
    pub precision: f64,
    /// CPU seconds a method may spend before it is left unresolved.
    #[arg(long, default_value_t = 600.0)]
    pub budget: f64,
    /// CPU seconds the reference (each mode's) may spend.
    #[arg(long, default_value_t = 1800.0)]
    pub reference_budget: f64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Threads, --out, --json.
    #[command(flatten)]
    pub place: StudyPlace,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = tradeoff::Config::default().max_steps)]
    pub max_steps: u64,
    /// Roll the pilot (a chunk of every method, kept), print the plan (the CPU the precision
    /// asked costs, and the precision an hour buys) and stop.
    #[arg(long)]
    pub plan: bool,
    /// Roll the first ROLLS throws (in whole 1,000s) of every stream (methods, reference, its
    /// ladder and checks) into --out/checkpoint and stop, deciding nothing: what the tasks of
    /// `dicephys slurm tradeoff` do, before its finishing job runs the study, reading them back.
    #[arg(long, value_name = "ROLLS")]
    pub preroll: Option<u64>,
}

/// `tradeoff`'s default precision, per cent at 2σ: what about 60 minutes on 2 cores buys at
/// the defaults (docs/results/tradeoff.md).
pub const DEFAULT_PRECISION: &str = "2";

/// `tradeoff`'s default ladder under the reference.
pub const DEFAULT_LADDER: &str = "1/2000,1/10000";

fn parse_dt_or_none(s: &str) -> std::result::Result<Option<f64>, String> {
    if s.trim() == "none" {
        Ok(None)
    } else {
        parse_dt(s).map(Some).map_err(|e| e.to_string())
    }
}

#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// Engines to simulate with (comma-separated): bullet, rapier, rapier-locked.
    #[arg(long, value_delimiter = ',', default_value = super::args::DEFAULT_ENGINES, value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Time steps of the dt × restitution grid.
    #[arg(long, value_delimiter = ',', default_value = "1/1000,1/240,1/60,1/30", value_parser = parse_dt)]
    pub dts: Vec<f64>,
    /// Restitutions of the grid (0 to 0.95).
    #[arg(long, value_delimiter = ',', default_value = "0,0.5,0.8,0.95")]
    pub restitutions: Vec<f64>,
    /// Frictions of the friction line (0 to 1.5).
    #[arg(long, value_delimiter = ',', default_value = "0,0.29,0.8,1.5")]
    pub frictions: Vec<f64>,
    /// Blocks of the aspect line: breadth/width up to 10, length/breadth down to 1.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "140x24x20,140x40x20,140x100x20,200x200x20,24x24x20"
    )]
    pub blocks: Vec<Block>,
    /// Rolls per cell: 300 make a fraction's standard error at most 2.9 % and a 0 mean below
    /// 1 % at 95 %.
    #[arg(long, default_value_t = 300)]
    pub rolls: u64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Threads, --out, --json.
    #[command(flatten)]
    pub place: StudyPlace,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = stability::Config::default().max_steps)]
    pub max_steps: u64,
    /// The box floor's thickness, m (DicePhys's 100); 0.02, a table top, lets a die at a
    /// coarse step really pass through it.
    #[arg(long, default_value_t = dicephys::model::scene::DICEPHYS_FLOOR_THICKNESS)]
    pub floor_thickness: f64,
}

impl ConvergeArgs {
    /// The study's configuration.
    pub fn config(&self) -> converge::Config {
        converge::Config {
            blocks: self.blocks.clone(),
            dts: self.dts.clone(),
            engines: self.engines.clone(),
            rolls: self.rolls,
            seed: *self.seed,
            max_steps: self.max_steps,
            precision: self.precision,
            budget_s: self.budget,
            reference_budget_s: self.reference_budget,
            fast: self.fast,
        }
    }
}

impl TradeoffArgs {
    /// The study's configuration.
    pub fn config(&self) -> Result<tradeoff::Config> {
        if let Some(r) = self.preroll {
            let max = dicephys::run::spec::MAX_ROLLS;
            if r == 0 || r > max {
                return Err(Error::Usage(format!(
                    "--preroll {r}: must be in 1..={max} rolls"
                )));
            }
        }
        let blocks = if self.blocks.is_empty() {
            vec![self.block]
        } else {
            self.blocks.clone()
        };
        Ok(tradeoff::Config {
            blocks,
            modes: self.modes.clone(),
            dts: self.dts.clone(),
            rapier_dts: self.rapier_dts.clone(),
            reference_dt: self.reference_dt,
            ladder: self.ladder.iter().flatten().copied().collect(),
            precision: self.precision,
            budget_s: self.budget,
            reference_budget_s: self.reference_budget,
            seed: *self.seed,
            max_steps: self.max_steps,
            plan_only: self.plan,
            preroll_chunks: self
                .preroll
                .map(|r| r.div_ceil(dicephys::run::runner::CHUNK_ROLLS)),
        })
    }
}

impl StabilityArgs {
    /// The study's configuration.
    pub fn config(&self) -> stability::Config {
        stability::Config {
            engines: self.engines.clone(),
            dts: self.dts.clone(),
            restitutions: self.restitutions.clone(),
            frictions: self.frictions.clone(),
            blocks: self.blocks.clone(),
            rolls: self.rolls,
            seed: *self.seed,
            max_steps: self.max_steps,
            floor_thickness: self.floor_thickness,
        }
    }
}

/// Runs `dicephys converge`.
pub fn converge(a: &ConvergeArgs) -> Result<()> {
    let cfg = StudyConfig::Converge(a.config());
    study::run(&cfg, &a.place.local("converge", &cfg)?)
}

/// Runs `dicephys tradeoff`.
pub fn tradeoff(a: &TradeoffArgs) -> Result<()> {
    let cfg = StudyConfig::Tradeoff(a.config()?);
    study::run(&cfg, &a.place.local("tradeoff", &cfg)?)
}

/// Runs `dicephys stability`.
pub fn stability(a: &StabilityArgs) -> Result<()> {
    let cfg = StudyConfig::Stability(a.config());
    study::run(&cfg, &a.place.local("stability", &cfg)?)
}
