//! Proper scores of a prediction held against counts it did not see (issue 71.3): coverage alone
//! passes a vague prediction, so every held-out test reports three things.
//!
//! - **The log predictive density** ln P(counts | prediction), the multinomial coefficient
//!   included, under the prediction's own predictive distribution: a Dirichlet-multinomial whose
//!   mean is the predicted probabilities p and whose concentration c is moment-matched to what
//!   the prediction says of the counts' scatter. A prediction p ± σ (σ_k each probability's
//!   whole error) from a fit whose counts scatter φ times the binomial's (its overdispersion; 1
//!   for a fit that fits) says count k varies by
//!
//!     Var n_k = φ N p_k (1 − p_k) + N (N − 1) σ_k²,
//!
//!   the first term the throws' noise about the true share, the second the share's own
//!   uncertainty (E over θ of N θ(1 − θ) + N² Var θ, with E θ(1 − θ) = p(1 − p) − σ²). A
//!   Dirichlet-multinomial DM(N; c p) has Var n_k = N p_k (1 − p_k) (N + c)/(1 + c)
//!   = N p_k (1 − p_k) (1 + (N − 1)/(1 + c)). Summing both over k (one c for all outcomes) and
//!   writing S = Σ σ_k² / Σ p_k (1 − p_k):
//!
//!     (N − 1)/(1 + c) = φ − 1 + (N − 1) S,   so   1 + c = (N − 1)/(φ − 1 + (N − 1) S).
//!
//!   With φ = 1 this is 1 + c = 1/S: the Dirichlet's own Var θ_k = p_k (1 − p_k)/(1 + c)
//!   matches σ² on the whole. As σ → 0 and φ → 1, c → ∞ and the Dirichlet-multinomial becomes
//!   the multinomial with probabilities p ([`ln_predictive`], tested against that limit). The
//!   score is proper: its expectation under the counts' true law is highest for the true law.
//! - **Calibration**: Σz² = Σ_k (n_k − N p_k)²/(φ N p_k + N² σ_k²) over a row's outcomes, on
//!   outcomes − 1 degrees of freedom (Pearson's χ² widened by the prediction's error, as
//!   [`crate::calibration::heldout::test`] has it), and the coverage of each outcome's 1σ and 2σ
//!   intervals, z_k = (n_k − N p_k)/√(φ N p_k (1 − p_k) + N² σ_k²) (68.3 % and 95.4 % when
//!   honest).
//! - **Sharpness**: the mean predicted σ_k against the mean of the counts' own binomial σ,
//!   √(q_k (1 − q_k)/N) with q_k = n_k/N, as a ratio: 1 is a prediction as sharp as the counts
//!   that test it, 10 one that says ten times less than they do.

use crate::inference::likelihood::{ln_dirichlet_multinomial, MAX_CONCENTRATION};
use crate::theory::stats;
use serde::{Deserialize, Serialize};
use statrs::function::gamma::ln_gamma;

/// The three scores of predictions held against counts (one row's, or the sum over rows).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// ln P(counts | prediction), the multinomial coefficient included (summed over rows).
    pub log_score: f64,
    /// Σz²: Pearson's χ² widened by the prediction's error.
    pub chi2: f64,
    /// Its degrees of freedom: the outcomes counted less one, per row.
    pub dof: usize,
    /// P(χ²_dof ≥ Σz²).
    pub p_value: f64,
    /// Outcomes scored (the cells the coverage counts).
    pub cells: usize,
    /// Of which within the prediction's 1σ.
    pub within_one_sigma: usize,
    /// Of which within its 2σ.
    pub within_two_sigma: usize,
    /// The mean predicted σ of a probability.
    pub sigma_predicted: f64,
    /// The mean binomial σ of the counted shares.
    pub sigma_counts: f64,
    /// sigma_predicted / sigma_counts.
    pub sharpness: f64,
}

/// ln Γ(N + 1) − Σ ln Γ(n_k + 1): the multinomial coefficient of `counts`, ln.
pub(crate) fn ln_coefficient(counts: &[u64]) -> f64 {
    let n: u64 = counts.iter().sum();
    ln_gamma(n as f64 + 1.0)
        - counts
            .iter()
            .map(|&k| ln_gamma(k as f64 + 1.0))
            .sum::<f64>()
}

/// The concentration c of the Dirichlet-multinomial whose count variance, summed over the
/// outcomes, is φ N p(1 − p) + N (N − 1) σ² (the module's derivation); `f64::INFINITY` (the
/// multinomial) where the prediction adds nothing to the binomial's scatter.
pub fn concentration(p: &[f64], sigma: &[f64], n: u64, phi: f64) -> f64 {
    let binomial: f64 = p.iter().map(|q| q * (1.0 - q)).sum();
    let s = sigma.iter().map(|s| s * s).sum::<f64>() / binomial;
    let n1 = n.saturating_sub(1) as f64;
    let a = (phi - 1.0).max(0.0) + n1 * s;
    if a.is_nan() || a <= 0.0 || !s.is_finite() || n1 == 0.0 {
        return f64::INFINITY;
    }
    // The largest scatter a Dirichlet-multinomial has is c → 0 (every throw the same):
    // a prediction vaguer than that is held there.
    (n1 / a - 1.0).max(1e-6)
}

/// ln P(counts) under the Dirichlet-multinomial of mean `p` and concentration `c` (∞: the
/// multinomial), its coefficient included.
pub fn ln_predictive(counts: &[u64], p: &[f64], c: f64) -> f64 {
    let c = c.min(MAX_CONCENTRATION);
    ln_dirichlet_multinomial(counts, p, c) + ln_coefficient(counts)
}

/// One row's three scores: `counts` against the predicted probabilities `p` ± `sigma`, from a
/// fit of overdispersion `phi`. The probabilities are taken over the outcomes counted (scaled
/// to sum to 1, their errors with them).
pub fn score(counts: &[u64], p: &[f64], sigma: &[f64], phi: f64) -> Score {
    let norm: f64 = p.iter().sum();
    let p: Vec<f64> = p.iter().map(|q| q / norm).collect();
    let sigma: Vec<f64> = sigma.iter().map(|s| s / norm).collect();
    let n: u64 = counts.iter().sum();
    let nf = n as f64;
    let phi = phi.max(1.0);
    let c = concentration(&p, &sigma, n, phi);
    let log_score = ln_predictive(counts, &p, c);
    let (mut chi2, mut one, mut two) = (0.0, 0, 0);
    for ((&k, &q), &s) in counts.iter().zip(&p).zip(&sigma) {
        let miss = k as f64 - nf * q;
        let pearson = phi * nf * q + nf * nf * s * s;
        if pearson > 0.0 {
            chi2 += miss * miss / pearson;
        }
        let var = phi * nf * q * (1.0 - q) + nf * nf * s * s;
        let z = if var > 0.0 {
            miss / var.sqrt()
        } else if miss == 0.0 {
            0.0
        } else {
            f64::INFINITY
        };
        one += usize::from(z.abs() <= 1.0);
        two += usize::from(z.abs() <= 2.0);
    }
    let cells = counts.len();
    let dof = cells.saturating_sub(1);
    let sigma_predicted = sigma.iter().sum::<f64>() / cells as f64;
    let sigma_counts = counts
        .iter()
        .map(|&k| {
            let q = k as f64 / nf;
            (q * (1.0 - q) / nf).sqrt()
        })
        .sum::<f64>()
        / cells as f64;
    Score {
        log_score,
        chi2,
        dof,
        p_value: p_value(chi2, dof),
        cells,
        within_one_sigma: one,
        within_two_sigma: two,
        sigma_predicted,
        sigma_counts,
        sharpness: sigma_predicted / sigma_counts,
    }
}

fn p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        f64::NAN
    } else {
        stats::chi_square_p_value(chi2, dof)
    }
}

impl Score {
    /// The rows' scores summed: log scores, Σz², degrees of freedom and coverage added, the
    /// mean σs over every cell. `None` for no rows.
    pub fn total(rows: &[Score]) -> Option<Score> {
        if rows.is_empty() {
            return None;
        }
        let cells: usize = rows.iter().map(|r| r.cells).sum();
        let mean = |f: fn(&Score) -> f64| {
            rows.iter().map(|r| f(r) * r.cells as f64).sum::<f64>() / cells as f64
        };
        let chi2 = rows.iter().map(|r| r.chi2).sum();
        let dof = rows.iter().map(|r| r.dof).sum();
        let (sp, sc) = (mean(|r| r.sigma_predicted), mean(|r| r.sigma_counts));
        Some(Score {
            log_score: rows.iter().map(|r| r.log_score).sum(),
            chi2,
            dof,
            p_value: p_value(chi2, dof),
            cells,
            within_one_sigma: rows.iter().map(|r| r.within_one_sigma).sum(),
            within_two_sigma: rows.iter().map(|r| r.within_two_sigma).sum(),
            sigma_predicted: sp,
            sigma_counts: sc,
            sharpness: sp / sc,
        })
    }

    /// One line: the log score, Σz² with its dof and p, the coverage, the sharpness.
    pub fn line(&self) -> String {
        format!(
            "log score {:.2}; Σz² {:.1} on {} (p {}); within 1σ {}/{}, 2σ {}/{}; σ predicted \
             {:.4} against the counts' {:.4} (×{:.2})",
            self.log_score,
            self.chi2,
            self.dof,
            if self.p_value.is_finite() {
                format!("{:.2e}", self.p_value)
            } else {
                "—".into()
            },
            self.within_one_sigma,
            self.cells,
            self.within_two_sigma,
            self.cells,
            self.sigma_predicted,
            self.sigma_counts,
            self.sharpness
        )
    }
}

/// A prediction's scores beside its baselines', on the same counts.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// The prediction as given (with the fit's discrepancy where it has one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prediction: Option<Score>,
    /// The same prediction without the discrepancy (its shares unmoved, its error without the
    /// model's part); left out where the fit has none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub without_discrepancy: Option<Score>,
    /// The uncalibrated default scene: the fit's fixed values for every parameter it frees,
    /// simulated; its error is the simulation's alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default_scene: Option<Score>,
    /// The quasi-static theory (exact: no error), where it applies (a die of any shape).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quasi_static: Option<Score>,
}

impl Scores {
    /// The rows' scores summed, each kind over the rows that have it.
    pub fn total(rows: &[&Scores]) -> Scores {
        let of = |f: fn(&Scores) -> Option<Score>| {
            let v: Vec<Score> = rows.iter().filter_map(|r| f(r)).collect();
            // A kind some rows lack is not summed: its total would not be comparable.
            (v.len() == rows.len()).then(|| Score::total(&v)).flatten()
        };
        Scores {
            prediction: of(|s| s.prediction),
            without_discrepancy: of(|s| s.without_discrepancy),
            default_scene: of(|s| s.default_scene),
            quasi_static: of(|s| s.quasi_static),
        }
    }

    /// Which way the discrepancy moved the held-out log score, in a sentence; `None` where there
    /// is none to compare.
    pub fn discrepancy_verdict(&self) -> Option<String> {
        let (with, without) = (self.prediction?, self.without_discrepancy?);
        let d = with.log_score - without.log_score;
        Some(format!(
            "the discrepancy {} the held-out log score ({:+.2}: {:.2} with it, {:.2} without)",
            if d > 0.0 {
                "improved"
            } else if d < 0.0 {
                "worsened"
            } else {
                "left unchanged"
            },
            d,
            with.log_score,
            without.log_score
        ))
    }

    /// Text lines: each kind's scores, and the discrepancy's verdict.
    pub fn lines(&self, indent: &str) -> String {
        let mut s = String::new();
        for (name, v) in [
            ("prediction", self.prediction),
            ("without the discrepancy", self.without_discrepancy),
            ("default scene (uncalibrated)", self.default_scene),
            ("quasi-static theory", self.quasi_static),
        ] {
            if let Some(v) = v {
                s += &format!("{indent}{name}: {}\n", v.line());
            }
        }
        if let Some(v) = self.discrepancy_verdict() {
            s += &format!("{indent}{v}\n");
        }
        s
    }
}

/// One die's rows of a fit's leave-one-out (a `die` column's), predicted by a fit of the other
/// dice: their scores summed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DieScores {
    /// The die, as the rows name it.
    pub die: String,
    /// Its rows' labels.
    pub rows: Vec<String>,
    /// Their scores summed, beside the baselines'.
    pub scores: Scores,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exact_prediction_scores_as_the_multinomial() {
        // σ = 0, φ = 1: the multinomial's ln P, by hand: 5!/(2! 1! 2!) 0.2² 0.3 0.5².
        let (k, p) = ([2u64, 1, 2], [0.2, 0.3, 0.5]);
        let want = (30.0 * 0.04 * 0.3 * 0.25f64).ln();
        let s = score(&k, &p, &[0.0; 3], 1.0);
        assert!((s.log_score - want).abs() < 1e-12, "{} {want}", s.log_score);
        assert_eq!(concentration(&p, &[0.0; 3], 5, 1.0), f64::INFINITY);
        // The limit σ → 0: the Dirichlet-multinomial tends to it.
        for (sigma, tol) in [(1e-2, 0.1), (1e-4, 1e-4), (1e-6, 1e-8)] {
            let near = score(&k, &p, &[sigma; 3], 1.0).log_score;
            assert!((near - want).abs() < tol, "σ {sigma}: {near} {want}");
        }
    }

    #[test]
    fn a_hand_computed_beta_binomial() {
        // Two outcomes, p = (½, ½), σ = (0.25, 0.25), N = 2, φ = 1: S = 0.125/0.5 = ¼, so
        // 1 + c = 4, c = 3 (Var θ = p(1 − p)/(1 + c) = 1/16 = σ²). The beta-binomial
        // with α = β = 1.5: P(1, 1) = 2 · B(2.5, 2.5)/B(1.5, 1.5) = 2 · (1.5 · 1.5)/(3 · 4)
        // = 0.375 (the multinomial would give 0.5).
        let c = concentration(&[0.5, 0.5], &[0.25, 0.25], 2, 1.0);
        assert!((c - 3.0).abs() < 1e-12, "{c}");
        let s = score(&[1, 1], &[0.5, 0.5], &[0.25, 0.25], 1.0);
        assert!(
            (s.log_score - 0.375f64.ln()).abs() < 1e-12,
            "{}",
            s.log_score
        );
        // An overdispersion alone widens too: φ = 2, σ = 0, N = 2: 1 + c = 1/(φ − 1) = 1.
        let c = concentration(&[0.5, 0.5], &[0.0, 0.0], 2, 2.0);
        assert!(c.abs() < 1e-5, "{c}");
    }

    #[test]
    fn the_predictive_distribution_sums_to_one_and_a_vague_prediction_scores_lower() {
        // Every split of N = 6 between two outcomes, at p = 0.3 ± 0.1.
        let total: f64 = (0..=6u64)
            .map(|k| {
                score(&[k, 6 - k], &[0.3, 0.7], &[0.1, 0.1], 1.0)
                    .log_score
                    .exp()
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        // Counts at the prediction: sharp beats vague; the sharpness ratio says by how much.
        let sharp = score(&[300, 700], &[0.3, 0.7], &[0.005, 0.005], 1.0);
        let vague = score(&[300, 700], &[0.3, 0.7], &[0.15, 0.15], 1.0);
        assert!(sharp.log_score > vague.log_score + 1.0);
        assert!(
            sharp.sharpness < 0.5 && vague.sharpness > 9.0,
            "{sharp:?} {vague:?}"
        );
        assert_eq!((vague.within_one_sigma, vague.cells, vague.dof), (2, 2, 1));
    }

    #[test]
    fn totals_add_and_weigh_the_sigmas_by_cells() {
        let a = score(&[30, 70], &[0.3, 0.7], &[0.01, 0.01], 1.0);
        let b = score(&[10, 20, 70], &[0.1, 0.2, 0.7], &[0.02, 0.02, 0.02], 1.0);
        let t = Score::total(&[a, b]).unwrap();
        assert!((t.log_score - a.log_score - b.log_score).abs() < 1e-12);
        assert_eq!((t.dof, t.cells), (3, 5));
        assert!((t.sigma_predicted - (2.0 * 0.01 + 3.0 * 0.02) / 5.0).abs() < 1e-12);
        let with = Scores {
            prediction: Some(a),
            without_discrepancy: Some(b),
            ..Scores::default()
        };
        assert!(with.discrepancy_verdict().unwrap().contains("improved"));
    }
}
