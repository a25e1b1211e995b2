//! Moments of a part about the die's geometric centre: what the parts of a made die add up
//! to (the pips' cavities, the insert, the rounded box).

use nalgebra::{Matrix3, Vector3};

/// Moments of a part about the geometric centre: its mass, Σ m r, and Σ m r rᵀ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Moments {
    pub(super) mass: f64,
    pub(super) first: Vector3<f64>,
    pub(super) second: Matrix3<f64>,
}

impl Moments {
    pub(super) fn add(&mut self, w: f64, o: &Moments) {
        self.mass += w * o.mass;
        self.first += w * o.first;
        self.second += w * o.second;
    }
}
