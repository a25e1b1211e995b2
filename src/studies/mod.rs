//! Studies built from many runs: the paper end to end, the cross-check of engines, the bench,
//! the sweeps of accuracy against cost and of where methods fail, and the validation against
//! exact limits, the fits and predictions. Each takes a configuration and a [`Study`] (how its
//! cells run and where they are kept) and returns its results, which `report` renders; each is
//! a [`kind::Kind`] and one variant of [`StudyConfig`], and runs the one way
//! ([`StudyConfig::run`]).

pub mod bench;
pub mod bias;
pub mod calibrated;
pub mod cluster;
pub mod converge;
pub mod crosscheck;
pub mod departure;
pub mod design;
pub mod fair;
pub mod fit;
pub mod kind;
pub mod outputs;
pub mod paper;
pub mod place;
pub mod precision;
pub mod roll;
pub mod stability;
pub mod stream;
pub mod study;
pub mod sweep;
pub mod trace;
pub mod tradeoff;
pub mod validate;

pub use study::{Progress, Study};

use crate::error::Result;
use crate::run::runner::ChunkShare;
use kind::Kind;
use place::{Done, Hooks, Place};
use serde::{Deserialize, Serialize};

/// Every study a command runs, as its configuration: what a cluster's plan stores
/// (`run::slurm::Plan::Study`) and what the Python package hands over. The one place (beside
/// serde's tag) its variants are matched is here: each is a [`Kind`], and what a cluster
/// needs beyond the trait (a study's identity, its finishing job, its stages) is said below.
#[derive(Clone, Debug, Serialize, Deserialize)]
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
    /// `validate`.
    Validate(validate::Config),
    /// `fit`, or one of its two passes.
    Fit(fit::FitStudy),
    /// `fit --recover`.
    Recover(fit::RecoverStudy),
    /// `predict --block`.
    Predict(fit::PredictStudy),
    /// `predict --blocks-file`.
    PredictBlocks(fit::BlocksStudy),
    /// `paper --calibrated`, or one of its two stages.
    Calibrated(calibrated::CalibratedStudy),
    /// `roll`, or `fair` rolling its die.
    Roll(roll::RollStudy),
    /// `bench`.
    Bench(bench::Config),
    /// `fair --vary`.
    Bias(bias::BiasStudy),
    /// `design`.
    Design(design::study::DesignStudy),
    /// `trace`.
    Trace(trace::TraceStudy),
}

impl StudyConfig {
    /// The study it configures.
    pub fn study(&self) -> &dyn Kind {
        match self {
            StudyConfig::Paper(c) => c,
            StudyConfig::Crosscheck(c) => c,
            StudyConfig::Converge(c) => c,
            StudyConfig::Tradeoff(c) => c,
            StudyConfig::Stability(c) => c,
            StudyConfig::Validate(c) => c,
            StudyConfig::Fit(c) => c,
            StudyConfig::Recover(c) => c,
            StudyConfig::Predict(c) => c,
            StudyConfig::PredictBlocks(c) => c,
            StudyConfig::Calibrated(c) => c,
            StudyConfig::Roll(c) => c,
            StudyConfig::Bench(c) => c,
            StudyConfig::Bias(c) => c,
            StudyConfig::Design(c) => c,
            StudyConfig::Trace(c) => c,
        }
    }

    /// Runs it in `place` ([`kind::run`]): checked, its directory claimed, run.
    pub fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        kind::run(self.study(), &self.identity(), place, hooks)
    }

    /// What makes two runs of it one run, for the directory it owns (`run::owner`): its
    /// configuration, less what only adds rounds to a study rolled to a precision.
    pub fn identity(&self) -> serde_json::Value {
        let id = match self {
            StudyConfig::Converge(c) => StudyConfig::Converge(c.identity()),
            StudyConfig::Tradeoff(c) => StudyConfig::Tradeoff(c.identity()),
            StudyConfig::Roll(c) => return c.identity(),
            StudyConfig::Bias(c) => return c.identity(),
            StudyConfig::Design(c) => return c.identity(),
            other => other.clone(),
        };
        serde_json::to_value(id).unwrap_or_default()
    }

    /// What the finishing job of a cluster run of `tasks` tasks runs, and with which share of
    /// the chunks: the study itself, reading every chunk back and rolling none; but
    /// `tradeoff`, whose tasks only rolled ahead, runs whole there, rolling on where a method
    /// needs more.
    pub fn finishing(&self, tasks: u64) -> (StudyConfig, ChunkShare) {
        match self {
            StudyConfig::Tradeoff(c) => (StudyConfig::Tradeoff(c.finishing()), ChunkShare::All),
            other => (other.clone(), ChunkShare::assemble(tasks)),
        }
    }

    /// A study of two chained stages (a refined `fit` or `paper --calibrated`: the first
    /// passes, then the rest) at `stage`, and the file its first stage writes; `None` for a
    /// study of one run.
    pub fn at_stage(&self, stage: fit::Stage) -> Option<(StudyConfig, &'static str)> {
        match self {
            StudyConfig::Fit(s) if s.config.design.refine => Some((
                StudyConfig::Fit(fit::FitStudy { stage, ..s.clone() }),
                fit::FIRST_PASS,
            )),
            StudyConfig::Calibrated(s) if s.config.design.refine => Some((
                StudyConfig::Calibrated(calibrated::CalibratedStudy { stage, ..s.clone() }),
                calibrated::FIRST_PASSES,
            )),
            _ => None,
        }
    }

    /// [`Kind::name`].
    pub fn name(&self) -> &'static str {
        self.study().name()
    }

    /// [`Kind::validate`].
    pub fn validate(&self) -> Result<()> {
        self.study().validate()
    }

    /// [`Kind::check_splittable`].
    pub fn check_splittable(&self) -> Result<()> {
        self.study().check_splittable()
    }

    /// [`Kind::unit`].
    pub fn unit(&self) -> crate::report::progress::Unit {
        self.study().unit()
    }

    /// [`Kind::cells`].
    pub fn cells(&self) -> &'static str {
        self.study().cells()
    }
}
