//! The result of a recovery check ([`crate::studies::fit::recovery`]): counts simulated at a
//! known truth, fitted back, many times.

use serde::{Deserialize, Serialize};

/// Repetitions of a recovery check when none are asked.
pub const DEFAULT_REPEATS: usize = 20;

/// One repetition.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Repetition {
    /// Its seed.
    pub seed: u64,
    /// Δ(−2 ln L) of the truth above the maximum.
    pub truth_delta: f64,
    /// The truth inside the joint 2σ region (Δ ≤ the region's bound).
    pub covered: bool,
    /// Per parameter: the truth inside its 2σ profile interval.
    pub in_interval: Vec<bool>,
    /// The fitted values.
    pub values: Vec<f64>,
}

/// The check's result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Recovery {
    /// The truth, per parameter.
    pub truth: Vec<f64>,
    /// The parameters' names.
    pub names: Vec<String>,
    /// The joint region's Δ bound.
    pub region_delta: f64,
    /// Each repetition.
    pub repetitions: Vec<Repetition>,
    /// The fraction whose joint 2σ region holds the truth.
    pub coverage: f64,
    /// Per parameter, the fraction whose 2σ interval holds it.
    pub interval_coverage: Vec<f64>,
    /// Rolls made.
    pub rolls: u64,
}
