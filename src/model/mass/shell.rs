//! A printed die's inner solid: the die offset inward by its wall, whose moments the sparse
//! infill takes back from the solid (`Features::shell`).
//!
//! The box's (rounded or sharp) is a closed form: a box of half sides h rounded with radius r,
//! offset inward by t, is the box of half sides h − t rounded with r − t, or sharp once t ≥ r.
//! A convex die's is the intersection of its facets' half-spaces, each moved inward by t
//! (`polytope::inner_hull`, through the dual: quickhull's O(N log N) on the N facets, where
//! intersecting every triple is O(N⁴), and a designed hull has hundreds of facets), its
//! corners' hull then integrated exactly (`Mesh::mass_properties`).

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
        Solid::Hull { .. } => polytope::inner_hull(&shape.planes(), wall)?.mass_properties(),
    };
    Some(moments_of(&integrals))
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
