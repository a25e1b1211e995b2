//! The method check ([`crate::calibration::check`]): each block rolled at the fitted values by
//! the fit's method and by a finer reference, on the same keyed throws.

use crate::calibration::check::{BlockCheck, Departure, MethodCheck};
use crate::calibration::data::DataRow;
use crate::calibration::design::{blocks, point_seed};
use crate::calibration::params::{Fixed, Method};
use crate::error::Result;
use crate::model::block::Side;
use crate::run::runner::Runner;
use crate::sim::roll::Fate;

/// What the method check compares: the fit's method against the same at a finer step, with
/// `rolls` keyed throws a block from `seed`.
pub struct Check<'a> {
    /// The fit's method.
    pub method: &'a Method,
    /// The reference's time step, s.
    pub reference_dt: f64,
    /// Throws a block.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
}

/// Checks the method of `check` against its reference at the values `at(row)` gives each
/// row's block; the progress it reports goes on from `rolled`, the rolls made before it.
/// `None` if stopped early.
pub fn run(
    rows: &[DataRow],
    check: &Check,
    at: &dyn Fn(&DataRow) -> Fixed,
    runner: &Runner,
    mut rolled: u64,
) -> Result<Option<MethodCheck>> {
    let Check {
        method,
        reference_dt,
        rolls,
        seed,
    } = *check;
    let reference = Method {
        dt: reference_dt,
        ..method.clone()
    };
    let mut checks = Vec::new();
    for (block, mode) in blocks(rows) {
        let block_rows: Vec<&DataRow> = rows
            .iter()
            .filter(|r| r.block == block && r.mode == mode)
            .collect();
        let values = at(block_rows[0]);
        let seed = point_seed(seed, block, mode, usize::MAX);
        let mut fates: [Vec<Fate>; 2] = Default::default();
        for (i, m) in [method, &reference].iter().enumerate() {
            let spec = m.spec(block, mode, &values, seed, rolls);
            spec.validate(false)?;
            let before = rolled;
            let progress = |n| (runner.progress)(before + n);
            let done = runner
                .with_progress(&progress)
                .run(&spec, None, &mut |recs| {
                    fates[i].extend(recs.iter().map(|r| r.fate));
                    Ok(())
                })?;
            rolled += done.tally.rolls;
            if !done.complete {
                return Ok(None);
            }
        }
        // Throws settled by both methods, paired, by the side standing vertical.
        let both: Vec<(Side, Side)> = fates[0]
            .iter()
            .zip(&fates[1])
            .filter_map(|(a, b)| match (a, b) {
                (Fate::Settled(a), Fate::Settled(b)) => Some((a.side(), b.side())),
                _ => None,
            })
            .collect();
        let ind = |o: Side, k: usize| -> Vec<bool> {
            both.iter()
                .map(|p| if k == 0 { p.0 == o } else { p.1 == o })
                .collect()
        };
        let breadth = Departure::paired(&ind(Side::Breadth, 0), &ind(Side::Breadth, 1));
        let length = Departure::paired(&ind(Side::Length, 0), &ind(Side::Length, 1));
        let data_err = block_rows
            .iter()
            .map(|r| {
                let n = r.n() as f64;
                let p = (r.counts[1] as f64 / n).clamp(0.5 / n, 1.0 - 0.5 / n);
                (p * (1.0 - p) / n).sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        let ok = |d: &Departure| d.value.abs() + 2.0 * d.err <= data_err;
        checks.push(BlockCheck {
            block,
            mode,
            rolls: both.len() as u64,
            within: ok(&breadth) && ok(&length),
            breadth,
            length,
            data_err,
        });
    }
    Ok(Some(MethodCheck {
        dt: method.dt,
        reference_dt,
        blocks: checks,
    }))
}
