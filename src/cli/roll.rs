//! `dicephys roll`: many throws of one block on one engine.

use super::args::Json;
use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::fair::Null;
use dicephys::run::request::RollRequest;
use dicephys::run::runner::Checkpoint;
use dicephys::run::spec::{RunSpec, Shard};
use dicephys::studies::roll::RollStudy;
use dicephys::studies::StudyConfig;
use std::path::{Path, PathBuf};

/// The options that define a run: `--resume` takes them from the checkpoint instead.
const DEFINING: [&str; 36] = [
    "shape",
    "size",
    "scale",
    "com",
    "pips",
    "edge_radius",
    "shell",
    "die",
    "floor_thickness",
    "engine",
    "block",
    "two_d",
    "dt",
    "friction",
    "restitution",
    "allow_restitution_above_one",
    "density",
    "preset",
    "floor",
    "seed",
    "source",
    "velocity",
    "spin",
    "drop_height",
    "rolls",
    "max_steps",
    "settle",
    "shard",
    "linear_damping",
    "angular_damping",
    "rolling_resistance",
    "bounce_threshold",
    "contact_time",
    "static_ratio",
    "no_sleep",
    "style",
];

/// `dicephys roll`'s arguments.
#[derive(Args, Debug)]
pub struct RollArgs {
    /// Physics engine: bullet, rapier (in 2D a true 2D body), rapier-locked (in 2D a locked 3D
    /// body, as DicePhys).
    #[arg(long, default_value = "bullet", value_parser = parse_engine)]
    pub engine: EngineKind,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub throw: ThrowArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
    /// Write one CSV row per throw to this file.
    #[arg(long, value_name = "FILE.csv")]
    pub per_roll: Option<PathBuf>,
    /// How the numbers sit on the faces, for `faces` and the per-roll `face` column: right
    /// (western dice: 1 on +z, 6 on −z, 2 on +x, 3 on +y; 1, 2, 3 counter-clockwise about
    /// their corner) or left (its mirror image) [default: right, or the --die file's layout
    /// or face map].
    #[arg(long, value_parser = super::args::parse_layout)]
    pub layout: Option<dicephys::model::faces::Layout>,
    /// Keep a checkpoint here as the run goes (chunks of 1,000 rolls, written atomically);
    /// `dicephys roll --resume DIR` continues it, bit for bit.
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub checkpoint: Option<PathBuf>,
    /// Continue the run checkpointed in DIR, with the specification stored there (only
    /// --threads, --json and --per-roll may be given beside it).
    #[arg(long, value_name = "DIR", conflicts_with_all = DEFINING.iter().chain(&["margin", "audit", "flight", "faithful"]))]
    pub resume: Option<PathBuf>,
    /// Roll only throws with index ≡ K (mod N); `dicephys merge` combines the shards' --json
    /// outputs into the unsharded result.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
}

impl RollArgs {
    /// The run's specification: from the command line, or from the checkpoint it resumes.
    pub fn spec(&self) -> Result<RunSpec> {
        self.spec_or(dicephys::model::throws::ThrowStyle::Paper)
    }

    /// The run's specification, thrown in the style `default` unless `--throw` gives one.
    pub fn spec_or(&self, default: dicephys::model::throws::ThrowStyle) -> Result<RunSpec> {
        if let Some(dir) = &self.resume {
            return Checkpoint::spec_in(dir)
                .map_err(|e| Error::Usage(format!("--resume {}: {e}", dir.display())));
        }
        // The numbers on the faces are the run's: stored in its specification, so that a
        // resumed, merged or Slurm run reads its faces as this one (and the pips follow the
        // numbers: the layout places them).
        let mut scene = self.scene.request();
        scene.die.layout = self.layout;
        let request = RollRequest {
            scene,
            throws: self.throw.request(),
            end: self.run.end(),
            engine: self.engine,
            rolls: self.run.rolls,
            to_precision: self.run.precision.is_some(),
            shard: self.shard,
        };
        request
            .spec_or(default)
            .map_err(|e| self.scene.made.named(e))
    }

    /// The numbers on the faces of `spec`'s die: `--layout`, else the die's own (a die
    /// file's layout or face map), else right.
    pub fn layout(&self, spec: &RunSpec) -> dicephys::model::faces::Layout {
        spec.scene.features.layout
    }
}

/// Runs `dicephys roll`.
pub fn run(a: &RollArgs) -> Result<()> {
    let spec = a.spec()?;
    if spec.scene.die.as_shape().is_some() && a.run.precision.is_some() {
        return Err(Error::Usage(
            "--precision is the ratio's (breadth against width vertical), which a die of any \
             shape has not: `dicephys fair --within PP` rolls until every face's probability is \
             known to PP percentage points"
                .into(),
        ));
    }
    study(a, spec, None, None)
}

/// Rolls `spec` as `a` asks (its checkpoint, per-roll CSV, precision), as every study runs
/// (`studies::roll`: its bar, its notes, what it prints, how it ends); with `fair`, its faces
/// judged against that null, and its files written into `out` if given.
pub fn study(a: &RollArgs, spec: RunSpec, fair: Option<Null>, out: Option<&Path>) -> Result<()> {
    if let (Some(_), Some(_)) = (a.run.precision, spec.shard) {
        // The flag that set the precision: fair's target is its faces (--within).
        let flag = if fair.is_some() {
            "--within"
        } else {
            "--precision"
        };
        return Err(Error::Usage(format!(
            "{flag} with --shard: a shard rolls a fixed share of the throws; give --rolls"
        )));
    }
    let threads = a.run.threads()?;
    let checkpoint = a.resume.clone().or_else(|| a.checkpoint.clone());
    let place = super::study::here(out, checkpoint, threads, *a.json)?;
    let study = RollStudy {
        spec,
        fair,
        precision: a.run.precision,
        per_roll: a.per_roll.clone(),
        resumed: a.resume.is_some(),
    };
    super::study::run(&StudyConfig::Roll(study), &place)
}
