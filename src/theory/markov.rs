//! The five-state Markov chain of figure (MarkovChainCompleate), from which the paper derives
//! equation (MasterEquM1).
//!
//! States, numbered as in the paper (index = number − 1 here):
//! 1. Initial, 2. K-dynamic, 3. L-dynamic, 4. K-static, 5. L-static.
//!
//! From Initial the die goes to K-dynamic or L-dynamic with the no-bounce probabilities of
//! (InElasK), (2/π)arctan(k/l) and (2/π)arctan(l/k). From a dynamic state it settles with a
//! probability proportional to its activation energy E_Trans − E, where E_Trans = ½mg sqrt(k²+l²)
//! (Etrans):
//!
//! P(K-dynamic → K-static) = γ(½mg)(sqrt(k²+l²) − l),
//! P(L-dynamic → L-static) = γ(½mg)(sqrt(k²+l²) − k),
//!
//! and otherwise returns to Initial. The static states absorb.
//!
//! **Parameter.** γ, m and g appear only as the product γ·½mg, so the chain takes that product as
//! its single parameter, `gamma_half_mg` (units 1/length, the same length unit as k and l). The
//! paper's point, shown here exactly, is that P(K) and P(L) do not depend on it anywhere in its
//! valid range 0 < γ·½mg·(sqrt(k²+l²) − min(k, l)) ≤ 1, where every arc is a probability.

use nalgebra::{Matrix3, Matrix3x2, Matrix5, Vector5};
use serde::Serialize;
use std::f64::consts::FRAC_2_PI;

use crate::error::{Error, Result};

/// Index of Initial (state 1) in the matrices and vectors; every index is the paper's number − 1.
pub const INITIAL: usize = 0;
/// Index of K-dynamic (state 2).
pub const K_DYNAMIC: usize = 1;
/// Index of L-dynamic (state 3).
pub const L_DYNAMIC: usize = 2;
/// Index of K-static (state 4): at rest on side k.
pub const K_STATIC: usize = 3;
/// Index of L-static (state 5): at rest on side l.
pub const L_STATIC: usize = 4;

/// The chain for a 2D block with sides k and l.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkovChain {
    k: f64,
    l: f64,
    gamma_half_mg: f64,
    /// P^T: column j holds the probabilities of leaving state j (each column sums to 1).
    p_transpose: Matrix5<f64>,
}

/// Final-state probabilities of the chain started in Initial.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Absorption {
    /// P(K): ending in K-static (resting on side k).
    pub p_k: f64,
    /// P(L): ending in L-static (resting on side l).
    pub p_l: f64,
}

impl Absorption {
    /// P(L)/P(K), to compare with (MasterEquM1).
    pub fn ratio(&self) -> f64 {
        self.p_l / self.p_k
    }
}

impl MarkovChain {
    /// The largest valid γ·½mg for sides k, l: 1/(sqrt(k²+l²) − min(k, l)). Above it the
    /// settling probability out of the dynamic state of the lower-energy outcome (resting on the
    /// longer side, the larger activation energy) exceeds 1, and its return arc is negative.
    pub fn max_gamma_half_mg(k: f64, l: f64) -> f64 {
        1.0 / (k.hypot(l) - k.min(l))
    }

    /// The chain of figure (MarkovChainCompleate) for sides k, l > 0 and parameter
    /// γ·½mg in (0, [`Self::max_gamma_half_mg`]]. Anything else is an `Error::Invalid`.
    pub fn new(k: f64, l: f64, gamma_half_mg: f64) -> Result<MarkovChain> {
        for (name, v) in [("k", k), ("l", l)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Invalid(format!(
                    "Markov chain side {name} must be positive and finite, got {v}"
                )));
            }
        }
        let max = Self::max_gamma_half_mg(k, l);
        if !(gamma_half_mg.is_finite() && gamma_half_mg > 0.0 && gamma_half_mg <= max) {
            return Err(Error::Invalid(format!(
                "Markov chain gamma*(mg/2) must be in (0, {max}] for k = {k}, l = {l} \
                 (every arc a probability), got {gamma_half_mg}"
            )));
        }
        let diag = k.hypot(l);
        // Arcs out of Initial: (InElasK).
        let to_k = FRAC_2_PI * (k / l).atan();
        let to_l = FRAC_2_PI * (l / k).atan();
        // Settling arcs: γ(½mg) times the activation energy over ½mg. At the upper bound the
        // product may round to 1 + 1 ulp; it is clamped to 1 so the return arc is not negative.
        let settle_k = (gamma_half_mg * (diag - l)).min(1.0);
        let settle_l = (gamma_half_mg * (diag - k)).min(1.0);
        // The matrix P^T exactly as printed after figure (MarkovChainCompleate).
        #[rustfmt::skip]
        let p_transpose = Matrix5::new(
            0.0,  1.0 - settle_k, 1.0 - settle_l, 0.0, 0.0,
            to_k, 0.0,            0.0,            0.0, 0.0,
            to_l, 0.0,            0.0,            0.0, 0.0,
            0.0,  settle_k,       0.0,            1.0, 0.0,
            0.0,  0.0,            settle_l,       0.0, 1.0,
        );
        Ok(MarkovChain {
            k,
            l,
            gamma_half_mg,
            p_transpose,
        })
    }

    /// Side k, on which the block rests in state K.
    pub fn k(&self) -> f64 {
        self.k
    }

    /// Side l, on which the block rests in state L.
    pub fn l(&self) -> f64 {
        self.l
    }

    /// The parameter γ·½mg, 1/length (the unit of k and l).
    pub fn gamma_half_mg(&self) -> f64 {
        self.gamma_half_mg
    }

    /// P^T as printed in the paper (columns sum to 1).
    pub fn p_transpose(&self) -> &Matrix5<f64> {
        &self.p_transpose
    }

    /// The transition matrix P, p_ij = P(i → j) (rows sum to 1).
    pub fn transition_matrix(&self) -> Matrix5<f64> {
        self.p_transpose.transpose()
    }

    /// The state after n steps from Initial: (P^T)^n (1,0,0,0,0)^T (equation (recur) for
    /// n → ∞). Computed by repeated squaring, so n may be huge.
    pub fn iterate(&self, n: u64) -> Vector5<f64> {
        let mut result = Matrix5::identity();
        let mut base = self.p_transpose;
        let mut e = n;
        while e > 0 {
            if e & 1 == 1 {
                result = base * result;
            }
            e >>= 1;
            if e > 0 {
                base = base * base;
            }
        }
        result.column(INITIAL).into_owned()
    }

    /// Iterates (doubling the step count) until the probability left in the transient states
    /// 1–3 is at most `tol`, or 2⁶² steps. Returns the state and the number of steps taken.
    pub fn iterate_to_convergence(&self, tol: f64) -> (Vector5<f64>, u64) {
        let mut n: u64 = 1;
        loop {
            let v = self.iterate(n);
            let transient = v[INITIAL] + v[K_DYNAMIC] + v[L_DYNAMIC];
            if transient <= tol || n >= 1 << 62 {
                return (v, n);
            }
            n *= 2;
        }
    }

    /// The fundamental matrix N = (I − Q)⁻¹ of the transient states 1–3, with
    /// P = [[Q, R], [0, I]] (R from the transient states into 4–5), by nalgebra's general
    /// inverse. N's entries are expected visit counts, of order 1/γ: for small γ·½mg the
    /// inverse is ill-conditioned (condition number ~ 1/(γ·½mg·length)) and loses that many
    /// digits; [`Self::absorption`] does not.
    pub fn fundamental_matrix(&self) -> Result<Matrix3<f64>> {
        let p = self.transition_matrix();
        let q: Matrix3<f64> = p.fixed_view::<3, 3>(0, 0).into_owned();
        (Matrix3::identity() - q).try_inverse().ok_or_else(|| {
            Error::failed("Markov chain: I - Q is singular (no absorbing path)".to_string())
        })
    }

    /// The transient-to-absorbing block R of P (rows: states 1–3, columns: K-static, L-static).
    pub fn absorbing_block(&self) -> Matrix3x2<f64> {
        self.transition_matrix()
            .fixed_view::<3, 2>(0, 3)
            .into_owned()
    }

    /// The absorption probabilities, exactly up to rounding: B = (I − Q)⁻¹ R (the fundamental
    /// matrix times R), the row of Initial being (P(K), P(L)).
    ///
    /// B is found by solving (I − Q) B = R with Gaussian elimination in the
    /// Grassmann–Taksar–Heyman form: each pivot, 1 − Q_tt after the earlier eliminations, is
    /// computed as the sum of state t's remaining off-diagonal probabilities, which equals it
    /// in exact arithmetic (the reduced rows stay stochastic) but has no cancellation. So
    /// every step adds non-negative numbers, and B is accurate to a few ulps however small γ
    /// is, where `fundamental_matrix() * absorbing_block()` loses digits as γ → 0.
    pub fn absorption(&self) -> Result<Absorption> {
        const T: usize = 3; // transient states 0..T, absorbing T..5
        let mut w = self.transition_matrix();
        let mut pivots = [0.0; T];
        // Forward elimination of the transient states in order.
        for t in 0..T {
            let d: f64 = (t + 1..5).map(|j| w[(t, j)]).sum();
            if d.is_nan() || d <= 0.0 {
                return Err(Error::failed(format!(
                    "Markov chain: state {} cannot leave the transient states",
                    t + 1
                )));
            }
            pivots[t] = d;
            for i in t + 1..T {
                let f = w[(i, t)] / d;
                if f != 0.0 {
                    for j in t + 1..5 {
                        let add = f * w[(t, j)];
                        w[(i, j)] += add;
                    }
                    w[(i, t)] = 0.0;
                }
            }
        }
        // Back substitution: B[t] = (W[t, absorbing] + Σ_{j>t transient} W[t, j] B[j]) / d_t.
        let mut b = [[0.0; 2]; T];
        for t in (0..T).rev() {
            for a in 0..2 {
                let mut sum = w[(t, T + a)];
                for (j, bj) in b.iter().enumerate().take(T).skip(t + 1) {
                    sum += w[(t, j)] * bj[a];
                }
                b[t][a] = sum / pivots[t];
            }
        }
        Ok(Absorption {
            p_k: b[INITIAL][0],
            p_l: b[INITIAL][1],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::theory::ratio_from_sides;

    /// Sides as in the paper's blocks (mm), both orders.
    const SIDES: [(f64, f64); 5] = [
        (24.0, 20.0),
        (22.0, 13.0),
        (30.0, 10.0),
        (20.0, 24.0),
        (43.9, 43.2),
    ];

    fn gammas(k: f64, l: f64) -> [f64; 5] {
        let max = MarkovChain::max_gamma_half_mg(k, l);
        [max * 1e-9, max * 1e-4, max * 0.37, max * 0.5, max]
    }

    #[test]
    fn columns_of_p_transpose_sum_to_one() {
        for (k, l) in SIDES {
            for g in gammas(k, l) {
                let c = MarkovChain::new(k, l, g).unwrap();
                for j in 0..5 {
                    let s: f64 = c.p_transpose().column(j).sum();
                    assert!((s - 1.0).abs() < 1e-15, "column {j}: {s}");
                    assert!(c
                        .p_transpose()
                        .column(j)
                        .iter()
                        .all(|&x| (0.0..=1.0).contains(&x)));
                }
            }
        }
    }

    #[test]
    fn absorption_is_independent_of_gamma() {
        for (k, l) in SIDES {
            let theory = ratio_from_sides(k, l);
            for g in gammas(k, l) {
                let a = MarkovChain::new(k, l, g).unwrap().absorption().unwrap();
                assert!((a.p_k + a.p_l - 1.0).abs() < 1e-12);
                assert!(
                    (a.ratio() - theory).abs() < 1e-12,
                    "k={k} l={l} g={g}: {} vs {theory}",
                    a.ratio()
                );
                assert!((a.p_k - 1.0 / (1.0 + theory)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn fundamental_matrix_agrees_away_from_tiny_gamma() {
        for (k, l) in SIDES {
            let max = MarkovChain::max_gamma_half_mg(k, l);
            for g in [max * 0.37, max * 0.5, max] {
                let c = MarkovChain::new(k, l, g).unwrap();
                let b = c.fundamental_matrix().unwrap() * c.absorbing_block();
                let a = c.absorption().unwrap();
                assert!((b[(INITIAL, 0)] - a.p_k).abs() < 1e-12);
                assert!((b[(INITIAL, 1)] - a.p_l).abs() < 1e-12);
                // Every transient state is absorbed somewhere.
                for i in 0..3 {
                    assert!((b[(i, 0)] + b[(i, 1)] - 1.0).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn iterating_converges_to_the_closed_form() {
        for (k, l) in SIDES {
            let theory = ratio_from_sides(k, l);
            for g in gammas(k, l) {
                let c = MarkovChain::new(k, l, g).unwrap();
                let (v, n) = c.iterate_to_convergence(1e-15);
                assert!(
                    v[INITIAL] + v[K_DYNAMIC] + v[L_DYNAMIC] <= 1e-15,
                    "g={g} n={n}"
                );
                let ratio = v[L_STATIC] / v[K_STATIC];
                assert!(
                    (ratio - theory).abs() < 1e-12,
                    "k={k} l={l} g={g} n={n}: {ratio} vs {theory}"
                );
            }
        }
    }

    #[test]
    fn two_steps_match_the_papers_expansion() {
        // (P^T)² e1 = (p12 p21 + p13 p31, 0, 0, p12 p24, p13 p35).
        let (k, l) = (24.0, 20.0);
        let c = MarkovChain::new(k, l, 0.01).unwrap();
        let p = c.transition_matrix();
        let v = c.iterate(2);
        let expect = [
            p[(0, 1)] * p[(1, 0)] + p[(0, 2)] * p[(2, 0)],
            0.0,
            0.0,
            p[(0, 1)] * p[(1, 3)],
            p[(0, 2)] * p[(2, 4)],
        ];
        for i in 0..5 {
            assert!((v[i] - expect[i]).abs() < 1e-15);
        }
        assert_eq!(c.iterate(0), Vector5::new(1.0, 0.0, 0.0, 0.0, 0.0));
    }

    #[test]
    fn refuses_gamma_outside_the_valid_range() {
        let (k, l) = (24.0, 20.0);
        let max = MarkovChain::max_gamma_half_mg(k, l);
        for g in [0.0, -1.0, max * (1.0 + 1e-9), f64::NAN, f64::INFINITY] {
            assert!(
                matches!(MarkovChain::new(k, l, g), Err(Error::Invalid(_))),
                "{g}"
            );
        }
        assert!(MarkovChain::new(0.0, l, 0.01).is_err());
        assert!(MarkovChain::new(k, f64::NAN, 0.01).is_err());
        // The bound is set by the lower-energy state, resting on the longer side (here K, k > l):
        // sqrt(k²+l²) − min(k, l).
        let c = MarkovChain::new(k, l, max).unwrap();
        assert!((c.transition_matrix()[(K_DYNAMIC, K_STATIC)] - 1.0).abs() < 1e-15);
        assert!(c.transition_matrix()[(K_DYNAMIC, INITIAL)].abs() < 1e-15);
    }
}
