//! The die as a rigid body: its half sides, mass, inertia and barriers, its energies, and
//! where its lowest point is.

use crate::model::scene::{Mode, Scene};
use crate::model::state::BodyState;
use nalgebra::{UnitQuaternion, Vector3};

/// The die as the roll, the energy watch and the certificate see it.
#[derive(Clone, Copy, Debug)]
pub struct DieShape {
    /// Half the sides along body x, y, z (breadth, width, length; in 2D, z is half the 1 m
    /// depth), m.
    pub half: Vector3<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// Principal moments of inertia about the body axes.
    pub inertia: Vector3<f64>,
    /// Gravity's magnitude, m/s², along −y.
    pub gravity: f64,
    /// Rotation about z only (2D): region and barrier over the x and y axes.
    pub planar: bool,
    /// Bᵢ: the lowest edge-balance height out of face region i (∞ for z in 2D).
    pub barrier: Vector3<f64>,
}

impl DieShape {
    /// The die of a scene: half sides, mass, inertia and barriers from its block, density
    /// and mode.
    pub fn of(scene: &Scene) -> DieShape {
        let [a, b, c] = scene.body_sides();
        let m = scene.mass();
        let half = Vector3::new(a, b, c) / 2.0;
        let planar = scene.mode == Mode::TwoD;
        let axes: &[usize] = if planar { &[0, 1] } else { &[0, 1, 2] };
        let barrier = Vector3::from_fn(|i, _| {
            axes.iter()
                .filter(|&&j| j != i && axes.contains(&i))
                .map(|&j| half[i].hypot(half[j]))
                .fold(f64::INFINITY, f64::min)
        });
        DieShape {
            half,
            mass: m,
            // A box's principal moments about its centre: m/12 (b² + c²), etc.
            inertia: Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (m / 12.0),
            gravity: scene.gravity,
            planar,
            barrier,
        }
    }

    /// Kinetic energy, translational plus rotational.
    pub fn kinetic(&self, s: &BodyState) -> f64 {
        let w = s.rotation.inverse_transform_vector(&s.angular_velocity);
        0.5 * self.mass * s.linear_velocity.norm_squared()
            + 0.5 * w.component_mul(&w).dot(&self.inertia)
    }

    /// Potential energy, with the floor's top at y = 0.
    pub fn potential(&self, s: &BodyState) -> f64 {
        self.mass * self.gravity * s.position.y
    }

    /// Kinetic plus potential energy.
    pub fn energy(&self, s: &BodyState) -> f64 {
        self.kinetic(s) + self.potential(s)
    }

    /// A lower bound of energy / (mg), the height the die's energy would lift it to, cheaper
    /// than `energy`: the rotational energy ½ωᵀIω is at least ½ I_min |ω|². Less than the
    /// exact value by far more than rounding (1e-9 m is taken off for it).
    pub fn energy_height_at_least(&self, s: &BodyState) -> f64 {
        let i_min = self.inertia.min();
        s.position.y
            + 0.5 * s.linear_velocity.norm_squared() / self.gravity
            + 0.5 * i_min * s.angular_velocity.norm_squared() / (self.mass * self.gravity)
            - 1e-9
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

/// Height above the floor of the lowest point of a box with half sides `half`:
/// y − Σ hᵢ |(Rᵀ ŷ)ᵢ| (the support function in the downward direction; in 2D the body turns
/// about z only, so z adds nothing).
pub fn lowest_point(half: &Vector3<f64>, s: &BodyState) -> f64 {
    s.position.y - up_in_body(&s.rotation).abs().dot(half)
}
