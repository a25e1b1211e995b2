//! Many rolls: a run's specification, parallel batches and their exact tally, the chunked
//! runner with its checkpoints, stop requests, atomic output, and Slurm job arrays.

pub mod batch;
pub mod cputime;
pub mod io;
pub mod lock;
pub mod owner;
pub mod pack;
pub mod request;
pub mod runner;
pub mod seal;
pub mod slurm;
pub mod spec;
pub mod stop;
pub mod tally;
