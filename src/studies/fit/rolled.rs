//! The fit's estimate rolled ([`crate::calibration::rolled`]): every row simulated afresh at
//! the fitted values, on throws of its own.

use super::baseline::{grouped, shares_at};
use crate::calibration::data::Outcomes;
use crate::calibration::rolled::{Rolled, RolledRow};
use crate::calibration::FitResult;
use crate::error::Result;
use crate::run::runner::Runner;

/// Rolls of each row at the estimate, per roll of one of the fit's design points: ten
/// points' worth, so the rolled shares' noise is a tenth of a design point's.
pub const ROLLED_POINTS: u64 = 10;

/// A seed of the rolls at the estimate, apart from every design's and baseline's.
const ROLLED_SEED: u64 = 0x0e57_1a7e;

/// Every row of `fit` rolled at its estimate (each row at its own surface's and thrower's
/// values, its own die where it names one), `cfg.design.rolls` × [`ROLLED_POINTS`] throws a
/// row. `None` if stopped early.
pub fn roll(fit: &FitResult, runner: &Runner) -> Result<Option<Rolled>> {
    let cfg = &fit.config;
    let rolls = cfg.design.rolls * ROLLED_POINTS;
    let mut rows = Vec::new();
    for (r, row) in cfg.rows.iter().enumerate() {
        let values = fit.values_at(row, &fit.estimate.x);
        let method = &*cfg.method.of_row(row);
        let faces = row.outcomes == Outcomes::Faces;
        let Some((shares, settled)) = shares_at(
            method,
            &values,
            (row.block, row.mode, faces),
            (cfg.seed ^ ROLLED_SEED).wrapping_add(r as u64),
            rolls,
            runner,
        )?
        else {
            return Ok(None);
        };
        let q: Vec<f64> = grouped(row, &shares, None)
            .iter()
            .map(|p| p.value)
            .collect();
        let counts: Vec<u64> = row
            .groups
            .iter()
            .map(|g| g.iter().map(|&k| row.counts[k]).sum())
            .collect();
        rows.push(RolledRow::new(&row.label, counts, q, settled));
    }
    Ok(Some(Rolled::of(rows, fit.params.len(), rolls)))
}
