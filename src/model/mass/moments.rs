//! Moments of a part about the die's geometric centre: what the parts of a made die add up
//! to (the pips' cavities, the insert, the rounded box).

use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

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

/// ∫ x² dx over [−b, b].
fn line2(b: f64) -> f64 {
    2.0 * b * b * b / 3.0
}

/// The volume and ∫ xᵢ² dV of a box with half sides `a` whose edges are rounded with radius
/// `r` (the inner box of half sides a − r swept by a ball of radius r), taken apart into the
/// inner box, six slabs, twelve quarter cylinders and eight eighths of a ball.
pub fn rounded_box(a: &Vector3<f64>, r: f64) -> (f64, Vector3<f64>) {
    let b = a.map(|x| x - r);
    let volume = 8.0 * b.x * b.y * b.z
        + 8.0 * r * (b.y * b.z + b.x * b.z + b.x * b.y)
        + 2.0 * PI * r * r * (b.x + b.y + b.z)
        + 4.0 * PI * r * r * r / 3.0;
    // ∫ (b + u)² dA over a quarter disc of radius r in u, v ≥ 0: πr²/4 b² + 2b r³/3 + πr⁴/16.
    let quarter_disc =
        |b: f64| PI * r * r / 4.0 * b * b + 2.0 * b * r * r * r / 3.0 + PI * r.powi(4) / 16.0;
    // ∫ (b + u)² dV over an eighth of a ball: πr³/6 b² + 2b πr⁴/16 + πr⁵/30.
    let eighth_ball =
        |b: f64| PI * r.powi(3) / 6.0 * b * b + b * PI * r.powi(4) / 8.0 + PI * r.powi(5) / 30.0;
    let second = Vector3::from_fn(|i, _| {
        let (bi, bj, bk) = (b[i], b[(i + 1) % 3], b[(i + 2) % 3]);
        line2(bi) * 4.0 * bj * bk
            + 2.0 * ((bi + r).powi(3) - bi.powi(3)) / 3.0 * 4.0 * bj * bk
            + 2.0 * line2(bi) * r * 2.0 * (bj + bk)
            + 4.0 * line2(bi) * PI * r * r / 4.0
            + 4.0 * 2.0 * (bj + bk) * quarter_disc(bi)
            + 8.0 * eighth_ball(bi)
    });
    (volume, second)
}
