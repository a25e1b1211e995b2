//! A convex solid given by its facets' planes, offset: the facets moved in by a wall
//! ([`inner_hull`], a printed die's inner solid, a rounded die's inner body), and a hull swept
//! by a ball ([`rounded_hull`], a die with its edges and corners rounded).
//!
//! The inner solid's corners are found through the dual: with the origin strictly inside, the
//! half-space n·x ≤ d − t is the point n/(d − t), the inner solid's facets are the points on
//! the convex hull of those points (a facet the offset squeezes out falls inside it), and each
//! triangle of that hull is a corner: the x with x·q = 1 for its three points q. Quickhull's
//! O(N log N) on the N facets, where intersecting every triple is O(N⁴): a designed hull has
//! hundreds of facets.

use super::hull::hull as convex_hull;
use super::mesh::{Mesh, VolumeIntegrals};
use nalgebra::{Matrix3, Vector3};

/// The corners of the intersection of the half-spaces n·x ≤ d − `wall` (n unit, outward; the
/// origin inside every one of them, else `None`), as their convex hull.
pub fn inner_hull(planes: &[(Vector3<f64>, f64)], wall: f64) -> Option<Mesh> {
    if !planes.iter().all(|(_, d)| d - wall > 0.0) {
        return None;
    }
    let dual: Vec<Vector3<f64>> = planes.iter().map(|(n, d)| n / (d - wall)).collect();
    let hull = convex_hull(&dual).ok()?;
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
    convex_hull(&corners).ok()
}

/// How many directions spread over the sphere (a Fibonacci lattice) sweep the inner corners.
pub const DIRECTIONS: usize = 4000;

/// The die of facet planes `planes` (outward unit normal n, offset d from the origin, which
/// lies inside) rounded by `radius` > 0: its inner body's corners, and the rounded body's
/// volume integrals (its centroid in the planes' frame). `None` if the rounding leaves no
/// inner body (a radius at or past the inradius).
pub fn rounded_hull(
    planes: &[(Vector3<f64>, f64)],
    radius: f64,
) -> Option<(Vec<Vector3<f64>>, VolumeIntegrals)> {
    let inner = inner_hull(planes, radius)?;
    let mut sweep: Vec<Vector3<f64>> = planes.iter().map(|(n, _)| *n).collect();
    sweep.extend(fibonacci(DIRECTIONS));
    let points: Vec<Vector3<f64>> = inner
        .vertices
        .iter()
        .flat_map(|v| sweep.iter().map(move |u| v + u * radius))
        .collect();
    let body = convex_hull(&points).ok()?;
    Some((inner.vertices.clone(), body.mass_properties()))
}

/// `n` unit vectors spread evenly over the sphere: the Fibonacci lattice (equal areas in z,
/// turned by the golden angle).
fn fibonacci(n: usize) -> impl Iterator<Item = Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n).map(move |k| {
        let z = 1.0 - (2 * k + 1) as f64 / n as f64;
        let rho = (1.0 - z * z).sqrt();
        let phi = golden * k as f64;
        Vector3::new(rho * phi.cos(), rho * phi.sin(), z)
    })
}
