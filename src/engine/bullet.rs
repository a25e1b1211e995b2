//! Bullet (Debian's libbullet, double precision) through the C++ shim in `cpp/`.

use super::interface::Engine;
use crate::model::collider::Collider;
use crate::model::mass::{BodyTurn, MassProps};
use crate::model::scene::{Floor, Mode, Preset, Scene};
use crate::model::state::BodyState;
use cxx::UniquePtr;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

#[cxx::bridge(namespace = "dicephys")]
mod ffi {
    /// The kind of solid that collides (`model::collider::Collider`'s variants).
    enum SolidKind {
        /// A box, `sides` its sides, rounded by `edge_radius`.
        Box,
        /// A convex hull, `hull` its vertices.
        Hull,
        /// A cylinder along body z (a coin), `sides` its diameter, diameter and height.
        Cylinder,
    }

    /// Everything the shim needs to build a world; no setting lives only in C++.
    struct BulletScene {
        /// Full side lengths along the body's x, y, z axes, m.
        sides: [f64; 3],
        mass: f64,
        /// A made die (`model::mass`): the body is its principal frame at its centre of mass
        /// and its solid (box, or rounded box) a compound's child off it. False: the paper's
        /// block, a box shape whose inertia Bullet computes.
        made: bool,
        /// A made die's centre of mass from its geometric centre, body axes, m.
        com: [f64; 3],
        /// Its principal frame in body axes (x, y, z, w).
        principal: [f64; 4],
        /// Its principal moments, kg m².
        moments: [f64; 3],
        /// Its edges' rounding radius, m.
        edge_radius: f64,
        /// What collides (`model::collider::Collider`).
        solid: SolidKind,
        /// A hull's vertices in body axes from its centroid, m, x y z after each other
        /// (empty for a box or a cylinder).
        hull: Vec<f64>,
        /// The hull's collision margin, m (Bullet's convex tests keep the shape this far out).
        hull_margin: f64,
        /// Its centre of mass is off the centre or its principal frame off the body axes:
        /// the solid is a compound's child (else the body's shape itself).
        offset: bool,
        /// DicePhys's 2D mode: linear factor (1,1,0), angular factor (0,0,1).
        planar: bool,
        die_friction: f64,
        die_restitution: f64,
        floor_friction: f64,
        floor_restitution: f64,
        /// A static plane instead of DicePhys's 10 km box.
        plane_floor: bool,
        /// The box floor's thickness, m (DicePhys: 100).
        floor_thickness: f64,
        gravity: f64,
        dt: f64,
        /// Bullet 2.83+'s per-body implicit gyroscopic force (2.81: off).
        gyroscopic_implicit: bool,
        /// The same force computed at unit scale, where Bullet's own drops it for a body as
        /// small as a die (`cpp/shim.cc`, `gyroscopic_impulse`): the die turns as Euler's
        /// equations say, in flight and in contact.
        gyroscopic_scaled: bool,
        /// Relative normal speed below which Bullet 3 drops restitution (2.81: none, 0).
        restitution_velocity_threshold: f64,
        split_impulse: bool,
        /// Split impulse at every depth (`m_splitImpulsePenetrationThreshold` = 0): the
        /// penetration is corrected apart from the velocity, so a bounce leaves at e; else
        /// Bullet's default, split only beyond 4 cm, the correction folded into the bounce.
        split_every_depth: bool,
        /// Two friction rows per contact point (Coulomb's cone, as a pyramid), not Bullet's
        /// default one along the slip (`SOLVER_USE_2_FRICTION_DIRECTIONS`; Bullet's own
        /// solver then runs, not the shim's `DieSolver`).
        two_friction_directions: bool,
        solver_iterations: i32,
        /// Bullet's sleeping (deactivation) at its defaults, or never.
        deactivation: bool,
        /// `btRigidBody::setDamping(linear, angular)`: d in [0, 1], the velocity scaled by
        /// (1 − d)^dt each step (`Scene::bullet_damping`); DicePhys: 0, 0.
        linear_damping: f64,
        angular_damping: f64,
        /// The die's rolling and spinning friction (`Scene::rolling_resistance` over the
        /// floor's friction, which Bullet multiplies them by); 0: none, as DicePhys.
        rolling_friction: f64,
        /// A soft contact (`model::compliance`): each contact point's stiffness, N/m, and
        /// damping, N s/m, set on the die (the floor's stiffness infinite, its damping 0, so
        /// the contact's are the die's); 0: the rigid contact, as DicePhys.
        contact_stiffness: f64,
        contact_damping: f64,
        /// Static friction over sliding friction (`Scene::static_ratio`): a contact point
        /// slipping no faster than `stick_speed`, m/s, as a step begins holds with this
        /// times its combined friction; 1: one friction, as DicePhys. The shim's solver
        /// sets it (`DieSolver`), so the stock world refuses anything but 1.
        static_ratio: f64,
        stick_speed: f64,
        /// Bullet's own world and solver, every part of a step as Bullet does it, without the
        /// shim's shortcuts (`DiceWorld`, `DieSolver` in cpp/shim.cc): for the check that
        /// they change nothing.
        stock_world: bool,
    }

    /// The die's state: position, orientation (x, y, z, w), velocities, and whether Bullet
    /// has put it to sleep.
    struct BodyStateFfi {
        position: [f64; 3],
        rotation: [f64; 4],
        linear_velocity: [f64; 3],
        angular_velocity: [f64; 3],
        sleeping: bool,
    }

    unsafe extern "C++" {
        include!("dicephys/cpp/shim.h");

        type BulletWorld;

        fn new_world(scene: &BulletScene) -> Result<UniquePtr<BulletWorld>>;
        fn reset(self: Pin<&mut BulletWorld>, start: &BodyStateFfi) -> Result<()>;
        fn set_state(self: Pin<&mut BulletWorld>, now: &BodyStateFfi) -> Result<()>;
        fn step(self: Pin<&mut BulletWorld>, out: &mut BodyStateFfi) -> Result<()>;
        fn step_n(self: Pin<&mut BulletWorld>, n: u32) -> Result<()>;
        fn state(self: &BulletWorld) -> BodyStateFfi;
        fn contact_points(self: &BulletWorld) -> u32;
        fn bullet_version() -> i32;
    }
}

/// Bullet's version as it reports it, e.g. "3.24".
pub fn version() -> String {
    let v = ffi::bullet_version();
    format!("{}.{:02}", v / 100, v % 100)
}

/// Bullet's settings for a preset.
struct Solver {
    gyroscopic_implicit: bool,
    gyroscopic_scaled: bool,
    restitution_velocity_threshold: f64,
    split_every_depth: bool,
    two_friction_directions: bool,
}

fn solver(preset: Preset) -> Solver {
    match preset {
        // Bullet 2.81 as the paper ran it, on Debian's 3.24: clear the per-body gyroscopic
        // flag (2.81's flags were 0) and the restitution velocity threshold (2.81 had none).
        // Measured in shared/reference: these two, and nothing else, make 3.24 reproduce 2.81
        // throw for throw. 2.81's m_erp2 = 0.8 must NOT be copied: 3.24 uses it differently.
        Preset::Dicephys281 => Solver {
            gyroscopic_implicit: false,
            gyroscopic_scaled: false,
            restitution_velocity_threshold: 0.0,
            split_every_depth: false,
            two_friction_directions: false,
        },
        // Debian 3.24's stock defaults.
        Preset::Bullet3 => Solver {
            gyroscopic_implicit: true,
            gyroscopic_scaled: false,
            restitution_velocity_threshold: 0.2,
            split_every_depth: false,
            two_friction_directions: false,
        },
        // dicephys281 with the bounce kept exact: a contact found d deep is pushed out by a
        // split impulse, not by a velocity of 0.2 d/dt added to its bounce (Baumgarte), which
        // raises the restitution to e + 0.2 U on average (tests/it/impact.rs).
        Preset::Split => Solver {
            gyroscopic_implicit: false,
            gyroscopic_scaled: false,
            restitution_velocity_threshold: 0.0,
            split_every_depth: true,
            two_friction_directions: false,
        },
        // split, with the die turning as Euler's equations say (Bullet's implicit gyroscopic
        // impulse, which its own arithmetic drops for a body as small as a die:
        // `gyroscopic_scaled`) and friction in Coulomb's cone (Bullet's default is one
        // friction row per point, along the slip as the step starts, so nothing resists a
        // slip across it; its two rows, each clamped on its own, make a square: the shim
        // solves a point's two together in the disc, DieSolver::coulomb). Each measured in
        // tests/it/impact.rs.
        Preset::Laws => Solver {
            gyroscopic_implicit: false,
            gyroscopic_scaled: true,
            restitution_velocity_threshold: 0.0,
            split_every_depth: true,
            two_friction_directions: true,
        },
    }
}

// A BulletWorld owns its whole world (broadphase, dispatcher, solver, bodies) and shares
// nothing mutable with another; Bullet's globals are only read while stepping. So a world may
// move to another thread; it is never used from two at once (it is not Sync).
unsafe impl Send for ffi::BulletWorld {}

/// The Bullet engine: one Bullet world with one die in it, through the C++ shim.
pub struct Bullet {
    world: UniquePtr<ffi::BulletWorld>,
    gyroscopic: bool,
    /// Damping slows the die in flight too, so its flight is not ballistic.
    damped: bool,
    /// How the body is turned from the die's axes (`to_ffi`, `state`).
    turn: BodyTurn,
    /// The die's state as the world last reported it (after reset, set_state or a step).
    now: ffi::BodyStateFfi,
}

/// The die's solid as the shim takes it (`BulletScene`'s fields that say what collides).
struct BulletSolid {
    solid: ffi::SolidKind,
    sides: [f64; 3],
    edge_radius: f64,
    hull: Vec<f64>,
    hull_margin: f64,
}

/// The die's collider in Bullet's terms: the one place a solid becomes Bullet's.
fn collider(c: &Collider) -> BulletSolid {
    match c {
        Collider::Box { half, radius } => BulletSolid {
            solid: ffi::SolidKind::Box,
            sides: (2.0 * half).into(),
            edge_radius: *radius,
            hull: Vec::new(),
            hull_margin: 0.0,
        },
        Collider::Hull { points, margin, .. } => BulletSolid {
            solid: ffi::SolidKind::Hull,
            sides: [0.0; 3],
            edge_radius: 0.0,
            hull: points.iter().flat_map(|v| [v.x, v.y, v.z]).collect(),
            hull_margin: *margin,
        },
        Collider::Cylinder {
            radius,
            half_height,
        } => BulletSolid {
            solid: ffi::SolidKind::Cylinder,
            sides: [2.0 * radius, 2.0 * radius, 2.0 * half_height],
            edge_radius: 0.0,
            hull: Vec::new(),
            hull_margin: 0.0,
        },
    }
}

impl Bullet {
    /// A fresh Bullet world for the scene, its solver set by the scene's preset.
    pub fn new(scene: &Scene) -> crate::Result<Bullet> {
        Bullet::build(scene, false)
    }

    /// The same world, stepped by Bullet's own `btDiscreteDynamicsWorld` and
    /// `btSequentialImpulseConstraintSolver` without the shim's shortcuts (its swept bounding
    /// boxes, predictions, island manager and the solver's pools, which change nothing for
    /// one die on a static floor): the check that they change nothing.
    pub fn stock(scene: &Scene) -> crate::Result<Bullet> {
        Bullet::build(scene, true)
    }

    fn build(scene: &Scene, stock_world: bool) -> crate::Result<Bullet> {
        let s = solver(scene.preset);
        let (linear_damping, angular_damping) = scene.bullet_damping();
        let mp = MassProps::of(scene)?;
        let p = mp.principal.quaternion();
        let collider = collider(&Collider::of(scene));
        let soft = scene.contact_time > 0.0;
        let (contact_stiffness, contact_damping) = if soft {
            crate::model::compliance::per_point(mp.mass, scene.restitution, scene.contact_time)
        } else {
            (0.0, 0.0)
        };
        let desc = ffi::BulletScene {
            sides: collider.sides,
            mass: mp.mass,
            made: Collider::made(scene),
            com: mp.com.into(),
            principal: [p.i, p.j, p.k, p.w],
            moments: mp.moments.into(),
            edge_radius: collider.edge_radius,
            solid: collider.solid,
            hull: collider.hull,
            hull_margin: collider.hull_margin,
            offset: mp.com != Vector3::zeros() || !mp.aligned(),
            planar: scene.mode == Mode::TwoD,
            die_friction: scene.friction,
            // A soft contact bounces by its spring: no restitution on top of it.
            die_restitution: if soft { 0.0 } else { scene.restitution },
            floor_friction: scene.floor_friction,
            floor_restitution: scene.floor_restitution,
            plane_floor: scene.floor == Floor::Plane,
            floor_thickness: scene.floor_thickness,
            gravity: scene.gravity,
            dt: scene.dt,
            gyroscopic_implicit: s.gyroscopic_implicit,
            gyroscopic_scaled: s.gyroscopic_scaled,
            restitution_velocity_threshold: s
                .restitution_velocity_threshold
                .max(scene.bounce_threshold),
            split_impulse: true,
            // A soft contact's spring acts through the penetration in the velocity solve;
            // split off, it would only push the die out, never throw it back.
            split_every_depth: s.split_every_depth && !soft,
            two_friction_directions: s.two_friction_directions,
            solver_iterations: 10,
            deactivation: scene.sleeping,
            linear_damping,
            angular_damping,
            rolling_friction: if scene.rolling_resistance > 0.0 {
                scene.rolling_resistance / scene.floor_friction
            } else {
                0.0
            },
            contact_stiffness,
            contact_damping,
            static_ratio: scene.static_ratio,
            stick_speed: scene.stick_speed(),
            stock_world,
        };
        let world =
            ffi::new_world(&desc).map_err(|e| crate::Error::Engine(format!("bullet: {e}")))?;
        let now = world.state();
        Ok(Bullet {
            world,
            gyroscopic: s.gyroscopic_implicit || s.gyroscopic_scaled,
            damped: scene.damped(),
            turn: mp.turn(),
            now,
        })
    }

    /// Steps `n` times inside C++ with no call back into Rust: the benchmark's baseline
    /// for what one FFI call per step costs.
    pub fn step_n(&mut self, n: u32) -> crate::Result<()> {
        self.world
            .pin_mut()
            .step_n(n)
            .map_err(|e| crate::Error::Engine(e.to_string()))
    }
}

impl Bullet {
    /// The body's orientation as Bullet holds it. Bullet keeps it as a matrix; its quaternion
    /// is already unit length to rounding, so it is taken as it is rather than renormalised.
    fn raw_rotation(&self) -> UnitQuaternion<f64> {
        let [x, y, z, w] = self.now.rotation;
        UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z))
    }
}

/// The engine's state of the body from the die's: the orientation turned by `turn` (the
/// centre of mass and velocities are the same).
fn to_ffi(s: &BodyState, turn: &BodyTurn) -> ffi::BodyStateFfi {
    let r = turn.to_body(&s.rotation);
    let q = r.quaternion();
    ffi::BodyStateFfi {
        position: s.position.into(),
        rotation: [q.i, q.j, q.k, q.w],
        linear_velocity: s.linear_velocity.into(),
        angular_velocity: s.angular_velocity.into(),
        sleeping: false,
    }
}

impl Engine for Bullet {
    fn reset(&mut self, start: &BodyState) -> crate::Result<()> {
        self.world
            .pin_mut()
            .reset(&to_ffi(start, &self.turn))
            .map_err(|e| crate::Error::Engine(e.to_string()))?;
        self.now = self.world.state();
        Ok(())
    }

    fn set_state(&mut self, now: &BodyState) -> crate::Result<()> {
        self.world
            .pin_mut()
            .set_state(&to_ffi(now, &self.turn))
            .map_err(|e| crate::Error::Engine(e.to_string()))?;
        self.now = self.world.state();
        Ok(())
    }

    /// Free flight is ballistic unless Bullet's implicit gyroscopic force turns ω or damping
    /// slows the die (a body turned off the die's axes is flown in its own frame,
    /// `body_state`).
    fn ballistic_flight(&self) -> bool {
        !self.gyroscopic && !self.damped
    }

    fn contact_free(&self) -> bool {
        self.world.contact_points() == 0
    }

    fn body_state(&self) -> BodyState {
        BodyState {
            rotation: self.raw_rotation(),
            ..self.state()
        }
    }

    fn set_body_state(&mut self, now: &BodyState) -> crate::Result<()> {
        self.world
            .pin_mut()
            .set_state(&to_ffi(now, &BodyTurn::default()))
            .map_err(|e| crate::Error::Engine(e.to_string()))?;
        self.now = self.world.state();
        Ok(())
    }

    fn step(&mut self) -> crate::Result<()> {
        self.world
            .pin_mut()
            .step(&mut self.now)
            .map_err(|e| crate::Error::Engine(e.to_string()))
    }

    fn state(&self) -> BodyState {
        let s = &self.now;
        BodyState {
            position: Vector3::from(s.position),
            rotation: self.turn.to_die(&self.raw_rotation()),
            linear_velocity: Vector3::from(s.linear_velocity),
            angular_velocity: Vector3::from(s.angular_velocity),
            sleeping: s.sleeping,
        }
    }
}
