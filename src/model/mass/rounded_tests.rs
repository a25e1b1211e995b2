//! A convex die with rounded edges (`Shape::rounded`, `rounded_hull`): its mass against two
//! closed forms (the rounded box's, and Steiner's volume of a polytope swept by a ball), its
//! outer faces kept, its labels kept, and what it refuses.

use super::*;
use crate::model::shape::{self, Reads, Shape};
use nalgebra::Vector3;
use std::f64::consts::PI;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// A box of half sides `h` (m) as a mesh: a die of any shape, not the cuboid.
fn box_mesh(h: [f64; 3]) -> Shape {
    let v: Vec<Vector3<f64>> = (0..8)
        .map(|i| {
            Vector3::new(
                if i & 1 == 0 { -h[0] } else { h[0] },
                if i & 2 == 0 { -h[1] } else { h[1] },
                if i & 4 == 0 { -h[2] } else { h[2] },
            )
        })
        .map(|v| v * 1e3)
        .collect();
    let mesh = crate::model::polytope::hull(&v).unwrap();
    shape::from_mesh(&mesh, "box".into(), None, Reads::Down).unwrap()
}

/// The inscribed polytope the mass is integrated over lies within r(1 − cos θ) of the rounded
/// surface: a box rounded by r through the general path has the rounded box's closed-form
/// volume and second moments (`rounded_box`: slabs, quarter cylinders and eighths of a ball)
/// to 3e-4 and 6e-4 (measured 2.0e-4 and 3.8e-4 on this 16 × 12 × 8 mm box at r = 2 mm, a
/// quarter of what 1,000 directions gave: the error falls as 1/N); ignoring the rounding
/// would miss the volume by 5 %.
#[test]
fn a_box_rounded_through_its_hull_has_the_rounded_boxs_closed_form_mass() {
    let h = [0.008, 0.006, 0.004];
    let r = 0.002;
    let s = box_mesh(h).rounded(r).unwrap();
    let (volume, second) = rounded_box(&Vector3::from(h), r);
    assert!(rel(s.volume, volume) < 3e-4, "{} {}", s.volume, volume);
    for i in 0..3 {
        assert!(
            rel(s.second[i], second[i]) < 6e-4,
            "{i}: {:?} {second}",
            s.second
        );
    }
    // The directions are not symmetric: products of inertia of a few parts in 10⁵.
    assert!(
        s.second[3..].iter().all(|x| x.abs() < 1e-4 * second[0]),
        "{:?}",
        s.second
    );
    assert!(rel(8.0 * h[0] * h[1] * h[2], volume) > 0.05);
    // It is no longer a box to the cuboid's closed forms, and it reaches as far as the box.
    assert!(s.as_box().is_none());
    let bb = s.bounding_box();
    assert!((0..3).all(|i| (bb[i] - 2.0 * h[i]).abs() < 1e-12), "{bb:?}");
}

/// Steiner's formula, exact for any convex body K swept by a ball: V(K ⊕ rB) is V + S r +
/// M r² + (4/3)π r³, M = ½ Σ over K's edges of length × exterior angle. For the d8 (a regular
/// octahedron, inradius ρ − r inside, edge a = ρ√6 at inradius ρ, exterior angle
/// π − arccos(−1/3)) the rounded d8's volume matches it to 1e-4 (measured 6.4e-5).
#[test]
fn a_rounded_octahedrons_volume_is_steiners() {
    let d8 = shape::named("d8", Some(16.0)).unwrap();
    let rho = d8.inradius();
    let r = 0.0015;
    let rounded = d8.rounded(r).unwrap();
    let a = (rho - r) * 6f64.sqrt();
    let v = 2f64.sqrt() / 3.0 * a.powi(3);
    let s = 2.0 * 3f64.sqrt() * a * a;
    let m = 0.5 * 12.0 * a * (PI - (-1.0f64 / 3.0).acos());
    let steiner = v + s * r + m * r * r + 4.0 / 3.0 * PI * r.powi(3);
    assert!(
        rel(rounded.volume, steiner) < 1e-4,
        "{} {steiner}",
        rounded.volume
    );
    // Its outer faces stay where the sharp die's were: each inner plane lies r inside one.
    for (n, d) in rounded.planes() {
        let (_, outer) = d8
            .planes()
            .into_iter()
            .find(|(m, _)| m.dot(&n) > 1.0 - 1e-12)
            .unwrap();
        // Within the few nm the rounded body's centroid moves from the sharp one's.
        assert!((d + r - outer).abs() < 1e-8, "{d} + {r} against {outer}");
    }
}

/// The designed die V1 rounded 1 mm keeps every label it shows, on the same outer faces; a
/// rounding past its inradius, a coin's, a second rounding and a rounding of 0 are refused or
/// are the die itself.
#[test]
fn a_rounded_die_keeps_its_labels_and_refuses_what_it_cannot_be() {
    let bytes = include_bytes!("../../../tests/data/hendecahedron_v1.obj");
    let mesh = crate::model::mesh_file::read_mesh(bytes, "hendecahedron_v1.obj").unwrap();
    let v1 = shape::from_mesh(&mesh.scaled(14.821972), "v1".into(), None, Reads::Down).unwrap();
    let rounded = v1.rounded(0.001).unwrap();
    assert_eq!(rounded.outcome_labels(), v1.outcome_labels());
    for (a, b) in rounded.faces.iter().zip(&v1.faces) {
        assert!(Vector3::from(a.normal).dot(&Vector3::from(b.normal)) > 1.0 - 1e-12);
    }
    assert!(rounded.volume < v1.volume && rounded.volume > 0.95 * v1.volume);
    assert_eq!(rounded.margin(), 0.001);
    assert!(rounded
        .rounded(0.001)
        .unwrap_err()
        .contains("rounded already"));
    let too_big = v1.rounded(v1.inradius() * 1.01).unwrap_err();
    assert!(too_big.contains("leaves no die"), "{too_big}");
    let coin = shape::named("coin:24,2", None).unwrap();
    assert!(coin.rounded(0.0005).is_err());
    assert_eq!(v1.rounded(0.0).unwrap(), v1);
}

/// Where a rounding goes (`take_rounding`): a box keeps it in its features (the cuboid's
/// closed forms), a d8 takes it in its hull, its features' radius then 0, and a coin refuses
/// it leaving both as they were; a rounding asked again of the same die at the same radius is
/// the one already made (`rounded_shared`), and another radius is another die.
#[test]
fn a_rounding_goes_to_a_boxs_features_or_a_hulls_shape_and_is_made_once() {
    use std::sync::Arc;
    let with_r = |r: f64| Features {
        edge_radius: r,
        ..Features::default()
    };
    let d6 = Arc::new(shape::named("d6", None).unwrap());
    let (mut s, mut f) = (Some(d6.clone()), with_r(0.001));
    take_rounding(s.as_mut(), &mut f).unwrap();
    assert!(Arc::ptr_eq(s.as_ref().unwrap(), &d6) && f.edge_radius == 0.001);
    let d8 = Arc::new(shape::named("d8", None).unwrap());
    let (mut s, mut f) = (Some(d8.clone()), with_r(0.001));
    take_rounding(s.as_mut(), &mut f).unwrap();
    let once = s.unwrap();
    assert_eq!(f.edge_radius, 0.0);
    assert_eq!(once.radius, 0.001);
    let (mut again, mut f) = (Some(d8.clone()), with_r(0.001));
    take_rounding(again.as_mut(), &mut f).unwrap();
    assert!(Arc::ptr_eq(&once, again.as_ref().unwrap()), "made twice");
    let other = rounded_shared(&d8, 0.0015).unwrap();
    assert_eq!(other.radius, 0.0015);
    assert_eq!(
        *rounded_shared(&d8, 0.001).unwrap(),
        d8.rounded(0.001).unwrap()
    );
    let coin = Arc::new(shape::named("coin:24,2", None).unwrap());
    let (mut s, mut f) = (Some(coin.clone()), with_r(0.0005));
    assert!(take_rounding(s.as_mut(), &mut f).is_err());
    assert!(Arc::ptr_eq(s.as_ref().unwrap(), &coin) && f.edge_radius == 0.0005);
    // No die of any shape: the cuboid's rounding, in its features.
    let (mut s, mut f) = (None, with_r(0.001));
    take_rounding(s.as_mut(), &mut f).unwrap();
    assert!(s.is_none() && f.edge_radius == 0.001);
}
