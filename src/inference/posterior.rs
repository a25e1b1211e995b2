//! Draws from the posterior of the parameters, flat on their box (in unit coordinates), by
//! random-walk Metropolis: the spread a prediction inherits from the parameters.
//!
//! The proposal is Gaussian with the chain's own covariance, learnt during the burn-in
//! (scaled by 2.38²/d, the optimal rate for Gaussian targets); a proposal outside the box is
//! reflected back at its face, which keeps the proposal symmetric and so the flat prior exact.
//! Seeded, so the same likelihood and seed give the same draws.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn reflect(v: f64) -> f64 {
    // Fold the real line onto [0, 1]: …, −0.2 → 0.2, 1.3 → 0.7, 2.4 → 0.4, ….
    let m = v.rem_euclid(2.0);
    if m > 1.0 {
        2.0 - m
    } else {
        m
    }
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller.
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// `draws` points from the density ∝ exp(−f(x)/2) on [0, 1]^d (f is −2 ln L), after `burn`
/// steps of burn-in, keeping every `thin`-th step, from `start`.
pub fn sample(
    f: &dyn Fn(&[f64]) -> f64,
    start: &[f64],
    draws: usize,
    burn: usize,
    thin: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let d = start.len();
    if d == 0 || draws == 0 {
        return vec![start.to_vec(); draws];
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut x = start.to_vec();
    let mut fx = f(&x);
    let mut scale = DMatrix::<f64>::from_diagonal_element(d, d, 0.02);
    let mut chol = scale.clone().cholesky().expect("diagonal").l();
    let mut history: Vec<Vec<f64>> = Vec::new();
    let mut out = Vec::with_capacity(draws);
    let total = burn + draws * thin.max(1);
    for step in 0..total {
        let z = DVector::from_iterator(d, (0..d).map(|_| normal(&mut rng)));
        let dx = &chol * z;
        let y: Vec<f64> = (0..d).map(|i| reflect(x[i] + dx[i])).collect();
        let fy = f(&y);
        let accept = fy.is_finite() && (fy <= fx || rng.random::<f64>() < (-(fy - fx) / 2.0).exp());
        if accept {
            x = y;
            fx = fy;
        }
        if step < burn {
            history.push(x.clone());
            // Adapt the proposal to the chain's covariance at a few points of the burn-in.
            if history.len() >= 200 && step % (burn / 5).max(200) == 0 {
                let n = history.len() as f64;
                let mean: Vec<f64> = (0..d)
                    .map(|i| history.iter().map(|h| h[i]).sum::<f64>() / n)
                    .collect();
                let mut c = DMatrix::<f64>::zeros(d, d);
                for h in &history {
                    for i in 0..d {
                        for j in 0..d {
                            c[(i, j)] += (h[i] - mean[i]) * (h[j] - mean[j]) / (n - 1.0);
                        }
                    }
                }
                let s = 2.38 * 2.38 / d as f64;
                scale = c * s + DMatrix::from_diagonal_element(d, d, 1e-8);
                if let Some(l) = scale.clone().cholesky() {
                    chol = l.l();
                }
            }
        } else if (step - burn).is_multiple_of(thin.max(1)) {
            out.push(x.clone());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_draws_a_known_posterior() {
        // A Gaussian (0.4 ± 0.05, 0.6 ± 0.1) well inside the box: the draws' mean and spread
        // agree with it to within what 4,000 correlated draws resolve.
        let f = |x: &[f64]| ((x[0] - 0.4) / 0.05).powi(2) + ((x[1] - 0.6) / 0.1).powi(2);
        let s = sample(&f, &[0.5, 0.5], 4000, 4000, 5, 1);
        let n = s.len() as f64;
        for (i, (m, sd)) in [(0.4, 0.05), (0.6, 0.1)].iter().enumerate() {
            let mean = s.iter().map(|x| x[i]).sum::<f64>() / n;
            let var = s.iter().map(|x| (x[i] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            assert!((mean - m).abs() < 0.2 * sd, "{i}: mean {mean}");
            assert!(
                (var.sqrt() / sd - 1.0).abs() < 0.15,
                "{i}: sd {}",
                var.sqrt()
            );
        }
        // The same seed, the same draws.
        assert_eq!(s, sample(&f, &[0.5, 0.5], 4000, 4000, 5, 1));
    }

    #[test]
    fn a_flat_posterior_fills_the_box() {
        let f = |_: &[f64]| 0.0;
        let s = sample(&f, &[0.5], 4000, 1000, 5, 2);
        let mean = s.iter().map(|x| x[0]).sum::<f64>() / s.len() as f64;
        assert!((mean - 0.5).abs() < 0.05, "{mean}");
        assert!(s.iter().all(|x| (0.0..=1.0).contains(&x[0])));
        assert!((reflect(-0.2) - 0.2).abs() < 1e-15);
        assert!((reflect(1.3) - 0.7).abs() < 1e-15);
    }
}
