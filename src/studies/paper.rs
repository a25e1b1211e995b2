//! `dicephys paper`: the paper end to end. Every row of its table with theory, measurement and
//! the no-bounce prediction; for the five rows it simulated (printed blocks on MDF, μ = 0.29,
//! e = 0.5) our simulations in 3D and 2D on each engine, with z-scores against experiment and
//! theory.

use crate::engine::EngineKind;
use crate::error::{Field, Result};
use crate::model::block::Block;
use crate::model::scene::{Mode, Preset, Scene};
use crate::report::paper::{PaperResults, Provenance, SimCell};
use crate::report::summary::{Cost, RunSummary};
use crate::report::table::{table_report, TableReport};
use crate::run::cputime::process_cpu_seconds;
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::sim::roll::{early_stop_exact, RollConfig, Rule};
use crate::studies::study::Study;
use crate::theory::stats;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The engines the paper's study runs when none are asked: both, side by side.
pub const DEFAULT_ENGINES: [crate::engine::EngineKind; 2] = [
    crate::engine::EngineKind::Bullet,
    crate::engine::EngineKind::Rapier,
];

/// What to simulate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PaperConfig {
    /// Rolls per cell.
    pub rolls: u64,
    /// The throws' seed (keyed throws, the same in every cell).
    pub seed: u64,
    /// The engines, each run in 3D and 2D.
    pub engines: Vec<EngineKind>,
    /// The time step, s.
    pub dt: f64,
    /// The step cap per roll.
    pub max_steps: u64,
    /// DicePhys's rest rule and stepped flight, instead of the early stop and fast flight.
    pub faithful: bool,
}

/// The blocks the paper simulated: the table rows marked `simulated`.
pub fn simulated_rows(table: &TableReport) -> Vec<(usize, String, Block)> {
    table
        .rows
        .iter()
        .filter(|r| r.simulated)
        .filter_map(|r| {
            Block::from_mm(r.length_mm, r.breadth_mm, r.width_mm)
                .ok()
                .map(|b| (r.row, r.label.clone(), b))
        })
        .collect()
}

impl PaperConfig {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        use crate::error::Error;
        if self.engines.is_empty() {
            return Err(Error::field(Field::Engines, "", "name at least one engine"));
        }
        let mut scene = Scene::paper(Block::from_mm(140.0, 24.0, 20.0)?, Mode::ThreeD);
        scene.dt = self.dt;
        scene.validate(false)?;
        RunSpec {
            engine: self.engines[0],
            scene,
            throws: ThrowSpec::keyed(self.seed),
            roll: self.roll(),
            rolls: self.rolls,
            shard: None,
        }
        .validate(false)
    }

    /// How each roll is carried out and ended.
    /// The early stop only where it is audited exact (`roll::EARLY_STOP_MAX_DT`).
    pub fn roll(&self) -> RollConfig {
        let fast = RollConfig {
            rule: if early_stop_exact(self.dt) {
                Rule::Certificate
            } else {
                Rule::Dicephys
            },
            ..RollConfig::fast()
        };
        RollConfig {
            max_steps: self.max_steps,
            ..if self.faithful {
                RollConfig::faithful()
            } else {
                fast
            }
        }
    }
}

/// The number of rolls `run` will make, for a progress bar.
pub fn total_rolls(cfg: &PaperConfig) -> Result<u64> {
    let table = table_report()?;
    Ok(simulated_rows(&table).len() as u64 * cfg.engines.len() as u64 * 2 * cfg.rolls)
}

/// Runs every simulated cell. The runner's `progress` gets the rolls finished so far, over all
/// cells.
pub fn run(cfg: &PaperConfig, command_line: String, study: &Study) -> Result<PaperResults> {
    cfg.validate()?;
    let runner = &study.runner;
    let mut partial = false;
    let table = table_report()?;
    let settle = cfg.roll();
    let mut done_before = 0u64;
    let mut simulations = Vec::new();
    'cells: for (row, label, block) in simulated_rows(&table) {
        let t = table.rows.iter().find(|r| r.row == row).expect("row");
        for &engine in &cfg.engines {
            for mode in [Mode::ThreeD, Mode::TwoD] {
                if partial {
                    break 'cells;
                }
                let mut scene = Scene::paper(block, mode);
                scene.dt = cfg.dt;
                let cell_wall = Instant::now();
                let cell_cpu = process_cpu_seconds();
                let base = done_before;
                let spec = RunSpec {
                    engine,
                    scene,
                    throws: ThrowSpec::keyed(cfg.seed),
                    roll: settle,
                    rolls: cfg.rolls,
                    shard: None,
                };
                let ck = study.cell(&format!("row{row}-{engine}-{}", mode.name()), &spec)?;
                let progress = |n| (runner.progress)(base + n);
                let done = runner
                    .with_progress(&progress)
                    .run(&spec, ck.as_ref(), &mut |_| Ok(()))?;
                done_before += cfg.rolls;
                let tally = done.tally;
                if !done.complete {
                    partial = true;
                }
                let run = RunSummary::new(
                    &spec,
                    &tally,
                    Cost {
                        wall_s: cell_wall.elapsed().as_secs_f64() + done.resumed_wall_s,
                        cpu_s: process_cpu_seconds() - cell_cpu + done.resumed_cpu_s,
                        threads: runner.threads,
                    },
                );
                let ratio = stats::ratio(tally.counts.breadth, tally.counts.width);
                simulations.push(SimCell {
                    row,
                    label: label.clone(),
                    engine,
                    mode,
                    partial: !done.complete,
                    ratio,
                    z_experiment: stats::z_score(
                        ratio.value,
                        ratio.err,
                        t.measured_ratio.value,
                        t.measured_ratio.err,
                    ),
                    z_theory: stats::z_score(
                        ratio.value,
                        ratio.err,
                        t.theory_ratio.value,
                        t.theory_ratio.err,
                    ),
                    run,
                });
            }
        }
    }
    // The cells' costs, summed: they include what a resumed cell cost before (and on a
    // cluster, what every task's chunks cost), which this process's clocks do not see.
    let wall_s = simulations.iter().map(|c| c.run.wall_s).sum();
    let cpu_s = simulations.iter().map(|c| c.run.cpu_s).sum();
    Ok(PaperResults {
        partial,
        provenance: Provenance {
            command_line,
            dicephys_version: env!("CARGO_PKG_VERSION").into(),
            engines: cfg.engines.iter().map(|e| e.version()).collect(),
            engines_short: cfg.engines.clone(),
            preset: Preset::Dicephys281,
            dt: cfg.dt,
            seed: cfg.seed,
            rolls_per_cell: cfg.rolls,
            date_utc: crate::report::paper::utc_now(),
        },
        table,
        simulations,
        wall_s,
        cpu_s,
        not_simulated: "Pine blocks on carpet and towel, and printed blocks on tough carpet: the \
                        paper measured μ and e only for printed blocks on MDF, so these rows \
                        are not simulated rather than simulated with invented coefficients."
            .into(),
    })
}
