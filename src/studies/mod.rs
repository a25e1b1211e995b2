//! Studies built from many runs: the paper end to end, the bench, and the sweeps of accuracy
//! against cost and of where methods fail.

pub mod bench;
pub mod calibrated;
pub mod converge;
pub mod fit;
pub mod paper;
pub mod stability;
pub mod sweep;
pub mod tradeoff;
pub mod validate;
