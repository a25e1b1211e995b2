//! Rapier's true 2D engine (`rapier2d-f64`) for DicePhys's 2D mode: a breadth × width box
//! (body x, y) in the x-y plane, spinning about z.
//!
//! Its mass and moment of inertia are those of the 1 m deep locked 3D box (`scene.mass()`,
//! I_z = m/12 (b² + w²)), set explicitly: a 2D density is per area, so one from the scene's
//! kg/m³ would give neither. The 2D state is reported as the 3D `BodyState` the rest of the
//! crate reads: position (x, y, 0), rotation about z, velocity (vx, vy, 0), spin (0, 0, ω).

use super::{BodyState, Engine};
use crate::model::scene::{Floor, Mode, Scene};
use nalgebra::{UnitQuaternion, Vector3};
use rapier2d_f64::prelude::*;

/// Rapier's 2D engine: a breadth × width box in the x-y plane, for the 2D scene only.
pub struct Rapier2d {
    world: PhysicsWorld,
    die: Option<RigidBodyHandle>,
    die_collider: ColliderBuilder,
    /// Rapier's (linear, angular) damping coefficients (`Scene::rapier_damping`).
    damping: (f64, f64),
    /// The die may sleep (`Scene::sleeping`).
    can_sleep: bool,
}

impl Rapier2d {
    /// A fresh 2D world for the scene; refuses a 3D scene, and a non-positive time step or mass.
    pub fn new(scene: &Scene) -> crate::Result<Rapier2d> {
        if scene.mode != Mode::TwoD {
            return Err(crate::Error::Engine(
                "rapier2d: a 2D engine needs the 2D scene (--2d)".into(),
            ));
        }
        if !(scene.dt > 0.0 && scene.mass() > 0.0) {
            return Err(crate::Error::Engine(
                "rapier2d: bad scene (dt and mass must be positive)".into(),
            ));
        }
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, -scene.gravity);
        world.integration_parameters.dt = scene.dt;
        // No CCD, as DicePhys (0 also turns off Rapier's automatic CCD of fast bodies).
        world.integration_parameters.max_ccd_substeps = 0;

        // Friction and restitution multiply, as in Bullet (see rapier3d.rs).
        let floor = match scene.floor {
            Floor::Box => ColliderBuilder::cuboid(5000.0, 0.5 * scene.floor_thickness)
                .translation(Vector::new(0.0, -0.5 * scene.floor_thickness)),
            Floor::Plane => ColliderBuilder::new(SharedShape::halfspace(Vector::Y)),
        };
        world.insert_collider(
            floor
                .friction(scene.floor_friction)
                .restitution(scene.floor_restitution)
                .friction_combine_rule(CoefficientCombineRule::Multiply)
                .restitution_combine_rule(CoefficientCombineRule::Multiply),
            None,
        );

        let [b, w, _] = scene.body_sides();
        let m = scene.mass();
        // The locked 3D box's I_z, as Bullet computes it: m/12 (b² + w²).
        let inertia = m / 12.0 * (b * b + w * w);
        let die_collider = ColliderBuilder::cuboid(0.5 * b, 0.5 * w)
            .mass_properties(MassProperties::new(Vector::ZERO, m, inertia))
            .friction(scene.friction)
            .restitution(scene.restitution)
            .friction_combine_rule(CoefficientCombineRule::Multiply)
            .restitution_combine_rule(CoefficientCombineRule::Multiply);
        Ok(Rapier2d {
            world,
            die: None,
            die_collider,
            damping: scene.rapier_damping(),
            can_sleep: scene.sleeping,
        })
    }

    /// The die's mass and moment of inertia as Rapier holds them (it keeps inverses).
    pub fn die_mass_inertia(&self) -> Option<(f64, f64)> {
        self.die.map(|h| {
            let p = self.world.bodies[h].mass_properties().local_mprops;
            (p.mass(), p.principal_inertia())
        })
    }
}

/// A state in the x-y plane as a 2D pose: the quaternion (cos θ/2, 0, 0, sin θ/2) becomes the
/// unit complex (cos θ, sin θ).
fn planar_pose(s: &BodyState) -> Pose {
    let q = s.rotation.quaternion();
    let (c, sin) = (q.w * q.w - q.k * q.k, 2.0 * q.w * q.k);
    let mut rotation = Rotation::from_cos_sin_unchecked(c, sin);
    rotation.normalize_mut();
    Pose::from_parts(Vector::new(s.position.x, s.position.y), rotation)
}

impl Engine for Rapier2d {
    /// As in 3D, a throw starts from a new body and collider. The start must lie in the
    /// plane: a rotation about z only, no z position or velocity, spin about z only.
    fn reset(&mut self, start: &BodyState) -> crate::Result<()> {
        let q = start.rotation.quaternion();
        if start.position.z != 0.0
            || start.linear_velocity.z != 0.0
            || start.angular_velocity.x != 0.0
            || start.angular_velocity.y != 0.0
            || q.i != 0.0
            || q.j != 0.0
        {
            return Err(crate::Error::Engine(
                "rapier2d: the start state is not in the x-y plane".into(),
            ));
        }
        if let Some(h) = self.die.take() {
            self.world.remove_body(h);
        }
        let v = &start.linear_velocity;
        let body = RigidBodyBuilder::dynamic()
            .pose(planar_pose(start))
            .linvel(Vector::new(v.x, v.y))
            .angvel(start.angular_velocity.z)
            .linear_damping(self.damping.0)
            .angular_damping(self.damping.1)
            .can_sleep(self.can_sleep);
        let (h, _) = self.world.insert(body, self.die_collider.clone());
        self.die = Some(h);
        Ok(())
    }

    fn step(&mut self) -> crate::Result<()> {
        if self.die.is_none() {
            return Err(crate::Error::Engine("rapier2d: step before reset".into()));
        }
        self.world.step();
        // A quarantined body is reset to a finite pose at rest; report it (see rapier3d.rs).
        if !self.world.quarantine().is_empty() {
            return Err(crate::Error::Engine(
                "rapier2d: the die's state went non-finite (quarantined)".into(),
            ));
        }
        Ok(())
    }

    fn state(&self) -> BodyState {
        let Some(h) = self.die else {
            return BodyState::at_origin();
        };
        let b = &self.world.bodies[h];
        let t = b.translation();
        let v = b.linvel();
        BodyState {
            position: Vector3::new(t.x, t.y, 0.0),
            rotation: UnitQuaternion::from_axis_angle(&Vector3::z_axis(), b.rotation().angle()),
            linear_velocity: Vector3::new(v.x, v.y, 0.0),
            angular_velocity: Vector3::new(0.0, 0.0, b.angvel()),
            sleeping: b.is_sleeping(),
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn same_release_as_rapier3d() {
        assert_eq!(rapier2d_f64::VERSION, rapier3d_f64::VERSION);
    }
}
