//! `crosscheck`: the very same throws on several engines, side by side: each engine's run, and
//! each engine against the first (the baseline): σ apart, per-throw agreement, cost.

use super::Study;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::report::crosscheck::{Crosscheck, Versus};
use crate::report::summary::{Cost, RunSummary};
use crate::run::cputime::process_cpu_seconds;
use crate::run::spec::RunSpec;
use crate::run::tally::Agreement;
use crate::theory::stats;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// What `crosscheck` runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The engines, the first the baseline.
    pub engines: Vec<EngineKind>,
    /// The run every engine makes (its `engine` replaced by each in turn).
    pub spec: RunSpec,
    /// Accept a restitution above 1 (an engine-stability study, not physics).
    pub allow_restitution_above_one: bool,
}

impl Config {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        if self.engines.len() < 2 {
            return Err(Error::field(
                "engines",
                "",
                "name at least two engines to compare",
            ));
        }
        self.spec.validate(self.allow_restitution_above_one)
    }
}

/// Rolls the run on every engine (each engine's cell kept under `study.checkpoint`, if any,
/// in a directory named by the engine and the run's key) and compares each with the first. A
/// stop request is `Error::Stopped`: nothing is compared. A cluster task's share (or a dry run)
/// compares nothing either: its runs are partial, for the finishing job to assemble.
pub fn run(cfg: &Config, study: &Study) -> Result<Crosscheck> {
    cfg.validate()?;
    let runner = &study.runner;
    let mut runs = Vec::new();
    let mut records = Vec::new();
    for &engine in &cfg.engines {
        let spec = RunSpec {
            engine,
            ..cfg.spec.clone()
        };
        let wall = Instant::now();
        let cpu = process_cpu_seconds();
        let mut recs = Vec::new();
        let ck = study
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
            threads: runner.threads,
        };
        if !done.complete {
            return Err(Error::Stopped);
        }
        runs.push(RunSummary::new(&spec, &done.tally, cost));
        records.push(recs);
    }
    if runner.share.is_partial() {
        return Ok(Crosscheck {
            runs,
            versus: Vec::new(),
        });
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
    Ok(Crosscheck { runs, versus })
}
