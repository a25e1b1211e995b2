//! The integration tests, one binary (it links once): real Bullet through the shim, real
//! Rapier, and the `dicephys` binary as a user runs it.

mod helpers;

mod bullet;
mod calibration_promises;
mod cli;
mod coarse;
mod docs;
mod faces;
mod fit;
mod fuzz;
mod impact;
mod made;
mod promises;
mod promises_files;
mod rapier;
mod reliability;
mod shape_fit;
mod shapes;
mod slurm;
mod speed;
mod sweeps;
mod theory_cli;
mod validate;
