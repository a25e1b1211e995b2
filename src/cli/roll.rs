//! `dicephys roll`: many throws of one block on one engine.

use super::args::Json;
use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use super::term::{out, outln};
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::precision::Target;
use dicephys::report::progress::{Progress, Unit};
use dicephys::run::request::RollRequest;
use dicephys::run::runner::{Checkpoint, Runner};
use dicephys::run::spec::{RunSpec, Shard};
use dicephys::studies::outputs;
use std::path::PathBuf;
use std::sync::atomic::Ordering::Relaxed;

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
    if spec.scene.shape.is_some() && a.run.precision.is_some() {
        return Err(Error::Usage(
            "--precision is the ratio's (breadth against width vertical), which a die of any \
             shape has not: `dicephys fair --within PP` rolls until every face's probability is \
             known to PP percentage points"
                .into(),
        ));
    }
    if let Some(w) = paper_throw_warning(&spec) {
        eprintln!("{w}");
    }
    if let Some(w) = spec.endless_roll_warning() {
        eprintln!("dicephys: warning: {w}");
    }
    if let Some(n) = hull_note(&spec).filter(|_| !*a.json) {
        eprintln!("dicephys: note: {n}");
    }
    if let Some(n) = spec.loaded_die_note(&[spec.engine]).filter(|_| !*a.json) {
        eprintln!("dicephys: note: {n}");
    }
    let (summary, done) = rolled(a, &spec, "roll", Target::Ratio)?;
    // Broken physics says so on the terminal too, whatever goes to stdout.
    if *a.json {
        for w in &summary.warnings {
            eprintln!("dicephys: warning: {w}");
        }
    }
    if *a.json {
        outln!("{}", dicephys::run::seal::to_string(&summary, true)?);
    } else {
        out!("{}", summary.human());
    }
    // A die of any shape none of whose rolls came to rest on a face has no shares to give.
    if let Some(shape) = summary.shape.as_ref().filter(|_| !summary.partial) {
        if summary.rolls > 0 && shape.faces.iter().all(|f| f.count == 0) {
            let why = dicephys::report::shape_outcomes::check_settled(&summary.tally)
                .err()
                .map_or_else(
                    || "no roll came to rest on a face".into(),
                    |e| e.to_string(),
                );
            return Err(Error::Run(why));
        }
    }
    done
}

/// Rolls `spec` as `roll` does (its checkpoint, per-roll CSV, precision and progress bar,
/// named `command`): its summary, numbered by `--layout`, and what to end with once it is
/// printed (a stop request's interruption, with how to continue).
pub fn rolled(
    a: &RollArgs,
    spec: &RunSpec,
    command: &'static str,
    target: dicephys::report::precision::Target,
) -> Result<(dicephys::report::summary::RunSummary, Result<()>)> {
    // The flag that set the precision: fair's target is its faces (--within).
    let flag = match target {
        Target::Ratio => "--precision",
        Target::Faces => "--within",
    };
    if let (Some(_), Some(_)) = (a.run.precision, spec.shard) {
        return Err(Error::Usage(format!(
            "{flag} with --shard: a shard rolls a fixed share of the throws; give --rolls"
        )));
    }
    let threads = a.run.threads()?;
    let per_roll = a
        .per_roll
        .as_deref()
        .map(|p| super::term::output(p).map(|o| (o, a.layout(spec))))
        .transpose()?;
    let dir = a.resume.as_ref().or(a.checkpoint.as_ref());
    let total = spec.indices().len();
    let unit = Unit::Rolls { per_cell: 0 };
    let bar = Progress::new(command, unit, true, *a.json, super::study::every());
    // Under --precision the total is the rolls expected so far, not the cap.
    let expected = std::sync::atomic::AtomicU64::new(total);
    let progress = |n: u64| bar.set(n as f64, expected.load(Relaxed) as f64);
    let expect = |n: u64| expected.store(n, Relaxed);
    let runner = Runner::new(threads, super::term::stop().clone());
    let runner = runner.with_progress(&progress);
    let summary = outputs::roll(
        spec,
        dir.map(PathBuf::as_path),
        per_roll,
        a.run
            .precision
            .map(|p| (p, target, &expect as &dyn Fn(u64))),
        &runner,
    );
    bar.finish();
    let summary = summary?.with_layout(a.layout(spec));
    let rolled = summary.rolls;
    if summary.partial {
        let resume = dir.map(|d| {
            format!(
                "dicephys {command} --resume {}{}",
                d.display(),
                a.run
                    .precision
                    .map_or(String::new(), |p| format!(" {flag} {}", 100.0 * p))
            )
        });
        let why = Error::Interrupted(dicephys::run::stop::interrupted(
            &dicephys::run::stop::Kept::Rolls {
                done: rolled,
                of: total,
                resume,
            },
        ));
        return Ok((summary, Err(why)));
    }
    Ok((summary, Ok(())))
}

/// A warning when the paper's throw meets a block whose long axis is not unique (a cube): the
/// throw spins it about body z, so the two z faces come up less often than a tester's throw
/// would show them (issue 50: "a fair cube that looks loaded").
fn paper_throw_warning(spec: &RunSpec) -> Option<String> {
    let b = &spec.scene.block;
    let paper = spec.throws.style == dicephys::model::throws::ThrowStyle::Paper;
    (paper && spec.scene.shape.is_none() && b.length <= b.breadth * (1.0 + 1e-9)).then(|| {
        format!(
            "dicephys: warning: the paper's throw spins the block about its length, and {} has \
             no longer length: faces 1 and 6 will come up less often than on a tester's throw; \
             --throw tumble throws it without a preferred axis",
            b
        )
    })
}

/// The note for a die of any shape that is not convex (it rolls on its hull), if it is one.
pub fn hull_note(spec: &RunSpec) -> Option<String> {
    spec.scene.shape.as_ref().and_then(|s| s.hull_note())
}
