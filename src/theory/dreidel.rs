//! The slightly off-square (moderately biased) dreidel: section "The slightly off-square
//! dreidel". Its cross-section has sides k and l = (1 + δ)k, so R = l/k = 1 + δ; each of the four
//! sides has half its state's probability.

use serde::Serialize;
use std::f64::consts::{FRAC_PI_4, SQRT_2};

use super::{p_k_from_ratio, ratio_from_r};

/// d(P(L)/P(K))/dR at R = 1: 1 + sqrt(2) + 4/π (≈ 3.6874). The term 1 + sqrt(2) comes from the
/// energy factor of (MasterEqu), 4/π from the angle factor.
pub const SLOPE: f64 = 1.0 + SQRT_2 + 1.0 / FRAC_PI_4;

/// The exact ratio P(L)/P(K) at R = 1 + δ, equation (MasterEqu). δ ≤ −1 gives NaN.
pub fn ratio_exact(delta: f64) -> f64 {
    ratio_from_r(1.0 + delta)
}

/// The paper's expansion of (MasterEqu) about R = 1: P(L)/P(K) = 1 + (1 + sqrt(2) + 4/π)δ + O(δ²).
pub fn ratio_first_order(delta: f64) -> f64 {
    1.0 + SLOPE * delta
}

/// The chance of landing on each one of the dreidel's four sides.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DreidelSides {
    /// Each of the two sides of length l = (1 + δ)k: P(L)/2.
    pub each_l_side: f64,
    /// Each of the two sides of length k: P(K)/2.
    pub each_k_side: f64,
}

/// The four side probabilities from (MasterEqu) and (rattoprob), exactly: P(K)/2 and P(L)/2.
pub fn sides_exact(delta: f64) -> DreidelSides {
    let p_k = p_k_from_ratio(ratio_exact(delta));
    DreidelSides {
        each_l_side: (1.0 - p_k) / 2.0,
        each_k_side: p_k / 2.0,
    }
}

/// The paper's first-order side probabilities, 1/4 ± (1 + sqrt(2) + 4/π)/8 · δ (plus for the
/// l sides).
pub fn sides_first_order(delta: f64) -> DreidelSides {
    let shift = SLOPE / 8.0 * delta;
    DreidelSides {
        each_l_side: 0.25 + shift,
        each_k_side: 0.25 - shift,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_is_the_derivative_at_one() {
        let h = 1e-6;
        let d = (ratio_from_r(1.0 + h) - ratio_from_r(1.0 - h)) / (2.0 * h);
        assert!((d - SLOPE).abs() < 1e-8, "{d} vs {SLOPE}");
        assert!((SLOPE - 3.687_453).abs() < 1e-6);
    }

    #[test]
    fn papers_numbers_at_one_percent() {
        let delta = 0.01;
        // "P(K) = 1/2.03737 ≃ 0.4908"
        let p_k = p_k_from_ratio(ratio_exact(delta));
        assert!((1.0 / p_k - 2.03737).abs() < 5e-6, "1/P(K) = {}", 1.0 / p_k);
        assert!((p_k - 0.4908).abs() < 5e-5);
        // "0.4908/0.5 ≃ 0.9817"
        assert!((p_k / 0.5 - 0.9817).abs() < 5e-5);
        // "25.46 % ... as opposed to 24.54 %", exact and to first order.
        for s in [sides_exact(delta), sides_first_order(delta)] {
            assert!((100.0 * s.each_l_side - 25.46).abs() < 0.005, "{s:?}");
            assert!((100.0 * s.each_k_side - 24.54).abs() < 0.005, "{s:?}");
            assert!((2.0 * (s.each_l_side + s.each_k_side) - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn first_order_error_is_second_order() {
        // The remainder over δ² tends to half the second derivative (≈ 4.9 at R = 1).
        let rem = |d: f64| (ratio_exact(d) - ratio_first_order(d)) / (d * d);
        for delta in [0.02, 0.01, 0.005, -0.01, -0.005] {
            assert!(
                rem(delta) > 4.0 && rem(delta) < 6.0,
                "δ={delta}: {}",
                rem(delta)
            );
        }
        assert!((rem(0.001) - rem(-0.001)).abs() < 0.05);
        assert!(ratio_exact(-1.0).is_nan());
    }
}
