//! The die as the viewer draws it: its surface as polygons in body axes from its centre of
//! mass (the frame the trace's positions and quaternions move), the label printed on each,
//! and its outcomes' resting normals, from which the page reads the face a frame shows.

use crate::model::block::Outcome;
use crate::model::die::DieShape;
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
}

/// Rounds to 0.1 µm: the page's coordinates.
fn round(v: &Vector3<f64>) -> [f64; 3] {
    v.map(|x| (x * 1e7).round() / 1e7).into()
}

impl DieView {
    /// The die of `scene`, whose body `die` is.
    pub fn of(scene: &Scene, die: &DieShape) -> DieView {
        match scene.shape.as_deref() {
            Some(shape) => shaped(shape, &die.com),
            None => block(scene, die),
        }
    }
}

/// The cuboid: its six faces about its geometric centre (at −com from the centre of mass),
/// each with the number its layout puts there (`faces::DIRECTIONS`' order); resting on a ±x face is "breadth vertical".
/// In 2D its 1 m depth is drawn as deep as its breadth.
fn block(scene: &Scene, die: &DieShape) -> DieView {
    let mut half = die.half;
    if scene.mode == Mode::TwoD {
        half.z = half.x.max(half.y);
    }
    let numbers = scene.features.layout.numbers();
    let mut polys = Vec::new();
    let mut outcomes = Vec::new();
    for (k, number) in numbers.iter().enumerate() {
        let (axis, sign) = (k / 2, if k % 2 == 0 { 1.0 } else { -1.0 });
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut n = Vector3::zeros();
        n[axis] = sign;
        let corner = |a: f64, b: f64| {
            let mut p = n * half[axis];
            p[u] = a * half[u];
            p[v] = b * half[v];
            round(&(p - die.com))
        };
        // u × v = the axis: counter-clockwise about +n seen from outside, reversed for −n.
        let mut corners = vec![
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        ];
        if sign < 0.0 {
            corners.reverse();
        }
        polys.push(Poly {
            corners,
            label: Some(number.to_string()),
        });
        let vertical = [Outcome::Breadth, Outcome::Width, Outcome::Length][axis];
        outcomes.push(Resting {
            normal: n.into(),
            label: format!("{} vertical", vertical.name()),
        });
    }
    let reach = (half + die.com.abs()).norm();
    let b = &scene.block;
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
    }
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
        Solid::Hull { .. } => shape
            .facets()
            .iter()
            .map(|f| Poly {
                corners: f.polygon.iter().map(|p| round(&(p - com))).collect(),
                label: printed(&f.normal),
            })
            .collect(),
        Solid::Cylinder { diameter, height } => cylinder(0.5 * diameter, 0.5 * height, com)
            .into_iter()
            .map(|(corners, n)| Poly {
                corners,
                label: n.and_then(|n| printed(&n)),
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
    }
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

    #[test]
    fn a_coin_has_two_labelled_caps_and_a_rim() {
        let shape = crate::model::shape::named("coin:24,2", None).unwrap();
        let v = shaped(&shape, &Vector3::zeros());
        assert_eq!(v.polys.len(), 2 + RIM_SIDES);
        assert_eq!(v.polys.iter().filter(|p| p.label.is_some()).count(), 2);
        assert!((v.reach - 0.012f64.hypot(0.001)).abs() < 1e-6);
    }
}
