//! Rapier (pure Rust, `rapier3d-f64`): the die as a free 3D body, or, in 2D, DicePhys's locked
//! 3D body (translation along z and rotation about x and y locked), the same scene Bullet runs.
//!
//! Rapier's public math is glam (`DVec3`, `DQuat`), not nalgebra; `to_na`/`from_na` below copy
//! the components across, exactly.

use super::{BodyState, Engine};
use crate::model::scene::{Floor, Mode, Scene};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;

/// Rapier's version, from the crate itself (`rapier3d_f64::VERSION`, its CARGO_PKG_VERSION).
pub fn version() -> &'static str {
    rapier3d_f64::VERSION
}

/// Rapier's solver substeps per step (its `num_solver_iterations`, left at the default): each
/// integrates the velocities and positions once, so free flight is symplectic Euler at dt/n.
pub fn substeps() -> usize {
    IntegrationParameters::default().num_solver_iterations
}

/// Rapier's 3D engine: a free 3D die, or in 2D DicePhys's locked 3D body.
pub struct Rapier3d {
    /// Rapier's bundle of one world: pipeline, islands, broad and narrow phase, bodies,
    /// colliders, integration parameters and gravity.
    world: PhysicsWorld,
    die: Option<RigidBodyHandle>,
    die_collider: ColliderBuilder,
    locked: LockedAxes,
    /// Rapier's (linear, angular) damping coefficients (`Scene::rapier_damping`).
    damping: (f64, f64),
    /// The die may sleep (`Scene::sleeping`).
    can_sleep: bool,
}

impl Rapier3d {
    /// A fresh world for the scene; refuses a non-positive time step or mass.
    pub fn new(scene: &Scene) -> crate::Result<Rapier3d> {
        if !(scene.dt > 0.0 && scene.mass() > 0.0) {
            return Err(crate::Error::Engine(
                "rapier: bad scene (dt and mass must be positive)".into(),
            ));
        }
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, -scene.gravity, 0.0);
        world.integration_parameters.dt = scene.dt;
        // No CCD, as DicePhys. Rapier's default (1 substep) still sweeps any fast-moving
        // dynamic body against fixed colliders; 0 turns all of it off.
        world.integration_parameters.max_ccd_substeps = 0;

        // Friction and restitution combine as in Bullet: the product of the two colliders'
        // coefficients (Rapier's default is their average). The floor's are 1, so the
        // contact's μ and e are the die's. Both colliders say Multiply, so no rule outranks it.
        let floor = match scene.floor {
            // DicePhys's static 10000 x 100 x 10000 m box, top face at y = 0.
            // (`--floor-thickness` makes it thinner.)
            Floor::Box => ColliderBuilder::cuboid(5000.0, 0.5 * scene.floor_thickness, 5000.0)
                .translation(Vector::new(0.0, -0.5 * scene.floor_thickness, 0.0)),
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

        let [bx, by, bz] = scene.body_sides();
        let die_collider = ColliderBuilder::cuboid(0.5 * bx, 0.5 * by, 0.5 * bz)
            .mass_properties(box_mass_properties(scene.mass(), [bx, by, bz]))
            .friction(scene.friction)
            .restitution(scene.restitution)
            .friction_combine_rule(CoefficientCombineRule::Multiply)
            .restitution_combine_rule(CoefficientCombineRule::Multiply);

        // DicePhys's 2D mode is Bullet's linear factor (1,1,0) and angular factor (0,0,1).
        // Rapier 0.36.1 applies no friction at all to a body with a locked translation (its
        // coupled 2x2 friction solve meets a zero effective mass along z and its safe inverse
        // zeroes the whole impulse), so only the rotations are locked: with no rotation about
        // x or y and no force along z, the body has no z motion to lock (checked in tests).
        let locked = match scene.mode {
            Mode::ThreeD => LockedAxes::empty(),
            Mode::TwoD => LockedAxes::ROTATION_LOCKED_X | LockedAxes::ROTATION_LOCKED_Y,
        };
        Ok(Rapier3d {
            world,
            die: None,
            die_collider,
            locked,
            damping: scene.rapier_damping(),
            can_sleep: scene.sleeping,
        })
    }

    /// The die's mass as Rapier holds it (it keeps 1/m), for checks.
    pub fn die_mass(&self) -> Option<f64> {
        self.die.map(|h| self.world.bodies[h].mass())
    }
}

/// A solid box's mass properties: the mass as given, centre at the origin, and the principal
/// moments as Bullet's `btBoxShape::calculateLocalInertia` computes them, m/12 (l₂² + l₃²).
/// Given explicitly rather than through a density, so the mass is `scene.mass()` to the bit.
fn box_mass_properties(mass: f64, [lx, ly, lz]: [f64; 3]) -> MassProperties {
    let inertia = Vector::new(
        mass / 12.0 * (ly * ly + lz * lz),
        mass / 12.0 * (lx * lx + lz * lz),
        mass / 12.0 * (lx * lx + ly * ly),
    );
    MassProperties::new(Vector::ZERO, mass, inertia)
}

fn from_na(v: &Vector3<f64>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

fn to_na(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

impl Engine for Rapier3d {
    /// A throw starts from a new body and collider: removing the old die also removes its
    /// contact pair (with its warm-start impulses), its island and its sleep timer. Verified
    /// in tests/rapier.rs: a throw after another on the same world goes step for step as on a
    /// fresh world.
    fn reset(&mut self, start: &BodyState) -> crate::Result<()> {
        if let Some(h) = self.die.take() {
            self.world.remove_body(h);
        }
        let q = start.rotation.quaternion();
        let pose = Pose::from_parts(
            from_na(&start.position),
            Rotation::from_xyzw(q.i, q.j, q.k, q.w),
        );
        let body = RigidBodyBuilder::dynamic()
            .pose(pose)
            .linvel(from_na(&start.linear_velocity))
            .angvel(from_na(&start.angular_velocity))
            .locked_axes(self.locked)
            .linear_damping(self.damping.0)
            .angular_damping(self.damping.1)
            .can_sleep(self.can_sleep);
        let (h, _) = self.world.insert(body, self.die_collider.clone());
        self.die = Some(h);
        Ok(())
    }

    fn step(&mut self) -> crate::Result<()> {
        if self.die.is_none() {
            return Err(crate::Error::Engine("rapier: step before reset".into()));
        }
        self.world.step();
        // Rapier does not let a NaN through: it puts the body back at its last finite pose
        // with zero velocity and disables it, which would look like a die at rest. Report it.
        if !self.world.quarantine().is_empty() {
            return Err(crate::Error::Engine(
                "rapier: the die's state went non-finite (quarantined)".into(),
            ));
        }
        Ok(())
    }

    fn state(&self) -> BodyState {
        let Some(h) = self.die else {
            return BodyState::at_origin();
        };
        let b = &self.world.bodies[h];
        let q = b.rotation();
        BodyState {
            position: to_na(b.translation()),
            // Rapier renormalises the quaternion after every integration; take it as it is.
            rotation: UnitQuaternion::new_unchecked(Quaternion::new(q.w, q.x, q.y, q.z)),
            linear_velocity: to_na(b.linvel()),
            angular_velocity: to_na(b.angvel()),
            sleeping: b.is_sleeping(),
        }
    }
}
