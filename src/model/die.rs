//! The die as a rigid body: its half sides, mass, inertia and barriers, its energies, and
//! where its lowest point is.

use crate::model::mass::{MassProps, Turn};
use crate::model::scene::{Mode, Scene};
pub use crate::model::state::up_in_body;
use crate::model::state::BodyState;
use nalgebra::{Matrix3, Vector3};

/// The die as the roll, the energy watch and the certificate see it. Its state's position is
/// its centre of mass; its orientation, its body axes (the faces').
#[derive(Clone, Copy, Debug)]
pub struct DieShape {
    /// Half the sides along body x, y, z (breadth, width, length; in 2D, z is half the 1 m
    /// depth), m.
    pub half: Vector3<f64>,
    /// The edges' rounding radius, m (0: sharp).
    pub radius: f64,
    /// The inner box the rounding sweeps: `half` − `radius`.
    pub core: Vector3<f64>,
    /// The centre of mass from the geometric centre, body axes, m.
    pub com: Vector3<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// The inertia tensor about the centre of mass, body axes.
    pub inertia: Matrix3<f64>,
    /// Its diagonal, when it is diagonal (the kinetic energy as the plain die's always was).
    diagonal: Option<Vector3<f64>>,
    /// The least principal moment.
    pub inertia_min: f64,
    /// Gravity's magnitude, m/s², along −y.
    pub gravity: f64,
    /// The centred sharp block: `lowest_point` and `face_region` take the paper's short forms.
    plain: bool,
    /// How an engine's body is turned from the die's axes (`MassProps::turn`).
    pub turn: Turn,
    /// Rotation about z only (2D): region and barrier over the x and y axes.
    pub planar: bool,
    /// The centre of mass's height at rest on each face, by the face on the floor:
    /// `rest[i][0]` the +i face, `rest[i][1]` the −i face.
    pub rest: [[f64; 2]; 3],
    /// The least height of the centre of mass out of each face's region (balanced on one of
    /// its edges), indexed as `rest`: ∞ for z in 2D, −∞ where no barrier is known.
    pub barrier: [[f64; 2]; 3],
}

impl DieShape {
    /// The die of a scene: its sides, mass properties (`MassProps`) and barriers.
    ///
    /// The barriers: seen from the centre of mass c, call face (i, s)'s region the downward
    /// directions g whose ray from c leaves the inner box (half sides kᵢ = hᵢ − r) through that
    /// face. On its boundary the ray meets an edge of the inner box at a point p, and the die
    /// touching the floor holds c at height h(g) ≥ (p − c)·g + r = |p − c| + r, at least the
    /// distance from c to the edge's line plus r: √((kᵢ − s cᵢ)² + (kⱼ − t cⱼ)²) + r for the
    /// edge shared with face (j, t). The least over its four edges is the face's barrier (for
    /// the centred sharp block, the paper's edge-balance height √(hᵢ² + hⱼ²)). Where c is not
    /// inside the inner box along i, the argument fails and no barrier is known.
    pub fn of(scene: &Scene) -> DieShape {
        let [a, b, c] = scene.body_sides();
        let mp = MassProps::compute(scene);
        let half = Vector3::new(a, b, c) / 2.0;
        let radius = scene.features.edge_radius;
        let core = half.map(|h| h - radius);
        let com = mp.com;
        let planar = scene.mode == Mode::TwoD;
        let axes: &[usize] = if planar { &[0, 1] } else { &[0, 1, 2] };
        let signs = [1.0, -1.0];
        let rest = std::array::from_fn(|i| std::array::from_fn(|k| half[i] - signs[k] * com[i]));
        let barrier = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                if !axes.contains(&i) {
                    return f64::INFINITY;
                }
                let di = core[i] - signs[k] * com[i];
                if di <= 0.0 {
                    return f64::NEG_INFINITY;
                }
                axes.iter()
                    .filter(|&&j| j != i)
                    .flat_map(|&j| signs.map(|t| (j, t)))
                    .map(|(j, t)| {
                        let dj = core[j] - t * com[j];
                        if dj <= 0.0 {
                            f64::NEG_INFINITY
                        } else {
                            di.hypot(dj) + radius
                        }
                    })
                    .fold(f64::INFINITY, f64::min)
            })
        });
        let diagonal = (mp.inertia == Matrix3::from_diagonal(&mp.inertia.diagonal()))
            .then(|| mp.inertia.diagonal());
        DieShape {
            half,
            radius,
            core,
            com,
            mass: mp.mass,
            inertia: mp.inertia,
            diagonal,
            inertia_min: mp.moments.min(),
            gravity: scene.gravity,
            plain: radius == 0.0 && com == Vector3::zeros(),
            turn: mp.turn(),
            planar,
            rest,
            barrier,
        }
    }

    /// Kinetic energy, translational plus rotational.
    pub fn kinetic(&self, s: &BodyState) -> f64 {
        let w = s.rotation.inverse_transform_vector(&s.angular_velocity);
        let rotational = match &self.diagonal {
            Some(d) => w.component_mul(&w).dot(d),
            None => w.dot(&(self.inertia * w)),
        };
        0.5 * self.mass * s.linear_velocity.norm_squared() + 0.5 * rotational
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
        s.position.y
            + 0.5 * s.linear_velocity.norm_squared() / self.gravity
            + 0.5 * self.inertia_min * s.angular_velocity.norm_squared()
                / (self.mass * self.gravity)
            - 1e-9
    }

    /// Height above the floor of the die's lowest point, its centre of mass at `s`: the
    /// support function in the downward direction from the centre of mass,
    /// y − (Σ kᵢ |uᵢ| + r) − c·u with u = Rᵀŷ (for the centred sharp block `lowest_point`).
    #[inline]
    pub fn lowest_point(&self, s: &BodyState) -> f64 {
        self.lowest_point_up(s, &up_in_body(&s.rotation))
    }

    /// `lowest_point` given the world's up direction in body axes (`up_in_body`).
    #[inline]
    pub fn lowest_point_up(&self, s: &BodyState, up: &Vector3<f64>) -> f64 {
        if self.plain {
            s.position.y - up.abs().dot(&self.half)
        } else {
            s.position.y - (up.abs().dot(&self.core) + self.radius) - self.com.dot(up)
        }
    }

    /// The face on the floor, as (axis i, 0 for +i or 1 for −i), given the world's up
    /// direction in body axes: the face the downward ray from the centre of mass leaves the
    /// inner box through, |gᵢ| / (kᵢ − sᵢ cᵢ) largest (in 2D, over x and y).
    #[inline]
    pub fn face_region(&self, up: &Vector3<f64>) -> (usize, usize) {
        let n = if self.planar { 2 } else { 3 };
        let down = |i: usize| usize::from(up[i] > 0.0);
        let key = |i: usize| {
            if self.plain {
                up[i].abs() / self.half[i]
            } else {
                let s = if down(i) == 0 { 1.0 } else { -1.0 };
                up[i].abs() / (self.core[i] - s * self.com[i])
            }
        };
        // The largest key, the last of equals (as `Iterator::max_by`).
        let (mut best, mut best_key) = (0, key(0));
        for i in 1..n {
            let k = key(i);
            if k.total_cmp(&best_key).is_ge() {
                (best, best_key) = (i, k);
            }
        }
        (best, down(best))
    }
}

/// Height above the floor of the lowest point of a box with half sides `half`:
/// y − Σ hᵢ |(Rᵀ ŷ)ᵢ| (the support function in the downward direction; in 2D the body turns
/// about z only, so z adds nothing).
pub fn lowest_point(half: &Vector3<f64>, s: &BodyState) -> f64 {
    s.position.y - up_in_body(&s.rotation).abs().dot(half)
}
