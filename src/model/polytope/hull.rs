//! A convex hull and its facets: the hull of a point set, its faces with coplanar triangles
//! merged, and whether a die resting on a facet is in equilibrium.

use super::mesh::Mesh;
use nalgebra::Vector3;
use std::collections::HashMap;

/// Default angle (radians) within which the normals of two adjacent triangles count as the same
/// face in [`facets`]. Large enough for a mesh read from an STL file (single-precision
/// coordinates: a 1 mm triangle on a 20 mm die tilts by ~1e-6 rad from rounding alone), small
/// enough for any real die (adjacent faces differ by more than 0.3 rad) and for a 20 000-gon
/// prism (sides 3e-4 rad apart).
pub const COPLANAR_TOLERANCE: f64 = 1e-5;

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
