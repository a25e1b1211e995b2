//! One roll, engine-agnostic: step (or fly) the die until the rest rule or the exact early
//! stop ends it, and classify the outcome.

pub mod certificate;
pub mod flight;
pub mod rest;
pub mod roll;
