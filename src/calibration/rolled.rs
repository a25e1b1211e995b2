//! The fit's estimate rolled (issue 72): each row's counts held against shares simulated
//! afresh at the fitted values, by Pearson's χ² with the simulation's noise counted. The fit's
//! own χ² is its surrogate's, its errors widened by the overdispersion it fits: a misfit the
//! surrogate smooths over, or that the overdispersion absorbs, shows here (V1's fit of e and μ
//! reported 12.0 on 3 with φ 3.8 where a roll at its values gives 41.7 on 5). The rolling is
//! `studies::fit::rolled`.

use serde::{Deserialize, Serialize};

/// The estimate rolled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rolled {
    /// Throws a row.
    pub rolls: u64,
    /// Pearson's χ² over every row's outcomes: Σ (n − N q)²/(N q (1 + N/M)), q the rolled share
    /// of M settled throws, N the row's counted throws.
    pub chi2: f64,
    /// Independent counts less free parameters.
    pub dof: i64,
    /// P(χ²_dof ≥ chi2); `None` where dof < 1.
    pub p_value: Option<f64>,
    /// Each row.
    pub rows: Vec<RolledRow>,
}

/// One row at the estimate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RolledRow {
    /// The row's label.
    pub label: String,
    /// Its outcomes' counts, in the row's groups' order.
    pub counts: Vec<u64>,
    /// The rolled shares of the same outcomes.
    pub shares: Vec<f64>,
    /// The rolls that settled.
    pub settled: u64,
    /// Its part of the χ².
    pub chi2: f64,
}

/// Pearson's χ² of `counts` against shares `q` of `settled` rolls, the rolls' noise counted
/// (a share is floored at half a roll, so that an outcome never rolled but counted is far off,
/// not infinitely).
pub fn pearson(counts: &[u64], q: &[f64], settled: u64) -> f64 {
    let n: f64 = counts.iter().sum::<u64>() as f64;
    let m = settled.max(1) as f64;
    counts
        .iter()
        .zip(q)
        .map(|(&k, &q)| {
            let q = q.max(0.5 / m);
            let expected = n * q;
            (k as f64 - expected).powi(2) / (expected * (1.0 + n / m))
        })
        .sum()
}

impl RolledRow {
    /// A row's `counts` (by group) against rolled `shares` of the same groups from `settled`.
    pub fn new(label: &str, counts: Vec<u64>, shares: Vec<f64>, settled: u64) -> RolledRow {
        RolledRow {
            label: label.to_string(),
            chi2: pearson(&counts, &shares, settled),
            counts,
            shares,
            settled,
        }
    }
}

impl Rolled {
    /// The rows together, `free` parameters fitted, `rolls` throws a row.
    pub fn of(rows: Vec<RolledRow>, free: usize, rolls: u64) -> Rolled {
        let chi2 = rows.iter().map(|r| r.chi2).sum();
        let cells: i64 = rows.iter().map(|r| r.counts.len() as i64 - 1).sum();
        let dof = cells - free as i64;
        let p_value =
            (dof >= 1).then(|| crate::theory::stats::chi_square_p_value(chi2, dof as usize));
        Rolled {
            rolls,
            chi2,
            dof,
            p_value,
            rows,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pearsons_chi_square_counts_the_rolls_noise() {
        // 100 counted, 40/60 against shares 0.5/0.5 of 100 rolls: (10² + 10²)/(50 · 2) = 2.
        assert!((pearson(&[40, 60], &[0.5, 0.5], 100) - 2.0).abs() < 1e-12);
        // Many rolls: the counts' own Pearson, (10² + 10²)/50 = 4, less a millionth.
        let many = pearson(&[40, 60], &[0.5, 0.5], 100_000_000);
        assert!((many - 4.0).abs() < 1e-5, "{many}");
        // An outcome counted but never rolled is far off, not infinite.
        let never = pearson(&[5, 95], &[0.0, 1.0], 1000);
        assert!(never.is_finite() && never > 40.0, "{never}");
    }
}
