//! `dicephys fit` and `predict`: the rolling behind a calibration ([`crate::calibration`]): each
//! block simulated over its design, the data simulated at a known truth for the recovery
//! check, and a new block simulated at the fit's posterior draws.

pub mod check;
pub mod outputs;
pub mod predict;
pub mod recovery;
pub mod simulate;

use crate::calibration::design::{self, Design};
use crate::calibration::{estimate_with, FitConfig, FitCost, FitResult};
use crate::error::Result;
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::Runner;
use simulate::Plan;
pub use simulate::Session;
use std::path::Path;
use std::time::Instant;

/// Simulates the designs of `cfg`'s rows (`None` if stopped early, what was rolled kept under
/// `dir`).
pub fn simulate(
    cfg: &FitConfig,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Vec<Design>>> {
    let plan = Plan {
        model: &cfg.model,
        method: &cfg.method,
        design: &cfg.design,
        seed: cfg.seed,
        session,
    };
    simulate::simulate(&plan, &design::keys(&cfg.rows, &cfg.model), runner, dir)
}

/// A fit's pieces before they are dressed as a [`FitResult`].
pub struct Fitted {
    /// The configuration of the last pass (its model carries the narrowed ranges).
    pub config: FitConfig,
    /// The free parameters.
    pub params: Vec<crate::calibration::params::Param>,
    /// The last pass's designs.
    pub designs: Vec<Design>,
    /// The last pass's estimate.
    pub estimate: crate::calibration::estimate::Estimate,
    /// The first pass's parameters, when a second refined them.
    pub first_pass: Option<Vec<crate::calibration::estimate::ParamFit>>,
    /// Rolls made, over both passes.
    pub rolls: u64,
    /// Of which did not settle on a face.
    pub unsettled: u64,
}

/// Simulates and estimates, in one pass or two (`cfg.design.refine`). `None` if stopped early.
pub fn fit(
    cfg: &FitConfig,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Fitted>> {
    let Some(designs) = simulate(cfg, runner, dir, session)? else {
        return Ok(None);
    };
    // A first pass that a second will refine needs only its maximum and profiles.
    let first_search = if cfg.design.refine {
        crate::calibration::estimate::Search {
            bootstrap: 0,
            draws: 0,
            ..cfg.search
        }
    } else {
        cfg.search
    };
    let (params, estimate) = estimate_with(&cfg.rows, &cfg.model, &designs, &first_search)?;
    let mut out = Fitted {
        config: cfg.clone(),
        rolls: designs.iter().map(|d| d.rolls).sum(),
        unsettled: designs.iter().map(|d| d.unsettled).sum(),
        params,
        designs,
        estimate,
        first_pass: None,
    };
    let narrowed = crate::calibration::narrow(&cfg.rows, &cfg.model, &out.params, &out.estimate);
    if cfg.design.refine && !narrowed.is_empty() {
        out.config.model.narrowed = narrowed;
        let Some(second) = simulate(&out.config, runner, dir, session)? else {
            return Ok(None);
        };
        out.rolls += second.iter().map(|d| d.rolls).sum::<u64>();
        out.unsettled += second.iter().map(|d| d.unsettled).sum::<u64>();
        let (params, estimate) =
            estimate_with(&out.config.rows, &out.config.model, &second, &cfg.search)?;
        out.first_pass = Some(std::mem::replace(&mut out.estimate, estimate).params);
        out.params = params;
        out.designs = second;
    } else if cfg.design.refine {
        // Nothing to narrow: the first pass is the last, so it gets the full search (the
        // bootstrap's region and the posterior draws `predict` needs).
        let (params, estimate) = estimate_with(&cfg.rows, &cfg.model, &out.designs, &cfg.search)?;
        out.params = params;
        out.estimate = estimate;
    }
    Ok(Some(out))
}

/// Runs the fit: simulates (resuming from `dir`), then estimates, refining once if asked.
/// `None` if a stop request ended the simulations early.
pub fn run(
    cfg: &FitConfig,
    command_line: String,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<FitResult>> {
    cfg.validate()?;
    let (wall, cpu) = (Instant::now(), process_cpu_seconds());
    let Some(f) = fit(cfg, runner, dir, &Session::default())? else {
        return Ok(None);
    };
    Ok(Some(FitResult {
        cost: FitCost {
            rolls: f.rolls,
            unsettled: f.unsettled,
            wall_s: wall.elapsed().as_secs_f64(),
            cpu_s: process_cpu_seconds() - cpu,
        },
        config: f.config,
        params: f.params,
        first_pass: f.first_pass,
        designs: f.designs,
        estimate: f.estimate,
        command_line,
        dicephys_version: env!("CARGO_PKG_VERSION").into(),
        date_utc: crate::report::paper::utc_now(),
    }))
}
