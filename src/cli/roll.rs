//! `dicephys roll`: many throws of one block on one engine.

use super::args::{parse_engine, parse_shard, RunArgs, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::summary::{Cost, RunSummary};
use dicephys::run::cputime::process_cpu_seconds;
use dicephys::run::runner::{Checkpoint, Runner};
use dicephys::run::spec::{RunSpec, Shard};
use dicephys::sim::roll::{Fate, RollRecord};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// The options that define a run: `--resume` takes them from the checkpoint instead.
const DEFINING: [&str; 19] = [
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
    "throws",
    "velocity",
    "spin",
    "drop_height",
    "rolls",
    "max_steps",
    "settle",
    "shard",
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
    /// Print one JSON document instead of the human summary.
    #[arg(long)]
    pub json: bool,
    /// Write one CSV row per throw to this file.
    #[arg(long, value_name = "FILE.csv")]
    pub per_roll: Option<PathBuf>,
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
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
}

impl RollArgs {
    /// The run's specification: from the command line, or from the checkpoint it resumes.
    pub fn spec(&self) -> Result<RunSpec> {
        if let Some(dir) = &self.resume {
            return Checkpoint::spec_in(dir)
                .map_err(|e| Error::Usage(format!("--resume {}: {e}", dir.display())));
        }
        let spec = RunSpec {
            engine: self.engine,
            scene: self.scene.scene()?,
            throws: self.throw.spec()?,
            roll: self.run.roll()?,
            rolls: self.run.rolls,
            shard: self.shard,
        };
        spec.validate(self.scene.allow_restitution_above_one)?;
        Ok(spec)
    }
}

/// Runs `dicephys roll`.
pub fn run(a: &RollArgs) -> Result<()> {
    let spec = a.spec()?;
    let threads = a.run.threads()?;
    let per_roll = a.per_roll.as_deref().map(super::output).transpose()?;
    let dir = a.resume.as_ref().or(a.checkpoint.as_ref());
    let checkpoint = dir.map(|d| Checkpoint::open(d, &spec)).transpose()?;
    // The per-roll CSV grows chunk by chunk in a temporary file, put in place at the end.
    let mut csv = match &per_roll {
        Some(out) => {
            let mut w = out.writer()?;
            w.write_all(PER_ROLL_HEADER.as_bytes())?;
            Some(w)
        }
        None => None,
    };
    let dt = spec.scene.dt;
    let mut sink = |recs: &[RollRecord]| -> dicephys::Result<()> {
        if let Some(f) = csv.as_mut() {
            f.write_all(per_roll_rows(recs, dt).as_bytes())
                .map_err(|e| dicephys::Error::Failed(format!("--per-roll: {e}")))?;
        }
        Ok(())
    };
    let wall = Instant::now();
    let cpu = process_cpu_seconds();
    let runner = Runner::new(threads, super::stop().clone());
    let done = runner.run(&spec, checkpoint.as_ref(), &mut sink)?;
    let cost = Cost {
        wall_s: wall.elapsed().as_secs_f64(),
        cpu_s: process_cpu_seconds() - cpu,
        threads,
    };
    if let Some(w) = csv {
        w.commit()?;
    }
    let tally = done.tally;
    let mut summary = RunSummary::new(&spec, &tally, cost);
    summary.partial = !done.complete;
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        print!("{}", summary.human());
    }
    if !done.complete {
        let total = spec.indices().len();
        return Err(Error::Interrupted(match dir {
            Some(d) => format!(
                "interrupted after {} of {total} rolls; continue with: dicephys roll --resume {}",
                tally.rolls,
                d.display()
            ),
            None => format!("interrupted after {} of {total} rolls", tally.rolls),
        }));
    }
    Ok(())
}

/// The per-throw CSV's header.
pub const PER_ROLL_HEADER: &str =
    "index,drop_height_m,velocity_m_s,spin_rad_s,status,outcome,steps,sim_time_s\n";

/// Per-throw CSV rows: index, initial conditions, status, outcome, steps, simulated time.
pub fn per_roll_rows(records: &[RollRecord], dt: f64) -> String {
    let mut s = String::new();
    for r in records {
        let (status, outcome) = match r.fate {
            Fate::Settled(o) => ("settled", o.name()),
            Fate::Unconverged(o) => ("unconverged", o.name()),
            Fate::Failed(f) => (f.name(), ""),
        };
        let t = &r.throw;
        s += &format!(
            "{},{:?},{:?},{:?},{},{},{},{:?}\n",
            t.index,
            t.drop_height,
            t.velocity,
            t.spin,
            status,
            outcome,
            r.steps,
            r.sim_time(dt)
        );
    }
    s
}
