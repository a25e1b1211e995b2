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
pub mod study;
pub mod sweep;
pub mod tradeoff;
pub mod validate;

pub use study::{Progress, Study};

use crate::error::Result;
use crate::run::runner::ChunkShare;
use serde::{Deserialize, Serialize};

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

/// What every study is, said once: its name, its checks, what it counts, how a cluster splits
/// it, and its run, which writes its named outputs (`outputs`). A study is one type that
/// implements this (its configuration) and one variant of [`StudyConfig`], which carries it
/// through a cluster's plan; everything else — the directory it owns, resume, interruption,
/// Slurm's tasks and finishing job, the command line's bar, the Python package — is written
/// against this trait. The implementations sit beside the outputs they write
/// ([`outputs`], [`fit::outputs`]).
pub trait Kind: Sync {
    /// Its name: its command.
    fn name(&self) -> &'static str;

    /// Checks every value before anything runs.
    fn validate(&self) -> Result<()>;

    /// The study as the configuration a plan stores.
    fn config(&self) -> StudyConfig;

    /// What makes two runs of it one run, for the directory it owns (`run::owner`): its
    /// configuration, less what only adds rounds to a study rolled to a precision.
    fn identity(&self) -> StudyConfig {
        self.config()
    }

    /// What its progress counts.
    fn unit(&self) -> crate::report::progress::Unit {
        crate::report::progress::Unit::Cells
    }

    /// The directory the study writes into and owns: its `out` (crosscheck: its checkpoint,
    /// if any).
    fn owns<'a>(&self, place: &'a place::Place) -> Option<&'a std::path::Path> {
        Some(place.out.as_path())
    }

    /// The name of its cells' directory under its `out` (the Python package's layout).
    fn cells(&self) -> &'static str {
        "checkpoint"
    }

    /// Refuses a study whose tasks could not agree on their shares: one that decides how far
    /// to roll from every roll so far, which no task sees.
    fn check_splittable(&self) -> Result<()> {
        Ok(())
    }

    /// What the finishing job of a cluster run of `tasks` tasks runs, and with which share of
    /// the chunks: the study itself, reading every chunk back and rolling none.
    fn finishing(&self, tasks: u64) -> (StudyConfig, ChunkShare) {
        (self.config(), ChunkShare::assemble(tasks))
    }

    /// A study of two chained stages, at `stage`, and the file its first stage writes; `None`
    /// for a study of one run.
    fn at_stage(&self, _stage: fit::Stage) -> Option<(StudyConfig, &'static str)> {
        None
    }

    /// Runs it in `place`, writing its outputs whole or not at all.
    fn run(&self, place: &place::Place, hooks: &place::Hooks) -> Result<place::Done>;
}

impl StudyConfig {
    /// The study it configures: the one place (beside serde's tag) its variants are matched.
    pub fn study(&self) -> &dyn Kind {
        match self {
            StudyConfig::Paper(c) => c,
            StudyConfig::Crosscheck(c) => c,
            StudyConfig::Converge(c) => c,
            StudyConfig::Tradeoff(c) => c,
            StudyConfig::Stability(c) => c,
            StudyConfig::Fit(c) => c,
            StudyConfig::Calibrated(c) => c,
        }
    }

    /// [`Kind::identity`], as JSON.
    pub fn identity(&self) -> serde_json::Value {
        serde_json::to_value(self.study().identity()).unwrap_or_default()
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

    /// [`Kind::finishing`].
    pub fn finishing(&self, tasks: u64) -> (StudyConfig, ChunkShare) {
        self.study().finishing(tasks)
    }

    /// [`Kind::unit`].
    pub fn unit(&self) -> crate::report::progress::Unit {
        self.study().unit()
    }
}
