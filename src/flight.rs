//! Free flight in closed form. Between bounces the die only falls and turns; an engine spends
//! hundreds of steps per roll on that. Out of reach of the floor, Bullet (without the
//! gyroscopic term) and Rapier advance a body by symplectic Euler under gravity alone:
//! v ← v + g·dt, x ← x + v·dt, and the orientation by the exponential map of the (constant)
//! angular velocity, q ← exp(½ω·dt)·q. That is cheap to do here, so the roll can jump to the
//! last step before the die comes within `clearance` of the floor, and hand the state back to
//! the engine: the same trajectory to rounding, far fewer engine steps.

use crate::engine::BodyState;
use crate::scene::Scene;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Bullet's clamp on the rotation per step (ANGULAR_MOTION_THRESHOLD = π/4).
const MAX_ANGLE_PER_STEP: f64 = 0.25 * std::f64::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct Flight {
    pub dt: f64,
    pub gravity: f64,
    pub half: Vector3<f64>,
    /// The lowest point of the die must stay this far above the floor: beyond Bullet's
    /// contact breaking threshold (0.02 m) and its AABB margins, so no contact can form.
    pub clearance: f64,
}

pub const CLEARANCE: f64 = 0.05;

impl Flight {
    pub fn of(scene: &Scene) -> Flight {
        let [a, b, c] = scene.body_sides();
        let half = Vector3::new(a, b, c) / 2.0;
        Flight {
            dt: scene.dt,
            gravity: scene.gravity,
            // In 2D the box is 1 m deep but turns about z only, so its reach below the
            // centre comes from x and y alone; the support function below handles both.
            half,
            clearance: CLEARANCE,
        }
    }

    /// Height of the die's lowest point above the floor: y − Σ hᵢ |(Rᵀ ŷ)ᵢ|.
    pub fn lowest_point(&self, s: &BodyState) -> f64 {
        crate::settle::lowest_point(&self.half, s)
    }

    /// The rotation one step applies, as Bullet's `integrateTransform` builds it.
    fn step_rotation(&self, w: &Vector3<f64>) -> UnitQuaternion<f64> {
        let dt = self.dt;
        let mut angle = w.norm();
        if angle * dt > MAX_ANGLE_PER_STEP {
            angle = MAX_ANGLE_PER_STEP / dt;
        }
        let axis = if angle < 0.001 {
            // Taylor expansion of sin(½θ dt)/θ, as Bullet.
            w * (0.5 * dt - dt * dt * dt * 0.020833333333 * angle * angle)
        } else {
            w * ((0.5 * angle * dt).sin() / angle)
        };
        UnitQuaternion::new_normalize(Quaternion::new(
            (0.5 * angle * dt).cos(),
            axis.x,
            axis.y,
            axis.z,
        ))
    }

    /// One engine step of free flight.
    pub fn step(&self, s: &BodyState, dq: &UnitQuaternion<f64>) -> BodyState {
        let mut v = s.linear_velocity;
        v.y -= self.gravity * self.dt;
        BodyState {
            position: s.position + v * self.dt,
            rotation: UnitQuaternion::new_normalize(dq.into_inner() * s.rotation.into_inner()),
            linear_velocity: v,
            angular_velocity: s.angular_velocity,
            sleeping: false,
        }
    }

    /// Advances free flight while the die stays clear of the floor, at most `max` steps;
    /// returns the state and the number of steps taken (0 if it is not clear now).
    pub fn coast(&self, s: &BodyState, max: u64) -> (BodyState, u64) {
        let dq = self.step_rotation(&s.angular_velocity);
        let mut now = *s;
        let mut n = 0;
        while n < max {
            let next = self.step(&now, &dq);
            if self.lowest_point(&next) <= self.clearance || !next.is_finite() {
                break;
            }
            now = next;
            n += 1;
        }
        (now, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{new_engine, EngineKind};
    use crate::scene::Mode;

    #[test]
    fn coasting_matches_bullet_stepping() {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
            let flight = Flight::of(&scene);
            let start = BodyState {
                position: Vector3::new(0.0, 0.5, 0.0),
                rotation: UnitQuaternion::from_euler_angles(0.3, 0.0, 0.2),
                linear_velocity: Vector3::new(0.1, 1.0, 0.0),
                angular_velocity: if mode == Mode::TwoD {
                    Vector3::new(0.0, 0.0, 120.0)
                } else {
                    Vector3::new(5.0, -3.0, 120.0)
                },
                sleeping: false,
            };
            let mut e = new_engine(EngineKind::Bullet, &scene).unwrap();
            e.reset(&start).unwrap();
            let (coasted, n) = flight.coast(&start, 200);
            assert_eq!(n, 200);
            for _ in 0..n {
                e.step().unwrap();
            }
            let stepped = e.state();
            assert!(
                (coasted.position - stepped.position).norm() < 1e-9,
                "{mode:?} position"
            );
            assert!(
                (coasted.linear_velocity - stepped.linear_velocity).norm() < 1e-9,
                "{mode:?} velocity"
            );
            assert!(
                coasted.rotation.angle_to(&stepped.rotation) < 1e-9,
                "{mode:?} rotation"
            );
        }
    }

    #[test]
    fn a_die_near_the_floor_does_not_coast() {
        let scene = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
        let flight = Flight::of(&scene);
        let s = BodyState {
            position: Vector3::new(0.0, 0.04, 0.0),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            sleeping: false,
        };
        assert_eq!(flight.coast(&s, 100).1, 0);
    }
}
