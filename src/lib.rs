//! dicephys: with what probability does a thrown die — the paper's cuboid, a d4 to d20, a coin,
//! a printed mesh — land on each face?
//!
//! Rigid-body simulation (Bullet through a thin C++ shim, and Rapier) beside the closed-form
//! theory and measured data of G. A. T. Pender and M. Uhrin, "Predicting Non-Square 2D Dice
//! Probabilities", Eur. J. Phys. 35 (2014), arXiv:1407.6307.
//!
//! The library's dependencies run one way, from the model up to the studies:
//!
//! * [`model`]: the die (block, shape, state), the scene it is thrown in, the throws;
//! * [`engine`]: Bullet and Rapier behind one trait;
//! * [`sim`]: one roll: free flight, the rest rule, the exact early stop;
//! * [`run`]: many rolls: the run's specification, batches, tallies, checkpoints, atomic output;
//! * [`theory`]: the paper's closed forms, its experimental table, the statistics;
//! * [`inference`]: the pure mathematics of a fit: the surrogate (a multinomial logit), the
//!   likelihood, the optimiser, the posterior sampler;
//! * [`calibration`]: the statistics of a fit to measured counts, with no rolling: the counts
//!   file, the free parameters and their boxes, the designs, the estimate, predictions and the
//!   held-out test;
//! * [`report`]: what a run or the paper's table says, as text, JSON, CSV and figures;
//! * [`studies`]: the paper end to end, the bench, the convergence, trade-off and stability
//!   sweeps, and the rolling behind a fit (`studies::fit`: a design simulated, a fit's passes,
//!   the recovery check, a prediction) and the calibrated paper.
//!
//! The command line lives in the binary (`src/main.rs`, `src/cli/`), on top of all of these.

#![warn(missing_docs)]

pub mod calibration;
pub mod engine;
pub mod error;
pub mod inference;
pub mod model;
pub mod report;
pub mod run;
pub mod sim;
pub mod studies;
pub mod theory;

pub use error::{Error, Result};
