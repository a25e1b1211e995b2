//! Convex-die geometry and exact mass properties.
//!
//! A die is a closed triangle mesh ([`Mesh`], triangles counter-clockwise seen from outside).
//! From it this module computes
//!
//! * its volume, centroid and inertia tensor about the centroid per unit density
//!   ([`Mesh::mass_properties`]), exactly, by the polyhedral volume integrals: the solid is cut
//!   into signed tetrahedra from a reference point, and each tetrahedron's integrals have closed
//!   forms (below). Non-convex meshes are allowed;
//! * its convex hull ([`hull`], by parry3d-f64's quickhull), the faces of a convex mesh with
//!   their coplanar triangles merged ([`facets`]), and whether a die resting on a face is in
//!   equilibrium ([`stable`]);
//! * the named dice of a games table ([`named`]: d4, d6, d8, d10, d12, d20 and N-gon prisms),
//!   with the label of each face, and a coin ([`Cylinder`]).
//!
//! Where parry3d-f64 is used, and where not: parry computes the convex hull ([`hull`]) only.
//! The mass properties are ours, in closed form, so that they can be tested against closed forms
//! to 1e-12; the tests compare them with parry's `MassProperties::from_trimesh` as a second
//! opinion (parry returns principal moments and a rotation, not the tensor in the mesh's axes).
//!
//! The module is unit-free: lengths are in whatever unit the caller uses (mm or m,
//! consistently), and mass properties are per unit density (mass = volume). The one exception
//! is the default size of a named die (`size: None`), which is in millimetres.
//!
//! Errors are `Result<_, String>`: one line saying what is wrong and where.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Default angle (radians) within which the normals of two adjacent triangles count as the same
/// face in [`facets`]. Large enough for a mesh read from an STL file (single-precision
/// coordinates: a 1 mm triangle on a 20 mm die tilts by ~1e-6 rad from rounding alone), small
/// enough for any real die (adjacent faces differ by more than 0.3 rad) and for a 20 000-gon
/// prism (sides 3e-4 rad apart).
pub const COPLANAR_TOLERANCE: f64 = 1e-5;

/// A closed triangle mesh: `triangles` index `vertices`, each counter-clockwise seen from
/// outside (so that the right-hand normal points outward).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The corners, in the caller's length unit.
    pub vertices: Vec<Vector3<f64>>,
    /// Each triangle's three vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
}

/// Volume, centroid and inertia tensor about the centroid, per unit density (so the mass is the
/// volume and the inertia is in length⁵).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps {
    /// The volume (length³), which is the mass at unit density.
    pub volume: f64,
    /// The centroid of the volume (centre of mass at uniform density).
    pub centroid: Vector3<f64>,
    /// About the centroid, in the mesh's axes, unit density.
    pub inertia: Matrix3<f64>,
}

impl MassProps {
    /// The principal moments of inertia in ascending order, and the principal axes (unit
    /// columns, in the same order).
    pub fn principal(&self) -> (Vector3<f64>, Matrix3<f64>) {
        let eig = SymmetricEigen::new(self.inertia);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        let moments = Vector3::from_fn(|i, _| eig.eigenvalues[order[i]]);
        let axes = Matrix3::from_fn(|r, c| eig.eigenvectors[(r, order[c])]);
        (moments, axes)
    }
}

impl Mesh {
    /// Checks that the mesh bounds a solid: finite coordinates, indices in range, no degenerate
    /// (zero-area: twice its area at most 1e-12 × its longest edge squared) triangle, every edge
    /// used by exactly two triangles, once in each direction
    /// (closed and consistently oriented), and a positive signed volume (outward normals).
    /// The error names the first offending vertex, triangle or edge (in triangle order).
    /// Vertices that no triangle uses are allowed (they must still be finite).
    pub fn check(&self) -> Result<(), String> {
        let n = self.vertices.len();
        if self.triangles.len() < 4 {
            return Err(format!(
                "the mesh has {} triangle(s): a closed surface needs at least 4",
                self.triangles.len()
            ));
        }
        if let Some((i, v)) = self
            .vertices
            .iter()
            .enumerate()
            .find(|(_, v)| !v.iter().all(|c| c.is_finite()))
        {
            return Err(format!(
                "vertex {i} has a non-finite coordinate ({}, {}, {})",
                v.x, v.y, v.z
            ));
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&k) = tri.iter().find(|&&k| k >= n) {
                return Err(format!(
                    "triangle {t} refers to vertex {k}, but the mesh has {n} vertices"
                ));
            }
            let [a, b, c] = *tri;
            if a == b || b == c || c == a {
                return Err(format!(
                    "triangle {t} (vertices {a}, {b}, {c}) repeats a vertex: it has zero area"
                ));
            }
            let (pa, pb, pc) = (self.vertices[a], self.vertices[b], self.vertices[c]);
            let longest = (pb - pa)
                .norm_squared()
                .max((pc - pb).norm_squared())
                .max((pa - pc).norm_squared());
            // Twice the area against the squared longest edge: a triangle whose height is below
            // 1e-12 of its length is numerically a segment (its normal is noise).
            if (pb - pa).cross(&(pc - pa)).norm() <= 1e-12 * longest {
                return Err(format!(
                    "triangle {t} (vertices {a}, {b}, {c}) has zero area: its corners are collinear"
                ));
            }
        }

        // Undirected edge -> the triangles using it, with the direction each uses it in.
        let mut edges: HashMap<(usize, usize), Vec<(usize, bool)>> = HashMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                edges
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((t, a < b));
            }
        }
        for tri in &self.triangles {
            for e in 0..3 {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                let users = &edges[&(a.min(b), a.max(b))];
                match users.len() {
                    2 if users[0].1 == users[1].1 => {
                        return Err(format!(
                            "edge {a}–{b} runs the same way in triangles {} and {}: the mesh is \
                             not consistently oriented (one of them is flipped)",
                            users[0].0, users[1].0
                        ));
                    }
                    2 => {}
                    1 => {
                        return Err(format!(
                            "edge {a}–{b} belongs to 1 triangle (triangle {}): the mesh is not \
                             closed",
                            users[0].0
                        ));
                    }
                    k => {
                        let list: Vec<String> = users.iter().map(|u| u.0.to_string()).collect();
                        return Err(format!(
                            "edge {a}–{b} belongs to {k} triangles (triangles {}): the mesh is \
                             not a closed manifold surface",
                            list.join(", ")
                        ));
                    }
                }
            }
        }

        let volume = self.signed_volume();
        let diagonal = self.bounding_diagonal();
        if volume.abs() <= 1e-12 * diagonal.powi(3) {
            return Err(format!(
                "the mesh encloses no volume (signed volume {volume:e}): it is flat"
            ));
        }
        if volume < 0.0 {
            return Err(format!(
                "the signed volume is {volume:e} < 0: the mesh is inside out (its triangles are \
                 clockwise seen from outside)"
            ));
        }
        Ok(())
    }

    /// Welds vertices whose coordinates are exactly equal (−0 and +0 count as equal), as needed
    /// for an STL file, which lists each triangle's corners separately. Vertices are numbered in
    /// order of first appearance; the triangles keep their order and winding.
    pub fn welded(vertices_per_triangle: &[[Vector3<f64>; 3]]) -> Mesh {
        let mut index: HashMap<[u64; 3], usize> = HashMap::new();
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(vertices_per_triangle.len());
        for corners in vertices_per_triangle {
            let mut tri = [0usize; 3];
            for (slot, p) in tri.iter_mut().zip(corners) {
                // Adding +0.0 turns −0.0 into +0.0, so that both have the same bits.
                let key = [
                    (p.x + 0.0).to_bits(),
                    (p.y + 0.0).to_bits(),
                    (p.z + 0.0).to_bits(),
                ];
                *slot = *index.entry(key).or_insert_with(|| {
                    vertices.push(*p);
                    vertices.len() - 1
                });
            }
            triangles.push(tri);
        }
        Mesh {
            vertices,
            triangles,
        }
    }

    /// The mesh scaled by `s` about the origin. A negative `s` mirrors it through the origin;
    /// the triangles are then reversed so that they stay counter-clockwise seen from outside.
    pub fn scaled(&self, s: f64) -> Mesh {
        let triangles = if s < 0.0 {
            self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
        } else {
            self.triangles.clone()
        };
        Mesh {
            vertices: self.vertices.iter().map(|v| v * s).collect(),
            triangles,
        }
    }

    /// The mesh moved by `t`.
    pub fn translated(&self, t: &Vector3<f64>) -> Mesh {
        Mesh {
            vertices: self.vertices.iter().map(|v| v + t).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The mesh moved so that its centroid (of volume) is at the origin.
    pub fn centred(&self) -> Mesh {
        self.translated(&-self.mass_properties().centroid)
    }

    /// The signed volume: positive for a closed mesh with outward normals.
    pub fn signed_volume(&self) -> f64 {
        let r0 = self.vertex_mean();
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let (a, b, c) = (
                    self.vertices[a] - r0,
                    self.vertices[b] - r0,
                    self.vertices[c] - r0,
                );
                a.dot(&b.cross(&c))
            })
            .sum::<f64>()
            / 6.0
    }

    /// Volume, centroid, and the inertia tensor about the centroid per unit density, exactly.
    ///
    /// The closed surface is cut into the tetrahedra (r0, a, b, c), one per triangle, from a
    /// reference point r0 (the mean vertex, which keeps the numbers small); each is counted with
    /// the sign of its determinant d = a·(b×c) (positions relative to r0), so the parts outside
    /// the solid cancel and a non-convex mesh is handled. For a tetrahedron with one corner at
    /// the origin (the "canonical tetrahedron" mapped by the matrix [a b c]):
    ///
    ///   ∫ dV = d/6,   ∫ x dV = d/24 (a+b+c),
    ///   ∫ x xᵀ dV = d/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ),  s = a+b+c
    ///
    /// (the covariance of the canonical tetrahedron, 1/120 (I + 1 1ᵀ), pushed through [a b c];
    /// e.g. Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of
    /// its vertex coordinates", J. Math. Stat. 1 (2004), and Blow & Binstock, "How to find the
    /// inertia tensor (or other mass properties) of a 3D solid body represented by a triangle
    /// mesh", 2004). Summed, shifted to the centroid (C − V c cᵀ), and turned into the inertia
    /// tensor I = tr(C) 1 − C.
    ///
    /// The mesh should pass [`Mesh::check`]; a mesh of zero volume gives zero inertia and the
    /// mean vertex as centroid.
    pub fn mass_properties(&self) -> MassProps {
        let r0 = self.vertex_mean();
        let mut det_sum = 0.0;
        let mut first = Vector3::zeros();
        let mut second = Matrix3::zeros();
        for &[a, b, c] in &self.triangles {
            let (a, b, c) = (
                self.vertices[a] - r0,
                self.vertices[b] - r0,
                self.vertices[c] - r0,
            );
            let d = a.dot(&b.cross(&c));
            let s = a + b + c;
            det_sum += d;
            first += s * d;
            second +=
                (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose()) * d;
        }
        let volume = det_sum / 6.0;
        if volume == 0.0 {
            return MassProps {
                volume,
                centroid: r0,
                inertia: Matrix3::zeros(),
            };
        }
        let c = first / (24.0 * volume); // centroid relative to r0
        let covariance = second / 120.0 - c * c.transpose() * volume;
        let inertia = Matrix3::identity() * covariance.trace() - covariance;
        MassProps {
            volume,
            centroid: r0 + c,
            inertia: (inertia + inertia.transpose()) * 0.5,
        }
    }

    fn vertex_mean(&self) -> Vector3<f64> {
        if self.vertices.is_empty() {
            return Vector3::zeros();
        }
        self.vertices.iter().sum::<Vector3<f64>>() / self.vertices.len() as f64
    }

    fn bounding_diagonal(&self) -> f64 {
        let Some(first) = self.vertices.first() else {
            return 0.0;
        };
        let (lo, hi) = self
            .vertices
            .iter()
            .fold((*first, *first), |(lo, hi), v| (lo.inf(v), hi.sup(v)));
        (hi - lo).norm()
    }

    /// The mesh without the vertices no triangle uses (renumbered in order).
    fn compacted(&self) -> Mesh {
        let mut new_index = vec![usize::MAX; self.vertices.len()];
        let mut vertices = Vec::new();
        let triangles = self
            .triangles
            .iter()
            .map(|tri| {
                tri.map(|k| {
                    if new_index[k] == usize::MAX {
                        new_index[k] = vertices.len();
                        vertices.push(self.vertices[k]);
                    }
                    new_index[k]
                })
            })
            .collect();
        Mesh {
            vertices,
            triangles,
        }
    }
}

/// The convex hull of `points`, as a closed mesh with outward (counter-clockwise) triangles and
/// only the hull's corners as vertices. Computed by parry3d-f64's quickhull
/// (`parry3d_f64::transformation::try_convex_hull`); the result is then checked with
/// [`Mesh::check`], so coplanar or collinear points are refused.
pub fn hull(points: &[Vector3<f64>]) -> Result<Mesh, String> {
    if points.len() < 4 {
        return Err(format!(
            "a convex hull needs at least 4 points, got {}",
            points.len()
        ));
    }
    if let Some(i) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        let p = points[i];
        return Err(format!(
            "point {i} has a non-finite coordinate ({}, {}, {})",
            p.x, p.y, p.z
        ));
    }
    let input: Vec<parry3d_f64::math::Vector> = points
        .iter()
        .map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z))
        .collect();
    let (vertices, indices) =
        parry3d_f64::transformation::try_convex_hull(&input).map_err(|e| {
            format!(
                "the convex hull of {} points could not be computed: {e:?}",
                points.len()
            )
        })?;
    let mut mesh = Mesh {
        vertices: vertices
            .iter()
            .map(|v| Vector3::new(v.x, v.y, v.z))
            .collect(),
        triangles: indices.iter().map(|t| t.map(|k| k as usize)).collect(),
    }
    .compacted();
    if mesh.signed_volume() < 0.0 {
        // parry documents counter-clockwise triangles; this only guards against a change.
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    mesh.check().map_err(|e| {
        format!(
            "the convex hull of {} points is not a solid (are they coplanar?): {e}",
            points.len()
        )
    })?;
    Ok(mesh)
}

/// A face of a convex mesh: its coplanar triangles merged.
#[derive(Clone, Debug, PartialEq)]
pub struct Facet {
    /// Unit, outward.
    pub normal: Vector3<f64>,
    /// normal·x for the points x of the face's plane.
    pub offset: f64,
    /// Its corners, counter-clockwise seen from outside (no collinear corner).
    pub polygon: Vec<Vector3<f64>>,
    /// The face's area.
    pub area: f64,
    /// The centroid of the face's area (on its plane).
    pub centroid: Vector3<f64>,
}

/// The faces of a convex mesh (e.g. from [`hull`]): adjacent triangles whose normals differ by
/// at most `tol` radians (default [`COPLANAR_TOLERANCE`]) are merged into one facet. Facets are
/// in the order of their first triangle. Zero-area triangles are skipped. Meant for convex
/// meshes: the corners of a non-convex face would be ordered wrongly.
pub fn facets(hull: &Mesh, tol: f64) -> Vec<Facet> {
    let m = hull.triangles.len();
    // Twice-area vectors (cross products); their directions are the triangles' normals.
    let cross: Vec<Vector3<f64>> = hull
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            (hull.vertices[b] - hull.vertices[a]).cross(&(hull.vertices[c] - hull.vertices[a]))
        })
        .collect();
    let live: Vec<bool> = cross.iter().map(|c| c.norm() > 0.0).collect();

    // Union-find over triangles sharing an edge whose normals are within tol. The angle is
    // atan2(|n1×n2|, n1·n2), accurate also near zero (acos is not).
    let mut parent: Vec<usize> = (0..m).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut edge_owner: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, tri) in hull.triangles.iter().enumerate() {
        if !live[t] {
            continue;
        }
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            if let Some(&u) = edge_owner.get(&(b, a)) {
                let (n1, n2) = (cross[t].normalize(), cross[u].normalize());
                if n1.cross(&n2).norm().atan2(n1.dot(&n2)) <= tol {
                    let (rt, ru) = (root(&mut parent, t), root(&mut parent, u));
                    parent[rt.max(ru)] = rt.min(ru);
                }
            }
            edge_owner.insert((a, b), t);
        }
    }

    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of_root: HashMap<usize, usize> = HashMap::new();
    for t in (0..m).filter(|&t| live[t]) {
        let r = root(&mut parent, t);
        let g = *group_of_root.entry(r).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(t);
    }

    groups
        .iter()
        .map(|group| {
            let mut area2 = Vector3::zeros(); // Σ cross: twice the vector area
            let mut weighted = Vector3::zeros(); // Σ |cross| · triangle centroid
            let mut total = 0.0; // Σ |cross|
            for &t in group {
                let [a, b, c] = hull.triangles[t];
                let w = cross[t].norm();
                area2 += cross[t];
                weighted += (hull.vertices[a] + hull.vertices[b] + hull.vertices[c]) * (w / 3.0);
                total += w;
            }
            let normal = area2.normalize();
            let centroid = weighted / total;
            let polygon = face_polygon(hull, group, &normal, &centroid, tol);
            Facet {
                normal,
                offset: normal.dot(&centroid),
                polygon,
                area: total / 2.0,
                centroid,
            }
        })
        .collect()
}

/// The boundary loop of a group of triangles (edges whose reverse is not in the group), chained
/// in the triangles' direction (so counter-clockwise seen from outside), without collinear
/// corners. If the boundary is not a single loop, the boundary vertices sorted by angle around
/// the centroid instead (right for a convex face).
fn face_polygon(
    mesh: &Mesh,
    group: &[usize],
    normal: &Vector3<f64>,
    centroid: &Vector3<f64>,
    tol: f64,
) -> Vec<Vector3<f64>> {
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for &t in group {
        let tri = mesh.triangles[t];
        for e in 0..3 {
            *directed.entry((tri[e], tri[(e + 1) % 3])).or_default() += 1;
        }
    }
    let mut next: HashMap<usize, usize> = HashMap::new();
    let mut single_loop = true;
    let mut boundary: Vec<(usize, usize)> = directed
        .keys()
        .filter(|&&(a, b)| !directed.contains_key(&(b, a)))
        .copied()
        .collect();
    boundary.sort_unstable();
    for &(a, b) in &boundary {
        if next.insert(a, b).is_some() {
            single_loop = false;
        }
    }
    let mut corners: Vec<usize> = Vec::new();
    if let Some(&(start, _)) = boundary.first() {
        let mut k = start;
        loop {
            corners.push(k);
            match next.get(&k) {
                Some(&n) if n == start => break,
                Some(&n) if corners.len() <= boundary.len() => k = n,
                _ => {
                    single_loop = false;
                    break;
                }
            }
        }
    }
    if corners.len() != boundary.len() {
        single_loop = false;
    }
    let mut polygon: Vec<Vector3<f64>> = if single_loop {
        corners.iter().map(|&k| mesh.vertices[k]).collect()
    } else {
        let mut ks: Vec<usize> = boundary.iter().map(|e| e.0).collect();
        ks.sort_unstable();
        ks.dedup();
        let mut pts: Vec<Vector3<f64>> = ks.iter().map(|&k| mesh.vertices[k]).collect();
        let u = normal
            .cross(&if normal.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            })
            .normalize();
        let v = normal.cross(&u);
        let angle = |p: &Vector3<f64>| {
            let d = p - centroid;
            d.dot(&v).atan2(d.dot(&u))
        };
        pts.sort_by(|p, q| angle(p).total_cmp(&angle(q)));
        pts
    };
    // Drop corners where the boundary goes straight on (turning angle within tol).
    loop {
        let n = polygon.len();
        if n <= 3 {
            break;
        }
        let straight = (0..n).find(|&i| {
            let e1 = polygon[i] - polygon[(i + n - 1) % n];
            let e2 = polygon[(i + 1) % n] - polygon[i];
            e1.cross(&e2).dot(normal).atan2(e1.dot(&e2)).abs() <= tol
        });
        match straight {
            Some(i) => {
                polygon.remove(i);
            }
            None => break,
        }
    }
    polygon
}

/// True when the foot of `com` on the facet's plane lies inside its polygon by more than
/// `margin` (a length, ≥ 0) from every edge: a die resting on that facet on a level floor is
/// then in equilibrium (its weight acts through the contact polygon), so the facet can be an
/// outcome. The signed distance of the foot p from the edge a→b (counter-clockwise seen from
/// outside) is (p − a)·(n × (b − a))/|b − a|, positive inside.
pub fn stable(f: &Facet, com: &Vector3<f64>, margin: f64) -> bool {
    let n = f.polygon.len();
    if n < 3 {
        return false;
    }
    let foot = com - f.normal * (f.normal.dot(com) - f.offset);
    (0..n).all(|i| {
        let (a, b) = (f.polygon[i], f.polygon[(i + 1) % n]);
        let edge = b - a;
        let inward = f.normal.cross(&edge) / edge.norm();
        (foot - a).dot(&inward) > margin
    })
}

/// Which face's label is the result of a throw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Reads {
    /// The face facing up (most dice).
    Up,
    /// The face on the floor (the d4, whose label counts as the face it rests on).
    Down,
    /// The face facing up, or the one on the floor where no face is opposite it (an odd
    /// prism's sides: it rests with an edge up, and shows the side it lies on).
    UpOrLying,
}

/// A named die: its mesh (centroid at the origin), the label of each face, and how it is read.
#[derive(Clone, Debug, PartialEq)]
pub struct Named {
    /// The solid, centroid at the origin, in the caller's length unit.
    pub mesh: Mesh,
    /// Outward unit normal of each labelled facet, and its label; in label order (numbers
    /// ascending, then "top", "bottom" for a prism's caps).
    pub labels: Vec<(Vector3<f64>, String)>,
    /// Whether the result is the label facing up or the one on the floor.
    pub reads: Reads,
}

/// The default size (millimetres) of a named die when `size` is `None`, and what it measures.
/// Proportions of a common games-table set; a choice, not a standard.
pub const DEFAULT_SIZES_MM: [(&str, f64, &str); 6] = [
    ("d4", 18.0, "edge length"),
    ("d6", 16.0, "distance between opposite faces (= edge)"),
    ("d8", 15.0, "distance between opposite faces"),
    ("d10", 16.0, "distance between opposite faces"),
    ("d12", 18.0, "distance between opposite faces"),
    ("d20", 20.0, "distance between opposite faces"),
];

/// The golden ratio, which places the corners of the d12 and d20.
const PHI: f64 = 1.618_033_988_749_895;

/// A named die, centred (centroid at the origin):
///
/// | name | solid | `size` measures | default | labels |
/// |---|---|---|---|---|
/// | `d4` | regular tetrahedron | edge | 18 mm | 1..4, read on the face down ([`Reads::Down`]) |
/// | `d6` | cube, axes along x, y, z | face to opposite face (= edge) | 16 mm | 1 +z, 6 −z, 2 +x, 5 −x, 3 +y, 4 −y (western, right-handed: 1, 2, 3 counter-clockwise round their corner) |
/// | `d8` | regular octahedron | face to opposite face | 15 mm | 1..8, opposite faces sum to 9 |
/// | `d10` | pentagonal trapezohedron, apexes on ±z | face to opposite face | 16 mm | 1..10, opposite faces sum to 11; odd labels meet at the −z apex |
/// | `d12` | regular dodecahedron | face to opposite face | 18 mm | 1..12, opposite faces sum to 13 |
/// | `d20` | regular icosahedron | face to opposite face | 20 mm | 1..20, opposite faces sum to 21 |
/// | `prism:N,D,L` | regular N-gon prism along z, N ≥ 3 | (no `size`: D is the circumscribed diameter, L the length) | — | sides 1..N counter-clockwise seen from +z, side 1 facing +x; caps "top" (+z), "bottom"; read up, an odd prism's sides on the side it lies on (an edge is up) |
///
/// The d10's shape: a ring of 10 corners at angles kπ/5 and radius r, alternately at z = ±z0,
/// and apexes at z = ±H with H = r (the proportions of the usual d10: apex to apex about 1.49
/// times face to face). Each kite face is planar when z0 = H tan²(π/10) (derived in `d10_points`).
///
/// Apart from the d6's, the arrangement of labels (which faces are neighbours) is this
/// module's choice: only the opposite-sum rule follows the dice trade's convention.
/// Names are case-insensitive. Defaults are in millimetres; other units pass `size`.
pub fn named(name: &str, size: Option<f64>) -> Result<Named, String> {
    let key = name.trim().to_ascii_lowercase();
    if let Some(spec) = key.strip_prefix("prism:") {
        if let Some(s) = size {
            return Err(format!(
                "\"{name}\" carries its own dimensions (diameter and length): give no size (got {s})"
            ));
        }
        return prism_die(spec, name);
    }
    let Some(&(_, default, _)) = DEFAULT_SIZES_MM.iter().find(|d| d.0 == key) else {
        return Err(format!(
            "unknown die \"{name}\": expected d4, d6, d8, d10, d12, d20, coin:D,H or \
             prism:N,D,L"
        ));
    };
    let size = size.unwrap_or(default);
    if !(size.is_finite() && size > 0.0) {
        return Err(format!(
            "the size of a {key} must be a positive length, got {size}"
        ));
    }
    let points = named_points(&key);
    let unit = hull(&points)?.centred();
    let scale = if key == "d4" {
        size / (2.0 * 2f64.sqrt())
    } else {
        // Centrally symmetric: face to opposite face is twice the (common) facet offset.
        let offset = facets(&unit, COPLANAR_TOLERANCE)
            .iter()
            .map(|f| f.offset)
            .fold(f64::INFINITY, f64::min);
        size / (2.0 * offset)
    };
    let mesh = unit.scaled(scale).centred();
    let normals: Vec<Vector3<f64>> = facets(&mesh, COPLANAR_TOLERANCE)
        .iter()
        .map(|f| f.normal)
        .collect();
    let labels = named_labels(&key, &normals)?;
    let expected = match key.as_str() {
        "d4" => 4,
        "d6" => 6,
        "d8" => 8,
        "d10" => 10,
        "d12" => 12,
        _ => 20,
    };
    let mut seen = labels.clone();
    seen.sort_unstable();
    if seen != (1..=expected).collect::<Vec<_>>() {
        return Err(format!(
            "internal error: the {key} got labels {labels:?} on {} faces",
            normals.len()
        ));
    }
    let mut labelled: Vec<(Vector3<f64>, usize)> = normals.into_iter().zip(labels).collect();
    labelled.sort_by_key(|l| l.1);
    Ok(Named {
        mesh,
        labels: labelled
            .into_iter()
            .map(|(n, l)| (n, l.to_string()))
            .collect(),
        reads: if key == "d4" { Reads::Down } else { Reads::Up },
    })
}

/// The four sign pairs (±1, ±1).
const SIGNS2: [[f64; 2]; 4] = [[1.0, 1.0], [1.0, -1.0], [-1.0, 1.0], [-1.0, -1.0]];

/// The eight sign triples (±1, ±1, ±1).
fn signs3() -> impl Iterator<Item = [f64; 3]> {
    (0..8).map(|i| [0, 1, 2].map(|b| if i >> b & 1 == 0 { 1.0 } else { -1.0 }))
}

/// The d10's corners for ring radius r = 1 and apex height H = 1.
///
/// Ring corner k (k = 0..9) is at angle kπ/5, z = +z0 for even k and −z0 for odd k. The face
/// round the +z apex T with far corner v1 (odd) is the kite (T, v0, v1, v2). It is symmetric
/// about the vertical plane through v1, so it is planar when T, v1 and the midpoint of v0v2 are
/// collinear. In that plane (radius ρ, height z): T = (0, H), midpoint = (r cos(π/5), z0),
/// v1 = (r, −z0); collinear iff (z0 − H)/(r cos(π/5)) = (−z0 − H)/r, i.e.
/// z0 = H (1 − cos(π/5))/(1 + cos(π/5)) = H tan²(π/10) ≈ 0.1056 H.
/// The −z faces follow by the central symmetry (corner k+5 = −corner k).
fn d10_points() -> Vec<Vector3<f64>> {
    let (r, h) = (1.0, 1.0);
    let z0 = h * (PI / 10.0).tan().powi(2);
    let mut p: Vec<Vector3<f64>> = (0..10)
        .map(|k| {
            let a = k as f64 * PI / 5.0;
            let z = if k % 2 == 0 { z0 } else { -z0 };
            Vector3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect();
    p.push(Vector3::new(0.0, 0.0, h));
    p.push(Vector3::new(0.0, 0.0, -h));
    p
}

/// Azimuth of a vector's projection on the xy-plane, in [0, 2π).
fn azimuth(n: &Vector3<f64>) -> f64 {
    let a = n.y.atan2(n.x);
    if a < 0.0 {
        a + 2.0 * PI
    } else {
        a
    }
}

/// A deterministic order of face normals: highest first, then by azimuth from +x
/// counter-clockwise; quantised (1e-6) so rounding noise cannot swap equals.
fn order_key(n: &Vector3<f64>) -> (i64, i64) {
    const Q: f64 = 1e6;
    let full = (2.0 * PI * Q).round() as i64;
    let mut a = (azimuth(n) * Q).round() as i64;
    if a >= full || n.x.hypot(n.y) < 1e-9 {
        a = 0;
    }
    ((-n.z * Q).round() as i64, a)
}

/// Labels 1..N for a centrally symmetric solid: in [`order_key`] order, each face not yet
/// labelled gets the next number k and its opposite face N + 1 − k.
fn opposite_pair_labels(normals: &[Vector3<f64>]) -> Result<Vec<usize>, String> {
    let n = normals.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| order_key(&normals[i]));
    let mut labels = vec![0usize; n];
    let mut next = 1;
    for &i in &order {
        if labels[i] != 0 {
            continue;
        }
        let j = (0..n)
            .find(|&j| j != i && labels[j] == 0 && normals[i].dot(&normals[j]) < -1.0 + 1e-9)
            .ok_or_else(|| format!("internal error: face {i} of {n} has no opposite face"))?;
        labels[i] = next;
        labels[j] = n + 1 - next;
        next += 1;
    }
    Ok(labels)
}

/// A right prism over a counter-clockwise (seen from +z) simple polygon, from z = z0 to z1,
/// with `cap` the polygon's triangulation (counter-clockwise triangles of polygon indices).
/// Vertices: the polygon at z0 (indices 0..n), then at z1 (n..2n).
fn extrude(polygon: &[(f64, f64)], cap: &[[usize; 3]], z0: f64, z1: f64) -> Mesh {
    let n = polygon.len();
    let mut vertices: Vec<Vector3<f64>> = polygon
        .iter()
        .map(|&(x, y)| Vector3::new(x, y, z0))
        .collect();
    vertices.extend(polygon.iter().map(|&(x, y)| Vector3::new(x, y, z1)));
    let mut triangles = Vec::with_capacity(2 * cap.len() + 2 * n);
    for &[a, b, c] in cap {
        triangles.push([a, c, b]); // bottom, seen from −z
        triangles.push([n + a, n + b, n + c]);
    }
    for k in 0..n {
        let k1 = (k + 1) % n;
        triangles.push([k, k1, n + k1]);
        triangles.push([k, n + k1, n + k]);
    }
    Mesh {
        vertices,
        triangles,
    }
}

/// A named die's vertices before sizing (the Platonic solids' standard coordinates; the d10's
/// from [`d10_points`]).
fn named_points(key: &str) -> Vec<Vector3<f64>> {
    match key {
        // Alternate corners of the cube [−1, 1]³: edge 2√2.
        "d4" => vec![
            Vector3::new(1.0, 1.0, 1.0),
            Vector3::new(1.0, -1.0, -1.0),
            Vector3::new(-1.0, 1.0, -1.0),
            Vector3::new(-1.0, -1.0, 1.0),
        ],
        "d6" => signs3()
            .map(|[sx, sy, sz]| Vector3::new(sx, sy, sz))
            .collect(),
        "d8" => (0..3)
            .flat_map(|i| [1.0, -1.0].map(|s| Vector3::ith(i, s)))
            .collect(),
        "d10" => d10_points(),
        // (±1, ±1, ±1), (0, ±1/φ, ±φ), (±1/φ, ±φ, 0), (±φ, 0, ±1/φ).
        "d12" => {
            let mut p: Vec<Vector3<f64>> = signs3()
                .map(|[sx, sy, sz]| Vector3::new(sx, sy, sz))
                .collect();
            for [s1, s2] in SIGNS2 {
                p.push(Vector3::new(0.0, s1 / PHI, s2 * PHI));
                p.push(Vector3::new(s1 / PHI, s2 * PHI, 0.0));
                p.push(Vector3::new(s1 * PHI, 0.0, s2 / PHI));
            }
            p
        }
        // (0, ±1, ±φ) and its cyclic permutations.
        "d20" => {
            let mut p = Vec::new();
            for [s1, s2] in SIGNS2 {
                p.push(Vector3::new(0.0, s1, s2 * PHI));
                p.push(Vector3::new(s1, s2 * PHI, 0.0));
                p.push(Vector3::new(s1 * PHI, 0.0, s2));
            }
            p
        }
        _ => unreachable!("every name of DEFAULT_SIZES_MM is built above"),
    }
}

/// The labels of a named die's faces, by their outward normals: the d4's in a fixed order, the
/// d6's the western layout, the d10's the usual zigzag, the others' opposite pairs summing to
/// N + 1.
fn named_labels(key: &str, normals: &[Vector3<f64>]) -> Result<Vec<usize>, String> {
    Ok(match key {
        "d4" => {
            let mut order: Vec<usize> = (0..normals.len()).collect();
            order.sort_by_key(|&i| order_key(&normals[i]));
            let mut labels = vec![0; normals.len()];
            for (rank, &i) in order.iter().enumerate() {
                labels[i] = rank + 1;
            }
            labels
        }
        "d6" => normals
            .iter()
            .map(|n| {
                // The face's axis and side: 1 +z, 6 −z, 2 +x, 5 −x, 3 +y, 4 −y.
                let axis = n.iamax();
                match (axis, n[axis] > 0.0) {
                    (2, true) => 1,
                    (2, false) => 6,
                    (0, true) => 2,
                    (0, false) => 5,
                    (1, true) => 3,
                    _ => 4,
                }
            })
            .collect(),
        "d10" => normals
            .iter()
            .map(|n| {
                // Faces round the ring by azimuth (36° apart; even steps are the faces of the
                // −z apex), labelled in the zigzag order of the usual d10 (0, 7, 4, 1, 6, 9, 2,
                // 5, 8, 3 on a 0–9 die, plus one): the face opposite step m is step m + 5.
                const ZIGZAG: [usize; 10] = [1, 8, 5, 2, 7, 10, 3, 6, 9, 4];
                let step = (azimuth(n) / (PI / 5.0)).round() as usize % 10;
                ZIGZAG[step]
            })
            .collect(),
        _ => opposite_pair_labels(normals)?,
    })
}

/// The regular N-gon prism of circumscribed diameter D and length L along z, centred. Corners
/// at angles (2k+1)π/N, so that the side between corners k and k+1 faces azimuth 2π(k+1)/N
/// and one side faces +x.
fn prism_mesh(n: usize, diameter: f64, length: f64) -> Mesh {
    let r = diameter / 2.0;
    let polygon: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let a = (2 * k + 1) as f64 * PI / n as f64;
            (r * a.cos(), r * a.sin())
        })
        .collect();
    let cap: Vec<[usize; 3]> = (1..n - 1).map(|k| [0, k, k + 1]).collect();
    extrude(&polygon, &cap, -length / 2.0, length / 2.0)
}

/// The most sides a `prism:N,D,L` may have: its N sides and two ends are at most the 255
/// outcomes a die may have (`model::shape::MAX_FACES`).
pub const MAX_PRISM_SIDES: usize = 253;

/// `prism:N,D,L` (the part after "prism:" in `spec`).
fn prism_die(spec: &str, name: &str) -> Result<Named, String> {
    let parts: Vec<&str> = spec.split(',').map(str::trim).collect();
    let usage = "expected prism:N,D,L with N ≥ 3 sides, D the circumscribed diameter and L the \
                 length, e.g. prism:6,16,30";
    if parts.len() != 3 {
        return Err(format!("\"{name}\": {usage}"));
    }
    let n: usize = parts[0]
        .parse()
        .ok()
        .filter(|n| (3..=MAX_PRISM_SIDES).contains(n))
        .ok_or_else(|| {
            format!(
                "\"{name}\": N = \"{}\" is not a whole number from 3 to {MAX_PRISM_SIDES} \
                 (its N sides and two ends: a die has at most 255 faces); \
                 {usage}",
                parts[0]
            )
        })?;
    let length_of = |s: &str, what: &str| -> Result<f64, String> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                format!("\"{name}\": {what} = \"{s}\" is not a positive length; {usage}")
            })
    };
    let diameter = length_of(parts[1], "D")?;
    let length = length_of(parts[2], "L")?;
    // A die's sizes, as a block's (`model::block`): 1 µm to 10 m.
    let (lo, hi) = (1e-3, 1e4);
    for (what, v) in [("D", diameter), ("L", length)] {
        if !(lo..=hi).contains(&v) {
            return Err(format!(
                "\"{name}\": {what} = {v} mm is too {} (a die's sizes are from {lo} to {hi} \
                 mm); {usage}",
                if v > hi { "long" } else { "short" }
            ));
        }
    }
    let mesh = prism_mesh(n, diameter, length);
    let mut labels: Vec<(Vector3<f64>, String)> = (0..n)
        .map(|k| {
            let a = 2.0 * PI * k as f64 / n as f64;
            (Vector3::new(a.cos(), a.sin(), 0.0), (k + 1).to_string())
        })
        .collect();
    labels.push((Vector3::z(), "top".to_string()));
    labels.push((-Vector3::z(), "bottom".to_string()));
    Ok(Named {
        mesh,
        labels,
        // An odd prism on a side has an edge up: it shows the side it lies on.
        reads: Reads::UpOrLying,
    })
}

/// A coin: a solid circular cylinder with its axis along z, centred at the origin.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    /// The diameter of the circular faces.
    pub diameter: f64,
    /// The length along the axis (the coin's thickness).
    pub height: f64,
}

impl Cylinder {
    /// Both dimensions finite and positive.
    pub fn check(&self) -> Result<(), String> {
        for (what, v) in [("diameter", self.diameter), ("height", self.height)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!(
                    "the cylinder's {what} must be a positive length, got {v}"
                ));
            }
        }
        Ok(())
    }

    /// Closed form, unit density: V = π r² h, I_zz = V r²/2, I_xx = I_yy = V (3r² + h²)/12,
    /// centroid at the origin, no products of inertia.
    pub fn mass_properties(&self) -> MassProps {
        let r = self.diameter / 2.0;
        let h = self.height;
        let volume = PI * r * r * h;
        let side = volume * (3.0 * r * r + h * h) / 12.0;
        MassProps {
            volume,
            centroid: Vector3::zeros(),
            inertia: Matrix3::from_diagonal(&Vector3::new(side, side, volume * r * r / 2.0)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative closeness |a − b| ≤ tol · max(|a|, |b|, floor).
    fn close(a: f64, b: f64, tol: f64, floor: f64) -> bool {
        (a - b).abs() <= tol * a.abs().max(b.abs()).max(floor)
    }

    fn assert_matrix_close(a: &Matrix3<f64>, b: &Matrix3<f64>, tol: f64, what: &str) {
        let scale = a.abs().max().max(b.abs().max());
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (a[(i, j)] - b[(i, j)]).abs() <= tol * scale,
                    "{what}: entry ({i},{j}) is {} but should be {}\n{a}\n{b}",
                    a[(i, j)],
                    b[(i, j)]
                );
            }
        }
    }

    /// The box [x0, x0+a] × [y0, y0+b] × [z0, z0+c]; corner i = x + 2y + 4z (bits).
    fn box_mesh(origin: Vector3<f64>, a: f64, b: f64, c: f64) -> Mesh {
        let vertices = (0..8)
            .map(|i| {
                origin
                    + Vector3::new(
                        if i & 1 != 0 { a } else { 0.0 },
                        if i & 2 != 0 { b } else { 0.0 },
                        if i & 4 != 0 { c } else { 0.0 },
                    )
            })
            .collect();
        let triangles = vec![
            [0, 2, 3],
            [0, 3, 1], // z = 0
            [4, 5, 7],
            [4, 7, 6], // z = c
            [0, 1, 5],
            [0, 5, 4], // y = 0
            [2, 6, 7],
            [2, 7, 3], // y = b
            [0, 4, 6],
            [0, 6, 2], // x = 0
            [1, 3, 7],
            [1, 7, 5], // x = a
        ];
        Mesh {
            vertices,
            triangles,
        }
    }

    /// Inertia of a box a×b×c about its centre, unit density.
    fn box_inertia(a: f64, b: f64, c: f64) -> Matrix3<f64> {
        let m = a * b * c;
        Matrix3::from_diagonal(&Vector3::new(
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
        ))
    }

    /// Parallel-axis theorem: inertia about a point at −d from the centroid.
    fn shifted(inertia: &Matrix3<f64>, mass: f64, d: &Vector3<f64>) -> Matrix3<f64> {
        inertia + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * mass
    }

    #[test]
    fn unit_cube_and_box_mass_properties() {
        let cube = box_mesh(Vector3::zeros(), 1.0, 1.0, 1.0);
        cube.check().unwrap();
        let mp = cube.mass_properties();
        assert!(close(mp.volume, 1.0, 1e-12, 0.0), "{}", mp.volume);
        assert!((mp.centroid - Vector3::repeat(0.5)).norm() < 1e-12);
        assert_matrix_close(
            &mp.inertia,
            &(Matrix3::identity() / 6.0),
            1e-12,
            "unit cube",
        );

        let (a, b, c) = (2.0, 3.0, 5.0);
        let origin = Vector3::new(-1.0, 4.0, 7.0);
        let bx = box_mesh(origin, a, b, c);
        bx.check().unwrap();
        let mp = bx.mass_properties();
        assert!(close(mp.volume, 30.0, 1e-12, 0.0), "{}", mp.volume);
        let centre = origin + Vector3::new(a, b, c) / 2.0;
        assert!((mp.centroid - centre).norm() < 1e-12 * centre.norm());
        assert_matrix_close(&mp.inertia, &box_inertia(a, b, c), 1e-12, "box");
    }

    #[test]
    fn regular_tetrahedron_mass_properties() {
        // Alternate cube corners (edge 2√2), moved off the origin.
        let offset = Vector3::new(1.0, -2.0, 3.0);
        let points: Vec<Vector3<f64>> = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ]
        .iter()
        .map(|p| Vector3::from(*p) + offset)
        .collect();
        let mesh = hull(&points).unwrap();
        let mp = mesh.mass_properties();
        let a = 2.0 * 2f64.sqrt();
        let volume = a.powi(3) / (6.0 * 2f64.sqrt());
        assert!(
            close(mp.volume, volume, 1e-12, 0.0),
            "{} vs {volume}",
            mp.volume
        );
        assert!((mp.centroid - offset).norm() < 1e-12 * offset.norm());
        // A regular tetrahedron's inertia is isotropic: m a²/20 about every centroidal axis.
        let expected = Matrix3::identity() * (volume * a * a / 20.0);
        assert_matrix_close(&mp.inertia, &expected, 1e-12, "regular tetrahedron");
    }

    #[test]
    fn regular_octahedron_mass_properties() {
        let r = 1.5;
        let points: Vec<Vector3<f64>> = (0..3)
            .flat_map(|i| [r, -r].map(|s| Vector3::ith(i, s)))
            .collect();
        let mesh = hull(&points).unwrap();
        let mp = mesh.mass_properties();
        let volume = 4.0 / 3.0 * r.powi(3);
        assert!(
            close(mp.volume, volume, 1e-12, 0.0),
            "{} vs {volume}",
            mp.volume
        );
        assert!(mp.centroid.norm() < 1e-12 * r);
        // m a²/10 with edge a = r√2, i.e. m r²/5 about every centroidal axis.
        let moment = volume * r * r / 5.0;
        for i in 0..3 {
            assert!(close(mp.inertia[(i, i)], moment, 1e-12, 0.0));
            for j in 0..3 {
                if i != j {
                    assert!(mp.inertia[(i, j)].abs() <= 1e-12 * moment, "{}", mp.inertia);
                }
            }
        }
    }

    /// The L-shaped prism: [0,2]×[0,1] ∪ [0,1]×[1,2] in xy, z in [0, 1].
    fn l_prism() -> Mesh {
        let polygon = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let cap = [[0, 1, 2], [0, 2, 3], [0, 3, 5], [3, 4, 5]];
        extrude(&polygon, &cap, 0.0, 1.0)
    }

    #[test]
    fn non_convex_l_prism_by_parallel_axes() {
        let mesh = l_prism();
        mesh.check().unwrap();
        let mp = mesh.mass_properties();
        // Box A [0,2]×[0,1]×[0,1] (mass 2), box B [0,1]×[1,2]×[0,1] (mass 1).
        let (ca, cb) = (Vector3::new(1.0, 0.5, 0.5), Vector3::new(0.5, 1.5, 0.5));
        let centroid = (ca * 2.0 + cb) / 3.0;
        assert!(close(mp.volume, 3.0, 1e-12, 0.0));
        assert!((mp.centroid - centroid).norm() < 1e-12);
        let expected = shifted(&box_inertia(2.0, 1.0, 1.0), 2.0, &(ca - centroid))
            + shifted(&box_inertia(1.0, 1.0, 1.0), 1.0, &(cb - centroid));
        assert!(
            expected[(0, 1)].abs() > 0.1,
            "the L has a product of inertia"
        );
        assert_matrix_close(&mp.inertia, &expected, 1e-12, "L prism");
    }

    #[test]
    fn cylinder_closed_form_and_polygon_prism_convergence() {
        let cyl = Cylinder {
            diameter: 2.0,
            height: 2.0,
        };
        cyl.check().unwrap();
        let mp = cyl.mass_properties();
        assert!(close(mp.volume, 2.0 * PI, 1e-15, 0.0));
        let expected = Matrix3::from_diagonal(&Vector3::new(7.0 * PI / 6.0, 7.0 * PI / 6.0, PI));
        assert_matrix_close(&mp.inertia, &expected, 1e-15, "cylinder");
        assert!(Cylinder {
            diameter: 0.0,
            height: 1.0
        }
        .check()
        .is_err());

        // A 2000-gon prism inscribed in the coin: area (N/2) r² sin(2π/N), relative error
        // ≈ (2π/N)²/6 ≈ 1.6e-6 in volume, ≈ 2× that in the moments about z.
        let coin = Cylinder {
            diameter: 25.0,
            height: 2.0,
        };
        let n = 2000;
        let prism = prism_mesh(n, coin.diameter, coin.height);
        prism.check().unwrap();
        let (p, c) = (prism.mass_properties(), coin.mass_properties());
        let err = (2.0 * PI / n as f64).powi(2);
        let polygon_area = n as f64 / 2.0 * 12.5f64.powi(2) * (2.0 * PI / n as f64).sin();
        assert!(close(p.volume, polygon_area * 2.0, 1e-12, 0.0));
        assert!(close(p.volume, c.volume, err / 5.0, 0.0));
        assert!(
            !close(p.volume, c.volume, err / 10.0, 0.0),
            "the error is the polygon's"
        );
        assert!(p.centroid.norm() < 1e-12 * coin.diameter);
        assert_matrix_close(
            &p.inertia,
            &c.inertia,
            err / 2.0,
            "2000-gon prism vs cylinder",
        );
    }

    /// parry's mass properties of a mesh: `from_trimesh`, and the inertia tensor it diagonalises,
    /// summed from parry's public per-tetrahedron tensor exactly as `from_trimesh` does (about
    /// parry's centre of mass).
    fn parry_mass_properties(
        mesh: &Mesh,
    ) -> (parry3d_f64::mass_properties::MassProperties, Matrix3<f64>) {
        use parry3d_f64::mass_properties::details::{
            tetrahedron_unit_inertia_tensor_wrt_point, trimesh_signed_volume_and_center_of_mass,
        };
        use parry3d_f64::math::Vector;
        let v: Vec<Vector> = mesh
            .vertices
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect();
        let t: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|k| k as u32)).collect();
        let props = parry3d_f64::mass_properties::MassProperties::from_trimesh(1.0, &v, &t);
        let (_, com) = trimesh_signed_volume_and_center_of_mass(&v, &t);
        let mut tensor = Matrix3::zeros();
        for tri in &t {
            let [p2, p3, p4] = tri.map(|k| v[k as usize]);
            let volume = parry3d_f64::shape::Tetrahedron::new(com, p2, p3, p4).signed_volume();
            let part = tetrahedron_unit_inertia_tensor_wrt_point(com, com, p2, p3, p4);
            tensor += Matrix3::from_fn(|r, c| part.col(c)[r]) * volume;
        }
        (props, tensor)
    }

    #[test]
    fn mass_properties_agree_with_parry() {
        for (name, mesh) in [
            ("d20", named("d20", None).unwrap().mesh),
            ("d10", named("d10", None).unwrap().mesh),
            (
                "L prism",
                l_prism().translated(&Vector3::new(3.0, -1.0, 2.0)),
            ),
        ] {
            let ours = mesh.mass_properties();
            let (theirs, tensor) = parry_mass_properties(&mesh);
            assert!(
                close(ours.volume, theirs.mass(), 1e-9, 0.0),
                "{name}: volume {} vs parry {}",
                ours.volume,
                theirs.mass()
            );
            let com = Vector3::new(theirs.local_com.x, theirs.local_com.y, theirs.local_com.z);
            let size = mesh.bounding_diagonal();
            assert!(
                (ours.centroid - com).norm() <= 1e-9 * size,
                "{name}: centroid {} vs parry {com}",
                ours.centroid
            );
            // The whole tensor, products of inertia included, in the mesh's axes.
            assert_matrix_close(&ours.inertia, &tensor, 1e-9, name);
            // Principal moments: against the eigenvalues of parry's tensor to 1e-9, and against
            // `from_trimesh`'s own principal moments to 1e-7 only: parry diagonalises by the
            // closed-form (trigonometric) roots of the 3×3 characteristic cubic, which lose half
            // the digits (√ε ≈ 1e-8) when two moments are equal, as the d10's are (about x and
            // y). Their sum (the trace) it keeps exactly.
            let (moments, _) = ours.principal();
            let (of_tensor, _) = MassProps {
                inertia: tensor,
                ..ours
            }
            .principal();
            let pi = theirs.principal_inertia();
            let mut from_trimesh = [pi.x, pi.y, pi.z];
            from_trimesh.sort_by(f64::total_cmp);
            for i in 0..3 {
                assert!(
                    close(moments[i], of_tensor[i], 1e-9, 0.0),
                    "{name}: principal moment {i}: {} vs parry's tensor {}",
                    moments[i],
                    of_tensor[i]
                );
                assert!(
                    close(moments[i], from_trimesh[i], 1e-7, 0.0),
                    "{name}: principal moment {i}: {} vs parry {}",
                    moments[i],
                    from_trimesh[i]
                );
            }
            let trace: f64 = from_trimesh.iter().sum();
            assert!(close(moments.sum(), trace, 1e-9, 0.0), "{name}: trace");
        }
    }

    #[test]
    fn check_refuses_open_flipped_inside_out_and_bad_data() {
        let cube = box_mesh(Vector3::zeros(), 1.0, 1.0, 1.0);
        assert_eq!(cube.check(), Ok(()));

        let mut open = cube.clone();
        open.triangles.remove(5); // [0, 5, 4]
        let e = open.check().unwrap_err();
        assert!(e.contains("not closed") && e.starts_with("edge "), "{e}");
        assert!(
            e.starts_with("edge 4–5 belongs to 1 triangle (triangle 2)"),
            "{e}"
        );

        let mut flipped = cube.clone();
        flipped.triangles[7].swap(1, 2);
        let e = flipped.check().unwrap_err();
        assert!(
            e.contains("not consistently oriented") && e.contains('7'),
            "{e}"
        );

        let e = cube.scaled(-1.0).scaled(-1.0).check();
        assert_eq!(e, Ok(()), "mirroring twice keeps the orientation");
        let mut inside_out = cube.clone();
        for t in &mut inside_out.triangles {
            t.swap(1, 2);
        }
        let e = inside_out.check().unwrap_err();
        assert!(e.contains("inside out"), "{e}");

        let mut bad = cube.clone();
        bad.triangles[3] = [4, 7, 8];
        assert!(bad
            .check()
            .unwrap_err()
            .contains("triangle 3 refers to vertex 8"));
        let mut bad = cube.clone();
        bad.vertices[2].y = f64::NAN;
        assert!(bad
            .check()
            .unwrap_err()
            .contains("vertex 2 has a non-finite"));
        let mut bad = cube.clone();
        bad.vertices[3] = (bad.vertices[0] + bad.vertices[1]) / 2.0;
        assert!(bad.check().unwrap_err().contains("zero area"));
        let mut bad = cube.clone();
        bad.triangles.extend([[0, 1, 2], [0, 2, 1]]);
        assert!(bad.check().unwrap_err().contains("not a closed manifold"));

        for e in [
            open.check(),
            flipped.check(),
            inside_out.check(),
            bad.check(),
        ] {
            assert!(!e.unwrap_err().contains('\n'));
        }
    }

    #[test]
    fn welded_soup_and_scaling() {
        let cube = box_mesh(Vector3::new(-0.5, -0.5, -0.5), 1.0, 1.0, 1.0);
        let soup: Vec<[Vector3<f64>; 3]> = cube
            .triangles
            .iter()
            .map(|t| t.map(|k| cube.vertices[k]))
            .collect();
        let welded = Mesh::welded(&soup);
        assert_eq!(welded.vertices.len(), 8);
        welded.check().unwrap();
        // −0 and +0 weld.
        let w = Mesh::welded(&[[
            Vector3::new(0.0, 1.0, 2.0),
            Vector3::new(-0.0, 1.0, 2.0),
            Vector3::x(),
        ]]);
        assert_eq!(w.vertices.len(), 2);

        let mp = welded.mass_properties();
        for s in [2.0, -3.0] {
            let m = welded.scaled(s);
            m.check().unwrap();
            let sp = m.mass_properties();
            assert!(close(sp.volume, mp.volume * s.abs().powi(3), 1e-12, 0.0));
            assert_matrix_close(
                &sp.inertia,
                &(mp.inertia * s.abs().powi(5)),
                1e-12,
                "scaled",
            );
        }
    }

    #[test]
    fn hull_of_a_point_cloud_and_degenerate_points() {
        let mut points: Vec<Vector3<f64>> = signs3()
            .map(|[x, y, z]| Vector3::new(x, y, z) * 0.5)
            .collect();
        // Interior points, deterministic.
        for i in 0..50 {
            let t = i as f64;
            points.push(Vector3::new((t * 0.37).sin(), (t * 0.71).cos(), (t * 1.3).sin()) * 0.49);
        }
        let h = hull(&points).unwrap();
        assert_eq!(h.vertices.len(), 8);
        assert!(close(h.mass_properties().volume, 1.0, 1e-12, 0.0));
        let flat: Vec<Vector3<f64>> = (0..6)
            .map(|i| Vector3::new(i as f64, (i * i) as f64, 0.0))
            .collect();
        let e = hull(&flat).unwrap_err();
        assert!(!e.contains('\n'), "{e}");
        assert!(hull(&points[..3])
            .unwrap_err()
            .contains("at least 4 points"));
        // Degenerate inputs are refused, not a panic.
        let same = vec![Vector3::new(1.0, 2.0, 3.0); 6];
        let line: Vec<Vector3<f64>> = (0..6).map(|i| Vector3::repeat(i as f64)).collect();
        for points in [same, line] {
            let e = hull(&points).unwrap_err();
            assert!(!e.contains('\n'), "{e}");
        }
        let mut with_nan = points.clone();
        with_nan[5].z = f64::NAN;
        assert!(hull(&with_nan)
            .unwrap_err()
            .starts_with("point 5 has a non-finite"));
    }

    const DICE: [(&str, usize, usize, usize); 6] = [
        // name, faces, corners per face, vertices
        ("d4", 4, 3, 4),
        ("d6", 6, 4, 8),
        ("d8", 8, 3, 6),
        ("d10", 10, 4, 12),
        ("d12", 12, 5, 20),
        ("d20", 20, 3, 12),
    ];

    #[test]
    fn facets_of_the_named_dice() {
        let cube = hull(
            &signs3()
                .map(|[x, y, z]| Vector3::new(x, y, z))
                .collect::<Vec<_>>(),
        )
        .unwrap();
        assert_eq!(cube.triangles.len(), 12);
        let f = facets(&cube, COPLANAR_TOLERANCE);
        assert_eq!(f.len(), 6);
        assert!(f
            .iter()
            .all(|f| f.polygon.len() == 4 && close(f.area, 4.0, 1e-12, 0.0)));

        // A cube with a vertex added at the middle of the top edge 4–5: it is a corner of no
        // face, so both faces that hold it still have 4 corners.
        let mut split = box_mesh(Vector3::zeros(), 1.0, 1.0, 1.0);
        split.vertices.push(Vector3::new(0.5, 0.0, 1.0));
        let tri = |t: &[usize; 3]| split.triangles.iter().position(|u| u == t).unwrap();
        let (top, side) = (tri(&[4, 5, 7]), tri(&[0, 5, 4]));
        split.triangles[top] = [4, 8, 7];
        split.triangles[side] = [0, 5, 8];
        split.triangles.extend([[8, 5, 7], [0, 8, 4]]);
        split.check().unwrap();
        let f = facets(&split, COPLANAR_TOLERANCE);
        assert_eq!(f.len(), 6);
        for f in &f {
            assert_eq!(f.polygon.len(), 4, "{:?}", f.polygon);
            assert!(!f.polygon.contains(&Vector3::new(0.5, 0.0, 1.0)));
        }

        for (name, faces, corners, vertices) in DICE {
            let die = named(name, None).unwrap();
            die.mesh.check().unwrap();
            assert_eq!(die.mesh.vertices.len(), vertices, "{name}");
            let fs = facets(&die.mesh, COPLANAR_TOLERANCE);
            assert_eq!(fs.len(), faces, "{name}");
            let size = die.mesh.bounding_diagonal();
            let total_area: f64 = die
                .mesh
                .triangles
                .iter()
                .map(|&[a, b, c]| {
                    let v = &die.mesh.vertices;
                    (v[b] - v[a]).cross(&(v[c] - v[a])).norm() / 2.0
                })
                .sum();
            assert!(close(
                fs.iter().map(|f| f.area).sum(),
                total_area,
                1e-12,
                0.0
            ));
            for f in &fs {
                assert_eq!(f.polygon.len(), corners, "{name}");
                assert!((f.normal.norm() - 1.0).abs() < 1e-12, "{name}");
                assert!(
                    close(f.area, fs[0].area, 1e-12, 0.0),
                    "{name}: congruent faces"
                );
                // Corners on the plane, counter-clockwise seen from outside.
                let n = f.polygon.len();
                for i in 0..n {
                    let (a, b, c) = (f.polygon[i], f.polygon[(i + 1) % n], f.polygon[(i + 2) % n]);
                    assert!(
                        (f.normal.dot(&a) - f.offset).abs() < 1e-12 * size,
                        "{name}: planar"
                    );
                    assert!(
                        (b - a).cross(&(c - b)).dot(&f.normal) > 0.0,
                        "{name}: convex, ccw"
                    );
                }
                for v in &die.mesh.vertices {
                    assert!(
                        f.normal.dot(v) <= f.offset + 1e-12 * size,
                        "{name}: hull inside"
                    );
                }
            }
        }
    }

    #[test]
    fn d10_kites_are_planar() {
        let p = d10_points();
        let (top, bottom) = (p[10], p[11]);
        for j in 0..5 {
            // Top kite (T, v2j, v2j+1, v2j+2) and bottom kite (B, v2j+1, v2j+2, v2j+3).
            for (apex, k) in [(top, 2 * j), (bottom, 2 * j + 1)] {
                let (a, b, c) = (
                    p[k % 10] - apex,
                    p[(k + 1) % 10] - apex,
                    p[(k + 2) % 10] - apex,
                );
                let triple = a.dot(&b.cross(&c));
                assert!(triple.abs() < 1e-14, "kite {k}: {triple}");
            }
        }
        // A slightly wrong ring height breaks each kite into two faces.
        let mut q = p.clone();
        for v in q.iter_mut().take(10) {
            v.z *= 1.01;
        }
        let fs = facets(&hull(&q).unwrap(), COPLANAR_TOLERANCE);
        assert_eq!(fs.len(), 20);
    }

    #[test]
    fn sizes_and_centring_of_the_named_dice() {
        for (name, default, _) in DEFAULT_SIZES_MM {
            for size in [None, Some(1.0)] {
                let die = named(name, size).unwrap();
                let s = size.unwrap_or(default);
                let mp = die.mesh.mass_properties();
                assert!(mp.centroid.norm() < 1e-12 * s, "{name}: centred");
                if name == "d4" {
                    let [a, b, _] = die.mesh.triangles[0];
                    let edge = (die.mesh.vertices[a] - die.mesh.vertices[b]).norm();
                    assert!(close(edge, s, 1e-12, 0.0), "{name}: edge {edge}");
                    assert!(close(
                        mp.volume,
                        s.powi(3) / (6.0 * 2f64.sqrt()),
                        1e-12,
                        0.0
                    ));
                } else {
                    for f in facets(&die.mesh, COPLANAR_TOLERANCE) {
                        assert!(
                            close(2.0 * f.offset, s, 1e-12, 0.0),
                            "{name}: face distance"
                        );
                    }
                }
            }
        }
        // The d10's proportions: apex to apex = √(1 + (1 + tan²(π/10))²) × face to face.
        let d10 = named("d10", Some(1.0)).unwrap();
        let height = d10
            .mesh
            .vertices
            .iter()
            .map(|v| v.z)
            .fold(f64::MIN, f64::max)
            * 2.0;
        let t2 = (PI / 10.0).tan().powi(2);
        assert!(
            close(height, (1.0 + (1.0 + t2).powi(2)).sqrt(), 1e-12, 0.0),
            "{height}"
        );
    }

    #[test]
    fn labels_of_the_named_dice() {
        for (name, faces, _, _) in DICE {
            let die = named(name, None).unwrap();
            assert_eq!(die.labels.len(), faces, "{name}");
            let mut numbers: Vec<usize> = die.labels.iter().map(|l| l.1.parse().unwrap()).collect();
            numbers.sort_unstable();
            assert_eq!(
                numbers,
                (1..=faces).collect::<Vec<_>>(),
                "{name}: each label once"
            );
            let fs = facets(&die.mesh, COPLANAR_TOLERANCE);
            for (n, label) in &die.labels {
                assert!(
                    fs.iter().any(|f| (f.normal - n).norm() < 1e-9),
                    "{name}: label {label} is on a facet"
                );
                if name != "d4" {
                    let (_, opposite) = die
                        .labels
                        .iter()
                        .find(|(m, _)| (m + n).norm() < 1e-9)
                        .expect("an opposite face");
                    let sum: usize =
                        label.parse::<usize>().unwrap() + opposite.parse::<usize>().unwrap();
                    assert_eq!(sum, faces + 1, "{name}: {label} + {opposite}");
                }
            }
            let expected = if name == "d4" { Reads::Down } else { Reads::Up };
            assert_eq!(die.reads, expected);
        }

        // The d6: 1 +z, 6 −z, 2 +x, 5 −x, 3 +y, 4 −y.
        let d6 = named("d6", None).unwrap();
        let want = [
            (Vector3::z(), "1"),
            (-Vector3::z(), "6"),
            (Vector3::x(), "2"),
            (-Vector3::x(), "5"),
            (Vector3::y(), "3"),
            (-Vector3::y(), "4"),
        ];
        for (n, label) in want {
            let got = d6
                .labels
                .iter()
                .find(|(m, _)| (m - n).norm() < 1e-12)
                .unwrap();
            assert_eq!(got.1, label, "d6 face {n:?}");
        }
        // Right-handed: 1, 2, 3 counter-clockwise seen from outside their common corner.
        let corner = Vector3::new(1.0, 1.0, 1.0);
        assert!(Vector3::z().cross(&Vector3::x()).dot(&corner) > 0.0);

        // The d10: odd labels meet at one apex, even at the other.
        let d10 = named("d10", None).unwrap();
        for (n, label) in &d10.labels {
            let odd = label.parse::<usize>().unwrap() % 2 == 1;
            assert_eq!(odd, n.z < 0.0, "d10 label {label} at {n:?}");
        }
    }

    #[test]
    fn prism_dice() {
        let die = named("prism:6,16,30", None).unwrap();
        die.mesh.check().unwrap();
        let fs = facets(&die.mesh, COPLANAR_TOLERANCE);
        assert_eq!(fs.len(), 8);
        assert_eq!(die.labels.len(), 8);
        for (n, _) in &die.labels {
            assert!(fs.iter().any(|f| (f.normal - n).norm() < 1e-12));
        }
        assert_eq!(die.labels[0].1, "1");
        assert!((die.labels[0].0 - Vector3::x()).norm() < 1e-15);
        assert_eq!(die.labels[6].1, "top");
        assert_eq!(die.labels[7].1, "bottom");
        let mp = die.mesh.mass_properties();
        let hexagon = 3.0 * 3f64.sqrt() / 2.0 * 64.0;
        assert!(close(mp.volume, hexagon * 30.0, 1e-12, 0.0));
        assert!(mp.centroid.norm() < 1e-12);
        let square = named("PRISM:4, 2, 40", None).unwrap();
        assert!(close(
            square.mesh.mass_properties().volume,
            2.0 * 40.0,
            1e-12,
            0.0
        ));
        for bad in [
            "prism:1000000,16,30",
            "prism:2,16,30",
            "prism:6,16",
            "prism:6,-1,30",
            "prism:x,1,1",
            "prism:6,1,inf",
        ] {
            let e = named(bad, None).unwrap_err();
            assert!(e.contains("prism:N,D,L") && !e.contains('\n'), "{e}");
        }
        assert!(named("prism:6,16,30", Some(3.0))
            .unwrap_err()
            .contains("no size"));
    }

    #[test]
    fn named_refuses_unknown_names_and_bad_sizes() {
        let e = named("d7", None).unwrap_err();
        assert!(e.contains("unknown die \"d7\""), "{e}");
        for s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(named("d6", Some(s))
                .unwrap_err()
                .contains("positive length"));
        }
        assert!(named(" D20 ", None).is_ok());
    }

    #[test]
    fn stability_of_faces() {
        for (name, _, _, _) in DICE {
            let die = named(name, None).unwrap();
            let com = die.mesh.mass_properties().centroid;
            for f in facets(&die.mesh, COPLANAR_TOLERANCE) {
                assert!(stable(&f, &com, 0.0), "{name}: every face stable");
                assert!(!stable(&f, &com, 100.0), "{name}: not by 100 mm");
            }
        }
        // An obtuse tetrahedron: its centroid (1, 1, 1/4) falls outside the base triangle.
        let tet = hull(&[
            Vector3::zeros(),
            Vector3::x(),
            Vector3::y(),
            Vector3::new(3.0, 3.0, 1.0),
        ])
        .unwrap();
        let com = tet.mass_properties().centroid;
        assert!((com - Vector3::new(1.0, 1.0, 0.25)).norm() < 1e-12);
        let fs = facets(&tet, COPLANAR_TOLERANCE);
        let base = fs
            .iter()
            .find(|f| (f.normal + Vector3::z()).norm() < 1e-12)
            .unwrap();
        assert!(!stable(base, &com, 0.0), "the base is not a resting face");
        assert!(fs.iter().any(|f| stable(f, &com, 0.0)), "some face is");

        // A long square prism: the sides are stable about the centroid but not about a point
        // beyond a cap; the margin is a length.
        let rod = named("prism:4,2,40", None).unwrap();
        let fs = facets(&rod.mesh, COPLANAR_TOLERANCE);
        let side = fs
            .iter()
            .find(|f| (f.normal - Vector3::x()).norm() < 1e-12)
            .unwrap();
        let half_width = 2f64.sqrt() / 2.0;
        assert!(stable(side, &Vector3::zeros(), 0.0));
        assert!(stable(side, &Vector3::zeros(), half_width * 0.99));
        assert!(!stable(side, &Vector3::zeros(), half_width * 1.01));
        assert!(stable(side, &Vector3::new(0.0, 0.0, 19.0), 0.0));
        assert!(!stable(side, &Vector3::new(0.0, 0.0, 21.0), 0.0));
    }
}
