//! `dicephys crosscheck`: the very same throws on several engines, side by side.

use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use super::{out, outln};
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::summary::{Cost, RunSummary};
use dicephys::run::cputime::process_cpu_seconds;
use dicephys::run::spec::RunSpec;
use dicephys::run::tally::Agreement;
use dicephys::theory::stats;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// `dicephys crosscheck`'s arguments.
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
    /// Keep each engine's rolls here as they are made (a directory per engine, in chunks of
    /// 1,000 rolls): the same command run again continues where it stopped.
    #[arg(long, value_name = "DIR")]
    pub checkpoint: Option<PathBuf>,
    /// Print one JSON document instead of the human summary.
    #[arg(long)]
    pub json: bool,
}

/// One engine against the baseline, on identical throws.
#[derive(Clone, Debug, Serialize)]
pub struct Versus {
    /// The engine compared.
    pub engine: EngineKind,
    /// The baseline engine.
    pub baseline: EngineKind,
    /// (ratio − baseline ratio) / combined binomial error.
    pub z: f64,
    /// Throws both engines settled: how many, and the fraction of them with the same outcome.
    pub both_settled: u64,
    /// Same outcome over the throws both settled.
    pub same_outcome_fraction: f64,
    /// This engine's CPU time per roll over the baseline's.
    pub cpu_ratio: f64,
}

/// The whole cross-check.
#[derive(Clone, Debug, Serialize)]
pub struct Crosscheck {
    /// Each engine's run, baseline first.
    pub runs: Vec<RunSummary>,
    /// Each other engine against the baseline.
    pub versus: Vec<Versus>,
}

/// Runs `dicephys crosscheck`.
pub fn run(a: &CrosscheckArgs) -> Result<()> {
    if a.engines.len() < 2 {
        return Err(Error::Usage(
            "--engines: name at least two engines to compare".into(),
        ));
    }
    let scene = a.scene.scene()?;
    let base = RunSpec {
        engine: a.engines[0],
        roll: a.run.roll(scene.dt)?,
        scene,
        throws: a.throw.spec()?,
        rolls: a.run.rolls,
        shard: None,
    };
    base.validate(a.scene.allow_restitution_above_one)?;
    let threads = a.run.threads()?;
    let runner = super::runner(threads);
    let mut runs = Vec::new();
    let mut records = Vec::new();
    for &engine in &a.engines {
        let spec = RunSpec {
            engine,
            ..base.clone()
        };
        let wall = Instant::now();
        let cpu = process_cpu_seconds();
        let mut recs = Vec::new();
        let ck = a
            .checkpoint
            .as_ref()
            .map(|d| runner.open_cell(&d.join(format!("{engine}-{}", spec.key())), &spec))
            .transpose()?;
        let done = runner.run(&spec, ck.as_ref(), &mut |r| {
            recs.extend_from_slice(r);
            Ok(())
        })?;
        let cost = Cost {
            wall_s: wall.elapsed().as_secs_f64(),
            cpu_s: process_cpu_seconds() - cpu,
            threads,
        };
        if !done.complete {
            return Err(Error::Interrupted(format!(
                "interrupted during {engine} after {} of {} rolls; nothing compared",
                done.tally.rolls, spec.rolls
            )));
        }
        runs.push(RunSummary::new(&spec, &done.tally, cost));
        records.push(recs);
    }
    if super::is_task() {
        // A cluster task's share: its chunks are kept for the finishing job; nothing to compare.
        return Ok(());
    }
    let versus: Vec<Versus> = (1..runs.len())
        .map(|i| {
            let agree = Agreement::of(&records[0], &records[i]);
            Versus {
                engine: runs[i].engine,
                baseline: runs[0].engine,
                z: stats::z_score(
                    runs[i].ratio,
                    runs[i].ratio_err,
                    runs[0].ratio,
                    runs[0].ratio_err,
                ),
                both_settled: agree.both_settled,
                same_outcome_fraction: agree.of_settled(),
                cpu_ratio: runs[i].cpu_ms_per_roll / runs[0].cpu_ms_per_roll,
            }
        })
        .collect();
    let out = Crosscheck { runs, versus };
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        for r in &out.runs {
            out!("{}", r.human());
        }
        for v in &out.versus {
            outln!(
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
