//! The paper's closed-form theory (section 2, "2D Theory").
//!
//! The paper's 2D block has sides k and l; state K rests on side k (so l is vertical, energy
//! ½mgl) and state L rests on side l. With R = l/k its main result is the ratio P(L)/P(K) of
//! equation (MasterEqu). In this project's words (see [`crate::model::block`]): k = breadth, l = width,
//! so R = width/breadth ≤ 1, L = "breadth vertical", K = "width vertical", and the ratio
//! N(breadth vertical)/N(width vertical) is below 1.
//!
//! The functions take R (or sides) positive and finite; anything else gives NaN, never a panic.
//!
//! Submodules: [`markov`] (the five-state chain the result is derived from), [`dreidel`] (the
//! slightly off-square expansion), [`propagation`] (side-length uncertainties into R and the
//! ratio).

use serde::Serialize;
use std::f64::consts::FRAC_2_PI;

use crate::model::block::Block;

pub mod basins;
pub mod dreidel;
pub mod markov;
pub mod null;
pub mod paper_data;
pub mod propagation;
pub mod quasi_static;
pub mod stats;

fn valid(r: f64) -> bool {
    r.is_finite() && r > 0.0
}

/// The 2D probability ratio P(L)/P(K) of equation (MasterEqu), with R = l/k:
///
/// P(L)/P(K) = (sqrt(1+R²) − 1)/(sqrt(1+R²) − R) · arctan R / arctan(1/R).
///
/// Evaluated in the algebraically equal form R²(s + R)/(s + 1) · arctan R / arctan(1/R),
/// s = sqrt(1+R²) (from s − 1 = R²/(s + 1) and s − R = 1/(s + R)), which has no cancellation
/// for small R. Valid on both sides of R = 1: `ratio_from_r(1/R) == 1/ratio_from_r(R)`, which
/// is the paper's relabelling of the sides. Non-positive or non-finite R gives NaN.
pub fn ratio_from_r(r: f64) -> f64 {
    if !valid(r) {
        return f64::NAN;
    }
    let s = r.hypot(1.0);
    r * r * (s + r) / (s + 1.0) * (r.atan() / r.recip().atan())
}

/// The same ratio from the two sides, equation (MasterEquM1):
///
/// P(L)/P(K) = (sqrt(k²+l²) − k)/(sqrt(k²+l²) − l) · arctan(l/k) / arctan(k/l).
///
/// For this project's blocks call it as `ratio_from_sides(breadth, width)`.
pub fn ratio_from_sides(k: f64, l: f64) -> f64 {
    if !valid(k) || !valid(l) {
        return f64::NAN;
    }
    ratio_from_r(l / k)
}

/// P(K) from the ratio P(L)/P(K), equation (rattoprob): P(K) = 1/(1 + P(L)/P(K)).
/// An infinite ratio gives 0; a negative or NaN ratio gives NaN.
pub fn p_k_from_ratio(ratio: f64) -> f64 {
    if ratio.is_nan() || ratio < 0.0 {
        return f64::NAN;
    }
    1.0 / (1.0 + ratio)
}

/// The two outcome probabilities of a 2D block (they sum to 1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SideProbabilities {
    /// P(L): the breadth stands upright (the block rests on a width face).
    pub breadth_vertical: f64,
    /// P(K): the width stands upright (the block rests on a breadth face).
    pub width_vertical: f64,
}

impl SideProbabilities {
    /// The probabilities from the ratio P(L)/P(K) = P(breadth vertical)/P(width vertical),
    /// equation (rattoprob).
    pub fn from_ratio(ratio: f64) -> SideProbabilities {
        let p_k = p_k_from_ratio(ratio);
        SideProbabilities {
            breadth_vertical: 1.0 - p_k,
            width_vertical: p_k,
        }
    }

    /// P(breadth vertical)/P(width vertical).
    pub fn ratio(&self) -> f64 {
        self.breadth_vertical / self.width_vertical
    }
}

/// The 2D theory's probabilities for R = width/breadth: equations (MasterEqu) and (rattoprob).
pub fn two_d(r: f64) -> SideProbabilities {
    SideProbabilities::from_ratio(ratio_from_r(r))
}

/// The "no bounce" (2D Simpson) probabilities, equation (InElasK): a block dropped inelastically
/// in a uniformly random orientation lands on the side whose angle it is over,
/// P_I(K) = arctan(k/l)/(π/2), P_I(L) = arctan(l/k)/(π/2).
/// With R = l/k = width/breadth: P(breadth vertical) = (2/π) arctan R.
pub fn no_bounce_2d(r: f64) -> SideProbabilities {
    if !valid(r) {
        return SideProbabilities {
            breadth_vertical: f64::NAN,
            width_vertical: f64::NAN,
        };
    }
    SideProbabilities {
        breadth_vertical: FRAC_2_PI * r.atan(),
        width_vertical: FRAC_2_PI * r.recip().atan(),
    }
}

/// The no-bounce ratio P_I(L)/P_I(K) = arctan R / arctan(1/R), from equation (InElasK).
pub fn no_bounce_ratio(r: f64) -> f64 {
    if !valid(r) {
        return f64::NAN;
    }
    r.atan() / r.recip().atan()
}

/// Simpson's 3D no-bounce probability (section 2, the unnumbered equation after (InElasK)) that
/// an a × b × c cuboid comes to rest on ONE given a × b face, i.e. with c vertical and that
/// particular face down:
///
/// P_I(c vertical) = (1/π) arctan(ab / (c sqrt(a² + b² + c²))).
///
/// This is the solid angle the face subtends at the centre, over 4π; a cube gives 1/6. The two
/// opposite faces of a pair together have twice this.
pub fn simpson_face(a: f64, b: f64, c: f64) -> f64 {
    if !valid(a) || !valid(b) || !valid(c) {
        return f64::NAN;
    }
    let diag = (a * a + b * b + c * c).sqrt();
    (a * b / (c * diag)).atan() / std::f64::consts::PI
}

/// The 3D no-bounce (Simpson) probabilities of each face pair of a block.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PairProbabilities {
    /// Breadth upright: resting on either length × width face.
    pub breadth_vertical: f64,
    /// Width upright: resting on either length × breadth face.
    pub width_vertical: f64,
    /// Length upright: standing on either end (breadth × width face).
    pub length_vertical: f64,
}

/// The 3D Simpson model for a block: each face pair's probability, 2 × [`simpson_face`],
/// divided by the sum of the three. The second value is that sum, the normalisation factor; the
/// six solid angles fill 4π, so it is 1 up to rounding and the division changes only the last
/// bits.
pub fn simpson_3d(block: &Block) -> (PairProbabilities, f64) {
    let (l, b, w) = (block.length, block.breadth, block.width);
    let breadth = 2.0 * simpson_face(l, w, b);
    let width = 2.0 * simpson_face(l, b, w);
    let length = 2.0 * simpson_face(b, w, l);
    let sum = breadth + width + length;
    (
        PairProbabilities {
            breadth_vertical: breadth / sum,
            width_vertical: width / sum,
            length_vertical: length / sum,
        },
        sum,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    /// (MasterEqu) exactly as printed, for comparison with the stable form.
    fn printed_form(r: f64) -> f64 {
        let s = (1.0 + r * r).sqrt();
        (s - 1.0) / (s - r) * (r.atan() / (1.0 / r).atan())
    }

    #[test]
    fn ratio_matches_the_printed_form() {
        for r in [
            0.05,
            0.2,
            1.0 / 3.0,
            0.5,
            0.72,
            0.8333,
            0.99,
            1.0,
            1.01,
            2.0,
            7.5,
        ] {
            assert!(close(ratio_from_r(r), printed_form(r), 1e-12), "R = {r}");
        }
        assert_eq!(ratio_from_r(1.0), 1.0);
    }

    #[test]
    fn ratio_for_the_papers_blocks() {
        // Printed in the paper's table to 3 decimals.
        assert!((ratio_from_r(20.0 / 24.0) - 0.511).abs() < 0.0005);
        assert!((ratio_from_r(13.0 / 22.0) - 0.146).abs() < 0.0005);
        assert!((ratio_from_r(10.0 / 30.0) - 0.019).abs() < 0.0005);
        assert!((ratio_from_sides(0.024, 0.020) - ratio_from_r(20.0 / 24.0)).abs() < 1e-15);
    }

    #[test]
    fn relabelling_the_sides_inverts_the_ratio() {
        for r in [1e-3, 0.1, 0.3, 0.5, 0.72, 0.9, 0.999, 1.0] {
            let a = ratio_from_r(1.0 / r);
            let b = 1.0 / ratio_from_r(r);
            assert!(close(a, b, 1e-12), "R = {r}: {a} vs {b}");
            assert!(close(
                ratio_from_sides(2.0, 2.0 * r),
                1.0 / ratio_from_sides(2.0 * r, 2.0),
                1e-12
            ));
        }
    }

    #[test]
    fn bad_r_is_nan() {
        for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(ratio_from_r(r).is_nan());
            assert!(no_bounce_ratio(r).is_nan());
            assert!(two_d(r).breadth_vertical.is_nan());
        }
        assert!(ratio_from_sides(0.0, 1.0).is_nan());
        assert!(simpson_face(1.0, -1.0, 1.0).is_nan());
        assert!(p_k_from_ratio(-0.5).is_nan());
        assert_eq!(p_k_from_ratio(f64::INFINITY), 0.0);
    }

    #[test]
    fn probabilities_from_ratio() {
        let p = two_d(20.0 / 24.0);
        assert!(close(p.breadth_vertical + p.width_vertical, 1.0, 1e-15));
        assert!(close(p.ratio(), ratio_from_r(20.0 / 24.0), 1e-12));
        assert!(close(
            p.width_vertical,
            1.0 / (1.0 + ratio_from_r(20.0 / 24.0)),
            1e-15
        ));
        let sq = two_d(1.0);
        assert_eq!(sq.breadth_vertical, 0.5);
    }

    #[test]
    fn no_bounce_is_the_angle_subtended() {
        for r in [0.2, 0.5, 0.8333, 1.0, 1.7] {
            let p = no_bounce_2d(r);
            assert!(close(p.breadth_vertical + p.width_vertical, 1.0, 1e-15));
            assert!(close(p.ratio(), no_bounce_ratio(r), 1e-12));
            // Closer to 1 than the bouncing theory, on the same side of 1.
            let t = ratio_from_r(r);
            if r < 1.0 {
                assert!(t < no_bounce_ratio(r) && no_bounce_ratio(r) < 1.0);
            }
        }
    }

    #[test]
    fn simpson_cube_is_a_third_per_pair() {
        let cube = Block::from_mm(10.0, 10.0, 10.0).unwrap();
        assert!(close(simpson_face(1.0, 1.0, 1.0), 1.0 / 6.0, 1e-15));
        let (p, sum) = simpson_3d(&cube);
        assert!((sum - 1.0).abs() < 1e-12);
        for v in [p.breadth_vertical, p.width_vertical, p.length_vertical] {
            assert!((v - 1.0 / 3.0).abs() < 1e-12);
        }
    }

    #[test]
    fn simpson_solid_angles_fill_the_sphere() {
        for dims in [
            (140.0, 24.0, 20.0),
            (782.0, 25.0, 18.0),
            (99.3, 43.9, 43.2),
            (5.0, 3.0, 1.0),
            (1000.0, 2.0, 1.0),
        ] {
            let b = Block::from_mm(dims.0, dims.1, dims.2).unwrap();
            let (p, sum) = simpson_3d(&b);
            assert!((sum - 1.0).abs() < 1e-12, "{dims:?}: sum {sum}");
            let total = p.breadth_vertical + p.width_vertical + p.length_vertical;
            assert!((total - 1.0).abs() < 1e-15);
            // The biggest faces down are likeliest: width vertical > breadth vertical > length.
            assert!(
                p.width_vertical >= p.breadth_vertical && p.breadth_vertical > p.length_vertical
            );
        }
    }

    #[test]
    fn simpson_long_block_tends_to_the_2d_no_bounce() {
        let b = Block::from_mm(1.0e4, 24.0, 20.0).unwrap();
        let (p, _) = simpson_3d(&b);
        let two = no_bounce_2d(b.r());
        assert!((p.breadth_vertical - two.breadth_vertical).abs() < 1e-3);
        assert!(p.length_vertical < 1e-3);
    }

    #[test]
    fn the_solid_angle_formula_is_simpsons() {
        // The validation's P(i) = (2/π) arctan(w_j w_k / (w_i |w|)), w the sides and i the
        // vertical one, is twice Simpson's one-face probability: simpson_3d is it, normalised.
        for dims in [
            (20.0, 20.0, 20.0),
            (40.0, 20.0, 20.0),
            (30.0, 20.0, 10.0),
            (140.0, 24.0, 20.0),
        ] {
            let b = Block::from_mm(dims.0, dims.1, dims.2).unwrap();
            let (l, br, w) = (b.length, b.breadth, b.width);
            let norm = (l * l + br * br + w * w).sqrt();
            let p = |wi: f64, wj: f64, wk: f64| FRAC_2_PI * (wj * wk / (wi * norm)).atan();
            let (s, _) = simpson_3d(&b);
            assert!((p(br, l, w) - s.breadth_vertical).abs() < 1e-14, "{dims:?}");
            assert!((p(w, l, br) - s.width_vertical).abs() < 1e-14, "{dims:?}");
            assert!((p(l, br, w) - s.length_vertical).abs() < 1e-14, "{dims:?}");
            let total = p(br, l, w) + p(w, l, br) + p(l, br, w);
            assert!((total - 1.0).abs() < 1e-14, "{dims:?}: {total}");
        }
        let cube = Block::from_mm(20.0, 20.0, 20.0).unwrap();
        assert!((simpson_3d(&cube).0.length_vertical - 1.0 / 3.0).abs() < 1e-15);
    }
}
