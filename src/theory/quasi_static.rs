//! The quasi-static theory of a made die: released at rest in a uniformly random orientation,
//! it rolls without bouncing down to a stable face. Which face is the end of the gradient flow
//! of the support function seen from the centre of mass (Baktash et al. 2025, "Putting rigid
//! bodies to rest"), the height of the centre of mass while the die touches the floor.
//!
//! For a box with half sides k (the inner box of a rounded die) and centre of mass c inside it,
//! with g the downward direction in body axes, that height is h(g) = Σ kᵢ|gᵢ| + r − c·g. Where
//! the die stands on a corner w = (sᵢkᵢ) − c, h = w·g + r is linear, and its flow on the sphere
//! runs along the great circle g(λ) ∝ g₀ − λw: each |gᵢ| falls as |g₀ᵢ| − λ dᵢ with
//! dᵢ = kᵢ − sᵢcᵢ, so every ratio |gᵢ|/dᵢ falls by the same λ. The first to reach 0 puts the die
//! on an edge, where (with |cⱼ| < kⱼ) the flow slides along it on the same rule in the two
//! coordinates left, and the last ratio standing is the face it ends on: the face (i, sᵢ) with
//! the largest |gᵢ|/dᵢ, which is the face the ray from c along g leaves the inner box through.
//! So a face's probability is the solid angle it subtends at the centre of mass, over 4π: for
//! a centred sharp cuboid, the paper's (Simpson's) solid angles; rounding changes it only
//! through the inner box's proportions (a rounded cube stays fair), a centre off the centre
//! through its distances to the faces.

use crate::model::die::DieBody;
use crate::model::shape::{Shape, Solid};
use nalgebra::Vector3;

/// The solid angle at the origin of the rectangle [x₁, x₂] × [y₁, y₂] in the plane at distance
/// `d`: Σ ± atan(xy / (d √(x² + y² + d²))) over its corners (the corner formula is odd in x and
/// in y, so the signed sum covers a rectangle on any side of the foot of the perpendicular).
pub fn rectangle(d: f64, [x1, x2]: [f64; 2], [y1, y2]: [f64; 2]) -> f64 {
    let f = |x: f64, y: f64| (x * y / (d * (x * x + y * y + d * d).sqrt())).atan();
    f(x2, y2) - f(x1, y2) - f(x2, y1) + f(x1, y1)
}

/// The probability of each face being up, in `faces::DIRECTIONS`' order (+x, −x, +y, −y, +z,
/// −z), for a die released at rest in a uniformly random orientation (3D): the solid angle of
/// the opposite face of the inner box, seen from the centre of mass, over 4π.
pub fn faces_up(die: &DieBody) -> [f64; 6] {
    let (k, c) = (die.core, die.com);
    std::array::from_fn(|d| {
        let i = d / 2;
        // Up +i means the −i face is down, and the other way round.
        let s = if d.is_multiple_of(2) { -1.0 } else { 1.0 };
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let dist = k[i] - s * c[i];
        rectangle(
            dist,
            [-k[j] - c[j], k[j] - c[j]],
            [-k[l] - c[l], k[l] - c[l]],
        ) / (4.0 * std::f64::consts::PI)
    })
}

/// The quasi-static probability of each outcome of a die of any shape, in its order
/// (`Shape::faces`), with its centre of mass at `com` (m, body axes, from the centroid). A hull:
/// the exact basins of the flow (`theory::basins`); a facet that is a resting face at this
/// centre but not among the die's outcomes (it was none at the centroid) keeps its share out
/// of the list, so the list sums to less than 1. A coin with its centre on its axis: each
/// cap's share is the cap of the sphere inside the cone from the centre of mass to the cap's
/// rim, (1 − d/√(r² + d²))/2 at the cap's distance d, and the edge has the rest (the flow on
/// a rim point's directions runs in its meridian, away from the rim: the solid angle).
pub fn shape(shape: &Shape, com: &Vector3<f64>) -> Result<Vec<f64>, String> {
    match &shape.solid {
        Solid::Cylinder { diameter, height } => {
            if com.xy().norm() > 1e-9 * diameter {
                return Err(
                    "the quasi-static theory of a coin is built for a centre of mass on its axis"
                        .into(),
                );
            }
            let r = 0.5 * diameter;
            let cap = |d: f64| 0.5 * (1.0 - d / r.hypot(d));
            // Heads rests on the −z cap (its outward normal −z), tails on the +z cap.
            let below = 0.5 * height + com.z;
            let above = 0.5 * height - com.z;
            Ok(shape
                .faces
                .iter()
                .map(|f| match f.normal[2] {
                    z if z < 0.0 => cap(below),
                    z if z > 0.0 => cap(above),
                    _ => 1.0 - cap(below) - cap(above),
                })
                .collect())
        }
        Solid::Hull { .. } => {
            let facets = shape.facets();
            let p = crate::theory::basins::facets(&facets, com)?;
            Ok(shape
                .faces
                .iter()
                .map(|f| {
                    let n = Vector3::from(f.normal);
                    facets
                        .iter()
                        .zip(&p)
                        .filter(|(x, _)| x.normal.dot(&n) > 1.0 - 1e-9)
                        .map(|(_, p)| p)
                        .sum()
                })
                .collect())
        }
    }
}

/// The quasi-static share of each label a scene's die shows, of the rolls that end on one of
/// its outcomes, each label once in the order of its outcomes (`Form::face_labels`): for every
/// die the solid angle of each resting face's basin seen from the centre of mass. A block's
/// numbers under `layout`, each by the face up ([`faces_up`], of its inner box); a die of any
/// shape's labels ([`shape_labels`], at its centre of mass; a facet that holds the die only at
/// this centre is no outcome). What `fair --null quasi-static` sets a run's counts and a
/// tester's against, and `roll`'s summary a die of any shape's; an error in 2D (the theory is
/// 3D) and where it is not built (a coin loaded off its axis).
pub fn label_shares(
    scene: &crate::model::scene::Scene,
    layout: crate::model::faces::Layout,
) -> Result<Vec<(String, f64)>, String> {
    if scene.mode != crate::model::scene::Mode::ThreeD {
        return Err("the quasi-static theory is 3D; in 2D give uniform".into());
    }
    let p = match scene.die.as_shape() {
        None => {
            let up = faces_up(&DieBody::of(scene));
            let numbers = layout.numbers().map(|n| n.to_string());
            numbers.into_iter().zip(up).collect()
        }
        Some(s) => shape_labels(s, &crate::model::mass::MassProps::compute(scene).com)?,
    };
    let listed: f64 = p.iter().map(|(_, q)| q).sum();
    Ok(p.into_iter().map(|(l, q)| (l, q / listed)).collect())
}

/// [`shape`] summed over the outcomes that show the same label, in the order of their first
/// appearance (`report::shape_outcomes::shape_faces`'s).
pub fn shape_labels(shape_: &Shape, com: &Vector3<f64>) -> Result<Vec<(String, f64)>, String> {
    Ok(shape_.by_label(shape(shape_, com)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::{Mode, Scene};

    fn die(block: &str, com: Option<[f64; 3]>, r: f64) -> DieBody {
        let mut s = Scene::paper(block.parse().unwrap(), Mode::ThreeD);
        s.features.com = com;
        s.features.edge_radius = r;
        DieBody::of(&s)
    }

    #[test]
    fn the_faces_fill_the_sphere_and_a_centred_block_is_simpsons() {
        for (block, com, r) in [
            ("140x24x20", None, 0.0),
            ("16x16x16", Some([0.001, -0.002, 0.003]), 0.0),
            ("16x16x15.8", Some([0.0, 0.0, -0.002]), 0.0015),
        ] {
            let p = faces_up(&die(block, com, r));
            assert!(
                (p.iter().sum::<f64>() - 1.0).abs() < 1e-13,
                "{block}: {p:?}"
            );
        }
        let block = "140x24x20".parse().unwrap();
        let (simpson, _) = crate::theory::simpson_3d(&block);
        let p = faces_up(&die("140x24x20", None, 0.0));
        // +x, −x up: the breadth vertical; ±y the width; ±z the length.
        assert!((p[0] + p[1] - simpson.breadth_vertical).abs() < 1e-13);
        assert!((p[2] + p[3] - simpson.width_vertical).abs() < 1e-13);
        assert!((p[4] + p[5] - simpson.length_vertical).abs() < 1e-13);
    }

    #[test]
    fn a_coin_is_the_cones_to_its_rims_and_a_named_die_is_fair() {
        let coin = crate::model::shape::coin(24.0, 2.0).unwrap();
        let p = shape(&coin, &Vector3::zeros()).unwrap();
        // r = 12, d = 1 mm: the edge 1/√145 (the classic three-way coin needs r = 2√2 d).
        assert!((p[2] - 1.0 / 145f64.sqrt()).abs() < 1e-12, "{p:?}");
        assert!((p[0] - p[1]).abs() < 1e-15 && (p.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let third = crate::model::shape::coin(24.0, 24.0 / 8f64.sqrt()).unwrap();
        let p = shape(&third, &Vector3::zeros()).unwrap();
        assert!((p[2] - 1.0 / 3.0).abs() < 1e-12, "{p:?}");
        // Loaded towards heads' cap (−z): heads more often.
        let p = shape(&coin, &Vector3::new(0.0, 0.0, -0.0002)).unwrap();
        assert!(p[0] > p[1], "{p:?}");
        assert!(shape(&coin, &Vector3::new(0.001, 0.0, 0.0)).is_err());
        let d20 = crate::model::shape::named("d20", None).unwrap();
        let p = shape_labels(&d20, &Vector3::zeros()).unwrap();
        assert_eq!(p.len(), 20);
        assert!(p.iter().all(|(_, q)| (q - 0.05).abs() < 1e-9), "{p:?}");
    }

    #[test]
    fn a_weight_toward_six_brings_one_up_and_rounding_keeps_a_cube_fair() {
        // A cube rounded at any radius is still a cube's inner box: every face 1/6.
        let p = faces_up(&die("16x16x16", None, 0.003));
        assert!(p.iter().all(|x| (x - 1.0 / 6.0).abs() < 1e-14), "{p:?}");
        // The centre 2 mm toward −z: −z down (+z up) more often, ±x and ±y alike.
        let p = faces_up(&die("16x16x16", Some([0.0, 0.0, -0.002]), 0.0));
        assert!(
            p[4] > 1.0 / 6.0 && p[5] < 1.0 / 6.0 && p[4] > 1.5 * p[5],
            "{p:?}"
        );
        for d in 1..4 {
            assert!((p[d] - p[0]).abs() < 1e-14);
        }
        // At the limit of a centre on the −z face itself, the −z face fills half the sphere.
        let p = faces_up(&die("16x16x16", Some([0.0, 0.0, -0.008 + 1e-12]), 0.0));
        assert!((p[4] - 0.5).abs() < 1e-6, "{p:?}");
    }
}
