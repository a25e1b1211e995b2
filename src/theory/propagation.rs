//! Side-length uncertainties carried into R = width/breadth and into the predicted ratio of
//! equation (MasterEqu), to first order (independent Gaussian errors on breadth and width).
//!
//! σ_R = R sqrt((σ_b/b)² + (σ_w/w)²), σ_ratio = |d ratio/dR| σ_R,
//!
//! with the derivative taken analytically ([`d_ratio_d_r`]), not by finite differences.

use serde::Serialize;

use super::ratio_from_r;

/// d(P(L)/P(K))/dR of equation (MasterEqu), analytically. Writing the ratio as A·B with
/// A = R²(s + R)/(s + 1), s = sqrt(1 + R²), and B = arctan R / arctan(1/R):
///
/// d ln A/dR = 2/R + 1/s − R/(s(s + 1)),
/// d ln B/dR = (1/(1 + R²)) (1/arctan R + 1/arctan(1/R)),
///
/// and d ratio/dR = ratio · (d ln A/dR + d ln B/dR). At R = 1 this is 1 + sqrt(2) + 4/π.
/// Non-positive or non-finite R gives NaN.
pub fn d_ratio_d_r(r: f64) -> f64 {
    let ratio = ratio_from_r(r);
    if ratio.is_nan() {
        return f64::NAN;
    }
    let s = r.hypot(1.0);
    let d_ln_a = 2.0 / r + 1.0 / s - r / (s * (s + 1.0));
    let d_ln_b = (1.0 / r.atan() + 1.0 / r.recip().atan()) / (1.0 + r * r);
    ratio * (d_ln_a + d_ln_b)
}

/// R and the predicted ratio, each with its propagated one-standard-error uncertainty.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Propagated {
    /// R = width/breadth.
    pub r: f64,
    /// σ_R, propagated from the sides' errors.
    pub r_err: f64,
    /// The predicted ratio P(breadth vertical)/P(width vertical) of (MasterEqu).
    pub ratio: f64,
    /// Its error, |d ratio/dR| σ_R.
    pub ratio_err: f64,
}

/// σ_R = R sqrt((σ_b/b)² + (σ_w/w)²) for R = w/b.
pub fn r_err(breadth: f64, breadth_err: f64, width: f64, width_err: f64) -> f64 {
    (width / breadth) * (breadth_err / breadth).hypot(width_err / width)
}

/// R = width/breadth and the (MasterEqu) ratio with their errors, from the two sides and their
/// standard errors (any one length unit; the paper's table uses mm). Sides need not be ordered:
/// R > 1 gives the reciprocal labelling, as [`ratio_from_r`].
pub fn propagate(breadth: f64, breadth_err: f64, width: f64, width_err: f64) -> Propagated {
    let r = width / breadth;
    let r_err = r_err(breadth, breadth_err, width, width_err);
    Propagated {
        r,
        r_err,
        ratio: ratio_from_r(r),
        ratio_err: d_ratio_d_r(r).abs() * r_err,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_derivative_matches_central_difference() {
        for r in [0.05, 0.2, 1.0 / 3.0, 0.5, 0.72, 0.8333, 1.0, 1.3, 4.0] {
            let h = 1e-5 * r;
            let fd = (ratio_from_r(r + h) - ratio_from_r(r - h)) / (2.0 * h);
            let an = d_ratio_d_r(r);
            assert!((fd - an).abs() <= 1e-7 * an.abs(), "R={r}: {an} vs {fd}");
        }
        assert!(d_ratio_d_r(0.0).is_nan());
    }

    #[test]
    fn the_papers_140x24x20_block() {
        // Table: R = 0.833 ± 0.005, predicted 0.511 ± 0.013 (see paper_data for the rounding).
        let p = propagate(24.0, 0.1, 20.0, 0.1);
        assert!((p.r - 0.833).abs() < 0.0005);
        assert!((p.r_err - 0.005).abs() < 0.0005);
        assert!((p.ratio - 0.511).abs() < 0.0005);
        assert!(p.ratio_err > 0.012 && p.ratio_err < 0.013);
    }

    #[test]
    fn zero_tolerance_gives_zero_error() {
        let p = propagate(24.0, 0.0, 20.0, 0.0);
        assert_eq!((p.r_err, p.ratio_err), (0.0, 0.0));
    }
}
