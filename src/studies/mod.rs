//! Studies built from many runs: the paper end to end, the bench, and the sweeps of accuracy
//! against cost and of where methods fail.

pub mod bench;
pub mod converge;
pub mod departure;
pub mod paper;
pub mod precision;
pub mod stability;
pub mod stream;
pub mod sweep;
pub mod tradeoff;
pub mod validate;
