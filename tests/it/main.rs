//! The integration tests, one binary (it links once): real Bullet through the shim, real
//! Rapier, and the `dicephys` binary as a user runs it.

mod helpers;

mod bench;
mod browser;
mod bullet;
mod cli;
mod coarse;
mod counting;
mod crosscheck;
mod design;
mod dice_fit;
mod docs;
mod faces;
mod fit;
mod friction;
mod fuzz;
mod impact;
mod inputs;
mod io;
mod made;
mod one_die;
mod paper;
mod rapier;
mod real_throws;
mod roll;
mod shape_fit;
mod shapes;
mod slurm;
mod speed;
mod sweeps;
mod theory_cli;
mod validate;
