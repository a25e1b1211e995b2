//! The three outcomes of a 3D run as such: P(breadth vertical), P(width vertical) and
//! P(length vertical), each with its binomial error, beside the solid-angle (Simpson)
//! prediction, eq. after (InElasK): P(i vertical) = (2/π) arctan(w_j w_k / (w_i |w|))
//! (`theory::simpson_3d`). A thrown die bounces, so the paper expects the measured
//! probabilities to lean away from Simpson's towards the low-energy faces; the z says how far.

use crate::model::block::Block;
use crate::run::tally::Counts;
use crate::theory::{self, stats};
use serde::{Deserialize, Serialize};

/// One outcome's probability.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Probability {
    /// The count over the dice at rest on a face.
    pub p: f64,
    /// Its binomial standard error √(p(1−p)/n).
    pub err: f64,
    /// The solid-angle prediction.
    pub solid_angle: f64,
    /// (p − solid angle)/√(s(1−s)/n), s the solid angle: how many standard errors apart.
    pub z: f64,
}

impl Probability {
    /// `k` of `n` against the prediction `s`.
    pub fn of(k: u64, n: u64, s: f64) -> Probability {
        let p = stats::proportion(k, n);
        Probability {
            p: p.value,
            err: p.err,
            solid_angle: s,
            z: (p.value - s) / stats::binomial_err(s, n),
        }
    }
}

/// The three outcomes of a 3D run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcomes3d {
    /// Dice at rest on a face (breadth, width or length vertical): the denominator.
    pub n: u64,
    /// Breadth vertical.
    pub breadth: Probability,
    /// Width vertical.
    pub width: Probability,
    /// Length vertical.
    pub length: Probability,
}

impl Outcomes3d {
    /// The outcomes of `counts` for `block`; none if no die came to rest on a face.
    pub fn of(block: &Block, counts: &Counts) -> Option<Outcomes3d> {
        let n = counts.breadth + counts.width + counts.length;
        if n == 0 {
            return None;
        }
        let (s, _) = theory::simpson_3d(block);
        Some(Outcomes3d {
            n,
            breadth: Probability::of(counts.breadth, n, s.breadth_vertical),
            width: Probability::of(counts.width, n, s.width_vertical),
            length: Probability::of(counts.length, n, s.length_vertical),
        })
    }

    /// One line: each probability ± error (solid angle, z).
    pub fn line(&self) -> String {
        let f = |name: &str, p: &Probability| {
            format!(
                "P({name}) {:.4} ± {:.4} (solid angle {:.4}, {:+.1} σ)",
                p.p, p.err, p.solid_angle, p.z
            )
        };
        format!(
            "{}   {}   {}",
            f("breadth", &self.breadth),
            f("width", &self.width),
            f("length", &self.length)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_at_a_third_each_is_on_the_prediction() {
        let cube = Block::from_mm(20.0, 20.0, 20.0).unwrap();
        let c = Counts {
            breadth: 100,
            width: 100,
            length: 100,
            unknown: 7,
            face: 0,
        };
        let o = Outcomes3d::of(&cube, &c).unwrap();
        assert_eq!(o.n, 300);
        for p in [o.breadth, o.width, o.length] {
            assert!((p.p - 1.0 / 3.0).abs() < 1e-15);
            assert!((p.solid_angle - 1.0 / 3.0).abs() < 1e-12);
            assert!(p.z.abs() < 1e-9);
            assert!((p.err - (2.0f64 / 9.0 / 300.0).sqrt()).abs() < 1e-15);
        }
        assert!(Outcomes3d::of(&cube, &Counts::default()).is_none());
    }
}
