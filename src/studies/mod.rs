//! Studies built from many runs: the paper end to end, the cross-check of engines, the bench,
//! the sweeps of accuracy against cost and of where methods fail, and the validation against
//! exact limits. Each takes a configuration and a [`Study`] (how its cells run and where they
//! are kept) and returns its results, which `report` renders.

pub mod bench;
pub mod calibrated;
pub mod cluster;
pub mod converge;
pub mod crosscheck;
pub mod departure;
pub mod fair;
pub mod fit;
pub mod outputs;
pub mod paper;
pub mod place;
pub mod precision;
pub mod stability;
pub mod stream;
pub mod sweep;
pub mod tradeoff;
pub mod validate;

use crate::error::{Error, Result};
use crate::run::runner::{ChunkShare, Runner};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// How a study runs its cells: the runner (threads, stop, progress, its share of the chunks),
/// and where its cells are kept (a checkpoint directory per cell under `checkpoint`): a
/// finished cell, with the CPU time it took, is not rolled again when the same study is run
/// again after a crash or Ctrl-C. A cell is kept whole or not at all, so its cost stays true.
pub struct Study<'a> {
    /// Threads and stop requests.
    pub runner: Runner<'a>,
    /// Where finished cells are kept, if anywhere.
    pub checkpoint: Option<PathBuf>,
}

/// How far a study has come: done and in all, in the study's unit (CPU seconds for a study
/// that rolls to a precision, else cells).
pub type Progress<'a> = &'a (dyn Fn(f64, f64) + Sync);

/// A study as a cluster runs it: its configuration, serialized into the run's plan
/// (`run::slurm::Plan::Study`), is all a task or the finishing job needs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "study", rename_all = "snake_case")]
pub enum StudyConfig {
    /// `paper`.
    Paper(paper::PaperConfig),
    /// `crosscheck`.
    Crosscheck(crosscheck::Config),
    /// `converge`.
    Converge(converge::Config),
    /// `tradeoff`.
    Tradeoff(tradeoff::Config),
    /// `stability`.
    Stability(stability::Config),
    /// `fit`, or one of its two passes.
    Fit(fit::FitStudy),
    /// `paper --calibrated`, or one of its two stages.
    Calibrated(calibrated::CalibratedStudy),
}

impl StudyConfig {
    /// What makes two runs of the study one run, for the directory it owns
    /// (`run::owner`): its configuration, less what only adds rounds to a study rolled to a
    /// precision (the precision, the budgets, `plan_only`, `preroll_chunks`, and `rolls`
    /// where a precision sets them).
    pub fn identity(&self) -> serde_json::Value {
        let c = match self {
            StudyConfig::Tradeoff(t) => StudyConfig::Tradeoff(tradeoff::Config {
                precision: 0.0,
                budget_s: 0.0,
                reference_budget_s: 0.0,
                plan_only: false,
                preroll_chunks: None,
                ..t.clone()
            }),
            StudyConfig::Converge(c) if c.precision.is_some() => {
                StudyConfig::Converge(converge::Config {
                    precision: Some(0.0),
                    budget_s: 0.0,
                    reference_budget_s: 0.0,
                    rolls: 0,
                    ..c.clone()
                })
            }
            other => other.clone(),
        };
        serde_json::to_value(&c).unwrap_or_default()
    }

    /// The study's name: its command.
    pub fn name(&self) -> &'static str {
        match self {
            StudyConfig::Paper(_) => "paper",
            StudyConfig::Crosscheck(_) => "crosscheck",
            StudyConfig::Converge(_) => "converge",
            StudyConfig::Tradeoff(_) => "tradeoff",
            StudyConfig::Stability(_) => "stability",
            StudyConfig::Fit(_) => "fit",
            StudyConfig::Calibrated(_) => "paper --calibrated",
        }
    }

    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        match self {
            StudyConfig::Paper(c) => c.validate(),
            StudyConfig::Crosscheck(c) => c.validate(),
            StudyConfig::Converge(c) => c.validate(),
            StudyConfig::Tradeoff(c) => c.validate(),
            StudyConfig::Stability(c) => c.validate(),
            StudyConfig::Fit(c) => c.validate(),
            StudyConfig::Calibrated(c) => c.validate(),
        }
    }

    /// Refuses a study whose tasks could not agree on their shares: one that decides how far to
    /// roll from every roll so far, which no task sees. `tradeoff` runs only rolled ahead
    /// (`preroll_chunks`); `converge` only without a precision.
    pub fn check_splittable(&self) -> Result<()> {
        match self {
            StudyConfig::Tradeoff(t) if t.preroll_chunks.is_none() => Err(Error::field(
                "preroll_chunks",
                "",
                "needed: the rounds are decided from every roll so far, which no task sees, \
                 so the tasks roll the first throws of every stream ahead and the finishing job \
                 runs the study, reading them back and rolling on itself where a method needs \
                 more (a plan, `plan_only`, prints the rolls each needs)",
            )),
            StudyConfig::Converge(c) if c.precision.is_some() => Err(Error::field(
                "precision",
                "",
                "decides each cell's rounds from all its rolls, which no task sees; give \
                 `rolls` instead (a run to a precision prints the rolls each cell needs)",
            )),
            _ => Ok(()),
        }
    }

    /// What the finishing job of a cluster run runs, and with which share of the chunks: the
    /// study itself, reading every chunk back and rolling none; but `tradeoff`, whose tasks
    /// only rolled ahead, runs whole (no `preroll_chunks`), reading their chunks back and
    /// rolling on where a method needs more.
    /// The run was split among `tasks` tasks (named when a chunk is missing).
    pub fn finishing(&self, tasks: u64) -> (StudyConfig, ChunkShare) {
        match self {
            StudyConfig::Tradeoff(t) => (
                StudyConfig::Tradeoff(tradeoff::Config {
                    preroll_chunks: None,
                    ..t.clone()
                }),
                ChunkShare::All,
            ),
            other => (other.clone(), ChunkShare::assemble(tasks)),
        }
    }
}
