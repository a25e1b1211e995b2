//! The die as it is made: a centre of mass moved off the centre, drilled pips, rounded edges
//! (`Features`), and the mass properties of the solid that results (`MassProps`): its mass,
//! centre of mass and inertia tensor, computed exactly.
//!
//! Every part is a box, a slab, a quarter cylinder, an eighth of a sphere, a spherical cap or a
//! cylinder, whose mass and first and second moments are closed forms (the cavities' are
//! polynomials of degree 4 along their axis, integrated exactly by 3-point Gauss–Legendre,
//! which avoids the cancellation of the antiderivatives for shallow pips). The parts add up
//! as moments about the geometric centre; the tensor about the centre of mass follows from
//! the parallel-axis theorem, and its eigenvectors are the body's principal frame.

use crate::error::{Error, Field, Result};
use crate::model::block::Mode;
use crate::model::faces::Layout;
use nalgebra::{Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// How the die departs from the paper's ideal block: uniform, sharp, plain. Each is off by
/// default, and a die with none of them is rolled on exactly the paper's path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// The centre of mass, given outright: its offset from the geometric centre, m, in body
    /// axes (x breadth, y width, z length). The second moments about the geometric centre
    /// stay the solid's (a weight hidden inside moves the centre; what it does to the
    /// inertia is the die file's business). `None`: the solid's own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<[f64; 3]>,
    /// Pips drilled in the standard pattern, one to six on the faces the layout numbers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pips: Option<Pips>,
    /// Edges and corners rounded with this radius, m (0: sharp).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub edge_radius: f64,
    /// Which number is on which face (it decides where the pips are): `roll --layout`.
    #[serde(default, skip_serializing_if = "is_right")]
    pub layout: Layout,
    /// A block of a second material inside the die (a weight hidden on purpose).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub insert: Option<Insert>,
    /// The inertia tensor about the centre of mass, given outright (kg m², body axes: xx, yy,
    /// zz, xy, xz, yz), in place of the solid's; its principal frame is found from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 6]>,
}

/// A cuboid of another density inside the die, its edges along the die's axes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Insert {
    /// Its sides along x, y, z, m.
    pub size: [f64; 3],
    /// Its centre, m from the die's geometric centre, body axes.
    pub centre: [f64; 3],
    /// Its density, kg/m³ (0: a hollow).
    pub density: f64,
}

impl Insert {
    /// Its moments at unit density about the die's geometric centre: a box of volume V at c
    /// has Σ m r = V c and Σ m r rᵀ = V (diag(sᵢ²)/12 + c cᵀ).
    fn moments(&self) -> Moments {
        let s = Vector3::from(self.size);
        let c = Vector3::from(self.centre);
        let v = s.x * s.y * s.z;
        Moments {
            mass: v,
            first: v * c,
            second: v * (Matrix3::from_diagonal(&(s.component_mul(&s) / 12.0)) + c * c.transpose()),
        }
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_right(l: &Layout) -> bool {
    *l == Layout::Right
}

/// The shape of a pip's cavity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PipShape {
    /// A spherical cap: the drill's round end (depth at most half the diameter).
    #[default]
    Cap,
    /// A flat-bottomed cylinder.
    Cylinder,
}

/// Drilled pips. They change the mass, not the collision surface: a pip is narrower than
/// anything the floor could reach into.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pips {
    /// The pip's diameter on the face, m.
    pub diameter: f64,
    /// Its depth, m.
    pub depth: f64,
    /// Cap or cylinder.
    #[serde(default)]
    pub shape: PipShape,
    /// The paint filling the pips, kg/m³ (0: empty).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fill_density: f64,
    /// The off-centre pips sit this fraction of the face's side from its centre along each
    /// face axis (standard dice: about a quarter).
    #[serde(default = "quarter")]
    pub spacing: f64,
}

fn quarter() -> f64 {
    0.25
}

impl Pips {
    /// Empty spherical caps `diameter` across and `depth` deep (m), at the standard spacing:
    /// what `--pips D,H` drills.
    pub fn caps(diameter: f64, depth: f64) -> Pips {
        Pips {
            diameter,
            depth,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: quarter(),
        }
    }
}

/// The pips on a face carrying `n`, in units of the spacing along the face's two axes.
pub fn pattern(n: u8) -> &'static [(f64, f64)] {
    match n {
        1 => &[(0.0, 0.0)],
        2 => &[(1.0, 1.0), (-1.0, -1.0)],
        3 => &[(1.0, 1.0), (0.0, 0.0), (-1.0, -1.0)],
        4 => &[(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)],
        5 => &[
            (1.0, 1.0),
            (1.0, -1.0),
            (0.0, 0.0),
            (-1.0, 1.0),
            (-1.0, -1.0),
        ],
        _ => &[
            (1.0, -1.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (-1.0, 0.0),
            (-1.0, 1.0),
        ],
    }
}

/// The solid's mass properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps {
    /// kg.
    pub mass: f64,
    /// The centre of mass in body axes from the geometric centre, m.
    pub com: Vector3<f64>,
    /// The inertia tensor about the centre of mass, body axes, kg m².
    pub inertia: Matrix3<f64>,
    /// The principal frame in body axes: a body vector is `principal` × its principal
    /// coordinates. The identity when the tensor is diagonal in body axes.
    pub principal: UnitQuaternion<f64>,
    /// The principal moments, in the principal frame's axes.
    pub moments: Vector3<f64>,
}

impl MassProps {
    /// True if the principal frame is the body's own axes (no rotation between them).
    pub fn aligned(&self) -> bool {
        self.principal == UnitQuaternion::identity()
    }

    /// How an engine's body (the principal frame) is turned from the die's axes.
    pub fn turn(&self) -> Turn {
        Turn((!self.aligned()).then_some(self.principal))
    }
}

/// How an engine's body is turned from the die's axes: by the die's principal frame when that
/// is not the body axes, else not at all. Every engine and the free flight turn orientations
/// through this one pair, so that the die's state is the same number wherever it is read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Turn(Option<UnitQuaternion<f64>>);

impl Turn {
    /// True if the body is turned off the die's axes.
    pub fn turned(&self) -> bool {
        self.0.is_some()
    }

    /// The body's orientation from the die's.
    #[inline]
    pub fn to_body(&self, die: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        match &self.0 {
            Some(p) => die * p,
            None => *die,
        }
    }

    /// The die's orientation from the body's.
    #[inline]
    pub fn to_die(&self, body: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        match &self.0 {
            Some(p) => body * p.inverse(),
            None => *body,
        }
    }
}

/// Moments of a part about the geometric centre: its mass, Σ m r, and Σ m r rᵀ.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Moments {
    mass: f64,
    first: Vector3<f64>,
    second: Matrix3<f64>,
}

impl Moments {
    fn add(&mut self, w: f64, o: &Moments) {
        self.mass += w * o.mass;
        self.first += w * o.first;
        self.second += w * o.second;
    }
}

/// ∫ x² dx over [−b, b].
fn line2(b: f64) -> f64 {
    2.0 * b * b * b / 3.0
}

/// The volume and ∫ xᵢ² dV of a box with half sides `a` whose edges are rounded with radius
/// `r` (the inner box of half sides a − r swept by a ball of radius r), taken apart into the
/// inner box, six slabs, twelve quarter cylinders and eight eighths of a ball.
pub fn rounded_box(a: &Vector3<f64>, r: f64) -> (f64, Vector3<f64>) {
    let b = a.map(|x| x - r);
    let volume = 8.0 * b.x * b.y * b.z
        + 8.0 * r * (b.y * b.z + b.x * b.z + b.x * b.y)
        + 2.0 * PI * r * r * (b.x + b.y + b.z)
        + 4.0 * PI * r * r * r / 3.0;
    // ∫ (b + u)² dA over a quarter disc of radius r in u, v ≥ 0: πr²/4 b² + 2b r³/3 + πr⁴/16.
    let quarter_disc =
        |b: f64| PI * r * r / 4.0 * b * b + 2.0 * b * r * r * r / 3.0 + PI * r.powi(4) / 16.0;
    // ∫ (b + u)² dV over an eighth of a ball: πr³/6 b² + 2b πr⁴/16 + πr⁵/30.
    let eighth_ball =
        |b: f64| PI * r.powi(3) / 6.0 * b * b + b * PI * r.powi(4) / 8.0 + PI * r.powi(5) / 30.0;
    let second = Vector3::from_fn(|i, _| {
        let (bi, bj, bk) = (b[i], b[(i + 1) % 3], b[(i + 2) % 3]);
        line2(bi) * 4.0 * bj * bk
            + 2.0 * ((bi + r).powi(3) - bi.powi(3)) / 3.0 * 4.0 * bj * bk
            + 2.0 * line2(bi) * r * 2.0 * (bj + bk)
            + 4.0 * line2(bi) * PI * r * r / 4.0
            + 4.0 * 2.0 * (bj + bk) * quarter_disc(bi)
            + 8.0 * eighth_ball(bi)
    });
    (volume, second)
}

/// A pip's cavity along its axis z (0 at the face, inward): volume, ∫z dV, ∫z² dV and
/// ∫u² dV for either transverse axis u. The slice at depth z is a disc of radius s(z):
/// for a cap of a ball of radius ρ whose rim is the pip's circle, s² = ρ² − (z + ρ − h)².
/// Each integrand is a polynomial of degree at most 4 in z, so 3-point Gauss–Legendre is exact.
pub fn cavity(p: &Pips) -> [f64; 4] {
    let (h, half_d) = (p.depth, 0.5 * p.diameter);
    let rho = (half_d * half_d + h * h) / (2.0 * h);
    let s2 = |z: f64| match p.shape {
        PipShape::Cap => {
            // ρ² − (z + ρ − h)² = (h − z)(2ρ − h + z): no cancellation near the rim.
            (h - z) * (2.0 * rho - h + z)
        }
        PipShape::Cylinder => half_d * half_d,
    };
    let nodes = [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()];
    let weights = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let mut out = [0.0; 4];
    for (x, w) in nodes.iter().zip(weights) {
        let z = 0.5 * h * (1.0 + x);
        let s = s2(z);
        let dv = PI * s * w * 0.5 * h;
        out[0] += dv;
        out[1] += z * dv;
        out[2] += z * z * dv;
        out[3] += 0.25 * s * dv;
    }
    out
}

/// Every pip's place: its face's axis i, the face's sign (+1, −1), and its centre's
/// coordinates along the face's other two axes j = i+1, k = i+2 (mod 3), m.
pub fn pip_places(half: &Vector3<f64>, p: &Pips, layout: Layout) -> Vec<(usize, f64, f64, f64)> {
    let numbers = layout.numbers();
    let mut out = Vec::new();
    for (d, &n) in numbers.iter().enumerate() {
        let (i, sign) = (d / 2, if d.is_multiple_of(2) { 1.0 } else { -1.0 });
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        for &(u, v) in pattern(n) {
            out.push((
                i,
                sign,
                u * p.spacing * 2.0 * half[j],
                v * p.spacing * 2.0 * half[k],
            ));
        }
    }
    out
}

/// True if `x` (m, from the geometric centre) lies in the pip's cavity at `place`: at most
/// its depth below its face, within the cavity's slice there (`cavity`'s s(z)).
fn in_pip(p: &Pips, half: &Vector3<f64>, (i, sign, pj, pk): Place, x: &Vector3<f64>) -> bool {
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    let z = half[i] - sign * x[i];
    if !(0.0..=p.depth).contains(&z) {
        return false;
    }
    let r2 = (x[j] - pj).powi(2) + (x[k] - pk).powi(2);
    r2 <= match p.shape {
        PipShape::Cap => {
            let rho = (0.25 * p.diameter * p.diameter + p.depth * p.depth) / (2.0 * p.depth);
            (p.depth - z) * (2.0 * rho - p.depth + z)
        }
        PipShape::Cylinder => 0.25 * p.diameter * p.diameter,
    }
}

/// A length in m shown in mm as the user would write it: to 12 significant digits (so
/// 7.999 mm read in and stored in metres prints as 7.999, not 7.998999999999999, and
/// 8.0000001 as itself), a length too large to write out in scientific notation (1e308, not
/// inf or 309 digits).
fn shown_mm(v: f64) -> String {
    let mm: f64 = format!("{:.11e}", v * 1e3).parse().unwrap_or(v * 1e3);
    let plain = format!("{mm}");
    if plain.len() > 20 {
        format!("{mm:e}")
    } else {
        plain
    }
}

/// A pip's place (`pip_places`).
type Place = (usize, f64, f64, f64);

/// The box a pip's cavity lies in: its low and high corners.
fn pip_box(p: &Pips, half: &Vector3<f64>, (i, sign, pj, pk): Place) -> [Vector3<f64>; 2] {
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    let r = 0.5 * p.diameter;
    let (mut lo, mut hi) = (Vector3::zeros(), Vector3::zeros());
    let (a, b) = (sign * half[i], sign * (half[i] - p.depth));
    (lo[i], hi[i]) = (a.min(b), a.max(b));
    (lo[j], hi[j]) = (pj - r, pj + r);
    (lo[k], hi[k]) = (pk - r, pk + r);
    [lo, hi]
}

/// Cells a side of the grid each overlap of two pips is integrated on.
const OVERLAP_GRID: usize = 96;

/// What the die must be given back where pips on adjacent faces hollow out the same region
/// near their common edge or corner (moments at unit density, about the centre): a point in
/// m cavities was subtracted m times and must be subtracted once, so m − 1 times its weight
/// comes back (reliability round 5, class C: the die loses the union of its cavities).
/// Integrated by the midpoint rule on a 96³ grid over each two cavities' common box; a point
/// in m cavities is met by each of their m(m − 1)/2 pairs and counted 2/m each time. Kept per
/// die, so that a die rolled many times computes it once.
fn pip_overlaps(half: &Vector3<f64>, p: &Pips, layout: Layout) -> Moments {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static KEPT: OnceLock<Mutex<HashMap<String, Moments>>> = OnceLock::new();
    let key = format!("{half:?} {p:?} {layout:?}");
    let kept = KEPT.get_or_init(Default::default);
    if let Some(m) = kept.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return *m;
    }
    let places = pip_places(half, p, layout);
    let mut total = Moments {
        mass: 0.0,
        first: Vector3::zeros(),
        second: Matrix3::zeros(),
    };
    for (n, &a) in places.iter().enumerate() {
        for &b in &places[n + 1..] {
            if a.0 == b.0 {
                continue; // one face (checked apart) or opposite faces (too far apart)
            }
            let ([alo, ahi], [blo, bhi]) = (pip_box(p, half, a), pip_box(p, half, b));
            let (lo, hi) = (alo.sup(&blo), ahi.inf(&bhi));
            if (0..3).any(|d| lo[d] >= hi[d]) {
                continue;
            }
            let cell = (hi - lo) / OVERLAP_GRID as f64;
            let dv = cell.x * cell.y * cell.z;
            for c in 0..OVERLAP_GRID.pow(3) {
                let g = OVERLAP_GRID;
                let at = Vector3::new(c % g, (c / g) % g, c / (g * g)).map(|i| i as f64 + 0.5);
                let x = lo + cell.component_mul(&at);
                if in_pip(p, half, a, &x) && in_pip(p, half, b, &x) {
                    let m = places.iter().filter(|&&q| in_pip(p, half, q, &x)).count();
                    let w = dv * 2.0 / m as f64;
                    total.mass += w;
                    total.first += x * w;
                    total.second += x * x.transpose() * w;
                }
            }
        }
    }
    kept.lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, total);
    total
}

/// The moments of one pip's cavity (unit density) about the geometric centre.
fn pip_moments(
    half: &Vector3<f64>,
    c: &[f64; 4],
    (i, sign, pj, pk): (usize, f64, f64, f64),
) -> Moments {
    let [v, z1, z2, u2] = *c;
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    // A point of the cavity: xᵢ = sign (hᵢ − z), xⱼ = pⱼ + u, xₖ = pₖ + w.
    let hi = half[i];
    let mut first = Vector3::zeros();
    first[i] = sign * (hi * v - z1);
    first[j] = pj * v;
    first[k] = pk * v;
    let mut second = Matrix3::zeros();
    second[(i, i)] = hi * hi * v - 2.0 * hi * z1 + z2;
    second[(j, j)] = pj * pj * v + u2;
    second[(k, k)] = pk * pk * v + u2;
    second[(j, k)] = pj * pk * v;
    second[(i, j)] = pj * first[i];
    second[(i, k)] = pk * first[i];
    for (a, b) in [(i, j), (i, k), (j, k)] {
        second[(b, a)] = second[(a, b)];
    }
    Moments {
        mass: v,
        first,
        second,
    }
}

/// A die file (TOML), every length in mm, every key optional:
///
/// ```toml
/// com = [0.0, 0.0, -2.0]   # the centre of mass from the geometric centre, body axes
/// edge_radius = 1.0        # edges and corners rounded
/// density = 1180.0         # kg/m³ (the solid's)
/// [pips]
/// diameter = 3.0
/// depth = 1.0
/// shape = "cap"            # or "cylinder"
/// fill_density = 1400.0    # paint, kg/m³ (0: empty)
/// spacing = 0.25           # off-centre pips' distance from the face's centre / its side
/// ```
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DieFile {
    /// mm.
    pub com: Option<[f64; 3]>,
    /// mm.
    pub edge_radius: Option<f64>,
    /// kg/m³.
    pub density: Option<f64>,
    /// Pips, in mm.
    pub pips: Option<Pips>,
    /// "right" or "left".
    pub layout: Option<Layout>,
    /// The number on each face: `{ "+x" = 2, "-x" = 5, … }`.
    pub faces: Option<std::collections::BTreeMap<String, u8>>,
    /// An insert, in mm and kg/m³.
    pub insert: Option<Insert>,
    /// The inertia about the centre of mass, g mm²: xx, yy, zz, xy, xz, yz.
    pub inertia: Option<[f64; 6]>,
    /// A die of any shape: its mesh (OBJ or STL, in mm; a path from the die file's folder).
    pub mesh: Option<std::path::PathBuf>,
    /// The mesh's lengths times this (e.g. 25.4 for a mesh in inches).
    pub scale: Option<f64>,
    /// Which face's label the die shows: "up" (most dice) or "down" (a d4).
    pub reads: Option<crate::model::shape::Reads>,
    /// The mesh's facets' labels: `{ normal = [0, 0, 1], label = "6" }`, one per resting
    /// facet (matched by its outward normal); none: numbered 1…N.
    pub labels: Option<Vec<LabelDef>>,
}

/// One facet's label in a die file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelDef {
    /// The facet's outward normal, body axes (any length).
    pub normal: [f64; 3],
    /// What it carries.
    pub label: String,
}

/// The largest die file read (TOML): 1 MiB.
pub const MAX_DIE_FILE: u64 = 1 << 20;

/// True if `path` names a mesh by its extension (.obj, .stl).
pub fn is_mesh(path: &std::path::Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("obj") || e.eq_ignore_ascii_case("stl"))
}

impl DieFile {
    /// Reads and parses a die file, through the capped reader (`run::io::read_capped`: a
    /// missing file, a directory, a pipe or a file over 1 MiB is refused naming `--die`, and a
    /// stop request is honoured while it blocks): a key it does not know, a value of the
    /// wrong kind, or a file that is not TOML is one line naming it. A mesh (.obj, .stl)
    /// describes no features: its die file is empty.
    pub fn read(path: &std::path::Path) -> Result<DieFile> {
        if is_mesh(path) {
            return Ok(DieFile::default());
        }
        let bytes = read_die_bytes(path, MAX_DIE_FILE)?;
        let text = String::from_utf8(bytes).map_err(|_| {
            Error::field(
                Field::Die,
                path.display(),
                "is not a text file (a die file is TOML; a mesh is .obj or .stl)",
            )
        })?;
        toml::from_str(&text).map_err(|e| {
            let line = e
                .span()
                .map(|s| format!(" (line {})", text[..s.start].matches('\n').count() + 1))
                .unwrap_or_default();
            Error::Invalid(format!(
                "die file {}{line}: {}",
                path.display(),
                e.message().trim()
            ))
        })
    }

    /// The features it describes, lengths in metres; a face map that is not a permutation of
    /// 1 to 6, or given beside `layout`, is refused.
    pub fn features(&self) -> Result<Features> {
        let layout = match (&self.faces, self.layout) {
            (Some(_), Some(_)) => {
                return Err(Error::field(
                    Field::Faces,
                    "",
                    "give either a layout or a face map, not both",
                ))
            }
            (Some(map), None) => Layout::from_map(map)?,
            (None, l) => l.unwrap_or_default(),
        };
        let mm = |c: [f64; 3]| c.map(|x| x / 1000.0);
        Ok(Features {
            com: self.com.map(mm),
            pips: self.pips.as_ref().map(|p| Pips {
                diameter: p.diameter / 1000.0,
                depth: p.depth / 1000.0,
                ..*p
            }),
            edge_radius: self.edge_radius.unwrap_or(0.0) / 1000.0,
            layout,
            insert: self.insert.map(|i| Insert {
                size: mm(i.size),
                centre: mm(i.centre),
                density: i.density,
            }),
            // g mm² = 10⁻³ kg × 10⁻⁶ m².
            inertia: self.inertia.map(|t| t.map(|x| x * 1e-9)),
        })
    }
}

/// A die file's bytes, at most `max`, through the capped reader; any failure names `--die`.
pub fn read_die_bytes(path: &std::path::Path, max: u64) -> Result<Vec<u8>> {
    if path.is_dir() {
        return Err(Error::field(Field::Die, path.display(), "is a directory"));
    }
    crate::run::io::read_capped(path, max, crate::run::stop::Stop::global()).map_err(|e| match e {
        Error::Stopped => Error::Stopped,
        Error::Invalid(m) => Error::field(
            Field::Die,
            path.display(),
            m.strip_prefix(&format!("{}: ", path.display()))
                .unwrap_or(&m)
                .to_string(),
        ),
        e => e,
    })
}

impl Features {
    /// A die as the command line and the Python package describe it: a die file's, if one is
    /// named, with a centre of mass, pips' diameter and depth and an edge radius given in mm
    /// laid over it ([`Features::with_mm`]), and a layout over the file's where the die has
    /// pips for it to place (a plain die's numbers are the summary's business, not its
    /// mass's). Returns the features and the density given (`density`, else the file's).
    pub fn described(
        file: Option<&std::path::Path>,
        com: Option<[f64; 3]>,
        pips: Option<[f64; 2]>,
        edge_radius: Option<f64>,
        layout: Option<Layout>,
        density: Option<f64>,
    ) -> Result<(Features, Option<f64>)> {
        let file = match file {
            Some(path) => DieFile::read(path)?,
            None => DieFile::default(),
        };
        let mut f = file.features()?.with_mm(com, pips, edge_radius);
        if let (Some(l), Some(_)) = (layout, f.pips) {
            f.layout = l;
        }
        Ok((f, density.or(file.density)))
    }

    /// These features with the ones given in mm (the command line's and the Python
    /// package's units) laid over them: a centre of mass, pips' diameter and depth (on the
    /// pips already here, keeping their shape, paint and spacing, or as empty caps), an edge
    /// radius.
    pub fn with_mm(
        mut self,
        com: Option<[f64; 3]>,
        pips: Option<[f64; 2]>,
        edge_radius: Option<f64>,
    ) -> Features {
        if let Some(c) = com {
            self.com = Some(c.map(|x| x / 1000.0));
        }
        if let Some([d, h]) = pips {
            let (d, h) = (d / 1000.0, h / 1000.0);
            self.pips = Some(match self.pips.take() {
                Some(p) => Pips {
                    diameter: d,
                    depth: h,
                    ..p
                },
                None => Pips::caps(d, h),
            });
        }
        if let Some(r) = edge_radius {
            self.edge_radius = r / 1000.0;
        }
        self
    }

    /// These features with the centre of mass on `axis` (0 x, 1 y, 2 z) given outright at `m`
    /// metres from the geometric centre, its other components the ones given, else 0.
    pub fn with_com_on(mut self, axis: usize, m: f64) -> Features {
        let mut c = self.com.unwrap_or([0.0; 3]);
        c[axis] = m;
        self.com = Some(c);
        self
    }

    /// These features with the pips `m` metres deep; `None` if the die has no pips.
    pub fn with_pip_depth(mut self, m: f64) -> Option<Features> {
        self.pips.as_mut()?.depth = m;
        Some(self)
    }

    /// True if nothing is set, not even the layout.
    pub fn is_default(&self) -> bool {
        *self == Features::default()
    }

    /// True if the die is the paper's ideal block.
    pub fn plain(&self) -> bool {
        self.com.is_none()
            && self.pips.is_none()
            && self.edge_radius == 0.0
            && self.insert.is_none()
            && self.inertia.is_none()
    }

    /// Checks the features against the die's half sides: one line naming the field.
    pub fn validate(&self, half: &Vector3<f64>, mode: Mode) -> Result<()> {
        if self.plain() {
            return Ok(());
        }
        if mode == Mode::TwoD {
            return Err(Error::Invalid(
                "a centre of mass off the centre, pips and rounded edges are modelled in 3D only \
                 (2D is the paper's ideal block): roll it in 3D"
                    .into(),
            ));
        }
        let mm = shown_mm;
        let min_half = half.min();
        let r = self.edge_radius;
        if !(r.is_finite() && r >= 0.0 && r < min_half) {
            return Err(Error::field(
                Field::EdgeRadius,
                mm(r),
                format!(
                    "must be at least 0 and under half the shortest side ({} mm)",
                    mm(min_half)
                ),
            ));
        }
        if let Some(c) = self.com {
            let c = Vector3::from(c);
            // Inside the rounded box: within r of the inner box of half sides h − r.
            let out = (c.abs() - half.map(|h| h - r)).map(|x| x.max(0.0)).norm();
            let inside = if r > 0.0 {
                out < r
            } else {
                (c.abs() - half).max() < 0.0
            };
            if !(c.iter().all(|x| x.is_finite()) && inside) {
                return Err(Error::field(
                    Field::Com,
                    format!("{},{},{}", mm(c.x), mm(c.y), mm(c.z)),
                    "must lie inside the die (mm from its centre, body axes)",
                ));
            }
        }
        if let Some(p) = &self.pips {
            self.validate_pips(p, half)?;
        }
        if let Some(i) = &self.insert {
            self.validate_insert(i, half)?;
        }
        if let Some(t) = self.inertia {
            validate_inertia(t)?;
        }
        Ok(())
    }

    /// Checks the features on a die of any shape: pips and rounded edges are the cuboid's
    /// (refused, with the reason); a centre of mass and an insert inside its hull.
    pub fn validate_on(&self, shape: &crate::model::shape::Shape, mode: Mode) -> Result<()> {
        let mm = shown_mm;
        let triple = |v: [f64; 3]| format!("{},{},{}", mm(v[0]), mm(v[1]), mm(v[2]));
        if mode == Mode::TwoD {
            return Err(Error::field(
                Field::Shape,
                &shape.name,
                "a die of any shape is rolled in 3D only (2D is the paper's block)",
            ));
        }
        if self.pips.is_some() {
            return Err(Error::field(
                Field::PipsDiameter,
                "",
                "pips are drilled in a cuboid's faces (the standard pattern); a die of another \
                 shape carries its mass as its mesh gives it",
            ));
        }
        if self.edge_radius != 0.0 {
            return Err(Error::field(
                Field::EdgeRadius,
                mm(self.edge_radius),
                "rounded edges are the cuboid's; round a mesh's edges in the mesh itself",
            ));
        }
        if let Some(c) = self.com {
            if !(c.iter().all(|x| x.is_finite()) && shape.contains(&Vector3::from(c))) {
                return Err(Error::field(
                    Field::Com,
                    triple(c),
                    "must lie inside the die (mm from its centroid, body axes)",
                ));
            }
        }
        if let Some(i) = &self.insert {
            let corners_inside = (0..8).all(|n| {
                let corner = Vector3::from_fn(|k, _| {
                    let sign = if n >> k & 1 == 1 { 0.5 } else { -0.5 };
                    i.centre[k] + sign * i.size[k]
                });
                shape.contains(&corner)
            });
            if !(i.size.iter().all(|s| s.is_finite() && *s > 0.0) && corners_inside) {
                return Err(Error::field(
                    Field::InsertCentre,
                    triple(i.centre),
                    "the insert must lie inside the die (mm from its centroid)",
                ));
            }
            if !(i.density.is_finite() && (0.0..=1e5).contains(&i.density)) {
                return Err(Error::field(
                    Field::InsertDensity,
                    i.density,
                    "must be in [0, 100000] kg/m³",
                ));
            }
        }
        if let Some(t) = self.inertia {
            validate_inertia(t)?;
        }
        Ok(())
    }

    /// The pips: a positive diameter, a depth a cap or cylinder can have, paint and spacing in
    /// range, every pip inside its face (clear of the rounding) and apart from the others.
    fn validate_pips(&self, p: &Pips, half: &Vector3<f64>) -> Result<()> {
        let mm = shown_mm;
        let min_half = half.min();
        let r = self.edge_radius;
        let bad = |field: Field, v: f64, why: String| Err(Error::field(field, mm(v), why));
        if !(p.diameter.is_finite() && p.diameter > 0.0) {
            return bad(
                Field::PipsDiameter,
                p.diameter,
                "must be a positive number of mm".into(),
            );
        }
        let deepest = match p.shape {
            PipShape::Cap => 0.5 * p.diameter,
            PipShape::Cylinder => min_half,
        };
        if !(p.depth.is_finite() && p.depth > 0.0 && p.depth <= deepest && p.depth < min_half) {
            return bad(
                Field::PipsDepth,
                p.depth,
                format!(
                    "must be positive, at most {} mm ({})",
                    mm(deepest.min(min_half)),
                    match p.shape {
                        PipShape::Cap => "a cap is at most a hemisphere",
                        PipShape::Cylinder => "under half the shortest side",
                    }
                ),
            );
        }
        if !(p.fill_density.is_finite() && (0.0..=1e5).contains(&p.fill_density)) {
            return Err(Error::field(
                Field::PipsFillDensity,
                p.fill_density,
                "must be in [0, 100000] kg/m³",
            ));
        }
        if !(p.spacing.is_finite() && p.spacing > 0.0 && p.spacing < 0.5) {
            return Err(Error::field(
                Field::PipsSpacing,
                p.spacing,
                "must be in (0, 0.5): a fraction of the face's side",
            ));
        }
        let places = pip_places(half, p, self.layout);
        let rad = 0.5 * p.diameter;
        for &(i, _, pj, pk) in &places {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            if pj.abs() + rad > half[j] - r || pk.abs() + rad > half[k] - r {
                return bad(
                    Field::PipsDiameter,
                    p.diameter,
                    "pips cross an edge of their face (or its rounding): smaller pips or a smaller spacing".into(),
                );
            }
        }
        for (n, a) in places.iter().enumerate() {
            for b in &places[n + 1..] {
                if a.0 == b.0 && a.1 == b.1 && (a.2 - b.2).hypot(a.3 - b.3) <= p.diameter {
                    return bad(
                        Field::PipsDiameter,
                        p.diameter,
                        "pips on a face overlap each other: smaller pips or a larger spacing"
                            .into(),
                    );
                }
            }
        }
        Ok(())
    }

    /// The insert: positive sizes, inside the die clear of its rounding and pips, a density in
    /// range.
    fn validate_insert(&self, i: &Insert, half: &Vector3<f64>) -> Result<()> {
        let mm = shown_mm;
        let r = self.edge_radius;
        // Clear of the rounding and of the pips' cavities: inside the box whose faces
        // lie the larger of the two inside the die's.
        let skin = r.max(self.pips.map_or(0.0, |p| p.depth));
        let triple = |v: [f64; 3]| format!("{},{},{}", mm(v[0]), mm(v[1]), mm(v[2]));
        if !(i.size.iter().all(|s| s.is_finite() && *s > 0.0)) {
            return Err(Error::field(
                Field::InsertSize,
                triple(i.size),
                "must be three positive lengths, mm",
            ));
        }
        let inside = (0..3).all(|k| {
            i.centre[k].is_finite() && i.centre[k].abs() + 0.5 * i.size[k] <= half[k] - skin
        });
        if !inside {
            return Err(Error::field(
                Field::InsertCentre,
                triple(i.centre),
                format!(
                    "the insert must lie inside the die, clear of its rounding and pips \
                     (within {} mm of each face)",
                    mm(skin)
                ),
            ));
        }
        if !(i.density.is_finite() && (0.0..=1e5).contains(&i.density)) {
            return Err(Error::field(
                Field::InsertDensity,
                i.density,
                "must be in [0, 100000] kg/m³",
            ));
        }
        Ok(())
    }
}

/// An inertia given outright: finite, positive definite, and each principal moment at most
/// the sum of the other two (as every solid's).
fn validate_inertia(t: [f64; 6]) -> Result<()> {
    let [xx, yy, zz, xy, xz, yz] = t;
    let m = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let e = SymmetricEigen::new(m).eigenvalues;
    let physical = t.iter().all(|x| x.is_finite())
        && e.iter().all(|&x| x > 0.0)
        && (0..3).all(|k| e[k] <= e[(k + 1) % 3] + e[(k + 2) % 3]);
    if !physical {
        return Err(Error::field(
            Field::Inertia,
            t.map(|x| format!("{}", x * 1e9)).join(","),
            "no solid has this inertia: its principal moments must be positive and \
             each at most the sum of the other two (g mm²: xx, yy, zz, xy, xz, yz)",
        ));
    }
    Ok(())
}

/// What a die's mass properties depend on: its body's sides (x, y, z; in 2D the 1 m depth),
/// its density, its plain mass as the engines multiply it, 2D or 3D, and its features
/// (`Scene::solid`).
#[derive(Clone, Copy, Debug)]
pub struct Solid<'a> {
    /// The body's sides along x, y, z, m.
    pub sides: [f64; 3],
    /// kg/m³.
    pub density: f64,
    /// The plain block's mass, as the engines compute it (`Scene::mass`).
    pub plain_mass: f64,
    /// 2D or 3D.
    pub mode: Mode,
    /// The die as made.
    pub features: &'a Features,
    /// A die of any shape (`model::shape`), in place of the block of `sides`.
    pub shape: Option<&'a crate::model::shape::Shape>,
}

impl MassProps {
    /// The mass properties of a die: a solid of its density, rounded with `edge_radius`, less
    /// its pips (plus their fill), with its centre of mass where `com` puts it if given. The
    /// plain block's are the closed forms the engines use. Checked.
    pub fn of_solid(s: &Solid) -> Result<MassProps> {
        let [a, b, c] = s.sides;
        match s.shape {
            Some(shape) => s.features.validate_on(shape, s.mode)?,
            None => s
                .features
                .validate(&(Vector3::new(a, b, c) / 2.0), s.mode)?,
        }
        let m = MassProps::compute_solid(s);
        let ok = m.moments.iter().all(|&x| x > 0.0)
            && (0..3).all(|i| m.moments[i] <= m.moments[(i + 1) % 3] + m.moments[(i + 2) % 3]);
        if !ok {
            let c = m.com * 1e3;
            return Err(Error::field(
                Field::Com,
                format!("{},{},{}", c.x, c.y, c.z),
                "is too far from the centre for this die's inertia (no solid has these moments)",
            ));
        }
        if let Some(t) = s.features.inertia {
            // Reliability round 5, class E: any solid's moment about an axis through its
            // centre of mass is at most m r², r the farthest any of its points lies from that
            // centre; far below it (a millionth) no engine here integrates the die.
            let reach = match s.shape {
                Some(shape) => shape.circumradius() + m.com.norm(),
                None => (Vector3::new(a, b, c) / 2.0).norm() + m.com.norm(),
            };
            let most = m.mass * reach * reach;
            if m.moments
                .iter()
                .any(|&x| x > most * (1.0 + 1e-9) || x < 1e-6 * most)
            {
                return Err(Error::field(
                    Field::Inertia,
                    t.map(|x| format!("{}", x * 1e9)).join(","),
                    format!(
                        "no die of this mass and size turns so: its principal moments must lie \
                         between a millionth of m·r² and m·r² = {:.4} g mm² (r = {:.3} mm, the \
                         farthest point from its centre of mass)",
                        most * 1e9,
                        reach * 1e3
                    ),
                ));
            }
        }
        Ok(m)
    }

    /// `of_solid` for a die already checked.
    pub fn compute_solid(s: &Solid) -> MassProps {
        let f = s.features;
        let [a, b, c] = s.sides;
        let half = Vector3::new(a, b, c) / 2.0;
        let rho = s.density;
        if f.plain() && s.shape.is_none() {
            let m = s.plain_mass;
            let inertia = Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (m / 12.0);
            return MassProps {
                mass: m,
                com: Vector3::zeros(),
                inertia: Matrix3::from_diagonal(&inertia),
                principal: UnitQuaternion::identity(),
                moments: inertia,
            };
        }
        let mut total = match s.shape {
            // A die of any shape: its solid's moments about its centroid.
            Some(shape) => Moments {
                mass: rho * shape.volume,
                first: Vector3::zeros(),
                second: shape.second_matrix() * rho,
            },
            None => {
                let (volume, second) = rounded_box(&half, f.edge_radius);
                Moments {
                    mass: rho * volume,
                    first: Vector3::zeros(),
                    second: Matrix3::from_diagonal(&(second * rho)),
                }
            }
        };
        if let Some(p) = &f.pips {
            let cav = cavity(p);
            for place in pip_places(&half, p, f.layout) {
                total.add(p.fill_density - rho, &pip_moments(&half, &cav, place));
            }
            // Where two cavities meet, the die lost that region once, not twice.
            total.add(rho - p.fill_density, &pip_overlaps(&half, p, f.layout));
        }
        if let Some(i) = &f.insert {
            total.add(i.density - rho, &i.moments());
        }
        let m = total.mass;
        let com = match f.com {
            Some(c) => Vector3::from(c),
            None => total.first / m,
        };
        // About the centre: I = tr(S) 1 − S; about the centre of mass (parallel axes):
        // I − m (|c|² 1 − c cᵀ).
        let s = total.second;
        let about_centre = Matrix3::identity() * s.trace() - s;
        let inertia = match f.inertia {
            Some([xx, yy, zz, xy, xz, yz]) => Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz),
            None => {
                about_centre
                    - m * (Matrix3::identity() * com.norm_squared() - com * com.transpose())
            }
        };
        let (principal, moments) = principal_frame(&inertia);
        MassProps {
            mass: m,
            com,
            inertia,
            principal,
            moments,
        }
    }
}

/// The principal frame and moments of a symmetric tensor: the identity and its diagonal
/// when it is diagonal already (so that an aligned die keeps its body axes exactly), else its
/// eigenvectors made a right-handed rotation.
fn principal_frame(t: &Matrix3<f64>) -> (UnitQuaternion<f64>, Vector3<f64>) {
    let off = t[(0, 1)].abs() + t[(0, 2)].abs() + t[(1, 2)].abs();
    if off == 0.0 {
        return (UnitQuaternion::identity(), t.diagonal());
    }
    let e = SymmetricEigen::new(*t);
    let mut v = e.eigenvectors;
    if v.determinant() < 0.0 {
        v.column_mut(2).neg_mut();
    }
    let r = Rotation3::from_matrix_unchecked(v);
    (UnitQuaternion::from_rotation_matrix(&r), e.eigenvalues)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::block::Block;
    use crate::model::scene::Scene;

    fn cube_scene(side_mm: f64) -> Scene {
        let b = Block::from_mm(side_mm, side_mm, side_mm).unwrap();
        Scene::paper(b, Mode::ThreeD)
    }

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn a_rounded_box_is_a_box_at_radius_zero_and_a_ball_at_the_largest() {
        let a = Vector3::new(0.012, 0.010, 0.07);
        let (v, s) = rounded_box(&a, 0.0);
        assert!(rel(v, 8.0 * a.x * a.y * a.z) < 1e-15);
        for i in 0..3 {
            // ∫xᵢ² dV = V aᵢ²/3.
            assert!(rel(s[i], v * a[i] * a[i] / 3.0) < 1e-14);
        }
        let r = 0.008;
        let (v, s) = rounded_box(&Vector3::repeat(r), r);
        assert!(rel(v, 4.0 * PI * r.powi(3) / 3.0) < 1e-15);
        for i in 0..3 {
            assert!(rel(s[i], 4.0 * PI * r.powi(5) / 15.0) < 1e-14);
        }
    }

    #[test]
    fn a_rounded_box_matches_a_fine_quadrature() {
        // A midpoint sum over a fine grid of the inside test: slow but independent.
        let a = Vector3::new(0.008, 0.007, 0.006);
        let r = 0.002;
        let (v, s) = rounded_box(&a, r);
        let n = 240;
        let (mut qv, mut qs) = (0.0, Vector3::zeros());
        let h = a * 2.0 / n as f64;
        for ix in 0..n {
            for iy in 0..n {
                for iz in 0..n {
                    let p = Vector3::new(
                        -a.x + (ix as f64 + 0.5) * h.x,
                        -a.y + (iy as f64 + 0.5) * h.y,
                        -a.z + (iz as f64 + 0.5) * h.z,
                    );
                    let out = (p.abs() - a.map(|x| x - r)).map(|x| x.max(0.0)).norm();
                    if out <= r {
                        let dv = h.x * h.y * h.z;
                        qv += dv;
                        qs += p.component_mul(&p) * dv;
                    }
                }
            }
        }
        // The grid resolves the curved boundary to about h/a ≈ 1/n in volume.
        assert!(rel(qv, v) < 2e-3, "{qv} {v}");
        for i in 0..3 {
            assert!(rel(qs[i], s[i]) < 3e-3, "{i}");
        }
    }

    #[test]
    fn a_caps_moments_are_the_textbook_ones() {
        for (d, h) in [
            (0.003, 0.0015),
            (0.003, 0.0005),
            (0.002, 0.00001),
            (0.004, 0.001),
        ] {
            let p = Pips {
                diameter: d,
                depth: h,
                shape: PipShape::Cap,
                fill_density: 0.0,
                spacing: 0.25,
            };
            let [v, z1, z2, u2] = cavity(&p);
            let rho = ((d / 2.0) * (d / 2.0) + h * h) / (2.0 * h);
            // V = πh²(3ρ − h)/3; centroid 3(2ρ − h)²/(4(3ρ − h)) from the ball's centre.
            let want_v = PI * h * h * (3.0 * rho - h) / 3.0;
            assert!(rel(v, want_v) < 1e-12, "{d} {h}");
            let from_centre = 3.0 * (2.0 * rho - h).powi(2) / (4.0 * (3.0 * rho - h));
            // z is measured inward from the face, which is ρ − h from the ball's centre.
            assert!(rel(z1 / v, from_centre - (rho - h)) < 1e-9, "{d} {h}");
            let _ = (z2, u2);
        }
        // A hemisphere: about the centre of its flat face, ∫(u² + w²) dV = (2/5) V ρ² (half a
        // ball's), and ∫z² dV = ∫u² dV = V ρ²/5.
        let r = 0.0015;
        let p = Pips {
            diameter: 2.0 * r,
            depth: r,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: 0.25,
        };
        let [v, _, z2, u2] = cavity(&p);
        assert!(rel(v, 2.0 * PI * r.powi(3) / 3.0) < 1e-14);
        assert!(rel(z2, v * r * r / 5.0) < 1e-13);
        assert!(rel(u2, v * r * r / 5.0) < 1e-13);
        // A cylinder: V = π a² h, ∫z dV = V h/2, ∫z² dV = V h²/3, ∫u² dV = V a²/4.
        let p = Pips {
            diameter: 0.003,
            depth: 0.001,
            shape: PipShape::Cylinder,
            fill_density: 0.0,
            spacing: 0.25,
        };
        let [v, z1, z2, u2] = cavity(&p);
        let a = 0.0015;
        assert!(rel(v, PI * a * a * 0.001) < 1e-14);
        assert!(rel(z1, v * 0.0005) < 1e-14);
        assert!(rel(z2, v * 1e-6 / 3.0) < 1e-13);
        assert!(rel(u2, v * a * a / 4.0) < 1e-13);
    }

    #[test]
    fn a_plain_die_has_the_boxes_mass_properties_and_a_moved_centre_the_parallel_axes() {
        let mut s = cube_scene(16.0);
        let plain = MassProps::of(&s).unwrap();
        assert!(plain.aligned() && plain.com == Vector3::zeros());
        // Rounded with radius 0 by the general path: the same to rounding.
        s.features.com = Some([0.0, 0.0, 0.0]);
        let general = MassProps::of(&s).unwrap();
        assert!(rel(general.mass, plain.mass) < 1e-15);
        for i in 0..3 {
            assert!(rel(general.moments[i], plain.moments[i]) < 1e-14);
        }
        // A centre 2 mm down z: I_xx and I_yy less m c², I_zz unchanged, axes kept.
        s.features.com = Some([0.0, 0.0, -0.002]);
        let moved = MassProps::of(&s).unwrap();
        assert!(moved.aligned());
        let m = plain.mass;
        assert!(rel(moved.moments.x, plain.moments.x - m * 4e-6) < 1e-14);
        assert!(rel(moved.moments.z, plain.moments.z) < 1e-14);
    }

    /// Overlapping pips (reliability round 5, class C), against an independent integral: one
    /// random point in each cell of a 160³ grid over the whole 16 mm cube (stratified, so
    /// that no lattice lines up with the pips' circles; ~5e-5 of the mass at 1σ), each kept
    /// unless inside a pip, the cavities written out here from their description (a cylinder,
    /// or a ball's cap below each pip's circle). Deep cylinders meeting in threes at the corners lose 3.5 % of the
    /// cube counted twice; caps at a wide spacing, 0.07 %.
    #[test]
    fn overlapping_pips_take_away_their_union() {
        for (shape, d, h, spacing) in [
            (PipShape::Cylinder, 0.003, 0.005, 0.25),
            (PipShape::Cap, 0.0016, 0.0008, 0.45),
        ] {
            let mut s = cube_scene(16.0);
            let p = Pips {
                diameter: d,
                depth: h,
                shape,
                fill_density: 0.0,
                spacing,
            };
            s.features.pips = Some(p);
            let m = MassProps::of(&s).unwrap();
            let half = Vector3::repeat(0.008);
            let places = pip_places(&half, &p, Layout::Right);
            let rho_ball = (0.25 * d * d + h * h) / (2.0 * h);
            let hollow = |x: &Vector3<f64>| {
                places.iter().any(|&(i, sign, pj, pk)| {
                    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                    let depth = 0.008 - sign * x[i];
                    let r2 = (x[j] - pj).powi(2) + (x[k] - pk).powi(2);
                    (0.0..=h).contains(&depth)
                        && match shape {
                            PipShape::Cylinder => r2 <= 0.25 * d * d,
                            // The ball's centre ρ beyond the pip's bottom, inward.
                            PipShape::Cap => {
                                r2 + (depth - (h - rho_ball)).powi(2) <= rho_ball * rho_ball
                            }
                        }
                })
            };
            use rand::{Rng, SeedableRng};
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
            let n = 160;
            let cell = 0.016 / n as f64;
            let (mut mass, mut first, mut second) = (0.0, Vector3::zeros(), Matrix3::zeros());
            for c in 0..n * n * n {
                let x = Vector3::new(c % n, (c / n) % n, c / (n * n))
                    .map(|i| (i as f64 + rng.random::<f64>()) * cell - 0.008);
                if !hollow(&x) {
                    let w = s.density * cell.powi(3);
                    mass += w;
                    first += x * w;
                    second += x * x.transpose() * w;
                }
            }
            let com = first / mass;
            let about = Matrix3::identity() * second.trace() - second;
            let inertia =
                about - mass * (Matrix3::identity() * com.norm_squared() - com * com.transpose());
            // About 4σ of the stratified sum.
            assert!(
                rel(m.mass, mass) < 2e-4,
                "{shape:?}: {} against {mass}",
                m.mass
            );
            assert!(
                (m.com - com).norm() < 2e-6,
                "{shape:?}: {:?} against {com:?}",
                m.com
            );
            assert!(
                (m.inertia - inertia).norm() < 1e-3 * inertia.norm(),
                "{shape:?}: {} against {}",
                m.inertia,
                inertia
            );
            let counted_twice = s.mass() - 21.0 * cavity(&p)[0] * s.density;
            assert!(
                mass > counted_twice,
                "{shape:?}: the overlaps are there to give back"
            );
        }
    }

    #[test]
    fn pips_lighten_the_die_by_their_volume_and_move_its_centre_toward_one() {
        let mut s = cube_scene(16.0);
        let p = Pips {
            diameter: 0.003,
            depth: 0.001,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: 0.25,
        };
        s.features.pips = Some(p);
        let m = MassProps::of(&s).unwrap();
        let v = cavity(&p)[0];
        let solid = s.mass();
        assert!(rel(m.mass, solid - 21.0 * v * s.density) < 1e-14);
        // Face n has n pips: the centre of mass moves toward the faces with fewer, each axis
        // by (pips on − face − pips on + face) × V × (h − z̄) / m... in sign: toward 1 (+z),
        // 2 (+x), 3 (+y), the faces opposite 6, 5, 4.
        assert!(
            m.com.x > 0.0 && m.com.y > 0.0 && m.com.z > 0.0,
            "{:?}",
            m.com
        );
        let [vv, z1, _, _] = cavity(&p);
        let h = 0.008;
        // Along z: 1 pip on +z, 6 on −z: Σ m x = −ρ (1·(h V − z̄V) − 6·(h V − z̄V)).
        let want_z = s.density * 5.0 * (h * vv - z1) / m.mass;
        assert!(rel(m.com.z, want_z) < 1e-12, "{} {want_z}", m.com.z);
        // The diagonal pips of 2 and 3 tilt the principal frame off the body axes.
        assert!(!m.aligned());
        let back = m.principal.to_rotation_matrix().matrix()
            * Matrix3::from_diagonal(&m.moments)
            * m.principal.to_rotation_matrix().matrix().transpose();
        assert!((back - m.inertia).norm() < 1e-12 * m.inertia.norm());
        // Filled with the die's own density, nothing is drilled.
        s.features.pips = Some(Pips {
            fill_density: s.density,
            ..p
        });
        let full = MassProps::of(&s).unwrap();
        assert!(rel(full.mass, solid) < 1e-15 && full.com.norm() < 1e-18);
    }

    #[test]
    fn an_insert_moves_the_centre_and_the_moments_as_two_boxes_do() {
        // A 16 mm cube (a = 8 mm half side) of density ρ with a cube of side b = 4 mm and
        // density ρ' at c = (0, 0, −4 mm): in closed form, with Δ = (ρ' − ρ) b³,
        // m = ρ (2a)³ + Δ, z̄ = Δ c / m, and about the geometric centre
        // I_xx = ρ (2a)⁵/6 + Δ (b²/6 + c²), I_zz = ρ (2a)⁵/6 + Δ b²/6; about the centre of mass
        // I_xx − m z̄², I_zz unchanged.
        let mut s = cube_scene(16.0);
        let (rho, rho2, side, b, c) = (s.density, 19300.0, 0.016, 0.004, -0.004);
        s.features.insert = Some(Insert {
            size: [b; 3],
            centre: [0.0, 0.0, c],
            density: rho2,
        });
        let m = MassProps::of(&s).unwrap();
        let delta = (rho2 - rho) * b * b * b;
        let mass = rho * side * side * side + delta;
        let zbar = delta * c / mass;
        let ixx = rho * side.powi(5) / 6.0 + delta * (b * b / 6.0 + c * c) - mass * zbar * zbar;
        let izz = rho * side.powi(5) / 6.0 + delta * b * b / 6.0;
        assert!(rel(m.mass, mass) < 1e-14, "{} {mass}", m.mass);
        assert!(rel(m.com.z, zbar) < 1e-13 && m.com.x == 0.0 && m.com.y == 0.0);
        assert!(m.aligned());
        assert!(rel(m.moments.x, ixx) < 1e-13 && rel(m.moments.y, ixx) < 1e-13);
        assert!(rel(m.moments.z, izz) < 1e-13);
        // Of the die's own density: the plain cube.
        s.features.insert = Some(Insert {
            density: rho,
            ..s.features.insert.unwrap()
        });
        let same = MassProps::of(&s).unwrap();
        assert!(rel(same.mass, rho * side.powi(3)) < 1e-15 && same.com.norm() < 1e-18);
        // Off every axis: the principal frame turns off the body's.
        s.features.insert = Some(Insert {
            size: [b; 3],
            centre: [0.001, 0.001, c],
            density: rho2,
        });
        assert!(!MassProps::of(&s).unwrap().aligned());
    }

    #[test]
    fn an_inertia_given_outright_is_the_bodys() {
        let mut s = cube_scene(16.0);
        // A tensor with a product of inertia: its principal moments are its eigenvalues.
        let t = [2.2e-7, 2.0e-7, 1.8e-7, 0.1e-7, 0.0, 0.0];
        s.features.inertia = Some(t);
        let m = MassProps::of(&s).unwrap();
        assert_eq!(m.inertia[(0, 1)], 0.1e-7);
        assert_eq!(m.inertia[(2, 2)], 1.8e-7);
        let mut moments: Vec<f64> = m.moments.iter().copied().collect();
        moments.sort_by(f64::total_cmp);
        // The xy block's eigenvalues 2.1e-7 ± √(0.1² + 0.1²)e-7, and 1.8e-7.
        let r = 0.02f64.sqrt() * 1e-7;
        for (got, want) in moments.iter().zip([1.8e-7, 2.1e-7 - r, 2.1e-7 + r]) {
            assert!(rel(*got, want) < 1e-12, "{got} {want}");
        }
        assert!(!m.aligned());
        // No solid has moments that break the triangle inequality.
        s.features.inertia = Some([1e-7, 1e-7, 3e-7, 0.0, 0.0, 0.0]);
        assert!(MassProps::of(&s)
            .unwrap_err()
            .to_string()
            .contains("no solid has this inertia"));
    }

    #[test]
    fn bad_dice_are_refused_by_field() {
        let half = Vector3::repeat(0.008);
        let field = |f: Features| match f.validate(&half, Mode::ThreeD) {
            Err(Error::Field { field, .. }) => field.name(),
            other => panic!("{other:?}"),
        };
        let pips = |d: f64, h: f64| {
            Some(Pips {
                diameter: d,
                depth: h,
                shape: PipShape::Cap,
                fill_density: 0.0,
                spacing: 0.25,
            })
        };
        assert_eq!(
            field(Features {
                edge_radius: 0.008,
                ..Default::default()
            }),
            "edge_radius"
        );
        assert_eq!(
            field(Features {
                edge_radius: -1e-3,
                ..Default::default()
            }),
            "edge_radius"
        );
        assert_eq!(
            field(Features {
                com: Some([0.0, 0.0, 0.009]),
                ..Default::default()
            }),
            "com"
        );
        assert_eq!(
            field(Features {
                com: Some([0.0, f64::NAN, 0.0]),
                ..Default::default()
            }),
            "com"
        );
        // Inside the sharp box's corner but outside the rounded one.
        assert_eq!(
            field(Features {
                com: Some([0.0079, 0.0079, 0.0079]),
                edge_radius: 0.002,
                ..Default::default()
            }),
            "com"
        );
        assert_eq!(
            field(Features {
                pips: pips(0.003, 0.002),
                ..Default::default()
            }),
            "pips.depth"
        );
        // 5 mm pips 4 mm apart overlap; 7 mm pips at 4 mm from the centre cross the edge.
        assert_eq!(
            field(Features {
                pips: pips(0.0045, 0.001),
                ..Default::default()
            }),
            "pips.diameter"
        );
        assert_eq!(
            field(Features {
                pips: pips(-1.0, 0.001),
                ..Default::default()
            }),
            "pips.diameter"
        );
        assert!(Features {
            pips: pips(0.003, 0.001),
            edge_radius: 0.001,
            ..Default::default()
        }
        .validate(&half, Mode::ThreeD)
        .is_ok());
        assert!(Features {
            com: Some([0.0, 0.0, 0.001]),
            ..Default::default()
        }
        .validate(&half, Mode::TwoD)
        .is_err());
    }
}
