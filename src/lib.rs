//! dicephys: with what probability does a thrown cuboid die land on each face?
//!
//! Rigid-body simulation (Bullet through a thin C++ shim, and Rapier) beside the closed-form
//! theory and measured data of G. A. T. Pender and M. Uhrin, "Predicting Non-Square 2D Dice
//! Probabilities", Eur. J. Phys. 35 (2014), arXiv:1407.6307.

pub mod block;
pub mod cli;
pub mod error;
pub mod paper_data;
pub mod stats;
pub mod theory;
