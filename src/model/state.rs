//! The die's state: where it is, how it is turned, how it moves.

use nalgebra::{UnitQuaternion, Vector3};

/// The die's state in world coordinates (y up, floor top at y = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// The centre of mass, m.
    pub position: Vector3<f64>,
    /// The orientation, body axes to world axes.
    pub rotation: UnitQuaternion<f64>,
    /// The centre's velocity, m/s.
    pub linear_velocity: Vector3<f64>,
    /// The angular velocity in world axes, rad/s.
    pub angular_velocity: Vector3<f64>,
    /// The engine has put the body to sleep (deactivated it).
    pub sleeping: bool,
}

impl BodyState {
    /// At rest at the origin, unrotated: the state of a world with no die in it yet.
    pub fn at_origin() -> BodyState {
        BodyState {
            position: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            sleeping: false,
        }
    }

    /// True if every component of position, rotation and velocities is finite.
    ///
    /// Asked of every walked step's state, so in one test rather than thirteen: x·0 is ±0
    /// for a finite x and NaN for ±∞ or NaN, so the sum of the components times 0 is 0
    /// exactly when every one is finite (a NaN never cancels; products first, so no sum of
    /// finite components can overflow).
    pub fn is_finite(&self) -> bool {
        let q = &self.rotation.coords;
        let v = self.position * 0.0 + self.linear_velocity * 0.0 + self.angular_velocity * 0.0;
        let w = q * 0.0;
        v.x + v.y + v.z + w.x + w.y + w.z + w.w == 0.0
    }
}

/// The world's up direction in body axes, Rᵀ ŷ: the second row of the rotation matrix.
pub fn up_in_body(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    Vector3::new(
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
    )
}
