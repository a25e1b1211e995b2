//! Rapier's true 2D engine (`rapier2d-f64`) for DicePhys's 2D mode: a breadth × width box
//! (body x, y) in the x-y plane, spinning about z.
//!
//! Its mass and moment of inertia are those of the 1 m deep locked 3D box (`scene.mass()`,
//! I_z = m/12 (b² + w²)), set explicitly: a 2D density is per area, so one from the scene's
//! kg/m³ would give neither. The 2D state is reported as the 3D `BodyState` the rest of the
//! crate reads: position (x, y, 0), rotation about z, velocity (vx, vy, 0), spin (0, 0, ω).

use super::interface::Engine;
use crate::model::scene::{Floor, Mode, Scene};
use crate::model::state::BodyState;
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
    /// What the die's own free flight needs (`Engine::own_flight`); `None` if not flown.
    flight: Option<Flight>,
}

/// The die's state as Rapier holds it. The crate's `BodyState` gives the rotation as an
/// angle (`state`), which does not give back Rapier's unit complex to the bit, so a flight
/// carries this instead and hands it back as it is.
#[derive(Clone, Copy)]
struct Exact {
    t: Vector,
    r: Rotation,
    v: Vector,
    w: f64,
}

impl Exact {
    fn pose(&self) -> Pose {
        Pose::from_parts(self.t, self.r)
    }

    /// The state as `Engine::state` reports it.
    fn state(&self) -> BodyState {
        BodyState {
            position: Vector3::new(self.t.x, self.t.y, 0.0),
            rotation: UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.r.angle()),
            linear_velocity: Vector3::new(self.v.x, self.v.y, 0.0),
            angular_velocity: Vector3::new(0.0, 0.0, self.w),
            sleeping: false,
        }
    }
}

/// The 2D die's free flight, flown exactly as Rapier steps it: as in 3D (`rapier3d::Flight`,
/// whose reasoning about contacts and the sleep timer holds here word for word), with the
/// 2D integration (no gyroscopic pass; the rotation a unit complex).
struct Flight {
    h: f64,
    substeps: usize,
    incr_linear: Vector,
    local_com: Vector,
    max_linear: f64,
    max_angular: f64,
    fast_rotation: bool,
    damp_linear: f64,
    damp_angular: f64,
    sleep_threshold_dt: f64,
    collider: ColliderHandle,
    loosen: f64,
    co_offset: Pose,
    skin: f64,
    floor_top: f64,
    leaf: Aabb,
    sleep_prev: Option<Pose>,
    /// The flight under way: its leaf, the AABBs that refattened it, the last flown state.
    course: Option<(Aabb, Vec<Aabb>, Exact)>,
}

super::rapier_shared::shared!("rapier2d");

impl Flight {
    fn resets_timer(&self, prev: &Pose, now: &Exact) -> bool {
        let half_pi = std::f64::consts::FRAC_PI_2;
        // Rapier's test, as it is: angular_ok = ω² < (π/2)².
        let angular_ok = now.w * now.w < half_pi * half_pi;
        if !angular_ok || self.sleep_threshold_dt < 0.0 {
            return true;
        }
        let trans = (now.t - prev.translation).length();
        trans * 0.5 >= self.sleep_threshold_dt * (1.0 + 1e-12)
    }

    fn fly(&self, s: &Exact) -> Exact {
        let pose = s.pose().prepend_translation(self.local_com);
        let (mut t, mut r) = (pose.translation, pose.rotation);
        let (mut v, mut w) = (s.v, s.w);
        for _ in 0..self.substeps {
            v += self.incr_linear;
            // Inverse inertia × zero torque × h: +0.
            w += 0.0;
            if self.max_linear != f64::MAX {
                let n = v.length();
                if n > self.max_linear {
                    v *= self.max_linear / n;
                }
            }
            if !self.fast_rotation && w.abs() > self.max_angular {
                w = w.signum() * self.max_angular;
            }
            let dang = w * self.h;
            let new_cos = r.re - dang * r.im;
            let new_sin = r.im + dang * r.re;
            r = Rotation::from_cos_sin_unchecked(new_cos, new_sin);
            r.normalize_mut();
            t += v * self.h;
        }
        let next = Pose::from_parts(t, r).prepend_translation(-self.local_com);
        Exact {
            t: next.translation,
            r: next.rotation,
            v: v * self.damp_linear,
            w: w * self.damp_angular,
        }
    }
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
        let t = scene.floor_thickness;
        let world = world_with_floor(
            scene,
            Vector::new(0.0, -scene.gravity),
            ColliderBuilder::cuboid(5000.0, 0.5 * t).translation(Vector::new(0.0, -0.5 * t)),
        );

        let [b, w, _] = scene.body_sides();
        let m = scene.mass();
        // The locked 3D box's I_z, as Bullet computes it: m/12 (b² + w²).
        let inertia = m / 12.0 * (b * b + w * w);
        let die_collider = multiply(
            ColliderBuilder::cuboid(0.5 * b, 0.5 * w)
                .mass_properties(MassProperties::new(Vector::ZERO, m, inertia))
                .friction(scene.friction)
                .restitution(scene.restitution),
        );
        Ok(Rapier2d {
            world,
            die: None,
            die_collider,
            damping: scene.rapier_damping(),
            can_sleep: scene.sleeping,
            flight: None,
        })
    }

    /// Sets up the die's own flight after a reset (see `rapier3d::Rapier3d::flight_of`).
    fn flight_of(&self, h: RigidBodyHandle) -> Option<Flight> {
        let w = &self.world;
        let p = &w.integration_parameters;
        let b = &w.bodies[h];
        let co_handle = b.colliders()[0];
        let co = &w.colliders[co_handle];
        if p.max_ccd_substeps != 0
            || b.additional_solver_iterations() != 0
            || b.user_force() != Vector::ZERO
            || b.user_torque() != 0.0
            || b.colliders().len() != 1
        {
            return None;
        }
        let mp = b.mass_properties();
        let substeps = p.num_solver_iterations;
        let hdt = p.dt / substeps as f64;
        let force = b.user_force()
            + w.gravity
                * mp.effective_inv_mass
                    .map(|x| if x == 0.0 { 0.0 } else { 1.0 / x })
                * b.gravity_scale();
        let skin = 4.0e-2 * p.length_unit;
        let floor_top = floor_top(w, co_handle, skin);
        let threshold = b.activation().normalized_linear_threshold;
        let mut f = Flight {
            h: hdt,
            substeps,
            incr_linear: force * mp.effective_inv_mass * hdt,
            local_com: mp.local_mprops.local_com,
            max_linear: p.max_linear_velocity(),
            max_angular: std::f64::consts::FRAC_PI_4 * p.inv_dt(),
            fast_rotation: b.is_fast_rotation_allowed(),
            damp_linear: 1.0 / (1.0 + p.dt * b.linear_damping()),
            damp_angular: 1.0 / (1.0 + p.dt * b.angular_damping()),
            sleep_threshold_dt: if threshold < 0.0 {
                -1.0
            } else {
                threshold * p.length_unit * p.dt
            },
            collider: co_handle,
            loosen: co.contact_skin() + (p.prediction_distance() / 2.0 + 0.0),
            co_offset: *co.position_wrt_parent()?,
            skin,
            floor_top,
            leaf: Aabb::new_invalid(),
            sleep_prev: None,
            course: None,
        };
        f.leaf = f.aabb(w, b.position());
        Some(f)
    }

    /// What the world keeps of the die besides its state, for checks: its contact pairs (with
    /// any manifold, empty or not), its sleep timer, and whether it sleeps.
    pub fn die_world(&self) -> Option<(usize, f64, bool)> {
        die_world_of(&self.world, self.die)
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
        self.flight = self.flight_of(h);
        Ok(())
    }

    /// Hands back the flight's last state as the flight holds it (`Exact`); `now` is its view.
    fn set_state(&mut self, now: &BodyState) -> crate::Result<()> {
        let (Some(h), Some(f)) = (self.die, self.flight.as_mut()) else {
            return Err(crate::Error::Engine(
                "rapier2d: no flight to hand back".into(),
            ));
        };
        let Some((leaf, refats, exact)) = f.course.take() else {
            return Err(crate::Error::Engine(
                "rapier2d: no flight to hand back".into(),
            ));
        };
        if exact.state() != *now {
            return Err(crate::Error::Engine(
                "rapier2d: the state handed back is not the flight's".into(),
            ));
        }
        let params = self.world.integration_parameters;
        for aabb in refats {
            self.world.broad_phase.set_aabb(&params, f.collider, aabb);
        }
        f.leaf = leaf;
        let b = &mut self.world.bodies[h];
        b.set_position(exact.pose(), false);
        b.set_linvel(exact.v, false);
        b.set_angvel(exact.w, false);
        Ok(())
    }

    fn own_flight(&self) -> bool {
        self.flight.is_some()
    }

    fn own_flight_start(&mut self, s: &BodyState) -> bool {
        let (Some(h), Some(f)) = (self.die, self.flight.as_mut()) else {
            return false;
        };
        let Some(prev) = f.sleep_prev else {
            return false;
        };
        let b = &self.world.bodies[h];
        let exact = Exact {
            t: b.translation(),
            r: *b.rotation(),
            v: b.linvel(),
            w: b.angvel(),
        };
        if s.sleeping
            || b.is_sleeping()
            || !f.leaf_clear(&f.leaf)
            || !f.resets_timer(&prev, &exact)
            || self
                .world
                .narrow_phase
                .contact_pairs_with(f.collider)
                .next()
                .is_some()
        {
            return false;
        }
        f.course = Some((f.leaf, Vec::new(), exact));
        true
    }

    /// One flown step from the flight's last state (of which `_s` is the view).
    fn own_flight_step(&mut self, _s: &BodyState) -> Option<BodyState> {
        let f = self.flight.as_ref()?;
        let (leaf, _, now) = f.course.as_ref()?;
        let next = f.fly(now);
        let finite = next.t.is_finite() && next.r.re.is_finite() && next.r.im.is_finite();
        if !(finite
            && next.v.is_finite()
            && next.w.is_finite()
            && f.resets_timer(&now.pose(), &next)
            && f.resets_timer(f.sleep_prev.as_ref()?, &next))
        {
            return None;
        }
        let aabb = f.aabb(&self.world, &next.pose());
        let refat = f.refatten(leaf, &aabb);
        if let Some(l) = &refat {
            if !f.leaf_clear(l) {
                return None;
            }
        }
        let f = self.flight.as_mut()?;
        let (leaf, refats, now) = f.course.as_mut()?;
        if let Some(l) = refat {
            *leaf = l;
            refats.push(aabb);
        }
        *now = next;
        Some(next.state())
    }

    fn step(&mut self) -> crate::Result<()> {
        step_world(&mut self.world, self.die, &mut self.flight)
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
