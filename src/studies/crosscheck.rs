//! `crosscheck`: the very same throws on several engines, side by side: each engine's run, and
//! each engine against the first (the baseline): σ apart, per-throw agreement, cost.

use super::study::Study;
use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::scene::Preset;
use crate::report::crosscheck::{Crosscheck, Versus};
use crate::report::precision::Reached;
use crate::report::summary::{Cost, RunSummary};
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::{Checkpoint, Runner, CHUNK_ROLLS};
use crate::run::spec::RunSpec;
use crate::run::tally::{Agreement, Tally};
use crate::sim::roll::RollRecord;
use crate::theory::stats;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The preset a crosscheck runs under where none is given: `laws`, the one under which every
/// engine is held to the same closed forms (a frictional impact, Coulomb's cone against the
/// slip, the die turning as Euler's equations say: `tests/it/impact.rs`). Under the others each
/// engine keeps its own contact model, and the engines part where those differ rather than
/// where the physics is in doubt: a 16 mm cube loaded 4.5 mm toward 6 and thrown in a tumble
/// comes up 6 in 5.1 % of 20,000 throws on Bullet under dicephys281 and 4.3 % on Rapier as it
/// ships (at 0.1 ms), where each engine under `laws` and the arbiter (`--engine moreau`) give
/// 12.1–12.4 % (issue 46; docs/results/rapier.md). `roll` and `fair` keep the paper's, dicephys281.
pub const PRESET: Preset = Preset::Laws;

/// The preset a crosscheck runs under where none is given: [`PRESET`], or the paper's where the
/// run is DicePhys as the paper ran it (`--faithful`), preset and all.
pub fn default_preset(faithful: bool) -> Preset {
    if faithful {
        crate::run::request::SceneRequest::default().preset
    } else {
        PRESET
    }
}

/// What `crosscheck` runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The engines, the first the baseline.
    pub engines: Vec<EngineKind>,
    /// The run every engine makes (its `engine` replaced by each in turn).
    pub spec: RunSpec,
    /// Accept a restitution above 1 (an engine-stability study, not physics).
    pub allow_restitution_above_one: bool,
    /// Roll every engine chunk by chunk, in step, until each one's ratio has a relative 2σ
    /// error at most this (a fraction), `spec.rolls` the cap.
    #[serde(default)]
    pub precision: Option<f64>,
}

impl Config {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        if self.engines.len() < 2 {
            return Err(Error::field(
                Field::Engines,
                "",
                "name at least two engines to compare",
            ));
        }
        for (i, e) in self.engines.iter().enumerate() {
            if self.engines[..i].contains(e) {
                return Err(Error::field(
                    Field::Engines,
                    e,
                    "named twice: name each engine once, at least two different ones",
                ));
            }
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
    let mut cells = Vec::new();
    for &engine in &cfg.engines {
        let spec = RunSpec {
            engine,
            ..cfg.spec.clone()
        };
        let ck = study
            .checkpoint
            .as_ref()
            .map(|d| runner.open_cell(&d.join(format!("{engine}-{}", spec.key())), &spec))
            .transpose()?;
        cells.push(Cell {
            spec,
            ck,
            records: Vec::new(),
            tally: Tally::default(),
            cpu_s: 0.0,
            wall_s: 0.0,
        });
    }
    let chunks = cfg.spec.indices().len().div_ceil(CHUNK_ROLLS);
    let mut reached = None;
    match cfg.precision {
        // Each engine in turn over all its throws.
        None => {
            for cell in &mut cells {
                cell.roll(runner, 0..chunks)?;
            }
        }
        // The engines in step, a chunk each, until every ratio is resolved: the rule sees
        // the same throws on every engine, at chunk boundaries only.
        Some(p) => {
            for c in 0..chunks {
                let tallies: Vec<&Tally> = cells.iter().map(|c| &c.tally).collect();
                if Reached::of(&tallies, p).resolved {
                    break;
                }
                for cell in &mut cells {
                    cell.roll(runner, c..c + 1)?;
                }
            }
            let tallies: Vec<&Tally> = cells.iter().map(|c| &c.tally).collect();
            reached = Some(Reached::of(&tallies, p));
        }
    }
    let runs: Vec<RunSummary> = cells
        .iter()
        .map(|c| {
            let cost = Cost {
                wall_s: c.wall_s,
                cpu_s: c.cpu_s,
                threads: runner.threads,
            };
            RunSummary::new(&c.spec, &c.tally, cost)
        })
        .collect();
    let records: Vec<Vec<RollRecord>> = cells.into_iter().map(|c| c.records).collect();
    if runner.share.is_partial() {
        return Ok(Crosscheck {
            runs,
            versus: Vec::new(),
            precision: reached,
        });
    }
    let versus: Vec<Versus> = (1..runs.len())
        .map(|i| {
            let agree = Agreement::of(
                &records[0],
                &records[i],
                runs[0].spec.scene.die.counts_sides(),
            );
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
                outcomes: crate::report::crosscheck::OutcomesCompared::of(&runs[i], &runs[0]),
            }
        })
        .collect();
    Ok(Crosscheck {
        runs,
        versus,
        precision: reached,
    })
}

/// One engine's run: its spec, its cell, what it has rolled and what that cost.
struct Cell {
    spec: RunSpec,
    ck: Option<Checkpoint>,
    records: Vec<RollRecord>,
    tally: Tally,
    cpu_s: f64,
    wall_s: f64,
}

impl Cell {
    /// Rolls the chunks in `range` (from the cell's checkpoint where kept); a stop request is
    /// `Error::Stopped`.
    fn roll(&mut self, runner: &Runner, range: std::ops::Range<u64>) -> Result<()> {
        let (wall, cpu) = (Instant::now(), process_cpu_seconds());
        let recs = &mut self.records;
        let done = runner.run_range(&self.spec, self.ck.as_ref(), range, &mut |r| {
            recs.extend_from_slice(r);
            Ok(())
        })?;
        self.tally.merge(&done.tally)?;
        self.cpu_s += process_cpu_seconds() - cpu;
        self.wall_s += wall.elapsed().as_secs_f64();
        if !done.complete {
            return Err(Error::Stopped);
        }
        Ok(())
    }
}
