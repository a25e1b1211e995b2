//! Rapier (pure Rust, `rapier3d-f64`): the die as a free 3D body, or, in 2D, DicePhys's locked
//! 3D body (translation along z and rotation about x and y locked), the same scene Bullet runs.
//!
//! Rapier's public math is glam (`DVec3`, `DQuat`), not nalgebra; `to_na`/`from_na` below copy
//! the components across, exactly.

use super::interface::Engine;
use crate::model::collider::Collider;
use crate::model::mass::{BodyTurn, MassProps};
use crate::model::scene::{Floor, Mode, Preset, Scene};
use crate::model::state::BodyState;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rapier3d_f64::parry;
use rapier3d_f64::parry::query::{
    DefaultQueryDispatcher, PersistentQueryDispatcher, QueryDispatcher, Unsupported,
};
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
    /// What the die's own free flight needs (`Engine::own_flight`); `None` if not flown.
    flight: Option<Flight>,
    /// A made die (`model::mass`): the body is its principal frame at its centre of mass, the
    /// collider off it.
    made: bool,
    /// How the body is turned from the die's axes.
    turn: BodyTurn,
    /// Rolling resistance, m (`Scene::rolling_resistance`; 0: none, Rapier's own).
    rolling: f64,
}

/// The die's free flight, flown here exactly as Rapier steps it (see `fly`), and what Rapier's
/// world keeps of the die besides its state: its broad-phase leaf and its sleep timer's pose.
///
/// When is a Rapier step pure flight? With no contact pair between the die and the floor in
/// the narrow phase, a step makes one only if the broad phase reports a new pair, which it
/// does only where the die's tree leaf (its AABB fattened by the change-detection skin,
/// refattened only when the AABB leaves it) meets the floor's. That leaf is mirrored here
/// step by step with parry's rule, so a flight lasts while the leaf stays above the floor's
/// (fattened too, to spare). The sleep timer resets at every step where the die moved more
/// than its threshold (or spins faster than π/2 rad/s); a flown step must be one, from the
/// pose before it and from the pose Rapier still holds from the last engine step (which is
/// what the first engine step after the flight compares against).
struct Flight {
    /// The substep, s.
    h: f64,
    substeps: usize,
    /// The velocity increment per substep: force × inverse mass × h, as the solver bakes it.
    incr_linear: Vector,
    /// The gyroscopic pass (3D dynamic body with the gyroscopic forces on: Rapier's default).
    gyro: bool,
    principal_frame: Rotation,
    principal_inertia: Vector,
    inv_principal_inertia: Vector,
    local_com: Vector,
    /// Speed caps per substep (Rapier's `max_linear_velocity`, π/4 per step of rotation).
    max_linear: f64,
    max_angular: f64,
    fast_rotation: bool,
    /// Damping factors at the end of the step, 1 / (1 + dt c).
    damp_linear: f64,
    damp_angular: f64,
    /// The sleep rule's linear threshold × dt (negative: the die never sleeps).
    sleep_threshold_dt: f64,
    /// The die's collider: its shape's AABB loosening and offset from the body.
    collider: ColliderHandle,
    loosen: f64,
    co_offset: Pose,
    skin: f64,
    /// The floor leaf's top, with the change-detection skin on top of it to spare.
    floor_top: f64,
    /// The die's broad-phase leaf as Rapier's tree holds it after the engine's last step.
    leaf: Aabb,
    /// The body pose at the start of the engine's last step (Rapier's `sleep_prev_pose`);
    /// `None` if unknown (the die was asleep then).
    sleep_prev: Option<Pose>,
    /// The flight under way: the leaf as the flown steps leave it, the AABBs that refattened
    /// it (replayed into the tree by `set_state`).
    course: Option<(Aabb, Vec<Aabb>)>,
}

fn pose_of(s: &BodyState) -> Pose {
    let q = s.rotation.quaternion();
    Pose::from_parts(
        from_na(&s.position),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

super::rapier_shared::shared!("rapier");

impl Flight {
    /// True if Rapier's sleep rule, from `prev` to the pose of `now` (spinning at `now`'s
    /// angular velocity), finds the die moving: the rule's drift is at least the
    /// translation, so a translation over the threshold (or a fast spin) is enough.
    fn resets_timer(&self, prev: &Pose, now: &BodyState) -> bool {
        let w = from_na(&now.angular_velocity);
        let half_pi = std::f64::consts::FRAC_PI_2;
        // Rapier's test, as it is: angular_ok = |ω|² < (π/2)².
        let angular_ok = w.dot(w) < half_pi * half_pi;
        if !angular_ok || self.sleep_threshold_dt < 0.0 {
            return true;
        }
        let trans = (from_na(&now.position) - prev.translation).length();
        trans * 0.5 >= self.sleep_threshold_dt * (1.0 + 1e-12)
    }

    /// One Rapier step of a body with no contact and no joint, operation for operation as
    /// the staged solver takes it: per substep, the velocity increment and the gyroscopic
    /// correction, the speed caps, then `integrate_linearized`; at the end, damping.
    fn fly(&self, s: &BodyState) -> BodyState {
        let pose = pose_of(s).prepend_translation(self.local_com);
        let (mut t, mut r) = (pose.translation, pose.rotation);
        let mut v = from_na(&s.linear_velocity);
        let mut w = from_na(&s.angular_velocity);
        for _ in 0..self.substeps {
            v += self.incr_linear;
            // The angular increment: inverse inertia × zero torque × h, +0 in every component.
            w += Vector::ZERO;
            if self.gyro {
                w = gyroscopic_corrected_angvel(
                    w,
                    r * self.principal_frame,
                    self.principal_inertia,
                    self.inv_principal_inertia,
                    self.h,
                );
            }
            if self.max_linear != f64::MAX {
                let n = v.length();
                if n > self.max_linear {
                    v *= self.max_linear / n;
                }
            }
            if !self.fast_rotation {
                let n = w.length();
                if n > self.max_angular {
                    w *= self.max_angular / n;
                }
            }
            let hang = w * (self.h * 0.5);
            let id_plus_hang = Rotation::from_xyzw(hang.x, hang.y, hang.z, 1.0);
            r = id_plus_hang * r;
            r = r.normalize();
            t += v * self.h;
        }
        let v = v * self.damp_linear;
        let w = w * self.damp_angular;
        let next = Pose::from_parts(t, r).prepend_translation(-self.local_com);
        let q = next.rotation;
        BodyState {
            position: to_na(next.translation),
            rotation: UnitQuaternion::new_unchecked(Quaternion::new(q.w, q.x, q.y, q.z)),
            linear_velocity: to_na(v),
            angular_velocity: to_na(w),
            sleeping: false,
        }
    }
}

/// Rapier's `gyroscopic_corrected_angvel` (crate-private there), copied as it is.
fn gyroscopic_corrected_angvel(
    angvel: Vector,
    principal_axes: Rotation,
    principal_inertia: Vector,
    inv_principal_inertia: Vector,
    dt: f64,
) -> Vector {
    let w = principal_axes.inverse() * angvel;
    let curr_momentum = principal_inertia * w;
    let explicit_gyro_momentum = -w.cross(curr_momentum) * dt;
    let total_momentum = curr_momentum + explicit_gyro_momentum;
    let total_momentum_sqnorm = total_momentum.length_squared();

    if total_momentum_sqnorm != 0.0 {
        let capped_momentum =
            total_momentum * (curr_momentum.length_squared() / total_momentum_sqnorm).sqrt();
        principal_axes * (inv_principal_inertia * capped_momentum)
    } else {
        angvel
    }
}

impl Rapier3d {
    /// A fresh world for the scene; refuses a non-positive time step or mass.
    pub fn new(scene: &Scene) -> crate::Result<Rapier3d> {
        if !(scene.dt > 0.0 && scene.mass() > 0.0) {
            return Err(crate::Error::Engine(
                "rapier: bad scene (dt and mass must be positive)".into(),
            ));
        }
        // No CCD, as DicePhys. Rapier's default (1 substep) still sweeps any fast-moving
        // dynamic body against fixed colliders; 0 turns all of it off. The floor's friction
        // and restitution are 1, so the contact's μ and e are the die's (`multiply`). Its box
        // is DicePhys's static 10000 x 100 x 10000 m (`floor_thickness` makes it thinner).
        let t = scene.floor_thickness;
        let mut world = world_with_floor(
            scene,
            Vector::new(0.0, -scene.gravity, 0.0),
            ColliderBuilder::cuboid(5000.0, 0.5 * t, 5000.0).translation(Vector::new(
                0.0,
                -0.5 * t,
                0.0,
            )),
        );

        // `laws`: Coulomb's friction at each contact point, which meets Coulomb's braking of
        // a sliding die's spin (tests/it/impact.rs); Rapier's default is one constraint at
        // the patch's centre and a twist, which brakes it 19 times too hard. This model's
        // bounce carries friction in the patched crate (vendor/rapier3d-f64/PATCH.md).
        if scene.preset == Preset::Laws {
            world.integration_parameters.friction_model = FrictionModel::Coulomb;
            // A die's impact is over within a substep: warm-started into the next, its impulse
            // is applied again where the corner no longer approaches, and one Gauss–Seidel
            // sweep undoes it only in part (an edge's or a face's points couple through the
            // die's turn), so the normal impulse overshoots in compression: 23 % over the
            // impact law at e = 0 on an edge, 36 % on a sticking corner. Each substep solved
            // from nothing, with three unbiased sweeps, meets both within 0.5 %
            // (tests/it/impact.rs), at 38 % more instructions a roll.
            let ip = &mut world.integration_parameters;
            ip.warmstart_coefficient = 0.0;
            ip.num_internal_stabilization_iterations = 3;
        }
        world.narrow_phase =
            NarrowPhase::with_query_dispatcher(RoundContacts.chain(DefaultQueryDispatcher));
        let made = Collider::made(scene);
        let mp = MassProps::of(scene)?;
        let die_collider = if made {
            // The solid in body axes, centred; the body in its principal frame P at the centre
            // of mass c: the solid sits at Pᵀ(−c), turned by Pᵀ. It carries the exact mass
            // properties, put in its own frame so that, moved by its pose onto the body, they
            // are the body's: the centre of mass at the origin and the principal axes the
            // body's. Rapier sums a body's colliders and its additional mass properties by
            // rediagonalising the sum (parry's `MassProperties::with_inertia_matrix`), which
            // sorts the moments and, for a diagonal tensor whose moments are not in ascending
            // order, turns the axes wrongly (a thick coin's axis took a side's moment, 13 %
            // off; a prism's 130 %); one collider's mass properties are taken as they are.
            let (solid, own) = collider(&Collider::of(scene))?;
            let p = mp.principal.quaternion();
            let turn = Rotation::from_xyzw(p.i, p.j, p.k, p.w).inverse();
            let pose = Pose::from_parts(turn * -from_na(&mp.com), turn * own);
            let inv = pose.inverse();
            let props = MassProperties::with_principal_inertia_frame(
                inv * Vector::ZERO,
                mp.mass,
                from_na(&mp.moments),
                inv.rotation,
            );
            solid.position(pose).mass_properties(props)
        } else {
            let [bx, by, bz] = scene.body_sides();
            ColliderBuilder::cuboid(0.5 * bx, 0.5 * by, 0.5 * bz)
                .mass_properties(box_mass_properties(scene.mass(), [bx, by, bz]))
        };
        let die_collider = multiply(
            die_collider
                .friction(scene.friction)
                .restitution(scene.restitution),
        );

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
            flight: None,
            made,
            turn: mp.turn(),
            rolling: scene.rolling_resistance,
        })
    }

    /// The die's inverse inertia in world axes, kg⁻¹ m⁻², as Rapier holds it after its last
    /// reset or step (`None` before the first reset): for the check that Rapier's body has
    /// the mass properties dicephys computed.
    pub fn world_inverse_inertia(&self) -> Option<nalgebra::Matrix3<f64>> {
        let m = self.world.bodies[self.die?]
            .mass_properties()
            .effective_world_inv_inertia;
        Some(nalgebra::Matrix3::new(
            m.m11, m.m12, m.m13, m.m12, m.m22, m.m23, m.m13, m.m23, m.m33,
        ))
    }

    /// Rolling resistance, which Rapier has not: after each step, a couple against the die's
    /// turning on the floor, as large as δ times the step's normal impulse (the floor's push
    /// over the step) but no larger than what stops the turn. A couple is the same about
    /// every point, so about the contact too: a die rolling without slipping slows as
    /// (I + m r²) ω̇ = −δ N says, friction carrying the turn's loss to its speed over the next
    /// steps. It opposes the whole turn, rolling and spinning in place together (Bullet bounds
    /// each of the three axes on its own); in flight, with no push, it does nothing.
    fn resist_rolling(&mut self) {
        let Some(h) = self.die else {
            return;
        };
        let w = &mut self.world;
        let co = w.bodies[h].colliders()[0];
        let push: f64 = w
            .narrow_phase
            .contact_pairs_with(co)
            .map(|p| p.total_impulse_magnitude())
            .sum();
        let b = &mut w.bodies[h];
        let turn = b.angvel();
        let speed = turn.length();
        if !(push > 0.0 && speed > 0.0) {
            return;
        }
        let axis = turn / speed;
        let inv = b.mass_properties().effective_world_inv_inertia;
        // The couple s along −axis changes the turn by −s I⁻¹ axis; past speed/(axisᵀ I⁻¹
        // axis) it would turn the die the other way.
        let most = speed / axis.dot(inv * axis);
        let s = (self.rolling * push).min(most);
        b.set_angvel(turn - (inv * axis) * s, false);
    }

    /// The body's orientation from the die's (turned by the principal frame if need be).
    fn body_rotation(&self, q: &UnitQuaternion<f64>) -> Rotation {
        let q = self.turn.to_body(q);
        let q = q.quaternion();
        Rotation::from_xyzw(q.i, q.j, q.k, q.w)
    }

    /// Sets up the die's own flight after a reset: its constants from the body as Rapier
    /// holds it, its leaf as the first step inserts it (the start's AABB, not fattened).
    fn flight_of(&self, h: RigidBodyHandle) -> Option<Flight> {
        let w = &self.world;
        let p = &w.integration_parameters;
        let b = &w.bodies[h];
        let co_handle = b.colliders()[0];
        let co = &w.colliders[co_handle];
        // Only the case worked through: one solve group of `num_solver_iterations`
        // substeps, no CCD, no user force or torque.
        if p.max_ccd_substeps != 0
            || b.additional_solver_iterations() != 0
            || b.user_force() != Vector::ZERO
            || b.user_torque() != Vector::ZERO
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
        let loosen = co.contact_skin() + (p.prediction_distance() / 2.0 + 0.0);
        let skin = 4.0e-2 * p.length_unit;
        let floor_top = floor_top(w, co_handle, skin);
        let mut f = Flight {
            h: hdt,
            substeps,
            incr_linear: force * mp.effective_inv_mass * hdt,
            gyro: b.gyroscopic_forces_enabled(),
            principal_frame: mp.local_mprops.principal_inertia_local_frame,
            principal_inertia: mp.local_mprops.principal_inertia(),
            inv_principal_inertia: mp.local_mprops.inv_principal_inertia,
            local_com: mp.local_mprops.local_com,
            max_linear: p.max_linear_velocity(),
            max_angular: std::f64::consts::FRAC_PI_4 * p.inv_dt(),
            fast_rotation: b.is_fast_rotation_allowed(),
            damp_linear: 1.0 / (1.0 + p.dt * b.linear_damping()),
            damp_angular: 1.0 / (1.0 + p.dt * b.angular_damping()),
            sleep_threshold_dt: b.activation().normalized_linear_threshold * p.length_unit * p.dt,
            collider: co_handle,
            loosen,
            co_offset: *co.position_wrt_parent()?,
            skin,
            floor_top,
            leaf: Aabb::new_invalid(),
            sleep_prev: None,
            course: None,
        };
        if b.activation().normalized_linear_threshold < 0.0 {
            f.sleep_threshold_dt = -1.0;
        }
        f.leaf = f.aabb(w, b.position());
        Some(f)
    }

    /// What the world keeps of the die besides its state, for checks: its contact pairs (with
    /// any manifold, empty or not), its sleep timer, and whether it sleeps.
    pub fn die_world(&self) -> Option<(usize, f64, bool)> {
        die_world_of(&self.world, self.die)
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
        let pose = Pose::from_parts(
            from_na(&start.position),
            self.body_rotation(&start.rotation),
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
        if self.made {
            // Rapier sums a body's mass properties at its next step; the flight below reads
            // them now.
            let w = &mut self.world;
            w.bodies[h].recompute_mass_properties_from_colliders(&w.colliders);
        }
        self.die = Some(h);
        // The own flight flies the body's frame; it is the die's axes unless turned.
        self.flight = if self.turn.turned() {
            None
        } else {
            self.flight_of(h)
        };
        Ok(())
    }

    fn set_state(&mut self, now: &BodyState) -> crate::Result<()> {
        let (Some(h), Some(f)) = (self.die, self.flight.as_mut()) else {
            return Err(crate::Error::Engine(
                "rapier: no flight to hand back".into(),
            ));
        };
        if let Some((leaf, refats)) = f.course.take() {
            let params = self.world.integration_parameters;
            for aabb in refats {
                self.world.broad_phase.set_aabb(&params, f.collider, aabb);
            }
            f.leaf = leaf;
        }
        let b = &mut self.world.bodies[h];
        b.set_position(pose_of(now), false);
        b.set_linvel(from_na(&now.linear_velocity), false);
        b.set_angvel(from_na(&now.angular_velocity), false);
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
        if s.sleeping
            || !f.leaf_clear(&f.leaf)
            || !f.resets_timer(&prev, s)
            || self.world.bodies[h].is_sleeping()
            || self
                .world
                .narrow_phase
                .contact_pairs_with(f.collider)
                .next()
                .is_some()
        {
            return false;
        }
        f.course = Some((f.leaf, Vec::new()));
        true
    }

    fn own_flight_step(&mut self, s: &BodyState) -> Option<BodyState> {
        let f = self.flight.as_ref()?;
        let (leaf, _) = f.course.as_ref()?;
        let next = f.fly(s);
        if !(next.is_finite()
            && f.resets_timer(&pose_of(s), &next)
            && f.resets_timer(f.sleep_prev.as_ref()?, &next))
        {
            return None;
        }
        let aabb = f.aabb(&self.world, &pose_of(&next));
        let refat = f.refatten(leaf, &aabb);
        if let Some(l) = &refat {
            if !f.leaf_clear(l) {
                return None;
            }
        }
        let f = self.flight.as_mut()?;
        let (leaf, refats) = f.course.as_mut()?;
        if let Some(l) = refat {
            *leaf = l;
            refats.push(aabb);
        }
        Some(next)
    }

    fn step(&mut self) -> crate::Result<()> {
        if self.rolling > 0.0 {
            self.resist_rolling();
        }
        step_world(&mut self.world, self.die, &mut self.flight)
    }

    fn state(&self) -> BodyState {
        let Some(h) = self.die else {
            return BodyState::at_origin();
        };
        let b = &self.world.bodies[h];
        let q = b.rotation();
        // Rapier renormalises the quaternion after every integration; take it as it is.
        let body = UnitQuaternion::new_unchecked(Quaternion::new(q.w, q.x, q.y, q.z));
        BodyState {
            position: to_na(b.translation()),
            rotation: self.turn.to_die(&body),
            linear_velocity: to_na(b.linvel()),
            angular_velocity: to_na(b.angvel()),
            sleeping: b.is_sleeping(),
        }
    }
}

/// Contacts recomputed every step where a round surface touches. Parry keeps a pair's
/// contact points from the last step, carried with the bodies, while their normals turn less
/// than 1° (`ContactManifold::try_update_contacts_eps`); on a round die those points ride
/// round with it as it rolls, and the floor pushes behind the true contact: a cylinder
/// rolling on its side slower than 1° a step is driven up to 1° a step (17.45 rad/s at
/// 1 ms) and held there, against any rolling resistance below about 0.2 mm, and a thick
/// coin rolls to the step cap. Marked as deformed, the manifold is computed afresh, its old
/// points kept to warm-start the new (`tests/it/bullet.rs`). A polyhedron's contacts sit at
/// its corners, which the body carries, and keep Rapier's reuse.
struct RoundContacts;

impl RoundContacts {
    fn round(g: &dyn Shape) -> bool {
        matches!(
            g.shape_type(),
            ShapeType::Cylinder | ShapeType::RoundCuboid | ShapeType::RoundConvexPolyhedron
        )
    }
}

/// Every query but the manifolds' is left to the next dispatcher of the chain.
impl QueryDispatcher for RoundContacts {
    fn intersection_test(
        &self,
        _: &Pose,
        _: &dyn Shape,
        _: &dyn Shape,
    ) -> Result<parry::query::ShapeIntersection, Unsupported> {
        Err(Unsupported)
    }
    fn distance(
        &self,
        _: &Pose,
        _: &dyn Shape,
        _: &dyn Shape,
    ) -> Result<parry::query::ShapeDistance, Unsupported> {
        Err(Unsupported)
    }
    fn contact(
        &self,
        _: &Pose,
        _: &dyn Shape,
        _: &dyn Shape,
        _: Real,
    ) -> Result<Option<parry::query::Contact>, Unsupported> {
        Err(Unsupported)
    }
    fn closest_points(
        &self,
        _: &Pose,
        _: &dyn Shape,
        _: &dyn Shape,
        _: Real,
    ) -> Result<parry::query::ClosestPoints, Unsupported> {
        Err(Unsupported)
    }
    fn cast_shapes(
        &self,
        _: &Pose,
        _: Vector,
        _: &dyn Shape,
        _: &dyn Shape,
        _: parry::query::ShapeCastOptions,
    ) -> Result<Option<parry::query::ShapeCastHit>, Unsupported> {
        Err(Unsupported)
    }
    fn cast_shapes_nonlinear(
        &self,
        _: &parry::query::NonlinearRigidMotion,
        _: &dyn Shape,
        _: &parry::query::NonlinearRigidMotion,
        _: &dyn Shape,
        _: Real,
        _: Real,
        _: bool,
    ) -> Result<Option<parry::query::ShapeCastHit>, Unsupported> {
        Err(Unsupported)
    }
}

/// Marks a round shape's manifolds deformed, then leaves them to Rapier's own dispatcher.
impl PersistentQueryDispatcher<ContactManifoldData, ContactData> for RoundContacts {
    fn contact_manifolds(
        &self,
        _: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        _: Real,
        manifolds: &mut Vec<ContactManifold>,
        _: &mut Option<parry::query::ContactManifoldsWorkspace>,
    ) -> Result<(), Unsupported> {
        if Self::round(g1) || Self::round(g2) {
            manifolds
                .iter_mut()
                .for_each(ContactManifold::mark_shapes_deformed);
        }
        Err(Unsupported)
    }
    fn contact_manifold_convex_convex(
        &self,
        _: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        _: Option<&dyn parry::query::details::NormalConstraints>,
        _: Option<&dyn parry::query::details::NormalConstraints>,
        _: Real,
        manifold: &mut ContactManifold,
    ) -> Result<(), Unsupported> {
        if Self::round(g1) || Self::round(g2) {
            manifold.mark_shapes_deformed();
        }
        Err(Unsupported)
    }
}

/// The die's collider in Rapier's terms, and the turn from its own axes to the die's (a
/// parry cylinder's axis is its y, turned onto the die's z): the one place a solid becomes
/// Rapier's.
fn collider(c: &Collider) -> crate::Result<(ColliderBuilder, Rotation)> {
    Ok(match c {
        Collider::Box { half, radius } if *radius > 0.0 => {
            let k = half.map(|h| h - radius);
            (
                ColliderBuilder::round_cuboid(k.x, k.y, k.z, *radius),
                Rotation::IDENTITY,
            )
        }
        Collider::Box { half, .. } => (
            ColliderBuilder::cuboid(half.x, half.y, half.z),
            Rotation::IDENTITY,
        ),
        Collider::Hull { points, radius, .. } => {
            let points: Vec<Vector> = points.iter().map(from_na).collect();
            // A rounded die: the inner body's hull with a border of its radius.
            let hull = if *radius > 0.0 {
                ColliderBuilder::round_convex_hull(&points, *radius)
            } else {
                ColliderBuilder::convex_hull(&points)
            };
            let hull = hull.ok_or_else(|| {
                crate::Error::Engine("rapier: the die's hull could not be built".into())
            })?;
            (hull, Rotation::IDENTITY)
        }
        Collider::Cylinder {
            radius,
            half_height,
        } => (
            ColliderBuilder::cylinder(*half_height, *radius),
            Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2),
        ),
    })
}
