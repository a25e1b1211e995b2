//! The die as the viewer draws it: its surface as polygons in body axes from its centre of
//! mass (the frame the trace's positions and quaternions move), the label printed on each,
//! and its outcomes' resting normals, from which the page reads the face a frame shows.

use crate::model::block::Side;
use crate::model::die::DieBody;
use crate::model::scene::{Mode, Scene};
use crate::model::shape::{Reads, Shape, Solid};
use nalgebra::Vector3;
use serde::Serialize;

/// A cylinder's rim is drawn as a polygon of this many sides.
const RIM_SIDES: usize = 32;

/// One flat piece of the die's surface.
#[derive(Debug, Serialize)]
pub struct Poly {
    /// Its corners, counter-clockwise seen from outside, m.
    pub corners: Vec<[f64; 3]>,
    /// The label printed on it, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// The pips drilled in it (a box with pips: they show its number), their centres on it, m.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pips: Vec<[f64; 3]>,
}

/// One outcome: the die resting on the face with this outward normal (body axes; a
/// cylinder's side: zero) shows `label`.
#[derive(Debug, Serialize)]
pub struct Resting {
    /// The face's outward normal, body axes.
    pub normal: [f64; 3],
    /// What the die shows resting on it.
    pub label: String,
}

/// The die the page draws.
#[derive(Debug, Serialize)]
pub struct DieView {
    /// What it is: `d20`, `coin:24,2`, `block 140x24x20`.
    pub name: String,
    /// Its surface.
    pub polys: Vec<Poly>,
    /// Its outcomes.
    pub outcomes: Vec<Resting>,
    /// The farthest any point of it is from its centre of mass, m (the camera's scale).
    pub reach: f64,
    /// A pip's radius on its face, m (0: no pips).
    #[serde(skip_serializing_if = "is_zero")]
    pub pip_radius: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Each rounded edge's quarter circle is drawn in this many flat strips (its two halves on the
/// two faces' sides).
const ROUND_STEPS: usize = 4;

/// Rounds to 0.1 µm: the page's coordinates.
fn round(v: &Vector3<f64>) -> [f64; 3] {
    v.map(|x| (x * 1e7).round() / 1e7).into()
}

impl DieView {
    /// The die of `scene`, whose body `die` is.
    pub fn of(scene: &Scene, die: &DieBody) -> DieView {
        match scene.die.as_shape() {
            Some(shape) => shaped(shape, &die.com),
            None => block(scene, die),
        }
    }
}

/// The cuboid: its six faces about its geometric centre (at −com from the centre of mass),
/// each with the number its layout puts there (`faces::DIRECTIONS`' order); resting on a ±x
/// face is "breadth vertical". Its pips are drawn where `pip_places` drills them, and rounded
/// edges ([`rounded_face`]) as the box swept by a sphere of the edge radius: each face's flat
/// middle carries its number, its rim the quarter circles of its edges and corners. In 2D its
/// 1 m depth is drawn as deep as its breadth.
fn block(scene: &Scene, die: &DieBody) -> DieView {
    let mut half = die.half;
    if scene.mode == Mode::TwoD {
        half.z = half.x.max(half.y);
    }
    let f = &scene.features;
    let r = f.edge_radius.clamp(0.0, half.min());
    let numbers = f.layout.numbers();
    let places = f
        .pips
        .map(|p| crate::model::mass::pip_places(&half, &p, f.layout))
        .unwrap_or_default();
    let mut polys = Vec::new();
    let mut outcomes = Vec::new();
    for (k, number) in numbers.iter().enumerate() {
        let (axis, sign) = (k / 2, if k % 2 == 0 { 1.0 } else { -1.0 });
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut n = Vector3::zeros();
        n[axis] = sign;
        let pips: Vec<[f64; 3]> = places
            .iter()
            .filter(|&&(i, s, _, _)| i == axis && s == sign)
            .map(|&(_, _, pu, pv)| {
                let mut c = n * half[axis];
                c[u] = pu;
                c[v] = pv;
                round(&(c - die.com))
            })
            .collect();
        for (corners, middle) in rounded_face(&half, r, axis, sign) {
            polys.push(Poly {
                corners: corners.iter().map(|c| round(&(c - die.com))).collect(),
                label: middle.then(|| number.to_string()),
                pips: if middle { pips.clone() } else { Vec::new() },
            });
        }
        let vertical = [Side::Breadth, Side::Width, Side::Length][axis];
        outcomes.push(Resting {
            normal: n.into(),
            label: format!("{} vertical", vertical.name()),
        });
    }
    let reach = (half + die.com.abs()).norm();
    let b = scene.die.block();
    DieView {
        name: format!(
            "block {}x{}x{}",
            b.length * 1e3,
            b.breadth * 1e3,
            b.width * 1e3
        ),
        polys,
        outcomes,
        reach,
        pip_radius: f.pips.map_or(0.0, |p| 0.5 * p.diameter),
    }
}

/// The face of the box of half sides `half` on `axis` at `sign`, its edges rounded with radius
/// `r`: quads about the geometric centre, counter-clockwise seen from outside, each marked
/// whether it is the face's flat middle. A point p of the face's grid is moved to q + r (p −
/// q)/|p − q|, q being p clamped to the inner box (the box less r on every side): the flat
/// middle stays, the rim's points go onto the quarter circles, half of each edge's on either
/// face. Sharp (r 0): the one quad.
fn rounded_face(
    half: &Vector3<f64>,
    r: f64,
    axis: usize,
    sign: f64,
) -> Vec<(Vec<Vector3<f64>>, bool)> {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let ticks = |h: f64| -> Vec<f64> {
        if r <= 0.0 {
            return vec![-h, h];
        }
        let band = |s: f64| {
            (0..=ROUND_STEPS).map(move |i| s * (h - r + r * i as f64 / ROUND_STEPS as f64))
        };
        let mut t: Vec<f64> = band(-1.0).collect();
        t.reverse();
        t.extend(band(1.0));
        t.dedup_by(|a, b| (*a - *b).abs() < 1e-15);
        t
    };
    let inner = half.map(|h| (h - r).max(0.0));
    let on_surface = |a: f64, b: f64| {
        let mut p = Vector3::zeros();
        p[axis] = sign * half[axis];
        p[u] = a;
        p[v] = b;
        if r <= 0.0 {
            return p;
        }
        let q = Vector3::new(
            p.x.clamp(-inner.x, inner.x),
            p.y.clamp(-inner.y, inner.y),
            p.z.clamp(-inner.z, inner.z),
        );
        let d = p - q;
        q + d * (r / d.norm())
    };
    let (tu, tv) = (ticks(half[u]), ticks(half[v]));
    let mut out = Vec::new();
    for i in 0..tu.len() - 1 {
        for j in 0..tv.len() - 1 {
            let (a0, a1, b0, b1) = (tu[i], tu[i + 1], tv[j], tv[j + 1]);
            // u × v = the axis: counter-clockwise about +n seen from outside, reversed for −n.
            let mut corners = vec![
                on_surface(a0, b0),
                on_surface(a1, b0),
                on_surface(a1, b1),
                on_surface(a0, b1),
            ];
            if sign < 0.0 {
                corners.reverse();
            }
            let middle = r <= 0.0
                || (a0 >= -inner[u] - 1e-15 && a1 <= inner[u] + 1e-15)
                    && (b0 >= -inner[v] - 1e-15 && b1 <= inner[v] + 1e-15);
            out.push((corners, middle));
        }
    }
    out
}

/// A die of any shape: its hull's facets (or a cylinder's caps and rim), each labelled as the
/// die reads it: the label it shows resting on the opposite facet (reading up), on this one
/// (reading down), or lying on it where no facet is opposite (`Reads::UpOrLying`).
fn shaped(shape: &Shape, com: &Vector3<f64>) -> DieView {
    let outcomes: Vec<Resting> = shape
        .faces
        .iter()
        .map(|f| Resting {
            normal: f.normal,
            label: f.label.clone(),
        })
        .collect();
    let printed = |n: &Vector3<f64>| printed_label(shape, n);
    let polys: Vec<Poly> = match &shape.solid {
        Solid::Hull { .. } => {
            let facets = if shape.radius > 0.0 {
                std::sync::Arc::new(rounded_facets(shape))
            } else {
                shape.facets()
            };
            facets
                .iter()
                .map(|f| Poly {
                    corners: f.polygon.iter().map(|p| round(&(p - com))).collect(),
                    label: printed(&f.normal),
                    pips: Vec::new(),
                })
                .collect()
        }
        Solid::Cylinder { diameter, height } => cylinder(0.5 * diameter, 0.5 * height, com)
            .into_iter()
            .map(|(corners, n)| Poly {
                corners,
                label: n.and_then(|n| printed(&n)),
                pips: Vec::new(),
            })
            .collect(),
    };
    let reach = polys
        .iter()
        .flat_map(|p| &p.corners)
        .map(|c| Vector3::from(*c).norm())
        .fold(0.0, f64::max);
    DieView {
        name: shape.name.clone(),
        polys,
        outcomes,
        reach,
        pip_radius: 0.0,
    }
}

/// A rounded die as drawn (`Shape::rounded`): its flat faces where they are, each of its inner
/// body's facets moved out by the radius, and its rounded edges and corners as the flat strips
/// and corners of the hull between them (the hull of every inner corner moved by the radius
/// along every facet's normal).
fn rounded_facets(shape: &Shape) -> Vec<crate::model::polytope::Facet> {
    use crate::model::polytope;
    let normals: Vec<Vector3<f64>> = shape.facets().iter().map(|f| f.normal).collect();
    let points: Vec<Vector3<f64>> = shape
        .points()
        .iter()
        .flat_map(|p| normals.iter().map(move |n| p + n * shape.radius))
        .collect();
    polytope::hull(&points)
        .map(|h| polytope::facets(&h, polytope::COPLANAR_TOLERANCE))
        .unwrap_or_default()
}

/// The label printed on the facet with outward normal `n`.
fn printed_label(shape: &Shape, n: &Vector3<f64>) -> Option<String> {
    let near = |m: &[f64; 3], sign: f64| Vector3::from(*m).dot(n) * sign > 1.0 - 1e-6;
    let find = |sign: f64| {
        shape
            .faces
            .iter()
            .find(|f| near(&f.normal, sign))
            .map(|f| f.label.clone())
    };
    match shape.reads {
        Reads::Down => find(1.0),
        Reads::Up => find(-1.0),
        Reads::UpOrLying => find(-1.0).or_else(|| {
            let opposite = shape.facets().iter().any(|g| g.normal.dot(n) < -0.999);
            if opposite {
                None
            } else {
                find(1.0)
            }
        }),
    }
}

/// A cylinder along z of radius `r` and half height `h` about its centroid (at −com): its two
/// caps (with their normals, for their labels) and its rim's quads.
type Piece = (Vec<[f64; 3]>, Option<Vector3<f64>>);
fn cylinder(r: f64, h: f64, com: &Vector3<f64>) -> Vec<Piece> {
    let at = |k: usize, z: f64| {
        let a = std::f64::consts::TAU * k as f64 / RIM_SIDES as f64;
        round(&(Vector3::new(r * a.cos(), r * a.sin(), z) - com))
    };
    let top: Vec<[f64; 3]> = (0..RIM_SIDES).map(|k| at(k, h)).collect();
    let bottom: Vec<[f64; 3]> = (0..RIM_SIDES).rev().map(|k| at(k, -h)).collect();
    let mut out = vec![(top, Some(Vector3::z())), (bottom, Some(-Vector3::z()))];
    for k in 0..RIM_SIDES {
        let j = (k + 1) % RIM_SIDES;
        out.push((vec![at(k, -h), at(j, -h), at(j, h), at(k, h)], None));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_d20_has_twenty_labelled_triangles() {
        let shape = crate::model::shape::named("d20", None).unwrap();
        let v = shaped(&shape, &Vector3::zeros());
        assert_eq!(v.polys.len(), 20);
        assert!(v
            .polys
            .iter()
            .all(|p| p.corners.len() == 3 && p.label.is_some()));
        let mut labels: Vec<u32> = v
            .polys
            .iter()
            .map(|p| p.label.as_ref().unwrap().parse().unwrap())
            .collect();
        labels.sort();
        assert_eq!(labels, (1..=20).collect::<Vec<_>>());
    }

    /// A rounded d20 is drawn with its twenty labelled faces where the sharp one's are (each
    /// face's plane as far from the centre) and unlabelled strips between them.
    #[test]
    fn a_rounded_d20_shows_its_faces_where_they_are_and_strips_between() {
        let sharp = crate::model::shape::named("d20", None).unwrap();
        let d = sharp.planes()[0].1;
        let v = shaped(&sharp.rounded(0.002).unwrap(), &Vector3::zeros());
        let labelled: Vec<&Poly> = v.polys.iter().filter(|p| p.label.is_some()).collect();
        assert_eq!(labelled.len(), 20);
        assert!(v.polys.len() > 20);
        for p in labelled {
            let c: Vector3<f64> = p
                .corners
                .iter()
                .map(|c| Vector3::from(*c))
                .sum::<Vector3<f64>>()
                / p.corners.len() as f64;
            // The corners are rounded to the µm for the page.
            assert!((c.norm() - d).abs() < 2e-6, "{} against {d}", c.norm());
        }
    }

    /// A 16 × 16 × 16 mm box with 3 mm pips 0.5 mm deep and edges rounded `r` mm, as drawn.
    fn box_view(r: f64) -> (DieView, Vector3<f64>) {
        use crate::model::block::Block;
        let mut scene = Scene::paper(Block::from_mm(16.0, 16.0, 16.0).unwrap(), Mode::ThreeD);
        scene.features.pips = Some(crate::model::mass::Pips::caps(3e-3, 0.5e-3));
        scene.features.edge_radius = r * 1e-3;
        let die = DieBody::of(&scene);
        (block(&scene, &die), die.com)
    }

    #[test]
    fn a_box_shows_its_pips_and_its_rounded_edges_where_they_are() {
        let h = 8e-3;
        for r in [0.0, 2.0] {
            let (v, com) = box_view(r);
            assert!((v.pip_radius - 1.5e-3).abs() < 1e-12);
            // Six labelled middles, each with as many pips as its number, on its face's plane.
            let faces: Vec<&Poly> = v.polys.iter().filter(|p| p.label.is_some()).collect();
            assert_eq!(faces.len(), 6, "r {r}");
            for f in &faces {
                let n: usize = f.label.as_ref().unwrap().parse().unwrap();
                assert_eq!(f.pips.len(), n, "face {n}, r {r}");
                let on = |c: &[f64; 3]| Vector3::from(*c) + com;
                let centre: Vector3<f64> = f.corners.iter().map(on).sum::<Vector3<f64>>() / 4.0;
                let axis = centre.iamax();
                for p in &f.pips {
                    assert!((on(p)[axis].abs() - h).abs() < 1e-6, "face {n}: {p:?}");
                }
            }
            assert_eq!(faces.iter().map(|f| f.pips.len()).sum::<usize>(), 21);
            // Every corner lies on the box swept by a sphere of radius r: at r from the inner
            // box (the box less r); its area is the swept box's, 2(AB + BC + CA) + 2πr(A + B +
            // C) + 4πr² for the inner sides A, B, C, within the quarter circles' chords (1 %).
            let (r, inner) = (r * 1e-3, h - r * 1e-3);
            let mut area = 0.0;
            for p in &v.polys {
                let c: Vec<Vector3<f64>> =
                    p.corners.iter().map(|c| Vector3::from(*c) + com).collect();
                for x in &c {
                    let d = x.map(|t| (t.abs() - inner).max(0.0)).norm();
                    assert!(
                        (d - r).abs() < 1e-6,
                        "{x:?} is {d} from the inner box, not {r}"
                    );
                }
                area += 0.5
                    * ((c[1] - c[0]).cross(&(c[2] - c[0])).norm()
                        + (c[2] - c[0]).cross(&(c[3] - c[0])).norm());
            }
            let a = 2.0 * inner;
            let want = 6.0 * a * a
                + 2.0 * std::f64::consts::PI * r * 3.0 * a
                + 4.0 * std::f64::consts::PI * r * r;
            assert!(
                (area / want - 1.0).abs() < 0.01,
                "r {r}: area {area} against {want}"
            );
            assert!(area <= want * (1.0 + 1e-9), "chords lie inside the arcs");
        }
        // Sharp: the six quads alone.
        assert_eq!(box_view(0.0).0.polys.len(), 6);
    }

    #[test]
    fn a_coin_has_two_labelled_caps_and_a_rim() {
        let shape = crate::model::shape::named("coin:24,2", None).unwrap();
        let v = shaped(&shape, &Vector3::zeros());
        assert_eq!(v.polys.len(), 2 + RIM_SIDES);
        assert_eq!(v.polys.iter().filter(|p| p.label.is_some()).count(), 2);
        assert!((v.reach - 0.012f64.hypot(0.001)).abs() < 1e-6);
    }
}
