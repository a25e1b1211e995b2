//! `dicephys crosscheck`: the very same throws on several engines, side by side.

use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use crate::batch::{self, Tally};
use crate::cputime::process_cpu_seconds;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::roll::{Fate, RollRecord};
use crate::stats;
use crate::summary::RunSummary;
use crate::throws::Throws;
use clap::Args;
use serde::Serialize;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct CrosscheckArgs {
    /// Engines to compare (comma-separated); the first is the baseline.
    #[arg(long, value_delimiter = ',', default_value = "bullet,rapier", value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub throw: ThrowArgs,
    #[command(flatten)]
    pub run: RunArgs,
    #[arg(long)]
    pub json: bool,
}

/// One engine against the baseline, on identical throws.
#[derive(Clone, Debug, Serialize)]
pub struct Versus {
    pub engine: String,
    pub baseline: String,
    /// (ratio − baseline ratio) / combined binomial error.
    pub z: f64,
    /// Throws both engines settled: how many, and the fraction with the same outcome.
    pub both_settled: u64,
    pub same_outcome_fraction: f64,
    /// This engine's CPU time per roll over the baseline's.
    pub cpu_ratio: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Crosscheck {
    pub runs: Vec<RunSummary>,
    pub versus: Vec<Versus>,
}

fn same_outcomes(a: &[RollRecord], b: &[RollRecord]) -> (u64, f64) {
    let mut both = 0u64;
    let mut same = 0u64;
    for (x, y) in a.iter().zip(b) {
        if let (Fate::Settled(p), Fate::Settled(q)) = (x.fate, y.fate) {
            both += 1;
            same += (p == q) as u64;
        }
    }
    (both, same as f64 / both.max(1) as f64)
}

pub fn run(a: &CrosscheckArgs) -> Result<()> {
    let scene = a.scene.scene()?;
    let ranges = a.throw.ranges()?;
    let settle = a.run.check_at(scene.dt)?;
    if a.engines.len() < 2 {
        return Err(Error::Usage(
            "--engines: name at least two engines to compare".into(),
        ));
    }
    let threads = if a.run.threads == 0 {
        rayon::current_num_threads()
    } else {
        a.run.threads
    };
    let throws = Throws::new(a.throw.throws, a.throw.seed, ranges, a.run.rolls);
    let mut runs = Vec::new();
    let mut records = Vec::new();
    for &engine in &a.engines {
        let wall = Instant::now();
        let cpu = process_cpu_seconds();
        let recs = batch::run(
            engine,
            &scene,
            &throws,
            &settle,
            0..a.run.rolls,
            threads,
            &|_| {},
        )
        .map_err(Error::Run)?;
        let tally = Tally::of(&recs);
        runs.push(RunSummary::new(
            engine,
            &scene,
            a.throw.seed,
            a.throw.throws,
            &ranges,
            &settle,
            &tally,
            wall.elapsed().as_secs_f64(),
            process_cpu_seconds() - cpu,
            threads,
        ));
        records.push(recs);
    }
    let versus: Vec<Versus> = (1..runs.len())
        .map(|i| {
            let (both, frac) = same_outcomes(&records[0], &records[i]);
            Versus {
                engine: runs[i].engine.clone(),
                baseline: runs[0].engine.clone(),
                z: stats::z_score(
                    runs[i].ratio,
                    runs[i].ratio_err,
                    runs[0].ratio,
                    runs[0].ratio_err,
                ),
                both_settled: both,
                same_outcome_fraction: frac,
                cpu_ratio: runs[i].cpu_ms_per_roll / runs[0].cpu_ms_per_roll,
            }
        })
        .collect();
    let out = Crosscheck { runs, versus };
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        for r in &out.runs {
            print!("{}", r.human());
        }
        for v in &out.versus {
            println!(
                "{} vs {}: {:+.1} σ apart; same outcome on {:.1} % of the {} throws both settled; CPU per roll {:.2}x",
                v.engine,
                v.baseline,
                v.z,
                100.0 * v.same_outcome_fraction,
                v.both_settled,
                v.cpu_ratio
            );
        }
    }
    Ok(())
}
