//! The die: what it is, as every command takes it ([`Die`]), and as a rigid body
//! ([`DieBody`]): its half sides, mass, inertia and barriers, its energies, and where its
//! lowest point is.

use crate::model::block::{Block, Side};
use crate::model::faces::Outcome;
use crate::model::form::Form;
use crate::model::mass::{BodyTurn, Features, MassProps};
use crate::model::scene::{Mode, Scene};
use crate::model::shape::Shape;
pub use crate::model::state::up_in_body;
use crate::model::state::BodyState;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A die as asked, resolved once wherever one is given (`roll`'s and `fair`'s flags, a die
/// file, `fit`'s die, a counts file's `die` column, `predict`'s other die, Python's
/// arguments): its shape, what departs from the uniform solid, and its density. The cuboid
/// has no shape: its sides are given where it is thrown (`roll`'s `--block`, each of a fit's
/// rows), and [`Die::form`] makes it the scene's form with them.
///
/// Written as a fit has always written its die (its features under `die`), so that a fit, its
/// directory and its `fit.json` read the same; `features` is read too.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Die {
    /// A named die, a mesh or a die file's mesh; `None`: the cuboid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Arc<Shape>>,
    /// Its centre of mass, pips, rounding, insert, inertia, shell and numbering.
    #[serde(
        default,
        rename = "die",
        alias = "features",
        skip_serializing_if = "Features::is_default"
    )]
    pub features: Features,
    /// kg/m³, where it is not the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
}

impl Die {
    /// The block a scene of it holds: its shape's bounding box, else `block` (the cuboid's).
    pub fn block(&self, block: Block) -> Block {
        self.shape.as_ref().map_or(block, |s| s.block())
    }

    /// Its form in a scene: its shape, else the cuboid `block`.
    pub fn form(&self, block: Block) -> Form {
        self.shape.clone().map_or(Form::Cuboid(block), Form::Shape)
    }

    /// The paper's scene (`Scene::paper`) of it: its shape, else the cuboid `block`; its
    /// features, and its density where it gives one.
    pub fn scene(&self, block: Block, mode: Mode) -> Scene {
        let mut scene = Scene::paper(block, mode);
        scene.die = self.form(block);
        scene.features = self.features;
        if let Some(d) = self.density {
            scene.density = d;
        }
        scene
    }

    /// How many outcomes its faces' counts have: a die of any shape's labels (a label on
    /// several facets one outcome), else a cube's six numbers.
    pub fn outcomes(&self) -> usize {
        self.shape.as_ref().map_or(6, |s| s.outcome_labels().len())
    }

    /// What it is, in a few words: its shape's name, else the block `block`.
    pub fn name(&self, block: Block) -> String {
        self.shape
            .as_ref()
            .map_or_else(|| format!("the block {block}"), |s| s.name.clone())
    }
}

/// A die of any shape as the roll sees it (`model::shape`): what its lowest point and its face
/// on the floor are computed from.
#[derive(Debug)]
pub struct Convex {
    /// The hull's vertices from the centre of mass, body axes, m (none for a cylinder).
    points: Vec<Vector3<f64>>,
    /// A cylinder along z: its radius and half height, m.
    cylinder: Option<(f64, f64)>,
    /// The centroid from the centre of mass, body axes, m.
    centroid: Vector3<f64>,
    /// Each outcome's resting normal (the face on the floor's outward normal); zero for a
    /// cylinder's curved side.
    normals: Vec<Vector3<f64>>,
    /// The largest distance from the centre of mass to any point of the die, m.
    pub reach: f64,
    /// Its least thickness, m (across its facets' planes; a cylinder's height or diameter):
    /// a centre that sinks deeper than this below the floor's top face has gone into it, not
    /// dipped (`sim::roll::Dip::through`).
    pub thickness: f64,
    /// The regions of down directions by the face the downward ray from the centre of mass
    /// leaves through (a hull's facets; a cylinder's caps, then its side).
    regions: Vec<Region>,
    /// A rounded die's rounding (`Shape::radius`), m: every support, rest height and barrier
    /// of its inner body (`points`, the facets) plus this.
    radius: f64,
}

/// The down directions g (body axes) whose ray from the centre of mass c leaves the die
/// through one face. On the region's boundary the ray leaves through a point p of the face's
/// rim, and a die touching the floor holds c at height h(g) ≥ (p − c)·g = |p − c|, at least
/// the distance from c to the rim (an edge's line; a cylinder's rim circle): the region's
/// barrier. So a die whose energy is below mg times the barrier cannot leave the region, and
/// comes to rest on that face: `sim::certificate`'s argument for the cuboid, for any convex
/// die.
#[derive(Clone, Debug)]
struct Region {
    /// The face's outward normal (a cylinder's side: zero, any radial direction).
    normal: Vector3<f64>,
    /// The centre of mass's height resting on the face (its distance from the face's plane;
    /// a cylinder's side: the radius less the centre's distance from the axis).
    rest: f64,
    /// The least height of the centre of mass on the region's boundary.
    barrier: f64,
    /// The outcome of a die at rest on the face (`None`: not a resting face).
    outcome: Option<u8>,
}

/// The distance from the origin to the line through `a` and `b`.
fn line_distance(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = b - a;
    a.cross(&d).norm() / d.norm()
}

impl Convex {
    fn of(shape: &crate::model::shape::Shape, com: &Vector3<f64>) -> Convex {
        use crate::model::shape::Solid;
        let centroid = -com;
        let radius = shape.radius;
        let (points, cylinder) = match &shape.solid {
            Solid::Hull { .. } => (shape.points().iter().map(|p| p - com).collect(), None),
            Solid::Cylinder { diameter, height } => {
                (Vec::new(), Some((0.5 * diameter, 0.5 * height)))
            }
        };
        // A coin is never rounded (`Shape::rounded`): the radius adds to a hull's alone.
        let reach = radius
            + match cylinder {
                Some((r, h)) => centroid.norm() + r.hypot(h),
                None => points.iter().map(|p| p.norm()).fold(0.0, f64::max),
            };
        let thickness = match cylinder {
            Some((r, h)) => (2.0 * r).min(2.0 * h),
            None => shape
                .facets()
                .iter()
                .map(|f| {
                    let depth = points
                        .iter()
                        .map(|p| f.normal.dot(&(p + com)))
                        .fold(f64::INFINITY, f64::min);
                    f.offset - depth + 2.0 * radius
                })
                .fold(f64::INFINITY, f64::min),
        };
        let normals: Vec<Vector3<f64>> = shape
            .faces
            .iter()
            .map(|f| Vector3::from(f.normal))
            .collect();
        let outcome = |n: &Vector3<f64>| {
            normals
                .iter()
                .position(|m| {
                    if *n == Vector3::zeros() {
                        *m == Vector3::zeros()
                    } else {
                        m.dot(n) > 1.0 - 1e-9
                    }
                })
                .map(|k| k as u8)
        };
        let regions = match cylinder {
            Some((r, h)) => {
                // From the centre of mass: the caps' planes at the centroid's z ± h, the rims
                // at the radius r about the axis through the centroid.
                let off = centroid.xy().norm();
                let caps = [1.0, -1.0].map(|sign: f64| {
                    let rest = h + sign * centroid.z;
                    let normal = Vector3::new(0.0, 0.0, sign);
                    Region {
                        normal,
                        rest,
                        barrier: (r - off).hypot(rest),
                        outcome: outcome(&normal),
                    }
                });
                let side = Region {
                    normal: Vector3::zeros(),
                    rest: r - off,
                    // The nearer rim.
                    barrier: (r - off).hypot(h - centroid.z.abs()),
                    outcome: outcome(&Vector3::zeros()),
                };
                vec![caps[0].clone(), caps[1].clone(), side]
            }
            None => shape
                .facets()
                .iter()
                .map(|f| {
                    let n = f.normal;
                    let m = f.polygon.len();
                    let barrier = (0..m)
                        .map(|i| {
                            line_distance(&(f.polygon[i] - com), &(f.polygon[(i + 1) % m] - com))
                        })
                        .fold(f64::INFINITY, f64::min)
                        + radius;
                    Region {
                        normal: n,
                        rest: f.offset - n.dot(com) + radius,
                        barrier,
                        outcome: outcome(&n),
                    }
                })
                .collect(),
        };
        Convex {
            points,
            cylinder,
            centroid,
            normals,
            reach,
            thickness,
            regions,
            radius,
        }
    }

    /// The region the down direction `down` (unit, body axes) is in: the face the ray from
    /// the centre of mass leaves through first (a hull: the largest n·g over its distance; a
    /// cylinder: a cap, unless the side comes first).
    fn region(&self, down: &Vector3<f64>) -> &Region {
        match self.cylinder {
            Some((r, _)) => {
                let cap = &self.regions[if down.z > 0.0 { 0 } else { 1 }];
                let t_cap = cap.rest / down.z.abs();
                // |c + t g| = r across the axis, c the centre of mass from the axis.
                let (c, g) = (-self.centroid.xy(), down.xy());
                let (a, b, e) = (g.norm_squared(), c.dot(&g), c.norm_squared() - r * r);
                let t_side = if a > 0.0 {
                    (-b + (b * b - a * e).max(0.0).sqrt()) / a
                } else {
                    f64::INFINITY
                };
                if t_cap <= t_side {
                    cap
                } else {
                    &self.regions[2]
                }
            }
            None => {
                let mut best = &self.regions[0];
                let mut key = f64::NEG_INFINITY;
                for reg in &self.regions {
                    let k = reg.normal.dot(down) / reg.rest;
                    if k > key {
                        (best, key) = (reg, k);
                    }
                }
                best
            }
        }
    }

    /// The early stop (`sim::certificate`): the outcome certain for a die whose world up is
    /// `up` (body axes) and whose energy height (E/mg, plus what it has sunk into the floor)
    /// is `height`, keeping `margin` of each barrier in reserve.
    /// `at_least` is a cheap lower bound of that height, tried first; `height` computes it.
    pub fn certain(
        &self,
        up: &Vector3<f64>,
        at_least: f64,
        height: impl FnOnce() -> f64,
        margin: f64,
    ) -> Option<u8> {
        let reg = self.region(&-up);
        let allowed = (1.0 - margin) * (reg.barrier - reg.rest);
        if allowed.is_nan() || allowed <= 0.0 || reg.outcome.is_none() {
            return None;
        }
        if at_least - reg.rest >= allowed || height() - reg.rest >= allowed {
            return None;
        }
        reg.outcome
    }

    /// The energy height above which nothing is certain: the largest over resting faces of
    /// rest + (1 − margin)(barrier − rest).
    pub fn ceiling(&self, margin: f64) -> f64 {
        self.regions
            .iter()
            .filter(|r| r.outcome.is_some())
            .map(|r| r.rest + (1.0 - margin) * (r.barrier - r.rest))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// How far the die reaches below its centre of mass along `down` (a unit vector, body
    /// axes): its support function. Kept out of line, so that the cuboid's checks, which
    /// branch past it, stay as small as they were (callgrind: inlined, the plain roll took
    /// 1 % more instructions).
    #[inline(never)]
    fn depth(&self, down: &Vector3<f64>) -> f64 {
        match self.cylinder {
            Some((r, h)) => self.centroid.dot(down) + h * down.z.abs() + r * down.x.hypot(down.y),
            None => {
                self.points
                    .iter()
                    .map(|p| p.dot(down))
                    .fold(f64::NEG_INFINITY, f64::max)
                    + self.radius
            }
        }
    }

    /// The outcome the die rests on given the world's up direction in body axes: the face
    /// whose resting normal points down within DicePhys's vertical tolerance
    /// ([`VERTICAL_TOLERANCE`]), else none.
    pub fn face_down(&self, up: &Vector3<f64>) -> Option<u8> {
        let tol = VERTICAL_TOLERANCE;
        let down = -up;
        self.normals
            .iter()
            .position(|n| {
                let dot = if *n == Vector3::zeros() {
                    // A cylinder's side: the radial direction straight down.
                    down.x.hypot(down.y)
                } else {
                    n.dot(&down)
                };
                dot > 1.0 - tol
            })
            .map(|k| k as u8)
    }
}

/// The die as a rigid body, as the roll, the energy watch and the certificate see it. Its
/// state's position is its centre of mass; its orientation, its body axes (the faces').
#[derive(Clone, Debug)]
pub struct DieBody {
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
    pub turn: BodyTurn,
    /// Rotation about z only (2D): region and barrier over the x and y axes.
    pub planar: bool,
    /// The centre of mass's height at rest on each face, by the face on the floor:
    /// `rest[i][0]` the +i face, `rest[i][1]` the −i face.
    pub rest: [[f64; 2]; 3],
    /// The least height of the centre of mass out of each face's region (balanced on one of
    /// its edges), indexed as `rest`: ∞ for z in 2D, −∞ where no barrier is known.
    pub barrier: [[f64; 2]; 3],
    /// A die of any shape (`model::shape`) but a box: its lowest point, faces and barriers
    /// from its hull (`Convex`); `None` for a box, which takes the cuboid's closed forms.
    pub convex: Option<Arc<Convex>>,
    /// A die of any shape that is a box (a d6, a box-shaped mesh): its outcome resting on
    /// each face, in `faces::DIRECTIONS`' order (`Form::box_faces`); `None` for the cuboid.
    pub box_faces: Option<[u8; 6]>,
    /// A soft contact's stiffness for a flat landing, N/m: m ω₀², the four points' together
    /// (`model::compliance`); 0 for the rigid contact.
    pub spring: f64,
}

impl DieBody {
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
    pub fn of(scene: &Scene) -> DieBody {
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
        let convex = scene.die.hull().map(|s| Arc::new(Convex::of(s, &com)));
        // A die of any shape: no barrier is known (the early stop is proven for the cuboid).
        let barrier = if convex.is_some() {
            [[f64::NEG_INFINITY; 2]; 3]
        } else {
            barrier
        };
        DieBody {
            half,
            radius,
            core,
            com,
            mass: mp.mass,
            inertia: mp.inertia,
            diagonal,
            inertia_min: mp.moments.min(),
            gravity: scene.gravity,
            plain: radius == 0.0 && com == Vector3::zeros() && convex.is_none(),
            turn: mp.turn(),
            planar,
            rest,
            barrier,
            convex,
            box_faces: scene.die.box_faces(),
            spring: if scene.contact_time > 0.0 {
                let (w0, _) =
                    crate::model::compliance::solve(scene.restitution, scene.contact_time);
                mp.mass * w0 * w0
            } else {
                0.0
            },
        }
    }

    /// At most the energy a soft contact's springs hold with the die's lowest point `sunk`
    /// below the floor: ½ K sunk², as if every point of the contact (four at most) were as
    /// deep (0 for the rigid contact).
    #[inline]
    pub fn elastic_at_most(&self, sunk: f64) -> f64 {
        0.5 * self.spring * sunk * sunk
    }

    /// The largest distance from the centre of mass to any point of the die, m; in 2D (turning
    /// about z) over the cross-section.
    pub fn reach(&self, planar: bool) -> f64 {
        if let Some(c) = &self.convex {
            return c.reach;
        }
        (if planar {
            self.core.x.hypot(self.core.y)
        } else {
            self.core.norm()
        }) + self.radius
            + self.com.norm()
    }

    /// How a die at rest in `s` came out: the face it rests on (`Outcome`: a cuboid's by the
    /// direction of its face up, a die of any shape's by its outcome), or none.
    pub fn outcome(&self, s: &BodyState) -> Outcome {
        if let Some(c) = &self.convex {
            return match c.face_down(&up_in_body(&s.rotation)) {
                Some(k) => Outcome::Face(k),
                None => Outcome::Unknown,
            };
        }
        self.labelled(classify(s), s)
    }

    /// The face of a box whose side `side` stands vertical at `s`: the cuboid's by the
    /// direction of its face up, a box-shaped die of any shape's by its outcome on the face
    /// opposite. What the certificate names (`RollRecord::certified`): out of line and cold,
    /// it runs once a roll, and inlined it cost the plain roll's step loop 0.2 % more
    /// instructions (callgrind).
    #[cold]
    #[inline(never)]
    pub fn labelled(&self, side: Side, s: &BodyState) -> Outcome {
        match (
            self.box_faces,
            crate::model::faces::up_direction(&s.rotation, side),
        ) {
            (None, Some(d)) => Outcome::Face(d),
            // Resting on the face opposite the one up (`DIRECTIONS` pairs them: d ^ 1).
            (Some(faces), Some(d)) => Outcome::Face(faces[usize::from(d ^ 1)]),
            (_, None) => Outcome::Unknown,
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
        } else if let Some(c) = &self.convex {
            s.position.y - c.depth(&-up)
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

/// DicePhys's tolerance on a vertical axis: |cos| within 1e-4 of 1.
pub const VERTICAL_TOLERANCE: f64 = 1e-4;

/// The side standing vertical: the body axis (x = breadth, y = width, z = length, tested in
/// that order, as DicePhys) whose direction is vertical within the tolerance; else unknown.
pub fn classify(s: &BodyState) -> Side {
    let up = Vector3::y();
    let sides = [Side::Breadth, Side::Width, Side::Length];
    for (axis, side) in [Vector3::x(), Vector3::y(), Vector3::z()].iter().zip(sides) {
        let dir = (s.rotation * axis).normalize();
        let dot = up.dot(&dir).abs();
        if dot > 1.0 - VERTICAL_TOLERANCE && dot < 1.0 + VERTICAL_TOLERANCE {
            return side;
        }
    }
    Side::Unknown
}
