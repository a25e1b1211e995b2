//! What a prediction is and how a row predicted without itself is scored: a predicted
//! probability with its error's parts, and a leave-one-out row (its counts against the
//! prediction, its log score). Types only, below the fit that stores them (`fit.json`'s `loo`)
//! and the modules that make them ([`crate::calibration::predict`],
//! [`crate::calibration::crossval`]).

use crate::theory::stats::{self, Ratio};
use serde::{Deserialize, Serialize};

/// Rolls of the default scene for each row a fit's leave-one-out scores (its uncalibrated
/// baseline), per roll of one of the fit's design points: ten points' worth.
pub const LOO_BASELINE_POINTS: u64 = 10;

/// A predicted probability.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Predicted {
    /// The prediction (the posterior mean).
    pub value: f64,
    /// Its whole standard error, √(params² + simulation² + model²).
    pub err: f64,
    /// The part from the parameters' uncertainty.
    pub err_params: f64,
    /// The part from the simulation's noise.
    pub err_sim: f64,
    /// The part from the model's discrepancy, learnt from the rows the fit predicted without
    /// themselves ([`crate::calibration::discrepancy`]); 0, and left out, where there is none.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub err_model: f64,
    /// The fit's own prediction, where the model's discrepancy moved it to `value` (along the
    /// line its rows' misses lie on); left out where nothing moved it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit_value: Option<f64>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Predicted {
    /// No prediction (NaN), where a table of blocks has a cell a die of any shape lacks.
    pub const NONE: Predicted = Predicted {
        value: f64::NAN,
        err: f64::NAN,
        err_params: f64::NAN,
        err_sim: f64::NAN,
        err_model: 0.0,
        fit_value: None,
    };

    /// The mean of `values` with their spread as the parameters' error and `sim_var` as the
    /// simulation's.
    pub fn of(values: &[f64], sim_var: f64) -> Predicted {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = if values.len() > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        Predicted {
            value: mean,
            err: (var + sim_var).sqrt(),
            err_params: var.sqrt(),
            err_sim: sim_var.sqrt(),
            err_model: 0.0,
            fit_value: None,
        }
    }

    /// (measured − predicted)/√(σ_measured² + σ_predicted²).
    pub fn z(&self, measured: f64, measured_err: f64) -> f64 {
        stats::z_score(measured, measured_err, self.value, self.err)
    }
}

/// An end count: a row's length-vertical outcomes, measured and predicted.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct EndCount {
    /// Counted length vertical.
    pub counted: u64,
    /// Throws.
    pub throws: u64,
    /// Predicted P(length vertical).
    pub predicted: Predicted,
    /// (counted/throws − predicted)/√(p(1 − p)/throws + σ_predicted²).
    pub z: f64,
}

/// One row, predicted by the fit of the others.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LooRow {
    /// The row's label.
    pub label: String,
    /// Its die, where a `die` column names one: its rows were left out together, and predicted
    /// by a fit of the other dice.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub die: Option<String>,
    /// Its surface.
    pub surface: String,
    /// The only row on its surface: without it the data say nothing of that surface's e and μ.
    pub alone: bool,
    /// The outcome groups.
    pub outcomes: Vec<String>,
    /// Counted per group.
    pub counts: Vec<u64>,
    /// Predicted per group.
    pub p: Vec<Predicted>,
    /// The measured ratio ± the paper's binomial error (when breadth and width are counted
    /// apart).
    pub measured_ratio: Option<Ratio>,
    /// The predicted ratio.
    pub ratio: Option<Predicted>,
    /// (measured − predicted)/combined error, on the ratio.
    pub z: Option<f64>,
    /// The end count (a 3D row with its length outcome apart).
    pub end: Option<EndCount>,
    /// ln P(counts | the fit without the row), the multinomial coefficient included.
    #[serde(deserialize_with = "nan_if_null")]
    pub log_score: f64,
    /// The same for the breadth count given the side throws only (comparable between models
    /// that simulate the row in 2D and in 3D).
    #[serde(deserialize_with = "nan_if_null")]
    pub side_log_score: f64,
    /// The proper scores of its prediction beside the baselines' ([`crate::calibration::
    /// proper`]); left out in a fit.json written before them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scores: Option<crate::calibration::proper::Scores>,
}

/// A number JSON wrote as null (NaN, or an infinity), read back as NaN.
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// A row of counts a prediction was scored against.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CountsTest {
    /// The row's label.
    pub label: String,
    /// The outcomes it counts.
    pub outcomes: Vec<String>,
    /// Its counts.
    pub counts: Vec<u64>,
    /// The prediction of each outcome counted (a group of faces the counts merge summed, its
    /// errors in quadrature), as scored.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub predicted: Vec<Predicted>,
    /// The prediction's scores beside the baselines'.
    pub scores: crate::calibration::proper::Scores,
}
