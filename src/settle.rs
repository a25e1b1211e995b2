//! When a roll is over, and how it came out: DicePhys's at-rest rule and its outcome test.

use crate::block::Outcome;
use crate::engine::BodyState;
use nalgebra::{UnitQuaternion, Vector3};

/// DicePhys's at-rest rule: over the last `window` steps, the vector sums of the linear and
/// of the angular velocity are both shorter than `tolerance` (sums of vectors, not of
/// lengths, so a die rocking back and forth also counts as at rest).
#[derive(Clone, Debug)]
pub struct RestDetector {
    tolerance: f64,
    linear: [Vector3<f64>; REST_WINDOW],
    angular: [Vector3<f64>; REST_WINDOW],
    seen: usize,
}

pub const REST_WINDOW: usize = 10;
pub const REST_TOLERANCE: f64 = 1e-4;

impl Default for RestDetector {
    fn default() -> Self {
        RestDetector::new(REST_TOLERANCE)
    }
}

impl RestDetector {
    pub fn new(tolerance: f64) -> RestDetector {
        RestDetector {
            tolerance,
            linear: [Vector3::zeros(); REST_WINDOW],
            angular: [Vector3::zeros(); REST_WINDOW],
            seen: 0,
        }
    }

    pub fn clear(&mut self) {
        self.seen = 0;
    }

    /// Records one step's state; true once the die is at rest.
    pub fn push(&mut self, s: &BodyState) -> bool {
        let slot = self.seen % REST_WINDOW;
        self.linear[slot] = s.linear_velocity;
        self.angular[slot] = s.angular_velocity;
        self.seen += 1;
        if self.seen < REST_WINDOW {
            return false;
        }
        let v: Vector3<f64> = self.linear.iter().sum();
        if v.norm() >= self.tolerance {
            return false;
        }
        let w: Vector3<f64> = self.angular.iter().sum();
        w.norm() < self.tolerance
    }
}

/// DicePhys's tolerance on a vertical axis: |cos| within 1e-4 of 1.
pub const VERTICAL_TOLERANCE: f64 = 1e-4;

/// The side standing vertical: the body axis (x = breadth, y = width, z = length, tested in
/// that order, as DicePhys) whose direction is vertical within the tolerance; else unknown.
pub fn classify(s: &BodyState) -> Outcome {
    let up = Vector3::y();
    let sides = [Outcome::Breadth, Outcome::Width, Outcome::Length];
    for (axis, side) in [Vector3::x(), Vector3::y(), Vector3::z()].iter().zip(sides) {
        let dir = (s.rotation * axis).normalize();
        let dot = up.dot(&dir).abs();
        if dot > 1.0 - VERTICAL_TOLERANCE && dot < 1.0 + VERTICAL_TOLERANCE {
            return side;
        }
    }
    Outcome::Unknown
}

/// The paper's "static" states made exact: once the die's mechanical energy is below the
/// lowest barrier out of the face region it is in, its outcome can no longer change.
///
/// Let g be the downward unit vertical in body coordinates and s = (a, b, c)/2 the box's half
/// sides. A box touching the floor with down-direction g has its centre at height
/// h(g) = Σ sᵢ|gᵢ| (the support function), and never lower: y ≥ h(g) while it is above the
/// floor. Call "region i" the directions g whose downward ray from the centre leaves the box
/// through a face normal to axis i (|gᵢ|/sᵢ largest). On the boundary between region i and
/// region j the ray hits an edge, and h there is at least the edge-balance height
/// B_ij = √(sᵢ² + sⱼ²) (a linear function on a circle arc takes its least value at an end;
/// the other end, a vertex, is higher). So with E = ½mv² + ½ω·Iω + mgy below mg·Bᵢ, where
/// Bᵢ = min over j≠i of B_ij, h(g) ≤ y ≤ E/mg < Bᵢ for ever (energy never rises), g cannot
/// leave region i, and the die comes to rest on face i: axis i vertical. In 2D (rotation about
/// z only) the same holds with j ranging over x and y alone: the paper's E_Trans (eq. Etrans)
/// is mg·B for the one edge of the cross-section.
///
/// Engines inject a little energy at contacts and let the die sink into the floor, so the
/// test keeps a margin: the die's energy above its resting height on face i must be below
/// (1 − margin) of the barrier above that height.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Certificate {
    /// Fraction of the barrier kept in reserve, in [0, 1).
    pub margin: f64,
}

/// What the certificate needs to know of the scene.
#[derive(Clone, Copy, Debug)]
pub struct DieShape {
    pub half: Vector3<f64>,
    pub mass: f64,
    /// Principal moments of inertia about the body axes.
    pub inertia: Vector3<f64>,
    pub gravity: f64,
    /// Rotation about z only (2D): region and barrier over the x and y axes.
    pub planar: bool,
    /// Bᵢ: the lowest edge-balance height out of face region i (∞ for z in 2D).
    pub barrier: Vector3<f64>,
}

impl DieShape {
    pub fn of(scene: &crate::scene::Scene) -> DieShape {
        let [a, b, c] = scene.body_sides();
        let m = scene.mass();
        let half = Vector3::new(a, b, c) / 2.0;
        let planar = scene.mode == crate::scene::Mode::TwoD;
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

const SIDES: [Outcome; 3] = [Outcome::Breadth, Outcome::Width, Outcome::Length];

impl Certificate {
    /// The outcome, if it is already certain.
    pub fn certain(&self, die: &DieShape, s: &BodyState) -> Option<Outcome> {
        let up = up_in_body(&s.rotation);
        let n = if die.planar { 2 } else { 3 };
        // Region i: the axis whose face the downward ray leaves through, |gᵢ|/sᵢ largest.
        let i = (0..n)
            .max_by(|&p, &q| (up[p].abs() / die.half[p]).total_cmp(&(up[q].abs() / die.half[q])))?;
        let rest = die.half[i];
        let allowed = (1.0 - self.margin) * (die.barrier[i] - rest);
        // The height plus the translational energy's worth of height is a lower bound of E/mg:
        // most states fail on it without the rotational energy being computed.
        // A die that has sunk into the floor (a corner or more, at a coarse step) holds less
        // potential energy than it will once the engine has pushed it back out: count it at
        // the height it will be pushed back to, its lowest point on the floor's top face.
        // Without this the certificate fired on dips and was wrong on up to 3 % of rolls at
        // dt = 1/60 (README, "Coarse time steps").
        let sunk = (-(s.position.y - up.abs().dot(&die.half))).max(0.0);
        let g = die.gravity;
        if s.position.y + sunk + 0.5 * s.linear_velocity.norm_squared() / g - rest >= allowed {
            return None;
        }
        let excess = die.energy(s) / (die.mass * g) + sunk - rest;
        (excess < allowed).then_some(SIDES[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Mode, Scene};
    use nalgebra::UnitQuaternion;

    fn state(y: f64, rot: UnitQuaternion<f64>, v: f64, w: f64) -> BodyState {
        BodyState {
            position: Vector3::new(0.0, y, 0.0),
            rotation: rot,
            linear_velocity: Vector3::new(v, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, 0.0, w),
            sleeping: false,
        }
    }

    #[test]
    fn a_die_at_rest_is_certain_and_a_flying_one_is_not() {
        let scene = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
        let die = DieShape::of(&scene);
        let c = Certificate { margin: 0.1 };
        let id = UnitQuaternion::identity();
        assert_eq!(
            c.certain(&die, &state(0.010, id, 0.0, 0.0)),
            Some(Outcome::Width)
        );
        let on_side = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 1.5);
        assert_eq!(
            c.certain(&die, &state(0.012, on_side, 0.0, 0.0)),
            Some(Outcome::Breadth)
        );
        // Dropped from 0.3 m: far above every barrier.
        assert_eq!(c.certain(&die, &state(0.3, id, 0.0, 0.0)), None);
        // On the floor but spinning fast enough to tip over.
        assert_eq!(c.certain(&die, &state(0.010, id, 0.0, 60.0)), None);
    }

    #[test]
    fn the_barrier_is_the_edge_balance_height() {
        // 2D, width face down (identity): barrier ½√(b² + w²) above the floor.
        let scene = Scene::paper("140x24x20".parse().unwrap(), Mode::TwoD);
        let die = DieShape::of(&scene);
        let c = Certificate { margin: 0.0 };
        let id = UnitQuaternion::identity();
        let b = 0.5 * (0.024f64).hypot(0.020);
        assert_eq!(
            c.certain(&die, &state(b - 1e-6, id, 0.0, 0.0)),
            Some(Outcome::Width)
        );
        assert_eq!(c.certain(&die, &state(b + 1e-6, id, 0.0, 0.0)), None);
    }
}
