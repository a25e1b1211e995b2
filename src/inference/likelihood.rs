//! The likelihood of measured counts given simulated probabilities that carry their own noise.
//!
//! A row of data counts N throws over K outcomes, k = (k_1..k_K). The simulator does not give
//! the probabilities p exactly but an estimate p̂ with a covariance V (from the surrogate, see
//! [`super::surrogate`]). The measured counts are then modelled as multinomial given p, with p
//! itself Dirichlet-distributed about p̂ with the concentration c whose variance matches V,
//! Var(p_k) = p̂_k(1 − p̂_k)/(c + 1), summed over outcomes:
//!
//! c + 1 = Σ p̂_k(1 − p̂_k) / Σ V_kk.
//!
//! The counts' marginal law is the Dirichlet-multinomial,
//!
//! P(k) ∝ Γ(c)/Γ(N + c) · Π_k Γ(k_k + c p̂_k)/Γ(c p̂_k),
//!
//! which tends to the multinomial as the simulation's noise goes to zero (c → ∞) and is wider
//! than it by the factor (N + c)/(1 + c) in variance otherwise. So a row simulated with few
//! rolls cannot pull a fit harder than its simulation can resolve.

use nalgebra::DMatrix;

/// The largest concentration used: beyond it the simulation's noise is nothing beside any
/// count, and the multinomial is used.
pub const MAX_CONCENTRATION: f64 = 1e12;

/// The grouped probabilities of [`merge`] alone.
pub fn merge_p(p: &[f64], groups: &[Vec<usize>]) -> Vec<f64> {
    groups
        .iter()
        .map(|m| m.iter().map(|&k| p[k]).sum())
        .collect()
}

/// Merges outcomes into groups (outcomes counted together because their faces are congruent,
/// or a 2D row's two side outcomes): each group's probability is its members' sum, and the
/// covariance is summed over the members' pairs.
pub fn merge(p: &[f64], cov: &DMatrix<f64>, groups: &[Vec<usize>]) -> (Vec<f64>, DMatrix<f64>) {
    let g = groups.len();
    let pm = merge_p(p, groups);
    let mut cm = DMatrix::zeros(g, g);
    for (a, ma) in groups.iter().enumerate() {
        for (b, mb) in groups.iter().enumerate() {
            cm[(a, b)] = ma
                .iter()
                .map(|&i| mb.iter().map(|&j| cov[(i, j)]).sum::<f64>())
                .sum();
        }
    }
    (pm, cm)
}

/// The Dirichlet concentration whose variance matches the covariance's trace (see the module).
pub fn concentration(p: &[f64], cov: &DMatrix<f64>) -> f64 {
    let binomial: f64 = p.iter().map(|q| q * (1.0 - q)).sum();
    let noise: f64 = (0..p.len()).map(|k| cov[(k, k)].max(0.0)).sum();
    if noise <= 0.0 {
        return MAX_CONCENTRATION;
    }
    (binomial / noise - 1.0).clamp(1e-3, MAX_CONCENTRATION)
}

/// ln Γ(a + k) − ln Γ(a), the log of the rising factorial a(a+1)…(a+k−1): exactly for small k,
/// by ln Γ otherwise, and by its expansion k ln a + k(k−1)/2a when a dwarfs k.
fn ln_rising(a: f64, k: u64) -> f64 {
    if k == 0 {
        return 0.0;
    }
    let kf = k as f64;
    if k <= 16 {
        return (0..k).map(|i| (a + i as f64).ln()).sum();
    }
    if a > 1e8 * kf {
        return kf * a.ln() + kf * (kf - 1.0) / (2.0 * a);
    }
    use statrs::function::gamma::ln_gamma;
    ln_gamma(a + kf) - ln_gamma(a)
}

/// ln P(counts) under the Dirichlet-multinomial with mean `p` and concentration `c`, less the
/// multinomial coefficient (which does not depend on the parameters).
pub fn ln_dirichlet_multinomial(counts: &[u64], p: &[f64], c: f64) -> f64 {
    let n: u64 = counts.iter().sum();
    if c >= MAX_CONCENTRATION {
        return ln_multinomial(counts, p);
    }
    let mut ll = -ln_rising(c, n);
    for (&k, &q) in counts.iter().zip(p) {
        ll += ln_rising(c * q.max(1e-300), k);
    }
    ll
}

/// ln P(counts) under the multinomial with probabilities `p`, less its coefficient.
pub fn ln_multinomial(counts: &[u64], p: &[f64]) -> f64 {
    counts
        .iter()
        .zip(p)
        .filter(|(k, _)| **k > 0)
        .map(|(&k, &q)| k as f64 * q.max(1e-300).ln())
        .sum()
}

/// The same row's saturated log-likelihood (p = counts/N), the deviance's zero.
pub fn ln_saturated(counts: &[u64]) -> f64 {
    let n: u64 = counts.iter().sum();
    counts
        .iter()
        .filter(|k| **k > 0)
        .map(|&k| k as f64 * (k as f64 / n as f64).ln())
        .sum()
}

/// One row's Pearson χ² under the Dirichlet-multinomial: the quadratic form of the counts'
/// departures over the first K − 1 outcomes with the covariance N(N + c)/(1 + c)·(diag p − ppᵀ).
/// Outcomes with p = 0 and no count add nothing.
pub fn pearson(counts: &[u64], p: &[f64], c: f64) -> f64 {
    let n: u64 = counts.iter().sum();
    let nf = n as f64;
    let inflate = if c >= MAX_CONCENTRATION {
        1.0
    } else {
        (nf + c) / (1.0 + c)
    };
    // Σ_k (k_k − N p_k)² / (N p_k) is the multinomial quadratic form over all K outcomes.
    counts
        .iter()
        .zip(p)
        .filter(|(k, q)| **k > 0 || **q > 0.0)
        .map(|(&k, &q)| (k as f64 - nf * q).powi(2) / (nf * q.max(1e-300)))
        .sum::<f64>()
        / inflate
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dirichlet_multinomial_tends_to_the_multinomial() {
        let (k, p) = ([30u64, 50, 20], [0.3, 0.5, 0.2]);
        let m = ln_multinomial(&k, &p);
        let d = ln_dirichlet_multinomial(&k, &p, 1e9);
        assert!((m - d).abs() < 1e-4, "{m} {d}");
        // A noisy simulation (small c) flattens the likelihood: a far point loses less.
        let far = [0.2, 0.6, 0.2];
        let sharp = ln_dirichlet_multinomial(&k, &p, 1e9) - ln_dirichlet_multinomial(&k, &far, 1e9);
        let soft =
            ln_dirichlet_multinomial(&k, &p, 100.0) - ln_dirichlet_multinomial(&k, &far, 100.0);
        assert!(soft > 0.0 && soft < sharp, "{soft} {sharp}");
    }

    #[test]
    fn the_dirichlet_multinomial_is_a_distribution() {
        // Two outcomes, N = 6, c = 3: the probabilities with their coefficients sum to 1.
        let (p, c, n) = ([0.3, 0.7], 3.0, 6u64);
        let ln_choose = |n: u64, k: u64| -> f64 {
            (1..=n).map(|i| (i as f64).ln()).sum::<f64>()
                - (1..=k).map(|i| (i as f64).ln()).sum::<f64>()
                - (1..=n - k).map(|i| (i as f64).ln()).sum::<f64>()
        };
        let total: f64 = (0..=n)
            .map(|k| (ln_choose(n, k) + ln_dirichlet_multinomial(&[k, n - k], &p, c)).exp())
            .sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        // Its large-k branch (ln Γ) agrees with the product.
        let a = 2.5;
        let exact: f64 = (0..40).map(|i| (a + i as f64).ln()).sum();
        assert!((ln_rising(a, 40) - exact).abs() < 1e-9);
    }

    #[test]
    fn concentration_matches_the_variance() {
        let p = [0.25, 0.75];
        let v = 0.25 * 0.75 / 101.0;
        let cov = DMatrix::from_row_slice(2, 2, &[v, -v, -v, v]);
        assert!((concentration(&p, &cov) - 100.0).abs() < 1e-9);
        let (pm, cm) = merge(
            &[0.1, 0.2, 0.7],
            &DMatrix::identity(3, 3),
            &[vec![0, 1], vec![2]],
        );
        assert!((pm[0] - 0.3).abs() < 1e-15 && cm[(0, 0)] == 2.0 && cm[(0, 1)] == 0.0);
    }
}
