//! The catalogue of named dice: d4 to d20 and N-gon prisms, each with its faces' labels and
//! how it is read.

use super::hull::{facets, hull, COPLANAR_TOLERANCE};
use super::mesh::Mesh;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which face's label is the result of a throw (`model::shape` re-exports it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reads {
    /// The face facing up (most dice).
    #[default]
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
pub(super) fn signs3() -> impl Iterator<Item = [f64; 3]> {
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
pub(super) fn d10_points() -> Vec<Vector3<f64>> {
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
pub(super) fn extrude(polygon: &[(f64, f64)], cap: &[[usize; 3]], z0: f64, z1: f64) -> Mesh {
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
pub(super) fn prism_mesh(n: usize, diameter: f64, length: f64) -> Mesh {
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
