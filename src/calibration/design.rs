//! The simulations a fit stands on: for each block (and mode) among the rows, the simulator
//! run at many parameter points spread over the free parameters' box, and a surrogate
//! ([`crate::inference::surrogate`]) fitted through them. The rolling itself is
//! [`crate::studies::fit`]'s; here are the points, the seeds and the result.
//!
//! The points are the box's 2^d corners, its centre, then a Halton sequence (bases 2, 3, 5, 7):
//! fixed in advance, so a run can be split over a cluster, resumed, or checked against another.
//! Each point rolls its own keyed throws (its seed is a hash of the run's seed, the block and
//! the point's number), so the points' counts are independent and the surrogate's covariance
//! is its simulation noise. Common throws across the points (one stream for all) were
//! measured against this: see [`crate::studies::fit`]'s documentation for why they were not
//! kept.
//!
//! Rows with the same block and mode share one design: their surfaces differ only in which
//! coordinates the likelihood reads the surrogate at.

use crate::calibration::data::DataRow;
use crate::calibration::params::{Axes, ModelSpec, Param};
use crate::error::{Error, Field, Result};
use crate::inference::surrogate::{DesignPoint, Surrogate};
use crate::model::block::Block;
use crate::model::scene::Mode;
use serde::{Deserialize, Serialize};

/// How densely each block is simulated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DesignSpec {
    /// Parameter points per block (at least the corners and the centre).
    pub points: usize,
    /// Rolls at each point.
    pub rolls: u64,
    /// The surrogate's polynomial degree (raised, up to `max_degree`, while it lacks fit).
    pub degree: usize,
    /// The highest degree tried.
    pub max_degree: usize,
    /// A second pass: every block simulated afresh over a box narrowed to the first pass's
    /// region ([`crate::calibration::narrow`]), and the fit made again there.
    pub refine: bool,
    /// Common random numbers: the same keyed throws at every point of a block, instead of
    /// independent ones (kept for comparison: docs/results/calibration.md measures both).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub common: bool,
}

impl Default for DesignSpec {
    fn default() -> Self {
        DesignSpec {
            points: 64,
            rolls: 500,
            degree: 3,
            max_degree: 4,
            refine: true,
            common: false,
        }
    }
}

impl DesignSpec {
    /// The surrogate's default degrees (first, highest) for a design of `outcomes` outcomes:
    /// 3 raised to 4 while it lacks fit, as the paper's blocks were calibrated; but 2 (not
    /// raised) for a die of more than six faces, whose outcomes share the design's events and
    /// whose degree-3 polynomials follow the design's noise. Measured on a d20 loaded 0.5, −0.3,
    /// −1.0 mm (6,000 throws, 64 points × 500 rolls, two passes): the joint 2σ region held the
    /// centre of mass in 12 of 20 repetitions at degree 3 (the truth's Δ(−2 ln L) averaging 6.3,
    /// χ²₃'s mean being 3) and in 13 of 16 over two seeds at degree 2; at degree 2 with the
    /// region bounded by the bootstrap that rolls the design again, in 28 of 30 over three.
    pub fn default_degrees(outcomes: usize) -> (usize, usize) {
        if outcomes > 6 {
            (2, 2)
        } else {
            (3, 4)
        }
    }

    /// The degrees given, each left out taken from [`DesignSpec::default_degrees`] for
    /// `outcomes` (the highest never below the first).
    pub fn degrees(
        degree: Option<usize>,
        max_degree: Option<usize>,
        outcomes: usize,
    ) -> (usize, usize) {
        let (d, m) = Self::default_degrees(outcomes);
        let degree = degree.unwrap_or(d);
        (degree, max_degree.unwrap_or(m.max(degree)))
    }

    /// Checks the sizes.
    pub fn validate(&self, dims: usize) -> Result<()> {
        let bad = |m: String| Err(Error::field(Field::Points, self.points, m));
        let corners = 1usize << dims.min(20);
        if self.points < corners + 1 {
            return bad(format!(
                "a design over {dims} parameters needs at least {} (its corners and centre)",
                corners + 1
            ));
        }
        let features = crate::inference::surrogate::exponents(dims, self.degree).len();
        if self.points < 2 * features {
            return bad(format!(
                "a degree-{} surrogate over {dims} parameters has {features} coefficients an \
                 outcome, and needs at least twice as many points ({})",
                self.degree,
                2 * features
            ));
        }
        if self.points > 100_000 {
            return Err(Error::field(Field::Points, self.points, "at most 100000"));
        }
        if self.rolls == 0 || self.rolls > crate::run::spec::MAX_ROLLS {
            return Err(Error::field(
                Field::PointRolls,
                self.rolls,
                format!("from 1 to {}", crate::run::spec::MAX_ROLLS),
            ));
        }
        if !(1..=6).contains(&self.degree) || self.max_degree < self.degree || self.max_degree > 6 {
            return bad(format!(
                "degree {}..{}: from 1 to 6, the highest not below the first",
                self.degree, self.max_degree
            ));
        }
        Ok(())
    }
}

/// The radical inverse of `i` in `base`: the Halton sequence's coordinate.
fn halton(mut i: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

/// The first `n` primes, the Halton sequence's bases.
fn primes(n: usize) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::with_capacity(n);
    let mut k = 2;
    while out.len() < n {
        if out.iter().all(|p| k % p != 0) {
            out.push(k);
        }
        k += 1;
    }
    out
}

/// Point `i` (from 1) of the Halton sequence in [0, 1)^dims.
pub fn halton_point(i: usize, dims: usize) -> Vec<f64> {
    primes(dims).into_iter().map(|b| halton(i, b)).collect()
}

/// The design's `n` points in [0, 1]^dims: the corners, the centre, then Halton points.
pub fn points(dims: usize, n: usize) -> Vec<Vec<f64>> {
    if dims == 0 {
        return vec![vec![]];
    }
    let mut out: Vec<Vec<f64>> = (0..1usize << dims)
        .map(|c| (0..dims).map(|j| ((c >> j) & 1) as f64).collect())
        .collect();
    out.push(vec![0.5; dims]);
    let mut i = 1;
    while out.len() < n.max(out.len()) {
        out.push(halton_point(i, dims));
        i += 1;
    }
    out.truncate(n.max(1 + (1 << dims)));
    out
}

/// A block simulated over the design.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Design {
    /// The block.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// Its coordinates: each free kind and its range.
    pub axes: Axes,
    /// True if its outcomes are the die's six faces (numbers 1 to 6), not the three sides.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub faces: bool,
    /// The rows' own die it was rolled as (a `die` column's), where not the fit's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub die: Option<String>,
    /// Each point and its counts of length, breadth and width vertical (or of faces 1 to 6).
    pub points: Vec<DesignPoint>,
    /// The points of earlier passes' designs of the same block that lie inside this one's box,
    /// in its unit coordinates ([`borrowed`]): the surrogate is fitted through them as well.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub borrowed: Vec<DesignPoint>,
    /// Rolls that did not settle on a face (unknown, unconverged or failed), over all points.
    pub unsettled: u64,
    /// Rolls made.
    pub rolls: u64,
    /// The surrogate through the points.
    pub surrogate: Surrogate,
}

impl Design {
    /// "140x24x20 3d", or its die's name ("d8 3d").
    pub fn name(&self) -> String {
        match &self.die {
            Some(d) => format!("{d} {}", self.mode.name()),
            None => format!("{} {}", self.block, self.mode.name()),
        }
    }
}

/// The points of the `earlier` designs of `d`'s block, mode and outcomes, over the same kinds,
/// that lie inside `d`'s box, in `d`'s unit coordinates. Each earlier box is counted once (a
/// design a later pass kept is the same rolls), and `d`'s own box not at all. Every point was
/// rolled on throws of its own (its seed a hash of its box and index), so the borrowed counts
/// are independent of `d`'s: a surrogate through both has all the rolls of a fit's passes in
/// the region, and the estimate is less a property of the box the last pass drew.
pub fn borrowed(d: &Design, earlier: &[Design]) -> Vec<DesignPoint> {
    let same_kinds = |e: &Design| {
        e.axes.len() == d.axes.len() && e.axes.iter().zip(&d.axes).all(|(a, b)| a.0 == b.0)
    };
    let mut seen: Vec<&Axes> = vec![&d.axes];
    let mut out = Vec::new();
    for e in earlier {
        let same = e.block == d.block && e.mode == d.mode && e.faces == d.faces && e.die == d.die;
        if !same || !same_kinds(e) || seen.contains(&&e.axes) {
            continue;
        }
        seen.push(&e.axes);
        for p in &e.points {
            let x: Vec<f64> =
                p.x.iter()
                    .zip(e.axes.iter().zip(&d.axes))
                    .map(|(&u, ((kind, from), (_, to)))| kind.coordinate(*to, kind.value(*from, u)))
                    .collect();
            // Inside, to the rounding of the round trip through the physical value.
            if x.iter().all(|&u| (-1e-9..=1.0 + 1e-9).contains(&u)) {
                out.push(DesignPoint {
                    x: x.iter().map(|u| u.clamp(0.0, 1.0)).collect(),
                    counts: p.counts.clone(),
                });
            }
        }
    }
    out
}

/// What one design simulates: a block, a mode, and its axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Key {
    /// The block.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// The free kinds and their ranges.
    pub axes: Axes,
    /// True if it counts faces, not sides.
    pub faces: bool,
    /// The row's own die, where a `die` column names one.
    pub die: Option<String>,
}

impl Key {
    /// The key of `row` under `model` with its parameters `params`.
    pub fn of(row: &DataRow, model: &ModelSpec, params: &[Param]) -> Key {
        Key {
            block: row.block,
            mode: row.mode,
            axes: model.axes(params, &model.row_dims(params, row)),
            faces: row.outcomes == crate::calibration::data::Outcomes::Faces,
            die: row.die.clone(),
        }
    }

    /// A name for its directory and its seeds: the block, the mode, and a hash of the axes.
    pub fn tag(&self) -> String {
        let axes: Vec<String> = self.axes.iter().map(|(k, r)| format!("{k}={r}")).collect();
        let h = fnv(&axes.join(","));
        let faces = if self.faces { "-faces" } else { "" };
        // A row's own die: its name's hash too (two dice may share a bounding box), a die
        // file's by its file name, so that its seeds do not move with the folder the command
        // runs in; a fit of one die keeps the tags, and so the seeds and checkpoints, it had.
        let die = self.die.as_ref().map_or(String::new(), |d| {
            let name = std::path::Path::new(d)
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or(d);
            format!("-die{:08x}", fnv(name) >> 32)
        });
        format!(
            "{}-{}{faces}{die}-{:08x}",
            self.block,
            self.mode.name(),
            h >> 32
        )
    }

    /// The seed of point `point`'s throws.
    pub fn seed(&self, seed: u64, point: usize) -> u64 {
        fnv(&format!("{seed}/{}/{point}", self.tag()))
    }

    /// The key `d` was simulated for.
    pub fn of_design(d: &Design) -> Key {
        Key {
            block: d.block,
            mode: d.mode,
            axes: d.axes.clone(),
            faces: d.faces,
            die: d.die.clone(),
        }
    }

    /// True if `d` is this key's design.
    pub fn is(&self, d: &Design) -> bool {
        d.block == self.block
            && d.mode == self.mode
            && d.axes == self.axes
            && d.faces == self.faces
            && d.die == self.die
    }
}

/// The distinct keys of `rows`, in first-seen order: rows with the same block, mode,
/// parameter ranges and outcomes share one design.
pub fn keys(rows: &[DataRow], model: &ModelSpec) -> Vec<Key> {
    let params = model.params(rows);
    let mut out: Vec<Key> = Vec::new();
    for r in rows {
        let k = Key::of(r, model, &params);
        if !out.contains(&k) {
            out.push(k);
        }
    }
    out
}

/// The distinct (block, mode) pairs of `rows`, in first-seen order.
pub fn blocks(rows: &[DataRow]) -> Vec<(Block, Mode)> {
    let mut out: Vec<(Block, Mode)> = Vec::new();
    for r in rows {
        if !out.contains(&(r.block, r.mode)) {
            out.push((r.block, r.mode));
        }
    }
    out
}

/// 64-bit FNV-1a of a text.
fn fnv(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The seed of one numbered set of throws of a block: FNV-1a of the run's seed, the block, the
/// mode and the number.
pub fn point_seed(seed: u64, block: Block, mode: Mode, point: usize) -> u64 {
    fnv(&format!("{seed}/{block}/{}/{point}", mode.name()))
}

/// The surrogate's probabilities over [length, breadth, width] (a 2D design: length 0).
pub fn three(p: &[f64], mode: Mode) -> Vec<f64> {
    match mode {
        Mode::ThreeD => p.to_vec(),
        Mode::TwoD => vec![0.0, p[0], p[1]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::throws::Range;

    #[test]
    fn the_design_starts_at_the_corners_and_fills_the_box() {
        let p = points(2, 20);
        assert_eq!(p.len(), 20);
        assert_eq!(
            &p[..5],
            &[
                vec![0.0, 0.0],
                vec![1.0, 0.0],
                vec![0.0, 1.0],
                vec![1.0, 1.0],
                vec![0.5, 0.5]
            ]
        );
        assert_eq!(p[5], vec![0.5, 1.0 / 3.0]);
        assert!(p.iter().all(|x| x.iter().all(|v| (0.0..=1.0).contains(v))));
        assert_eq!(points(0, 10), vec![Vec::<f64>::new()]);
        let b: Block = "140x24x20".parse().unwrap();
        assert_ne!(
            point_seed(1, b, Mode::ThreeD, 0),
            point_seed(1, b, Mode::ThreeD, 1)
        );
        assert_ne!(
            point_seed(1, b, Mode::ThreeD, 0),
            point_seed(1, b, Mode::TwoD, 0)
        );
    }

    /// A design over e and κ with `x` its points' unit coordinates, each counted (1, 2, 3).
    fn design(block: &str, e: (f64, f64), kappa: (f64, f64), xs: &[[f64; 2]]) -> Design {
        use crate::calibration::params::Kind;
        let points: Vec<DesignPoint> = xs
            .iter()
            .map(|x| DesignPoint {
                x: x.to_vec(),
                counts: vec![1, 2, 3],
            })
            .collect();
        Design {
            block: block.parse().unwrap(),
            mode: Mode::ThreeD,
            axes: vec![
                (Kind::E, Range::new(e.0, e.1)),
                (Kind::Kappa, Range::new(kappa.0, kappa.1)),
            ],
            faces: false,
            die: None,
            surrogate: Surrogate::fit(&points, 2, 3, 1),
            points,
            borrowed: vec![],
            unsettled: 0,
            rolls: 6 * xs.len() as u64,
        }
    }

    #[test]
    fn a_pass_borrows_the_earlier_points_inside_its_box_once_in_its_own_coordinates() {
        use crate::calibration::params::Kind;
        // The later box: e 0.3–0.5, κ 0–99 (κ is warped: log₁₀(1 + κ), so 9 is its middle).
        let d = design("140x24x20", (0.3, 0.5), (0.0, 99.0), &[[0.0, 0.0]]);
        // The whole range's design: e 0.05 + 0.75 u. Inside at u = 1/3 (e 0.3) and 0.4 (e 0.35)
        // with κ 9 (its unit coordinate 0.25 on 0–9999); out at e 0.8 and at κ 9999.
        let k9 = Kind::Kappa.coordinate(Range::new(0.0, 9999.0), 9.0);
        let whole = [[1.0 / 3.0, k9], [0.4, k9], [1.0, k9], [0.4, 1.0]];
        let first = design("140x24x20", (0.05, 0.8), (0.0, 9999.0), &whole);
        // The same box again (a pass that kept it), another block, and `d` itself add nothing.
        let other = design("100x24x20", (0.05, 0.8), (0.0, 9999.0), &whole);
        let got = borrowed(&d, &[first.clone(), first.clone(), other, d.clone()]);
        assert_eq!(got.len(), 2, "{got:?}");
        assert!(
            got[0].x[0].abs() < 1e-9 && (got[0].x[1] - 0.5).abs() < 1e-9,
            "{got:?}"
        );
        assert!((got[1].x[0] - 0.25).abs() < 1e-9, "{got:?}");
        assert_eq!(got[1].counts, vec![1, 2, 3]);
    }
}
