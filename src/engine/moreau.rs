//! A third engine, to arbitrate between Bullet and Rapier: a polyhedral die on a flat floor,
//! stepped by Moreau–Jean time stepping with Newton's restitution and Coulomb's friction
//! solved at every corner that touches.
//!
//! Why a third: on a loaded die that bounces, Bullet and Rapier part far beyond their noise
//! (issue 46, class N), and each fails a closed form (Rapier's bounce carries no friction and
//! brakes a sliding spin 19 times too fast; Bullet's sliding cube drops corners and rocks).
//! This engine is the contact model both claim, written so that each of its parts is the
//! textbook one and nothing is tuned (what it found: docs/results/rapier.md, "The arbiter and
//! the `laws` preset"):
//! - Contacts are the die's hull vertices against the plane y = 0 (a polyhedron meets a plane
//!   only at its vertices: an edge or a face on the floor is two or more of them), each kept by
//!   its vertex from step to step, so a sliding face keeps its corners.
//! - At each step the impulses solve, to convergence (projected Gauss–Seidel, warm-started),
//!   the contact problem at velocity level: at every touching vertex the normal velocity
//!   after the step is at least Newton's −e v⁻ (an approach faster than `BOUNCE_SPEED`) or
//!   what brings the vertex exactly onto the floor; the friction impulse lies in the disk of
//!   radius μ times the normal impulse, and where it is on the disk's rim it points against
//!   the vertex's slip (maximal dissipation: the step along −v with a scalar gain makes the
//!   fixed point anti-parallel to the slip, which a 2×2 effective-mass step would not).
//!   Friction therefore acts throughout a bounce, as Newton–Coulomb's impact law has it.
//! - Between impulses the body turns as Euler's equations say (a splitting that keeps the
//!   angular momentum exactly and the energy without drift), so a loaded die precesses as it
//!   should however long it flies (Bullet under any preset but `laws` keeps ω constant, which
//!   for a body with unequal moments does not keep its angular momentum).
//! - A vertex left below the floor (a bounce taken up to one step early, rounding) is lifted
//!   out by moving the body up, without touching its velocity: no energy is added.
//!
//! Its errors are O(dt): a finer step converges it, which is how it is used (`--dt 1e-4` and
//! finer). 3D only, a polyhedron only (no rounded edges, no cylinder), no rolling resistance.

use super::interface::Engine;
use crate::model::collider::Collider;
use crate::model::mass::MassProps;
use crate::model::scene::{Mode, Scene};
use crate::model::state::BodyState;
use nalgebra::{Matrix3, UnitQuaternion, Vector2, Vector3};

/// An approach slower than this, m/s, does not bounce: a die resting on the floor approaches
/// it by g dt every step, which Newton's law would turn into an endless hop. A bounce from 1 cm/s
/// would lift a corner by 5 µm at most (v²/2g), which no outcome can feel.
pub const BOUNCE_SPEED: f64 = 0.01;
/// Most Gauss–Seidel sweeps a step takes; it stops earlier once converged (`TOLERANCE`).
const MAX_SWEEPS: usize = 500;
/// Converged when no impulse changes by more than this fraction of m g dt in a sweep.
const TOLERANCE: f64 = 1e-9;

/// The die, its touching corners and their impulses.
pub struct Moreau {
    dt: f64,
    gravity: f64,
    mass: f64,
    /// The inverse inertia about the centre of mass, in the die's axes.
    inv_inertia: Matrix3<f64>,
    inertia: Matrix3<f64>,
    /// The principal frame in the die's axes, and the principal moments.
    principal: UnitQuaternion<f64>,
    moments: Vector3<f64>,
    /// The hull's vertices from the centre of mass, die axes.
    corners: Vec<Vector3<f64>>,
    mu: f64,
    e: f64,
    /// Per-step velocity factors from the damping rates, e^(−λ dt).
    damp: (f64, f64),
    state: BodyState,
    /// Each corner's impulses at the last step (normal, tangent along x and z), warm start.
    impulses: Vec<(f64, Vector2<f64>)>,
}

/// Ok if the arbiter models the scene's die: a polyhedron (no rounded edges, no cylinder) in
/// 3D, without rolling resistance; else why not.
pub fn models(scene: &Scene) -> crate::Result<()> {
    let refuse = |why: &str| Err(crate::Error::Engine(format!("moreau: {why}")));
    if scene.mode != Mode::ThreeD {
        return refuse("3D dice only");
    }
    match Collider::of(scene) {
        Collider::Box { radius, .. } | Collider::Hull { radius, .. } if radius > 0.0 => {
            return refuse("a polyhedron only (no rounded edges)")
        }
        Collider::Cylinder { .. } => return refuse("a polyhedron only (no cylinder)"),
        _ => {}
    }
    if scene.rolling_resistance > 0.0 {
        return refuse("no rolling resistance");
    }
    if scene.bounce_threshold > 0.0 {
        return refuse("no bounce threshold");
    }
    if scene.contact_time > 0.0 {
        return refuse("no soft contact");
    }
    if scene.static_ratio != 1.0 {
        return refuse("one friction coefficient (no static friction apart)");
    }
    Ok(())
}

/// The die's corners, body axes from its centroid: the one place a solid becomes the
/// arbiter's (a box's eight, a hull's vertices; `models` refuses the rest).
fn corners(c: &Collider) -> Vec<Vector3<f64>> {
    match c {
        Collider::Box { half, .. } => (0..8)
            .map(|k| {
                let sign = |bit: u32| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
                Vector3::new(sign(0) * half.x, sign(1) * half.y, sign(2) * half.z)
            })
            .collect(),
        Collider::Hull { points, .. } => points.clone(),
        Collider::Cylinder { .. } => Vec::new(),
    }
}

impl Moreau {
    /// The scene's die on a flat floor; refuses what it does not model (`models`).
    pub fn new(scene: &Scene) -> crate::Result<Moreau> {
        models(scene)?;
        let mp = MassProps::of(scene)?;
        let points = corners(&Collider::of(scene));
        let inv_inertia = mp
            .inertia
            .try_inverse()
            .ok_or_else(|| crate::Error::Engine("moreau: a singular inertia".into()))?;
        let rate = |r: f64| (-r * scene.dt).exp();
        let n = points.len();
        Ok(Moreau {
            dt: scene.dt,
            gravity: scene.gravity,
            mass: mp.mass,
            inv_inertia,
            inertia: mp.inertia,
            principal: mp.principal,
            moments: mp.moments,
            corners: points.iter().map(|p| p - mp.com).collect(),
            mu: scene.friction * scene.floor_friction,
            e: scene.restitution * scene.floor_restitution,
            damp: (rate(scene.linear_damping), rate(scene.angular_damping)),
            state: BodyState::at_origin(),
            impulses: vec![(0.0, Vector2::zeros()); n],
        })
    }
}

/// A touching corner in this step: its lever from the centre of mass (world axes), the
/// normal velocity it must reach, its effective mass terms and its impulses.
struct Touch {
    k: usize,
    r: Vector3<f64>,
    target: f64,
    /// 1 / K_nn, the normal's effective mass.
    normal_mass: f64,
    /// 1 / (K_tt's largest eigenvalue): the friction step's scalar gain.
    slip_gain: f64,
    normal: f64,
    tangent: Vector2<f64>,
}

impl Moreau {
    /// The velocity of the body's point at lever r.
    fn point_velocity(v: &Vector3<f64>, w: &Vector3<f64>, r: &Vector3<f64>) -> Vector3<f64> {
        v + w.cross(r)
    }

    /// The torque-free turn over `h` from orientation `q` at angular velocity `w` (world):
    /// Euler's equations by the symmetric splitting of the kinetic energy into its three
    /// principal terms (McLachlan 1993; Dullweber, Leimkuhler & McLachlan 1997), each of whose
    /// flows is an exact turn about one principal axis. The angular momentum in the world is
    /// kept to rounding, the energy without drift, and a loaded die precesses as it should
    /// (`impact::a_loaded_cube_keeps_its_angular_momentum_in_flight`).
    fn turn(
        &self,
        q: &UnitQuaternion<f64>,
        w: &Vector3<f64>,
        h: f64,
    ) -> (UnitQuaternion<f64>, Vector3<f64>) {
        // The principal frame's orientation and the angular momentum in its axes.
        let mut body = q * self.principal;
        let momentum = q * (self.inertia * (q.inverse() * w));
        let mut l = body.inverse() * momentum;
        let i = self.moments;
        for (axis, part) in [(0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)] {
            let mut unit = Vector3::zeros();
            unit[axis] = 1.0;
            let angle = part * h * l[axis] / i[axis];
            let spin = UnitQuaternion::from_scaled_axis(unit * angle);
            body *= spin;
            l = spin.inverse() * l;
        }
        let w_body = Vector3::new(l.x / i.x, l.y / i.y, l.z / i.z);
        (body * self.principal.inverse(), body * w_body)
    }

    /// Applies impulse `p` at lever `r`.
    fn push(
        &self,
        v: &mut Vector3<f64>,
        w: &mut Vector3<f64>,
        iw: &Matrix3<f64>,
        r: &Vector3<f64>,
        p: &Vector3<f64>,
    ) {
        *v += p / self.mass;
        *w += iw * r.cross(p);
    }
}

impl Engine for Moreau {
    fn reset(&mut self, start: &BodyState) -> crate::Result<()> {
        self.state = BodyState {
            sleeping: false,
            ..*start
        };
        self.impulses
            .iter_mut()
            .for_each(|i| *i = (0.0, Vector2::zeros()));
        Ok(())
    }

    fn step(&mut self) -> crate::Result<()> {
        let h = self.dt;
        let s = &self.state;
        let rot = s.rotation.to_rotation_matrix().into_inner();
        let iw = rot * self.inv_inertia * rot.transpose();
        let mut v = (s.linear_velocity + Vector3::new(0.0, -self.gravity * h, 0.0)) * self.damp.0;
        let mut w = s.angular_velocity * self.damp.1;
        let x = s.position;

        // The corners that touch the floor by the step's end at the free velocity.
        let mut touches = Vec::new();
        for (k, c) in self.corners.iter().enumerate() {
            let r = rot * c;
            let gap = x.y + r.y;
            let vn = Self::point_velocity(&v, &w, &r).y;
            if gap + h * vn > 0.0 {
                self.impulses[k] = (0.0, Vector2::zeros());
                continue;
            }
            // Newton's law for a real approach; else reach the floor and stay on it.
            let target = if -vn > BOUNCE_SPEED {
                -self.e * vn
            } else {
                -gap.max(0.0) / h
            };
            let k_of = |a: &Vector3<f64>, b: &Vector3<f64>| {
                a.dot(b) / self.mass + (r.cross(a)).dot(&(iw * r.cross(b)))
            };
            let (ex, ey, ez) = (Vector3::x(), Vector3::y(), Vector3::z());
            let (kxx, kxz, kzz) = (k_of(&ex, &ex), k_of(&ex, &ez), k_of(&ez, &ez));
            let largest = 0.5 * (kxx + kzz) + (0.25 * (kxx - kzz).powi(2) + kxz * kxz).sqrt();
            touches.push(Touch {
                k,
                r,
                target,
                normal_mass: 1.0 / k_of(&ey, &ey),
                slip_gain: 1.0 / largest,
                normal: 0.0,
                tangent: Vector2::zeros(),
            });
        }

        // Warm start with last step's impulses at the corners that touched then.
        for t in touches.iter_mut() {
            let (n, tan) = self.impulses[t.k];
            t.normal = n;
            t.tangent = tan;
            let p = Vector3::new(tan.x, n, tan.y);
            self.push(&mut v, &mut w, &iw, &t.r, &p);
        }
        let tol = TOLERANCE * self.mass * self.gravity.max(1.0) * h;
        for _ in 0..MAX_SWEEPS {
            let mut change: f64 = 0.0;
            for t in touches.iter_mut() {
                let u = Self::point_velocity(&v, &w, &t.r);
                let n = (t.normal + (t.target - u.y) * t.normal_mass).max(0.0);
                let dn = n - t.normal;
                t.normal = n;
                self.push(&mut v, &mut w, &iw, &t.r, &Vector3::new(0.0, dn, 0.0));
                let u = Self::point_velocity(&v, &w, &t.r);
                let mut f = t.tangent - t.slip_gain * Vector2::new(u.x, u.z);
                let cap = self.mu * t.normal;
                if f.norm() > cap {
                    f *= cap / f.norm();
                }
                let df = f - t.tangent;
                t.tangent = f;
                self.push(&mut v, &mut w, &iw, &t.r, &Vector3::new(df.x, 0.0, df.y));
                change = change.max(dn.abs()).max(df.norm());
            }
            if change <= tol {
                break;
            }
        }
        for t in &touches {
            self.impulses[t.k] = (t.normal, t.tangent);
        }

        let (rotation, w) = self.turn(&s.rotation, &w, h);
        let rot2 = rotation.to_rotation_matrix().into_inner();
        let mut position = x + v * h;
        let lowest = self
            .corners
            .iter()
            .map(|c| position.y + (rot2 * c).y)
            .fold(f64::INFINITY, f64::min);
        if lowest < 0.0 {
            position.y -= lowest;
        }
        self.state = BodyState {
            position,
            rotation,
            linear_velocity: v,
            angular_velocity: w,
            sleeping: false,
        };
        if !self.state.is_finite() {
            return Err(crate::Error::Engine(
                "moreau: the die's state is not finite".into(),
            ));
        }
        Ok(())
    }

    fn state(&self) -> BodyState {
        self.state
    }
}
