//! What every study is, said once, and the one way a study runs. The trait knows no study's
//! types: [`super::StudyConfig`] names them, and each study's implementation sits beside its
//! outputs.

use super::place::{claim, Claimant, Done, Hooks, Place};
use crate::error::Result;
use crate::report::progress::Unit;
use crate::run::runner::ChunkShare;
use std::path::Path;

/// A study: its name, its checks, what it counts, the directory and cells it owns, whether a
/// cluster can split it, and its run, which writes its named outputs whole or not at all.
/// Everything else — the directory's claim, resume, interruption, Slurm's tasks and finishing
/// job, the command line's bar, the Python package — is written against this trait.
pub trait Kind: Sync {
    /// Its name: its command.
    fn name(&self) -> &'static str;

    /// Checks every value before anything runs.
    fn validate(&self) -> Result<()>;

    /// What its progress counts.
    fn unit(&self) -> Unit {
        Unit::Cells
    }

    /// The directory the study writes into and owns: its `out` (`crosscheck`: its checkpoint,
    /// if any; `predict`: none).
    fn owns<'a>(&self, place: &'a Place) -> Option<&'a Path> {
        Some(place.out.as_path())
    }

    /// The name of its cells' directory under its `out`.
    fn cells(&self) -> &'static str {
        "checkpoint"
    }

    /// Refuses a study whose tasks could not agree on their shares: one that decides how far
    /// to roll from every roll so far, which no task sees.
    fn check_splittable(&self) -> Result<()> {
        Ok(())
    }

    /// Runs it in `place`, writing its outputs whole or not at all.
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done>;
}

/// Runs `study` in `place`: every value checked, the directory it owns claimed for `identity`
/// (refused if another command or another run owns it), then run. The caller that made
/// `place` has refused a Slurm run's directory already (a Slurm run's own stage claims it
/// here as its own).
pub fn run(
    study: &dyn Kind,
    identity: &serde_json::Value,
    place: &Place,
    hooks: &Hooks,
) -> Result<Done> {
    study.validate()?;
    let _held = match study.owns(place) {
        Some(dir) => {
            claim(dir, study.name(), identity, Claimant::Checked)?;
            // A whole run here holds its directory while it runs; a cluster's tasks share it.
            matches!(place.share, ChunkShare::All)
                .then(|| crate::run::owner::hold(dir))
                .transpose()?
        }
        None => None,
    };
    study.run(place, hooks)
}
