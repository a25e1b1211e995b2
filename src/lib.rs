//! dicephys: with what probability does a thrown cuboid die land on each face?
//!
//! Rigid-body simulation (Bullet through a thin C++ shim, and Rapier) beside the closed-form
//! theory and measured data of G. A. T. Pender and M. Uhrin, "Predicting Non-Square 2D Dice
//! Probabilities", Eur. J. Phys. 35 (2014), arXiv:1407.6307.
//!
//! Modules: `block` (the die and its sides' names), `scene` (what a throw happens in),
//! `throws` (initial conditions, keyed or DicePhys's sequence), `engine` (Bullet, Rapier),
//! `settle` (at rest, outcome), `theory` and `paper_data` (the paper's closed forms and table),
//! `stats` (binomial errors, z, χ²), `figures` (the paper's figures as SVG and PNG),
//! `roll` (one roll), `batch` (many, in parallel), `cli`.

pub mod batch;
pub mod bench;
pub mod block;
pub mod checkpoint;
pub mod cli;
pub mod cputime;
pub mod engine;
pub mod error;
pub mod figures;
pub mod flight;
pub mod glibc;
pub mod paper;
pub mod paper_data;
pub mod roll;
pub mod scene;
pub mod settle;
pub mod stats;
pub mod summary;
pub mod sweeps;
pub mod theory;
pub mod throws;
