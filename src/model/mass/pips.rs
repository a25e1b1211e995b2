//! The pips' geometry: each pip's cavity and place, and where cavities on adjacent faces
//! overlap.

use super::features::{pattern, PipShape, Pips};
use super::moments::Moments;
use crate::model::faces::Layout;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// A pip's cavity along its axis z (0 at the face, inward): volume, ∫z dV, ∫z² dV and
/// ∫u² dV for either transverse axis u. The slice at depth z is a disc of radius s(z):
/// for a cap of a ball of radius ρ whose rim is the pip's circle, s² = ρ² − (z + ρ − h)².
/// Each integrand is a polynomial of degree at most 4 in z, so 3-point Gauss–Legendre is exact.
pub fn cavity(p: &Pips) -> [f64; 4] {
    let (h, half_d) = (p.depth, 0.5 * p.diameter);
    let rho = (half_d * half_d + h * h) / (2.0 * h);
    let s2 = |z: f64| match p.shape {
        PipShape::Cap => {
            // ρ² − (z + ρ − h)² = (h − z)(2ρ − h + z): no cancellation near the rim.
            (h - z) * (2.0 * rho - h + z)
        }
        PipShape::Cylinder => half_d * half_d,
    };
    let nodes = [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()];
    let weights = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let mut out = [0.0; 4];
    for (x, w) in nodes.iter().zip(weights) {
        let z = 0.5 * h * (1.0 + x);
        let s = s2(z);
        let dv = PI * s * w * 0.5 * h;
        out[0] += dv;
        out[1] += z * dv;
        out[2] += z * z * dv;
        out[3] += 0.25 * s * dv;
    }
    out
}

/// Every pip's place: its face's axis i, the face's sign (+1, −1), and its centre's
/// coordinates along the face's other two axes j = i+1, k = i+2 (mod 3), m.
pub fn pip_places(half: &Vector3<f64>, p: &Pips, layout: Layout) -> Vec<(usize, f64, f64, f64)> {
    let numbers = layout.numbers();
    let mut out = Vec::new();
    for (d, &n) in numbers.iter().enumerate() {
        let (i, sign) = (d / 2, if d.is_multiple_of(2) { 1.0 } else { -1.0 });
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        for &(u, v) in pattern(n) {
            out.push((
                i,
                sign,
                u * p.spacing * 2.0 * half[j],
                v * p.spacing * 2.0 * half[k],
            ));
        }
    }
    out
}

/// True if `x` (m, from the geometric centre) lies in the pip's cavity at `place`: at most
/// its depth below its face, within the cavity's slice there (`cavity`'s s(z)).
fn in_pip(p: &Pips, half: &Vector3<f64>, (i, sign, pj, pk): Place, x: &Vector3<f64>) -> bool {
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    let z = half[i] - sign * x[i];
    if !(0.0..=p.depth).contains(&z) {
        return false;
    }
    let r2 = (x[j] - pj).powi(2) + (x[k] - pk).powi(2);
    r2 <= match p.shape {
        PipShape::Cap => {
            let rho = (0.25 * p.diameter * p.diameter + p.depth * p.depth) / (2.0 * p.depth);
            (p.depth - z) * (2.0 * rho - p.depth + z)
        }
        PipShape::Cylinder => 0.25 * p.diameter * p.diameter,
    }
}

/// A pip's place (`pip_places`).
type Place = (usize, f64, f64, f64);

/// The box a pip's cavity lies in: its low and high corners.
fn pip_box(p: &Pips, half: &Vector3<f64>, (i, sign, pj, pk): Place) -> [Vector3<f64>; 2] {
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    let r = 0.5 * p.diameter;
    let (mut lo, mut hi) = (Vector3::zeros(), Vector3::zeros());
    let (a, b) = (sign * half[i], sign * (half[i] - p.depth));
    (lo[i], hi[i]) = (a.min(b), a.max(b));
    (lo[j], hi[j]) = (pj - r, pj + r);
    (lo[k], hi[k]) = (pk - r, pk + r);
    [lo, hi]
}

/// Cells a side of the grid each overlap of two pips is integrated on.
const OVERLAP_GRID: usize = 96;

/// What the die must be given back where pips on adjacent faces hollow out the same region
/// near their common edge or corner (moments at unit density, about the centre): a point in
/// m cavities was subtracted m times and must be subtracted once, so m − 1 times its weight
/// comes back (reliability round 5, class C: the die loses the union of its cavities).
/// Integrated by the midpoint rule on a 96³ grid over each two cavities' common box; a point
/// in m cavities is met by each of their m(m − 1)/2 pairs and counted 2/m each time. Kept per
/// die, so that a die rolled many times computes it once.
pub(super) fn pip_overlaps(half: &Vector3<f64>, p: &Pips, layout: Layout) -> Moments {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static KEPT: OnceLock<Mutex<HashMap<String, Moments>>> = OnceLock::new();
    let key = format!("{half:?} {p:?} {layout:?}");
    let kept = KEPT.get_or_init(Default::default);
    if let Some(m) = kept.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return *m;
    }
    let places = pip_places(half, p, layout);
    let mut total = Moments {
        mass: 0.0,
        first: Vector3::zeros(),
        second: Matrix3::zeros(),
    };
    for (n, &a) in places.iter().enumerate() {
        for &b in &places[n + 1..] {
            if a.0 == b.0 {
                continue; // one face (checked apart) or opposite faces (too far apart)
            }
            let ([alo, ahi], [blo, bhi]) = (pip_box(p, half, a), pip_box(p, half, b));
            let (lo, hi) = (alo.sup(&blo), ahi.inf(&bhi));
            if (0..3).any(|d| lo[d] >= hi[d]) {
                continue;
            }
            let cell = (hi - lo) / OVERLAP_GRID as f64;
            let dv = cell.x * cell.y * cell.z;
            for c in 0..OVERLAP_GRID.pow(3) {
                let g = OVERLAP_GRID;
                let at = Vector3::new(c % g, (c / g) % g, c / (g * g)).map(|i| i as f64 + 0.5);
                let x = lo + cell.component_mul(&at);
                if in_pip(p, half, a, &x) && in_pip(p, half, b, &x) {
                    let m = places.iter().filter(|&&q| in_pip(p, half, q, &x)).count();
                    let w = dv * 2.0 / m as f64;
                    total.mass += w;
                    total.first += x * w;
                    total.second += x * x.transpose() * w;
                }
            }
        }
    }
    kept.lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, total);
    total
}

/// The moments of one pip's cavity (unit density) about the geometric centre.
pub(super) fn pip_moments(
    half: &Vector3<f64>,
    c: &[f64; 4],
    (i, sign, pj, pk): (usize, f64, f64, f64),
) -> Moments {
    let [v, z1, z2, u2] = *c;
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    // A point of the cavity: xᵢ = sign (hᵢ − z), xⱼ = pⱼ + u, xₖ = pₖ + w.
    let hi = half[i];
    let mut first = Vector3::zeros();
    first[i] = sign * (hi * v - z1);
    first[j] = pj * v;
    first[k] = pk * v;
    let mut second = Matrix3::zeros();
    second[(i, i)] = hi * hi * v - 2.0 * hi * z1 + z2;
    second[(j, j)] = pj * pj * v + u2;
    second[(k, k)] = pk * pk * v + u2;
    second[(j, k)] = pj * pk * v;
    second[(i, j)] = pj * first[i];
    second[(i, k)] = pk * first[i];
    for (a, b) in [(i, j), (i, k), (j, k)] {
        second[(b, a)] = second[(a, b)];
    }
    Moments {
        mass: v,
        first,
        second,
    }
}
