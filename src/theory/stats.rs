//! Counting statistics shared by the whole project: ratios and proportions of outcome counts
//! with their binomial errors, the distance between two measurements in standard errors, and χ².
//!
//! The paper (section "Experiment - 2D") estimates the probability ratio of outcomes L and K,
//! counted N_L and N_K times, as
//!
//! N_L/N_K ± sqrt(N_L N_K (N_L + N_K) / N_K⁴),
//!
//! and the probability as N_L/(N_L + N_K) ± sqrt(N_L N_K / (N_L + N_K)³). In this project L is
//! "breadth vertical" and K is "width vertical".
//!
//! Nothing here panics. Degenerate counts give IEEE values, as documented on each function:
//! infinities where a ratio has a zero denominator, NaN where a quantity is undefined.

use serde::{Deserialize, Serialize};

/// A ratio with its one-standard-error binomial error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ratio {
    /// The ratio.
    pub value: f64,
    /// Its binomial standard error.
    pub err: f64,
}

/// The paper's ratio N_L/N_K ± sqrt(N_L N_K (N_L + N_K) / N_K⁴).
///
/// With N_K = 0 the ratio is undefined as an estimate: value and error are +∞ when N_L > 0,
/// and NaN when both counts are 0. With N_L = 0 < N_K the ratio is 0 ± 0 (the binomial error
/// vanishes at the boundary; use [`proportion`]'s Wilson interval for an honest bound there).
pub fn ratio(n_l: u64, n_k: u64) -> Ratio {
    let (l, k) = (n_l as f64, n_k as f64);
    if n_k == 0 {
        let v = if n_l == 0 { f64::NAN } else { f64::INFINITY };
        return Ratio { value: v, err: v };
    }
    // sqrt(N_L N_K (N_L+N_K)/N_K⁴) = sqrt(N_L (N_L+N_K)/N_K³), written so as not to overflow.
    let value = l / k;
    let err = (value * (l + k) / (k * k)).sqrt();
    Ratio { value, err }
}

/// Two-sided 95 % normal quantile, used for the Wilson interval.
pub const Z95: f64 = 1.959_963_984_540_054;

/// A proportion k/n with its binomial error and Wilson 95 % score interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Proportion {
    /// The count of the outcome.
    pub k: u64,
    /// The number of trials.
    pub n: u64,
    /// k/n.
    pub value: f64,
    /// sqrt(p(1−p)/n), the usual binomial standard error.
    pub err: f64,
    /// Lower end of the Wilson 95 % interval.
    pub wilson_low: f64,
    /// Upper end of the Wilson 95 % interval.
    pub wilson_high: f64,
}

/// The proportion k/n ± sqrt(p(1−p)/n), with the Wilson 95 % interval
/// (p + z²/2n ± z·sqrt(p(1−p)/n + z²/4n²)) / (1 + z²/n).
///
/// n = 0, or k > n, gives NaN in every estimated field.
pub fn proportion(k: u64, n: u64) -> Proportion {
    if n == 0 || k > n {
        return Proportion {
            k,
            n,
            value: f64::NAN,
            err: f64::NAN,
            wilson_low: f64::NAN,
            wilson_high: f64::NAN,
        };
    }
    let nf = n as f64;
    let p = k as f64 / nf;
    let var = p * (1.0 - p) / nf;
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / nf;
    let centre = (p + z2 / (2.0 * nf)) / denom;
    let half = Z95 * (var + z2 / (4.0 * nf * nf)).sqrt() / denom;
    Proportion {
        k,
        n,
        value: p,
        err: binomial_err(p, n),
        wilson_low: (centre - half).max(0.0),
        wilson_high: (centre + half).min(1.0),
    }
}

/// √(p(1−p)/n): the binomial standard error of a proportion p over n trials (of a measured
/// one, `proportion(k, n).err`; of a predicted one, the error a measurement of it carries).
pub fn binomial_err(p: f64, n: u64) -> f64 {
    (p * (1.0 - p) / n as f64).sqrt()
}

/// The paper's probability N_L/(N_L + N_K) ± sqrt(N_L N_K / (N_L + N_K)³): the proportion of
/// L among the L and K outcomes (it equals [`proportion`]`(N_L, N_L + N_K)`).
/// Both counts 0 gives NaN.
pub fn probability(n_l: u64, n_k: u64) -> Proportion {
    match n_l.checked_add(n_k) {
        Some(n) => proportion(n_l, n),
        None => proportion(1, 0),
    }
}

/// How many standard errors apart two measurements a ± σ_a and b ± σ_b are:
/// (a − b) / sqrt(σ_a² + σ_b²). Signed: positive when a > b.
///
/// A zero (or non-finite) combined error gives NaN, as does any NaN input.
pub fn z_score(a: f64, a_err: f64, b: f64, b_err: f64) -> f64 {
    let combined = a_err.hypot(b_err);
    if combined.is_nan() || combined <= 0.0 || combined.is_infinite() {
        return f64::NAN;
    }
    (a - b) / combined
}

/// One comparison for χ²: a measurement and a prediction, each with its error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// The measured value.
    pub measured: f64,
    /// Its standard error.
    pub measured_err: f64,
    /// The predicted value.
    pub predicted: f64,
    /// Its standard error.
    pub predicted_err: f64,
}

impl Comparison {
    /// [`z_score`] of the measurement against the prediction.
    pub fn z(&self) -> f64 {
        z_score(
            self.measured,
            self.measured_err,
            self.predicted,
            self.predicted_err,
        )
    }
}

/// χ² = Σ z² over comparisons, with its degrees of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ChiSquare {
    /// χ², the sum of z² over the comparisons used.
    pub chi2: f64,
    /// Number of comparisons used: the prediction has no fitted parameter, so every comparison
    /// is one degree of freedom.
    pub dof: usize,
    /// Comparisons left out because their z was not finite (zero combined error, NaN, ∞).
    pub skipped: usize,
}

impl ChiSquare {
    /// The probability of a χ² at least this large by chance if the predictions are right:
    /// [`chi_square_p_value`]`(chi2, dof)`.
    pub fn p_value(&self) -> f64 {
        chi_square_p_value(self.chi2, self.dof)
    }
}

/// χ² over the comparisons whose z is finite; the others are counted in `skipped`.
/// No usable comparison gives χ² = 0 with dof = 0.
pub fn chi_square(rows: &[Comparison]) -> ChiSquare {
    let mut chi2 = 0.0;
    let mut dof = 0;
    let mut skipped = 0;
    for r in rows {
        let z = r.z();
        if z.is_finite() {
            chi2 += z * z;
            dof += 1;
        } else {
            skipped += 1;
        }
    }
    ChiSquare { chi2, dof, skipped }
}

/// The χ² value with `dof` degrees of freedom below which a share `level` of the
/// distribution lies (0.95: the 95 % point), by bisection on [`chi_square_p_value`].
pub fn chi_square_quantile(level: f64, dof: usize) -> f64 {
    let (mut lo, mut hi) = (0.0, 10.0 + 10.0 * dof as f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if 1.0 - chi_square_p_value(mid, dof) < level {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The upper tail P(χ²_dof ≥ chi2) (`statrs`'s χ² distribution). dof = 0, a negative or NaN
/// χ² give NaN.
pub fn chi_square_p_value(chi2: f64, dof: usize) -> f64 {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    if dof == 0 || chi2.is_nan() || chi2 < 0.0 {
        return f64::NAN;
    }
    if chi2.is_infinite() {
        return 0.0;
    }
    match ChiSquared::new(dof as f64) {
        Ok(d) => d.sf(chi2),
        Err(_) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn ratio_is_the_papers_formula() {
        let r = ratio(178, 622);
        let (l, k) = (178.0f64, 622.0f64);
        assert!(close(r.value, l / k, 1e-15));
        let paper = (l * k * (l + k) / k.powi(4)).sqrt();
        assert!(close(r.err, paper, 1e-15));
    }

    #[test]
    fn ratio_error_is_the_propagated_probability_error() {
        // ratio = p/(1−p) ⇒ σ_ratio = σ_p/(1−p)².
        let (l, k) = (361u64, 639u64);
        let p = probability(l, k);
        let r = ratio(l, k);
        assert!(close(r.err, p.err / (1.0 - p.value).powi(2), 1e-15));
        let n = (l + k) as f64;
        let paper = ((l * k) as f64 / n.powi(3)).sqrt();
        assert!(close(p.err, paper, 1e-15));
    }

    #[test]
    fn zeros_are_documented_not_panics() {
        let r = ratio(5, 0);
        assert!(r.value.is_infinite() && r.err.is_infinite());
        let r = ratio(0, 0);
        assert!(r.value.is_nan() && r.err.is_nan());
        let r = ratio(0, 7);
        assert_eq!((r.value, r.err), (0.0, 0.0));
        assert!(probability(0, 0).value.is_nan());
        assert!(proportion(3, 2).value.is_nan());
        assert!(z_score(1.0, 0.0, 2.0, 0.0).is_nan());
        assert!(z_score(1.0, f64::NAN, 2.0, 0.1).is_nan());
        let p = probability(u64::MAX, 1);
        assert!(p.value.is_nan());
    }

    #[test]
    fn wilson_interval_known_values() {
        // 0 of 10: Wilson upper bound z²/(n+z²) = 0.2775.
        let p = proportion(0, 10);
        assert_eq!(p.wilson_low, 0.0);
        assert!(close(p.wilson_high, Z95 * Z95 / (10.0 + Z95 * Z95), 1e-12));
        // 5 of 10: symmetric about 1/2, [0.2366, 0.7634].
        let p = proportion(5, 10);
        assert!(close(p.wilson_low, 0.236_593, 1e-6));
        assert!(close(p.wilson_low + p.wilson_high, 1.0, 1e-12));
        // Contains the estimate.
        let p = proportion(178, 800);
        assert!(p.wilson_low < p.value && p.value < p.wilson_high);
    }

    #[test]
    fn z_and_chi_square() {
        assert!(close(z_score(1.0, 0.3, 0.5, 0.4), 1.0, 1e-15));
        assert!(close(z_score(0.5, 0.3, 1.0, 0.4), -1.0, 1e-15));
        let rows = [
            Comparison {
                measured: 1.0,
                measured_err: 0.3,
                predicted: 0.5,
                predicted_err: 0.4,
            },
            Comparison {
                measured: 2.0,
                measured_err: 1.0,
                predicted: 0.0,
                predicted_err: 0.0,
            },
            Comparison {
                measured: 2.0,
                measured_err: 0.0,
                predicted: 0.0,
                predicted_err: 0.0,
            },
        ];
        let c = chi_square(&rows);
        assert!(close(c.chi2, 5.0, 1e-12));
        assert_eq!((c.dof, c.skipped), (2, 1));
        let c = chi_square(&[]);
        assert_eq!((c.chi2, c.dof, c.skipped), (0.0, 0, 0));
        assert!(c.p_value().is_nan());
    }

    #[test]
    fn chi_square_p_values() {
        // Two degrees of freedom: exactly e^{−χ²/2}.
        for x in [0.1, 1.0, 2.0, 5.0, 20.0] {
            assert!(
                close(chi_square_p_value(x, 2), (-x / 2.0).exp(), 1e-13),
                "{x}"
            );
        }
        // Table values: the 95th percentiles.
        assert!(close(
            chi_square_p_value(3.841_458_820_694_124, 1),
            0.05,
            1e-10
        ));
        assert!(close(
            chi_square_p_value(11.070_497_693_516_351, 5),
            0.05,
            1e-10
        ));
        assert!(close(
            chi_square_p_value(18.307_038_053_275_146, 10),
            0.05,
            1e-10
        ));
        assert!(close(chi_square_p_value(0.0, 3), 1.0, 0.0));
        use statrs::function::gamma::ln_gamma;
        assert!(close(ln_gamma(5.0), 24f64.ln(), 1e-13));
        assert!(close(
            ln_gamma(0.5),
            std::f64::consts::PI.sqrt().ln(),
            1e-13
        ));
        assert!(chi_square_p_value(1.0, 0).is_nan());
        // The quantiles the p-values above name.
        assert!(close(
            chi_square_quantile(0.95, 1),
            3.841_458_820_694_124,
            1e-9
        ));
        assert!(close(
            chi_square_quantile(0.95, 5),
            11.070_497_693_516_351,
            1e-9
        ));
        assert!(chi_square_p_value(-1.0, 2).is_nan());
        assert_eq!(chi_square_p_value(f64::INFINITY, 2), 0.0);
    }
}
