//! A printed die's inner solid: the die offset inward by its wall, whose moments the sparse
//! infill takes back from the solid (`Features::shell`).
//!
//! The box's (rounded or sharp) is a closed form: a box of half sides h rounded with radius r,
//! offset inward by t, is the box of half sides h − t rounded with r − t, or sharp once t ≥ r.
//! A convex die's is the intersection of its facets' half-spaces, each moved inward by t. Its
//! corners are found through the dual: with the origin (the centroid) strictly inside, the
//! half-space n·x ≤ d − t is the point n/(d − t), the inner solid's facets are the points on
//! the convex hull of those points (a facet that the offset squeezes out falls inside it), and
//! each triangle of that hull is a corner: the x with x·q = 1 for its three points q. The
//! corners' hull is then integrated exactly (`Mesh::mass_properties`). Quickhull's
//! O(N log N) on the N facets, where intersecting every triple is O(N⁴): a designed hull has
//! hundreds of facets.

use super::moments::{rounded_box, Moments};
use crate::model::polytope::{self, Cylinder, VolumeIntegrals};
use crate::model::shape::{Shape, Solid};
use nalgebra::{Matrix3, Vector3};

/// The moments at unit density, about the geometric centre, of the box of half sides `half`
/// rounded with `radius`, offset inward by `wall` (less than its smallest half side).
pub(super) fn inner_box(half: &Vector3<f64>, radius: f64, wall: f64) -> Moments {
    let (volume, second) = rounded_box(&half.map(|h| h - wall), (radius - wall).max(0.0));
    Moments {
        mass: volume,
        first: Vector3::zeros(),
        second: Matrix3::from_diagonal(&second),
    }
}

/// The moments at unit density, about the die's centroid, of a convex die (a hull or a coin)
/// offset inward by `wall`; `None` where there is none to integrate (a wall at or past the
/// inradius, the inner solid flat: it holds no infill).
pub(super) fn inner_shape(shape: &Shape, wall: f64) -> Option<Moments> {
    let integrals = match &shape.solid {
        Solid::Cylinder { diameter, height } => {
            let (d, h) = (diameter - 2.0 * wall, height - 2.0 * wall);
            if !(d > 0.0 && h > 0.0) {
                return None;
            }
            Cylinder {
                diameter: d,
                height: h,
            }
            .mass_properties()
        }
        Solid::Hull { .. } => inner_hull(&shape.planes(), wall)?.mass_properties(),
    };
    Some(moments_of(&integrals))
}

/// The corners of the intersection of the half-spaces n·x ≤ d − `wall` (n unit, outward; the
/// origin inside every one of them, else `None`), as their convex hull.
pub fn inner_hull(planes: &[(Vector3<f64>, f64)], wall: f64) -> Option<polytope::Mesh> {
    if !planes.iter().all(|(_, d)| d - wall > 0.0) {
        return None;
    }
    let dual: Vec<Vector3<f64>> = planes.iter().map(|(n, d)| n / (d - wall)).collect();
    let hull = polytope::hull(&dual).ok()?;
    let size = planes.iter().map(|(_, d)| d - wall).fold(0.0, f64::max);
    let mut corners: Vec<Vector3<f64>> = Vec::new();
    for t in &hull.triangles {
        let q = t.map(|k| hull.vertices[k]);
        let m = Matrix3::from_rows(&[q[0].transpose(), q[1].transpose(), q[2].transpose()]);
        let x = m.lu().solve(&Vector3::repeat(1.0))?;
        // Four or more planes through one corner (a d8's apex) give it once per triangle.
        if !corners.iter().any(|c| (c - x).norm() <= 1e-12 * size) {
            corners.push(x);
        }
    }
    polytope::hull(&corners).ok()
}

/// A solid's moments about the origin from its volume, centroid and inertia about the
/// centroid: Σ r rᵀ about the centroid is tr(I)/2 − I, moved by V c cᵀ.
fn moments_of(v: &VolumeIntegrals) -> Moments {
    let about_centroid = Matrix3::identity() * (0.5 * v.inertia.trace()) - v.inertia;
    Moments {
        mass: v.volume,
        first: v.centroid * v.volume,
        second: about_centroid + v.centroid * v.centroid.transpose() * v.volume,
    }
}

/// The die's inradius: the distance from its centroid to its nearest facet (a coin: its
/// radius or half its height), m. The thickest wall a shell can have is less.
pub fn inradius(shape: &Shape) -> f64 {
    match &shape.solid {
        Solid::Cylinder { diameter, height } => (0.5 * diameter).min(0.5 * height),
        Solid::Hull { .. } => shape
            .planes()
            .iter()
            .map(|(_, d)| *d)
            .fold(f64::INFINITY, f64::min),
    }
}
