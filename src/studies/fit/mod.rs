//! `dicephys fit` and `predict`: the rolling behind a calibration ([`crate::calibration`]): each
//! block simulated over its design, the data simulated at a known truth for the recovery
//! check, and a new block simulated at the fit's posterior draws.

pub mod check;
pub mod predict;
pub mod recovery;
pub mod simulate;

use crate::calibration::design::{self, Design};
use crate::calibration::{estimate_with, FitConfig, FitCost, FitResult};
use crate::error::Result;
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::Runner;
use simulate::Plan;
use std::path::Path;
use std::time::Instant;

/// Simulates the designs of `cfg`'s rows (`None` if stopped early, what was rolled kept under
/// `dir`).
pub fn simulate(
    cfg: &FitConfig,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<Vec<Design>>> {
    let plan = Plan {
        model: &cfg.model,
        method: &cfg.method,
        design: &cfg.design,
        seed: cfg.seed,
    };
    simulate::simulate(&plan, &design::keys(&cfg.rows, &cfg.model), runner, dir)
}

/// Runs the fit: simulates (resuming from `dir`), then estimates. `None` if a stop request
/// ended the simulations early.
pub fn run(
    cfg: &FitConfig,
    command_line: String,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<FitResult>> {
    cfg.validate()?;
    let (wall, cpu) = (Instant::now(), process_cpu_seconds());
    let Some(designs) = simulate(cfg, runner, dir)? else {
        return Ok(None);
    };
    let (params, estimate) = estimate_with(&cfg.rows, &cfg.model, &designs, &cfg.search)?;
    Ok(Some(FitResult {
        cost: FitCost {
            rolls: designs.iter().map(|d| d.rolls).sum(),
            unsettled: designs.iter().map(|d| d.unsettled).sum(),
            wall_s: wall.elapsed().as_secs_f64(),
            cpu_s: process_cpu_seconds() - cpu,
        },
        config: cfg.clone(),
        params,
        designs,
        estimate,
        command_line,
        dicephys_version: env!("CARGO_PKG_VERSION").into(),
        date_utc: crate::report::paper::utc_now(),
    }))
}
