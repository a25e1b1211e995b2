//! The exact early stop: once the die's energy is below the barrier out of its face region,
//! its outcome can no longer change.

use crate::model::block::Side;
use crate::model::die::{up_in_body, DieBody};
use crate::model::state::BodyState;

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
const SIDES: [Side; 3] = [Side::Breadth, Side::Width, Side::Length];

impl Certificate {
    /// The height E/(mg) must be below for the certificate to hold in any face region: the
    /// largest over faces of rest height + (1 − margin) × (barrier − rest height). A state
    /// whose energy is above it (`DieBody::energy_height_at_least`) is never certain, so
    /// the check can be skipped there (`flight::Flight::jump`).
    pub fn energy_ceiling(&self, die: &DieBody) -> f64 {
        if let Some(c) = &die.convex {
            return c.ceiling(self.margin);
        }
        let n = if die.planar { 2 } else { 3 };
        (0..n)
            .flat_map(|i| [(i, 0), (i, 1)])
            .map(|(i, k)| {
                let rest = die.rest[i][k];
                rest + (1.0 - self.margin) * (die.barrier[i][k] - rest)
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The outcome, if it is already certain.
    pub fn certain(&self, die: &DieBody, s: &BodyState) -> Option<Side> {
        let up = up_in_body(&s.rotation);
        let (i, k) = die.face_region(&up);
        let rest = die.rest[i][k];
        let allowed = (1.0 - self.margin) * (die.barrier[i][k] - rest);
        // No barrier known (−∞), or none left above the rest height: nothing is certain.
        if allowed.is_nan() || allowed <= 0.0 {
            return None;
        }
        // The height plus the translational energy's worth of height is a lower bound of E/mg:
        // most states fail on it without the rotational energy being computed.
        // A die that has sunk into the floor (a corner or more, at a coarse step) holds less
        // potential energy than it will once the engine has pushed it back out: count it at
        // the height it will be pushed back to, its lowest point on the floor's top face.
        // Without this the certificate fired on dips and was wrong on up to 3 % of rolls at
        // dt = 1/60 (docs/results/coarse-steps.md).
        let sunk = (-die.lowest_point_up(s, &up)).max(0.0);
        let g = die.gravity;
        if s.position.y + sunk + 0.5 * s.linear_velocity.norm_squared() / g - rest >= allowed {
            return None;
        }
        // On a soft table the springs hold energy of their own, which they give back.
        let excess = (die.energy(s) + die.elastic_at_most(sunk)) / (die.mass * g) + sunk - rest;
        (excess < allowed).then_some(SIDES[i])
    }
}

impl Certificate {
    /// `certain` for a die of any shape: its face, by `Convex::certain`'s regions. Kept out
    /// of line: the cuboid's check passes it by.
    #[inline(never)]
    pub fn certain_convex(
        &self,
        c: &crate::model::die::Convex,
        die: &DieBody,
        s: &BodyState,
    ) -> Option<u8> {
        let up = &up_in_body(&s.rotation);
        let sunk = (-die.lowest_point_up(s, up)).max(0.0);
        let g = die.gravity;
        // The cheap lower bound first, as for the cuboid.
        let quick = s.position.y + sunk + 0.5 * s.linear_velocity.norm_squared() / g;
        c.certain(
            up,
            quick,
            || (die.energy(s) + die.elastic_at_most(sunk)) / (die.mass * g) + sunk,
            self.margin,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::{Mode, Scene};
    use nalgebra::{UnitQuaternion, Vector3};

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
        let die = DieBody::of(&scene);
        let c = Certificate { margin: 0.1 };
        let id = UnitQuaternion::identity();
        assert_eq!(
            c.certain(&die, &state(0.010, id, 0.0, 0.0)),
            Some(Side::Width)
        );
        let on_side = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 1.5);
        assert_eq!(
            c.certain(&die, &state(0.012, on_side, 0.0, 0.0)),
            Some(Side::Breadth)
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
        let die = DieBody::of(&scene);
        let c = Certificate { margin: 0.0 };
        let id = UnitQuaternion::identity();
        let b = 0.5 * (0.024f64).hypot(0.020);
        assert_eq!(
            c.certain(&die, &state(b - 1e-6, id, 0.0, 0.0)),
            Some(Side::Width)
        );
        assert_eq!(c.certain(&die, &state(b + 1e-6, id, 0.0, 0.0)), None);
    }
}
