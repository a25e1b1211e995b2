//! `dicephys roll`: many throws of one block on one engine.

use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use crate::batch::{self, Tally};
use crate::cputime::process_cpu_seconds;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::roll::{Fate, RollRecord};
use crate::summary::RunSummary;
use crate::throws::Throws;
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

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
}

pub fn run(a: &RollArgs) -> Result<()> {
    let scene = a.scene.scene()?;
    let ranges = a.throw.ranges()?;
    let settle = a.run.check()?;
    if let Some(p) = &a.per_roll {
        super::check_writable(p)?;
    }
    let throws = Throws::new(a.throw.throws, a.throw.seed, ranges, a.run.rolls);
    let threads = if a.run.threads == 0 {
        rayon::current_num_threads()
    } else {
        a.run.threads
    };
    let wall = Instant::now();
    let cpu = process_cpu_seconds();
    let records = batch::run(
        a.engine,
        &scene,
        &throws,
        &settle,
        0..a.run.rolls,
        threads,
        &|_| {},
    )
    .map_err(Error::Run)?;
    let cpu_s = process_cpu_seconds() - cpu;
    let wall_s = wall.elapsed().as_secs_f64();
    let tally = Tally::of(&records);
    let summary = RunSummary::new(
        a.engine,
        &scene,
        a.throw.seed,
        a.throw.throws,
        &ranges,
        &settle,
        &tally,
        wall_s,
        cpu_s,
        threads,
    );
    if let Some(p) = &a.per_roll {
        write_per_roll(p, &records, scene.dt)?;
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        print!("{}", summary.human());
    }
    Ok(())
}

/// The per-throw CSV: index, initial conditions, status, outcome, steps, simulated time.
pub fn per_roll_csv(records: &[RollRecord], dt: f64) -> String {
    let mut s = String::from(
        "index,drop_height_m,velocity_m_s,spin_rad_s,status,outcome,steps,sim_time_s\n",
    );
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

fn write_per_roll(path: &std::path::Path, records: &[RollRecord], dt: f64) -> Result<()> {
    super::write_atomic(path, per_roll_csv(records, dt).as_bytes())
}
