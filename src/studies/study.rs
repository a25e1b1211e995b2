//! How a study runs its cells and where it keeps them: what every study takes, a leaf that
//! the studies' modules import (not their parent, which declares them).

use crate::error::Result;
use crate::run::runner::Runner;
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

impl Study<'_> {
    /// The checkpoint of the cell `name` under this study's checkpoint directory, opened for
    /// `spec`, if the study keeps its cells.
    pub fn cell(
        &self,
        name: &str,
        spec: &crate::run::spec::RunSpec,
    ) -> Result<Option<crate::run::runner::Checkpoint>> {
        self.checkpoint
            .as_ref()
            .map(|d| self.runner.open_cell(&d.join(name), spec))
            .transpose()
    }
}

/// How far a study has come: done and in all, in the study's unit (CPU seconds for a study
/// that rolls to a precision, else cells).
pub type Progress<'a> = &'a (dyn Fn(f64, f64) + Sync);
