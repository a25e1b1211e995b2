//! `paper --calibrated`'s result: all 19 rows of the paper's table simulated with e, μ and the
//! throw fitted to the counts, each row predicted by a fit without it, beside the paper's
//! theory on the same rows; the models compared; the method checked.

use crate::calibration::check::MethodCheck;
pub use crate::calibration::crossval::Decision;
use crate::calibration::crossval::{LooRow, ModelScore};
use crate::calibration::FitResult;
use crate::theory::stats::Ratio;
use serde::Serialize;

/// The paper's theory on one row (eq. MasterEqu), as `theory --table` gives it.
#[derive(Clone, Debug, Serialize)]
pub struct TheoryRow {
    /// The row's label ("row 7").
    pub label: String,
    /// The theory's ratio ± its error from the side tolerances.
    pub ratio: Ratio,
    /// (measured − theory)/combined error.
    pub z: f64,
}

/// The calibrated paper.
#[derive(Clone, Debug, Serialize)]
pub struct CalibratedPaper {
    /// The main model's fit on all rows.
    pub fit: FitResult,
    /// Each row predicted without itself, by the main model.
    pub loo: Vec<LooRow>,
    /// The theory on the same rows.
    pub theory: Vec<TheoryRow>,
    /// Every model's scores.
    pub models: Vec<ModelScore>,
    /// The decisions.
    pub decisions: Vec<Decision>,
    /// The method check at the main fit's values.
    pub check: MethodCheck,
    /// Surfaces with a single row.
    pub single_row_surfaces: Vec<String>,
    /// Rolls made in all.
    pub rolls: u64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// CPU seconds.
    pub cpu_s: f64,
}
