//! A smooth surrogate of the simulator: the outcome probabilities of one block as a function of
//! the parameters that move them, fitted to simulated counts at many parameter points.
//!
//! The model is a multinomial logit whose log-odds are polynomials of total degree ≤ D in the
//! parameters (each scaled to [−1, 1] and expanded in Legendre polynomials, which keeps the
//! fit well conditioned): for outcomes k = 1..K with the last as reference,
//!
//! ln(p_k / p_K) = β_kᵀ φ(x),   p = softmax(B φ(x)).
//!
//! It is fitted by maximum likelihood (Newton's method) on the counts of every design point,
//! with a small ridge penalty so that an outcome never seen (a block that never lands on its
//! end) gets a small, finite probability rather than −∞ log-odds. The design points must be
//! simulated on independent throws (one keyed stream each), so that their counts are
//! independent and the fit's inverse information is the coefficients' covariance; the lack of
//! fit (the deviance against its degrees of freedom) then says whether the degree suffices,
//! and a dispersion above 1 widens that covariance, so a surrogate too stiff for the
//! simulator is paid for in the likelihood's simulation noise, never hidden.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// The ridge penalty on every coefficient, λ‖β‖² (in counts: negligible beside thousands of
/// rolls, decisive only for an outcome that never occurs).
pub const RIDGE: f64 = 1e-3;

/// An outcome's polynomial keeps at least this many of its events per coefficient.
pub const EVENTS_PER_COEFFICIENT: f64 = 10.0;

/// Simulated counts at one parameter point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DesignPoint {
    /// The point in unit coordinates, each in [0, 1].
    pub x: Vec<f64>,
    /// Counts of each outcome (same order for every point).
    pub counts: Vec<u64>,
}

/// The Legendre polynomials P_0..=P_n at t in [−1, 1].
fn legendre(t: f64, n: usize) -> Vec<f64> {
    let mut p = vec![1.0; n + 1];
    if n >= 1 {
        p[1] = t;
    }
    for k in 2..=n {
        let kf = k as f64;
        p[k] = ((2.0 * kf - 1.0) * t * p[k - 1] - (kf - 1.0) * p[k - 2]) / kf;
    }
    p
}

/// The multi-indices of total degree ≤ `degree` in `dims` variables, graded (constant first).
pub fn exponents(dims: usize, degree: usize) -> Vec<Vec<usize>> {
    fn rec(dims: usize, left: usize, prefix: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if prefix.len() == dims {
            out.push(prefix.clone());
            return;
        }
        for e in 0..=left {
            prefix.push(e);
            rec(dims, left - e, prefix, out);
            prefix.pop();
        }
    }
    let mut out = Vec::new();
    rec(dims, degree, &mut Vec::new(), &mut out);
    out.sort_by_key(|e| (e.iter().sum::<usize>(), std::cmp::Reverse(e.clone())));
    out
}

/// The features φ(x) for unit coordinates `x`.
fn features(x: &[f64], exps: &[Vec<usize>], degree: usize) -> DVector<f64> {
    let polys: Vec<Vec<f64>> = x
        .iter()
        .map(|&u| legendre(2.0 * u.clamp(0.0, 1.0) - 1.0, degree))
        .collect();
    DVector::from_iterator(
        exps.len(),
        exps.iter()
            .map(|e| e.iter().enumerate().map(|(j, &k)| polys[j][k]).product()),
    )
}

fn softmax(eta: &[f64]) -> Vec<f64> {
    // The reference outcome has log-odds 0.
    let m = eta.iter().cloned().fold(0.0f64, f64::max);
    let mut p: Vec<f64> = eta.iter().map(|e| (e - m).exp()).collect();
    p.push((-m).exp());
    let s: f64 = p.iter().sum();
    p.iter_mut().for_each(|v| *v /= s);
    p
}

/// A fitted surrogate.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Surrogate {
    /// Parameters it depends on (their unit coordinates, in this order).
    pub dims: usize,
    /// Outcomes (the last is the reference).
    pub outcomes: usize,
    /// The polynomials' total degree.
    pub degree: usize,
    /// Each non-reference outcome's own degree (lower for a rare outcome).
    pub degrees: Vec<usize>,
    /// The exponents of each feature's Legendre polynomials ([`exponents`]).
    pub exps: Vec<Vec<usize>>,
    /// The coefficients, (outcomes − 1) × features, row-major.
    pub beta: Vec<f64>,
    /// Their covariance, widened by the dispersion when it is above 1, row-major, square of
    /// side (outcomes − 1) · features.
    pub cov: Vec<f64>,
    /// The deviance of the design's counts against the fit.
    pub deviance: f64,
    /// Its degrees of freedom: independent counts less coefficients.
    pub dof: usize,
    /// max(1, deviance/dof): how much the design scatters beyond the binomial noise.
    pub dispersion: f64,
}

/// What the surrogate says at a point: the probabilities and their covariance.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The outcome probabilities.
    pub p: Vec<f64>,
    /// Their covariance from the coefficients' (the simulation's noise, through the fit).
    pub cov: DMatrix<f64>,
}

impl Surrogate {
    /// The number of features.
    pub fn features(&self) -> usize {
        self.exps.len()
    }

    /// The penalised log-likelihood's gradient at `beta` (the score), and its information
    /// (minus its Hessian) into `info`, over the design's counts; `(k1, m)` the outcomes but
    /// the last and the features an outcome.
    fn score_and_information(
        beta: &DVector<f64>,
        counts: &[Vec<f64>],
        phis: &[DVector<f64>],
        ridge: &[f64],
        (k1, m): (usize, usize),
        info: &mut DMatrix<f64>,
    ) -> DVector<f64> {
        let size = k1 * m;
        let mut grad = DVector::from_iterator(size, (0..size).map(|i| -2.0 * ridge[i] * beta[i]));
        info.fill(0.0);
        for i in 0..size {
            info[(i, i)] = 2.0 * ridge[i];
        }
        for (c, phi) in counts.iter().zip(phis) {
            let nf: f64 = c.iter().sum();
            if nf == 0.0 {
                continue;
            }
            let p = Self::probs(beta, phi, k1, m);
            for a in 0..k1 {
                let r = c[a] - nf * p[a];
                for i in 0..m {
                    grad[a * m + i] += r * phi[i];
                }
                for b in 0..k1 {
                    let w = nf * (if a == b { p[a] } else { 0.0 } - p[a] * p[b]);
                    if w == 0.0 {
                        continue;
                    }
                    for i in 0..m {
                        let wi = w * phi[i];
                        for j in 0..m {
                            info[(a * m + i, b * m + j)] += wi * phi[j];
                        }
                    }
                }
            }
        }
        grad
    }

    /// Each outcome's degree (all but the last): the highest at most `degree` whose
    /// coefficients its events over the design carry (`EVENTS_PER_COEFFICIENT` each).
    fn outcome_degrees(
        design: &[DesignPoint],
        dims: usize,
        degree: usize,
        k1: usize,
    ) -> Vec<usize> {
        (0..k1)
            .map(|a| {
                let events: u64 = design.iter().map(|d| d.counts[a]).sum();
                (0..=degree)
                    .rev()
                    .find(|&d| {
                        exponents(dims, d).len() as f64 * EVENTS_PER_COEFFICIENT <= events as f64
                    })
                    .unwrap_or(0)
            })
            .collect()
    }

    /// The deviance against the saturated model over the outcomes seen anywhere, and its
    /// degrees of freedom (the cells less the coefficients of the outcomes seen).
    fn deviance(
        design: &[DesignPoint],
        phis: &[DVector<f64>],
        beta: &DVector<f64>,
        degrees: &[usize],
        (dims, k1, m): (usize, usize, usize),
    ) -> (f64, usize) {
        let outcomes = k1 + 1;
        let seen: Vec<bool> = (0..outcomes)
            .map(|k| design.iter().any(|d| d.counts[k] > 0))
            .collect();
        let mut deviance = 0.0;
        let mut cells = 0usize;
        for (d, phi) in design.iter().zip(phis) {
            let n: u64 = d.counts.iter().sum();
            if n == 0 {
                continue;
            }
            cells += seen.iter().filter(|s| **s).count().saturating_sub(1);
            let p = Self::probs(beta, phi, k1, m);
            for (k, &c) in d.counts.iter().enumerate() {
                if c > 0 {
                    deviance += 2.0 * c as f64 * (c as f64 / (n as f64 * p[k])).ln();
                }
            }
        }
        let coefficients: usize = (0..k1)
            .filter(|&a| seen[a])
            .map(|a| exponents(dims, degrees[a]).len())
            .sum();
        let dof = cells.saturating_sub(coefficients);
        (deviance, dof)
    }

    /// Fits the surrogate of total degree `degree` to `design` (every point's counts over the
    /// same `outcomes` outcomes; a point with no counts adds nothing). Newton's method on the
    /// penalised log-likelihood, from β = 0, to a relative change below 1e-10.
    ///
    /// Rare outcomes: an outcome seen T times over the whole design gets polynomials only up to
    /// the degree that leaves at least [`EVENTS_PER_COEFFICIENT`] events a coefficient (a
    /// constant log-odds when T is small), and half a pseudo-count spread evenly over the design
    /// (Jeffreys's prior for the whole design's total, biasing it by 1/(2·rolls)); so an
    /// outcome never or rarely seen keeps a small probability with a wide error, rather than a
    /// log-odds driven to −∞ with a spuriously tight one.
    pub fn fit(design: &[DesignPoint], dims: usize, outcomes: usize, degree: usize) -> Surrogate {
        Self::fit_until(design, dims, outcomes, degree, &|| false).expect("never stopped")
    }

    /// [`Surrogate::fit`], abandoned (`None`) as soon as `stop()` says so: asked before every
    /// Newton step, so that a stop ends a fit within one step (a d20's degree-4 surrogate, 665
    /// coefficients, took 0.15–0.35 s to fit in a fit's bootstrap: issue 69.11).
    pub fn fit_until(
        design: &[DesignPoint],
        dims: usize,
        outcomes: usize,
        degree: usize,
        stop: &dyn Fn() -> bool,
    ) -> Option<Surrogate> {
        let exps = exponents(dims, degree);
        let m = exps.len();
        let k1 = outcomes - 1;
        let size = k1 * m;
        let phis: Vec<DVector<f64>> = design
            .iter()
            .map(|d| features(&d.x, &exps, degree))
            .collect();
        let live_points = design
            .iter()
            .filter(|d| d.counts.iter().sum::<u64>() > 0)
            .count()
            .max(1) as f64;
        let pseudo = 0.5 / live_points;
        let counts: Vec<Vec<f64>> = design
            .iter()
            .map(|d| {
                if d.counts.iter().sum::<u64>() == 0 {
                    vec![0.0; outcomes]
                } else {
                    d.counts.iter().map(|&c| c as f64 + pseudo).collect()
                }
            })
            .collect();
        // Each outcome's degree, from its events over the design.
        let degrees = Self::outcome_degrees(design, dims, degree, k1);
        // A coefficient above its outcome's degree is held at 0 by a stiff penalty.
        let ridge: Vec<f64> = (0..size)
            .map(|i| {
                let (a, f) = (i / m, i % m);
                if exps[f].iter().sum::<usize>() > degrees[a] {
                    1e12
                } else {
                    RIDGE
                }
            })
            .collect();
        let mut beta = DVector::<f64>::zeros(size);
        let mut info = DMatrix::<f64>::zeros(size, size);
        let objective = |b: &DVector<f64>| -> f64 {
            let mut ll: f64 = -(0..size).map(|i| ridge[i] * b[i] * b[i]).sum::<f64>();
            for (c, phi) in counts.iter().zip(&phis) {
                let p = Self::probs(b, phi, k1, m);
                for (ck, pk) in c.iter().zip(&p) {
                    if *ck > 0.0 {
                        ll += ck * pk.max(1e-300).ln();
                    }
                }
            }
            ll
        };
        for _ in 0..100 {
            if stop() {
                return None;
            }
            let grad =
                Self::score_and_information(&beta, &counts, &phis, &ridge, (k1, m), &mut info);
            let Some(chol) = info.clone().cholesky() else {
                break;
            };
            let step = chol.solve(&grad);
            // Newton's step, halved until the penalised log-likelihood does not fall (far from
            // the optimum a full step on a nearly separable outcome can overshoot).
            let before = objective(&beta);
            let mut t = 1.0;
            let mut next = &beta + &step;
            while objective(&next) < before - 1e-12 * before.abs() && t > 1e-6 {
                t /= 2.0;
                next = &beta + t * &step;
            }
            let change = (t * step.norm()) / (1.0 + beta.norm());
            beta = next;
            if change < 1e-10 {
                break;
            }
        }
        // The information at the optimum, its inverse the coefficients' covariance.
        let cov = info
            .clone()
            .cholesky()
            .map(|c| c.inverse())
            .unwrap_or_else(|| DMatrix::from_diagonal_element(size, size, f64::INFINITY));
        // The deviance against the saturated model, over the outcomes seen anywhere.
        let (deviance, dof) = Self::deviance(design, &phis, &beta, &degrees, (dims, k1, m));
        let dispersion = if dof > 0 {
            (deviance / dof as f64).max(1.0)
        } else {
            1.0
        };
        Some(Surrogate {
            dims,
            outcomes,
            degree,
            degrees,
            exps,
            beta: beta.iter().copied().collect(),
            cov: (cov * dispersion).iter().copied().collect(),
            deviance,
            dof,
            dispersion,
        })
    }

    /// Fits degree `degree`, and higher degrees up to `max_degree` (those the design can
    /// carry: at least twice as many points as coefficients per outcome) only while the lack
    /// of fit is significant (P(χ²_dof ≥ deviance) < 0.01). Never lower: choosing a degree by
    /// a test that accepts a stiff fit biases it (measured in the tests: a selection down to
    /// degree 1 left a bias of 0.9–2.4 standard errors on a curved law; fixed degrees 2 to 4
    /// none). A surrogate that still lacks fit at the highest degree keeps its dispersion.
    pub fn fit_best(
        design: &[DesignPoint],
        dims: usize,
        outcomes: usize,
        degree: usize,
        max_degree: usize,
    ) -> Surrogate {
        let mut s = Surrogate::fit(design, dims, outcomes, degree.max(1));
        for d in degree.max(1) + 1..=max_degree {
            if s.lack_of_fit_p() >= 0.01 || 2 * exponents(dims, d).len() > design.len() {
                break;
            }
            s = Surrogate::fit(design, dims, outcomes, d);
        }
        s
    }

    /// The lack of fit's p-value, P(χ²_dof ≥ deviance).
    pub fn lack_of_fit_p(&self) -> f64 {
        crate::theory::stats::chi_square_p_value(self.deviance, self.dof)
    }

    fn probs(beta: &DVector<f64>, phi: &DVector<f64>, k1: usize, m: usize) -> Vec<f64> {
        let eta: Vec<f64> = (0..k1)
            .map(|a| (0..m).map(|i| beta[a * m + i] * phi[i]).sum())
            .collect();
        softmax(&eta)
    }

    /// The log-odds at features `phi`, from the coefficients as stored.
    fn eta(&self, phi: &DVector<f64>) -> Vec<f64> {
        let m = self.exps.len();
        (0..self.outcomes - 1)
            .map(|a| (0..m).map(|i| self.beta[a * m + i] * phi[i]).sum())
            .collect()
    }

    /// The probabilities at `x` (unit coordinates).
    pub fn p(&self, x: &[f64]) -> Vec<f64> {
        softmax(&self.eta(&features(x, &self.exps, self.degree)))
    }

    /// The probabilities at `x` with their covariance, by the delta method:
    /// ∂p_k/∂β_a = p_k (δ_ka − p_a) φ. Read from the stored coefficients and covariance in
    /// place (this runs for every row at every step of every search).
    pub fn predict(&self, x: &[f64]) -> Prediction {
        let m = self.exps.len();
        let k1 = self.outcomes - 1;
        let size = k1 * m;
        let phi = features(x, &self.exps, self.degree);
        let p = softmax(&self.eta(&phi));
        // The log-odds' covariance: V_ab = φᵀ C_ab φ over the (a, b) block of the coefficients'.
        let mut v_eta = DMatrix::<f64>::zeros(k1, k1);
        for a in 0..k1 {
            for b in a..k1 {
                let mut v = 0.0;
                for i in 0..m {
                    let row = &self.cov[(a * m + i) * size + b * m..(a * m + i) * size + b * m + m];
                    let dot: f64 = row.iter().zip(phi.iter()).map(|(c, f)| c * f).sum();
                    v += phi[i] * dot;
                }
                v_eta[(a, b)] = v;
                v_eta[(b, a)] = v;
            }
        }
        let mut j = DMatrix::<f64>::zeros(self.outcomes, k1);
        for k in 0..self.outcomes {
            for a in 0..k1 {
                j[(k, a)] = p[k] * (if k == a { 1.0 } else { 0.0 } - p[a]);
            }
        }
        let cov = &j * v_eta * j.transpose();
        Prediction { p, cov }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Draws counts at `x` from known probabilities.
    fn draw(rng: &mut ChaCha8Rng, p: &[f64], n: u64) -> Vec<u64> {
        let mut c = vec![0u64; p.len()];
        for _ in 0..n {
            let u: f64 = rng.random();
            let mut acc = 0.0;
            let mut k = p.len() - 1;
            for (i, pi) in p.iter().enumerate() {
                acc += pi;
                if u < acc {
                    k = i;
                    break;
                }
            }
            c[k] += 1;
        }
        c
    }

    fn truth(x: &[f64]) -> Vec<f64> {
        // A smooth three-outcome law with a minimum inside the box, and a rare outcome.
        let a = 0.4 * (x[0] - 0.3).powi(2) - 0.5 * x[1] - 0.2;
        let b = -4.0 + 1.5 * x[1];
        softmax(&[a, b])
    }

    #[test]
    fn exponents_count_the_monomials() {
        // C(d + D, D) monomials of total degree ≤ D in d variables.
        assert_eq!(exponents(3, 2).len(), 10);
        assert_eq!(exponents(3, 3).len(), 20);
        assert_eq!(exponents(2, 4).len(), 15);
        assert_eq!(exponents(3, 3)[0], vec![0, 0, 0]);
    }

    #[test]
    fn it_recovers_a_known_law_and_its_error_is_honest() {
        // 50 repetitions of a 49-point design with 400 draws each: the surrogate's error at
        // the centre, in its own standard errors, has mean ≈ 0 and spread ≈ 1 (checked to
        // within what 50 repetitions resolve).
        let mut zs = Vec::new();
        for rep in 0..50u64 {
            let mut rng = ChaCha8Rng::seed_from_u64(100 + rep);
            let mut design = Vec::new();
            for i in 0..7 {
                for j in 0..7 {
                    let x = vec![i as f64 / 6.0, j as f64 / 6.0];
                    let counts = draw(&mut rng, &truth(&x), 400);
                    design.push(DesignPoint { x, counts });
                }
            }
            let s = Surrogate::fit_best(&design, 2, 3, 2, 4);
            let x = [0.55, 0.45];
            let pr = s.predict(&x);
            let t = truth(&x);
            zs.push((pr.p[0] - t[0]) / pr.cov[(0, 0)].sqrt());
        }
        let n = zs.len() as f64;
        let mean = zs.iter().sum::<f64>() / n;
        let sd = (zs.iter().map(|z| (z - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!(mean.abs() < 3.0 / n.sqrt(), "mean z {mean}");
        assert!((0.7..1.35).contains(&sd), "spread of z {sd}");
    }

    #[test]
    fn an_outcome_never_seen_gets_a_small_finite_probability() {
        let design: Vec<DesignPoint> = (0..20)
            .map(|i| DesignPoint {
                x: vec![i as f64 / 19.0],
                counts: vec![0, 300 + i, 700 - i],
            })
            .collect();
        let s = Surrogate::fit(&design, 1, 3, 2);
        let p = s.p(&[0.5]);
        assert!(p[0] > 0.0 && p[0] < 1e-4, "{p:?}");
        assert!((p[1] - 0.31).abs() < 0.01, "{p:?}");
    }

    #[test]
    fn a_stiff_surrogate_is_caught_by_its_lack_of_fit() {
        // A law with a sharp bend fitted by a straight line: the deviance shows it, and the
        // dispersion widens the covariance.
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let design: Vec<DesignPoint> = (0..30)
            .map(|i| {
                let x = i as f64 / 29.0;
                let p = softmax(&[if x < 0.5 { -1.0 } else { 1.0 }]);
                DesignPoint {
                    x: vec![x],
                    counts: draw(&mut rng, &p, 2000),
                }
            })
            .collect();
        let s = Surrogate::fit(&design, 1, 2, 1);
        assert!(s.lack_of_fit_p() < 1e-6, "{}", s.lack_of_fit_p());
        assert!(s.dispersion > 3.0);
    }

    /// A stop ends a surrogate's fit within one Newton step: counted in the steps it asked
    /// about, not seconds (issue 69.11). Never stopped, it is `fit`'s to the bit.
    #[test]
    fn a_stop_ends_a_surrogates_fit_within_one_step() {
        use std::cell::Cell;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let design: Vec<DesignPoint> = (0..30)
            .map(|i| {
                let x = i as f64 / 29.0;
                DesignPoint {
                    x: vec![x],
                    counts: draw(&mut rng, &softmax(&[x - 0.5, 0.3 * x]), 500),
                }
            })
            .collect();
        let asked = &Cell::new(0);
        let counting = |stop_at: usize| {
            move || {
                asked.set(asked.get() + 1);
                asked.get() >= stop_at
            }
        };
        assert!(Surrogate::fit_until(&design, 1, 3, 2, &counting(1)).is_none());
        assert_eq!(asked.get(), 1);
        asked.set(0);
        let whole = Surrogate::fit_until(&design, 1, 3, 2, &counting(usize::MAX)).unwrap();
        let steps = asked.get();
        assert!(steps > 2, "{steps} steps");
        assert_eq!(whole.beta, Surrogate::fit(&design, 1, 3, 2).beta);
        asked.set(0);
        assert!(Surrogate::fit_until(&design, 1, 3, 2, &counting(2)).is_none());
        assert_eq!(asked.get(), 2);
    }
}
