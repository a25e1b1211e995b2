//! Calibration: what restitution, friction and throw make the simulator match measured
//! counts, how sure that is, and what it then predicts. The statistics of it, with no rolling
//! (that is [`crate::studies::fit`]'s):
//!
//! 1. [`data`]: the counts, one row per block and surface.
//! 2. [`params`]: the free parameters (e, μ per surface or shared; κ and the spin scale per
//!    thrower), their ranges and unit coordinates, and the simulation method.
//! 3. [`design`]: the fixed parameter points each block is simulated at, and the result: its
//!    counts and a surrogate (a polynomial multinomial logit) through them.
//! 4. [`estimate`]: the Dirichlet-multinomial likelihood of every row (the surrogate's noise
//!    folded in), its maximum, profile-likelihood intervals, the joint 2σ region, χ², and
//!    posterior draws.
//! 5. [`predict`]: probabilities at posterior draws, with an error from the parameters and one
//!    from the simulation.
//!
//! Why independent throws at each design point rather than common random numbers (the same
//! keyed throws at every point): the surrogate averages over the points, and common throws
//! give every point the same noise, so averaging removes none of it; independent throws give
//! the surrogate's level the noise of all the points' rolls together. Common throws help a
//! method that compares points one by one (a grid search, a finite difference); a surrogate
//! does not. Measured (`fit --common-throws`, docs/results/calibration.md): on 20 paired
//! recoveries no difference is resolved, and none favours common throws.

pub mod check;
pub mod crossval;
pub mod data;
pub mod design;
pub mod estimate;
pub mod heldout;
pub mod paper;
pub mod params;
pub mod predict;
pub mod recovery;

use crate::error::{Error, Result};
use data::DataRow;
use design::{Design, DesignSpec};
use estimate::{Estimate, Likelihood, Search};
use params::{Method, ModelSpec, Param};
use serde::{Deserialize, Serialize};

/// What to fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitConfig {
    /// The measured counts.
    pub rows: Vec<DataRow>,
    /// What is free, where.
    pub model: ModelSpec,
    /// How each throw is simulated.
    pub method: Method,
    /// How densely each block is simulated.
    pub design: DesignSpec,
    /// The search's settings.
    pub search: Search,
    /// The throws' seed.
    pub seed: u64,
}

impl FitConfig {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        self.model.validate()?;
        self.design.validate(self.model.free.len())?;
        if self.rows.is_empty() {
            return Err(Error::Invalid("no rows to fit".into()));
        }
        let params = self.model.params(&self.rows);
        if params.len() > 40 {
            return Err(Error::Invalid(format!(
                "{} free parameters: at most 40 (share e or mu across surfaces?)",
                params.len()
            )));
        }
        let cells: usize = self.rows.iter().map(|r| r.groups.len() - 1).sum();
        if params.len() > cells {
            return Err(Error::Invalid(format!(
                "{} free parameters from {cells} independent counts: the data cannot fix them \
                 (fewer free parameters, or shared ones)",
                params.len()
            )));
        }
        // One cell checks the method (engine, step, roll) for every row's block.
        for r in &self.rows {
            let v = params::values(
                &self.model.fixed,
                &self.model.whole_axes(),
                &vec![0.5; self.model.free.len()],
            );
            self.method
                .spec(r.block, r.mode, &v, self.seed, self.design.rolls)
                .validate(false)?;
        }
        Ok(())
    }

    /// The rolls the first pass makes.
    pub fn total_rolls(&self) -> u64 {
        let per_key = design::points(self.model.free.len(), self.design.points).len() as u64;
        design::keys(&self.rows, &self.model).len() as u64 * per_key * self.design.rolls
    }
}

/// What a fit cost.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct FitCost {
    /// Rolls simulated (or read back from the checkpoints).
    pub rolls: u64,
    /// Of which did not settle on a face (unknown, unconverged, failed): left out.
    pub unsettled: u64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// CPU seconds of this process.
    pub cpu_s: f64,
}

/// A fit's result: everything `predict` needs, and what the report shows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitResult {
    /// What was fitted.
    pub config: FitConfig,
    /// The free parameters, in the estimate's order (with the second pass's ranges).
    pub params: Vec<Param>,
    /// The first pass's parameters, when a second pass refined them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_pass: Option<Vec<estimate::ParamFit>>,
    /// The blocks simulated, with their surrogates.
    pub designs: Vec<Design>,
    /// The estimate.
    pub estimate: Estimate,
    /// What it cost.
    pub cost: FitCost,
    /// The command line that made it.
    pub command_line: String,
    /// This program's version.
    pub dicephys_version: String,
    /// When it ended, UTC.
    pub date_utc: String,
}

/// The second pass's box: each parameter's first-pass 2σ profile interval, widened by half its
/// width on each side (and to at least a tenth of its range), within its range. A parameter
/// whose widened interval still covers 80 % of its range keeps the whole range, and so does one
/// that only one row informs: a fit that leaves that row out (a leave-one-out prediction) must
/// then know nothing of it, not a box the row itself chose.
pub fn narrow(
    rows: &[DataRow],
    model: &ModelSpec,
    params: &[Param],
    first: &Estimate,
) -> Vec<params::Narrowed> {
    let mut uses = vec![0usize; params.len()];
    for r in rows {
        for d in model.row_dims(params, r) {
            uses[d] += 1;
        }
    }
    let mut out = Vec::new();
    for ((p, fit), &n) in params.iter().zip(&first.params).zip(&uses) {
        if n < 2 {
            continue;
        }
        let u = |v: f64| p.kind.coordinate(p.range, v).clamp(0.0, 1.0);
        let (lo, hi) = (u(fit.two_sigma[0]), u(fit.two_sigma[1]));
        let pad = (0.5 * (hi - lo)).max(0.05);
        let (a, b) = ((lo - pad).max(0.0), (hi + pad).min(1.0));
        if b - a >= 0.8 {
            continue;
        }
        out.push(params::Narrowed {
            param: p.name(),
            range: crate::model::throws::Range::new(
                p.kind.value(p.range, a),
                p.kind.value(p.range, b),
            ),
        });
    }
    out
}

/// Fits `rows` with the designs already simulated (the cheap part: no rolls).
pub fn estimate_with(
    rows: &[DataRow],
    model: &ModelSpec,
    designs: &[Design],
    search: &Search,
    watch: &crate::run::stop::Watch,
) -> Result<(Vec<Param>, Estimate)> {
    let params = model.params(rows);
    let lik = Likelihood::new(rows, designs, model, &params).stopped_by(watch.stop);
    let est = estimate::estimate(&lik, &params, search, watch)?;
    Ok((params, est))
}

/// The largest `fit.json` read (a fit of hundreds of rows is a few megabytes).
pub const MAX_FIT_BYTES: u64 = 64 << 20;

/// Reads a fit's `fit.json` and checks it: sealed (a damaged or edited file is refused, by
/// name), of a fit this version can use, and whole (its draws in its parameters' box).
pub fn read_fit(path: &std::path::Path, stop: &crate::run::stop::Stop) -> Result<FitResult> {
    let name = path.display();
    let bytes = crate::run::io::read_capped(path, MAX_FIT_BYTES, stop)?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::Invalid(format!("{name}: not UTF-8, not a fit's fit.json")))?;
    let fit: FitResult = crate::run::seal::open(text)
        .map_err(|e| Error::Invalid(format!("{name}: not a fit's fit.json as written: {e}")))?;
    fit.check()
        .map_err(|e| Error::Invalid(format!("{name}: {e}")))?;
    Ok(fit)
}

impl FitResult {
    /// Checks that the fit is whole: its configuration valid, its parameters those of its
    /// model, its posterior draws there and inside the unit box.
    pub fn check(&self) -> Result<()> {
        self.config.validate()?;
        let dims = self.params.len();
        if self.config.model.params(&self.config.rows).len() != dims {
            return Err(Error::Invalid(format!(
                "{dims} parameters where its model has {}",
                self.config.model.params(&self.config.rows).len()
            )));
        }
        let d = &self.estimate.draws;
        if d.is_empty() {
            return Err(Error::Invalid(
                "no posterior draws (a first pass, or a damaged fit): nothing to predict from"
                    .into(),
            ));
        }
        let bad = d
            .iter()
            .chain(std::iter::once(&self.estimate.x))
            .any(|x| x.len() != dims || x.iter().any(|u| !(0.0..=1.0).contains(u)));
        if bad {
            return Err(Error::Invalid(format!(
                "its draws are not points of its {dims} parameters' box"
            )));
        }
        Ok(())
    }
}
