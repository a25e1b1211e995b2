//! Mesh algebra: a closed triangle mesh and its exact volume integrals (volume, centroid,
//! inertia per unit density), and a cylinder's.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::f64::consts::PI;

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
pub struct VolumeIntegrals {
    /// The volume (length³), which is the mass at unit density.
    pub volume: f64,
    /// The centroid of the volume (centre of mass at uniform density).
    pub centroid: Vector3<f64>,
    /// About the centroid, in the mesh's axes, unit density.
    pub inertia: Matrix3<f64>,
}

impl VolumeIntegrals {
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
    pub fn mass_properties(&self) -> VolumeIntegrals {
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
            return VolumeIntegrals {
                volume,
                centroid: r0,
                inertia: Matrix3::zeros(),
            };
        }
        let c = first / (24.0 * volume); // centroid relative to r0
        let covariance = second / 120.0 - c * c.transpose() * volume;
        let inertia = Matrix3::identity() * covariance.trace() - covariance;
        VolumeIntegrals {
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

    pub(super) fn bounding_diagonal(&self) -> f64 {
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
    pub(super) fn compacted(&self) -> Mesh {
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
    pub fn mass_properties(&self) -> VolumeIntegrals {
        let r = self.diameter / 2.0;
        let h = self.height;
        let volume = PI * r * r * h;
        let side = volume * (3.0 * r * r + h * h) / 12.0;
        VolumeIntegrals {
            volume,
            centroid: Vector3::zeros(),
            inertia: Matrix3::from_diagonal(&Vector3::new(side, side, volume * r * r / 2.0)),
        }
    }
}
