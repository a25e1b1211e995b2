//! Predictions from a fit: outcome probabilities with an error that combines the parameters'
//! uncertainty (their posterior draws) with the simulation's noise.
//!
//! - A row the fit has a surrogate for (a leave-one-out check): the surrogate at every draw.
//! - A block it has not ([`predict_block`]): the simulator itself at `draws` of the posterior
//!   draws, `rolls` throws each (fresh keyed throws per draw). With p̂_m the draws' frequencies,
//!   the law of total variance splits their spread S² into the parameters' part,
//!   Var_θ = S² − mean p̂(1 − p̂)/n, and the rolls' noise; the mean's own error adds
//!   (Var_θ + p̄(1 − p̄)/n)/M for M draws.

use crate::calibration::discrepancy::{self, Corrected, Discrepancy};
use crate::calibration::estimate::Likelihood;
use crate::calibration::FitResult;
use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::model::scene::Mode;
use serde::{Deserialize, Serialize};

pub use crate::calibration::scores::Predicted;

/// Row `r`'s predicted group probabilities and ratio (breadth over width, when both are
/// counted apart) over the posterior `draws` (unit coordinates of the likelihood's parameters).
pub fn predict_row(
    lik: &Likelihood,
    r: usize,
    draws: &[Vec<f64>],
) -> (Vec<Predicted>, Option<Predicted>, Vec<String>) {
    let preds: Vec<_> = draws.iter().map(|x| lik.predict(r, x)).collect();
    let groups = lik.group_names(r);
    let k = preds[0].p.len();
    let m = preds.len() as f64;
    let probs = (0..k)
        .map(|g| {
            let v: Vec<f64> = preds.iter().map(|p| p.p[g]).collect();
            let sim = preds.iter().map(|p| p.cov[(g, g)].max(0.0)).sum::<f64>() / m;
            Predicted::of(&v, sim)
        })
        .collect();
    let (b, w) = (
        groups.iter().position(|g| g == "breadth"),
        groups.iter().position(|g| g == "width"),
    );
    let ratio = b.zip(w).map(|(b, w)| {
        let v: Vec<f64> = preds.iter().map(|p| p.p[b] / p.p[w]).collect();
        // The ratio's simulation variance by the delta method.
        let sim = preds
            .iter()
            .map(|p| {
                let (pb, pw) = (p.p[b], p.p[w]);
                let (vb, vw, cbw) = (p.cov[(b, b)], p.cov[(w, w)], p.cov[(b, w)]);
                (vb / (pw * pw) + vw * pb * pb / pw.powi(4) - 2.0 * cbw * pb / pw.powi(3)).max(0.0)
            })
            .sum::<f64>()
            / m;
        Predicted::of(&v, sim)
    });
    (probs, ratio, groups)
}

/// A prediction for a block the fit did not see.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BlockPrediction {
    /// The block.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// The surface whose e and μ were used ("all" when shared; "e E, μ M" when given).
    pub surface: String,
    /// The thrower whose throw was used.
    pub thrower: String,
    /// A die of any shape (the fit's), by name, in place of the block (its bounding box).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<String>,
    /// P(length), P(breadth), P(width) vertical (a 2D block: length 0); empty for a die of any
    /// shape.
    pub p: Vec<Predicted>,
    /// N(breadth vertical)/N(width vertical); left out for a die of any shape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio: Option<Predicted>,
    /// P(face 1) … P(face 6) up, for a fit of a made die or of face counts (3D), or each face
    /// of a die of any shape (in `labels`' order); `null` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<Vec<Predicted>>,
    /// What each of `faces` shows: "1" … "6", or a die of any shape's labels.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub labels: Vec<String>,
    /// The paper's 2D theory ratio (eq. MasterEqu) for the block; left out for a die of any
    /// shape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theory_ratio: Option<f64>,
    /// Posterior draws simulated.
    pub draws: usize,
    /// Rolls per draw.
    pub rolls: u64,
    /// Rolls that did not settle on a face, over all draws (left out).
    pub unsettled: u64,
    /// Where the block lies outside the blocks the fit saw (a prediction there extrapolates);
    /// `null` inside.
    #[serde(default)]
    pub extrapolation: Option<String>,
    /// The fit's overdispersion φ (1 for a fit that fits): its draws, so these errors, are
    /// widened by it already, and counts measured against this prediction are taken to
    /// scatter φ times the binomial's ([`crate::calibration::heldout::test`]).
    #[serde(default = "one")]
    pub overdispersion: f64,
    /// The fit's discrepancy where it has one: every error above is widened by it already
    /// (each share's `err_model`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub discrepancy: Option<Discrepancy>,
    /// Another die than the fit's, predicted: what it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other_die: Option<String>,
    /// Each row of counts given (`--counts`), the prediction scored against it beside the
    /// baselines.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tests: Vec<crate::calibration::scores::CountsTest>,
}

impl BlockPrediction {
    /// This prediction as the fit's discrepancy `d` leaves it (where any outcome has one):
    /// each share moved along its outcome's line and widened by its spread, each face by its
    /// label's, the others scaled so that they still sum to 1, and the ratio moved and widened
    /// with breadth's and width's.
    /// A discrepancy not applied (it did not improve the fit's held-out score) leaves the
    /// prediction as it was and is carried beside it, for the reader.
    pub fn widened(self, d: Option<&Discrepancy>) -> BlockPrediction {
        let Some(d) = d.filter(|d| d.any()) else {
            return self;
        };
        if !d.in_force() {
            return BlockPrediction {
                discrepancy: Some(d.clone()),
                ..self
            };
        }
        const SIDES: [&str; 3] = ["length", "breadth", "width"];
        let shares = |ps: &[Predicted], names: &[&str]| -> (Vec<Predicted>, Vec<Corrected>) {
            let values: Vec<f64> = ps.iter().map(|q| q.value).collect();
            let c = d.correct(names, &values);
            let moved = ps
                .iter()
                .zip(&c)
                .map(|(q, c)| discrepancy::apply(*q, *c))
                .collect();
            (moved, c)
        };
        let (p, c) = shares(&self.p, &SIDES[..self.p.len().min(3)]);
        let ratio = self.ratio.filter(|_| c.len() == 3).map(|r| {
            // N(breadth)/N(width) moves as the two shares do.
            let f = (c[1].value / self.p[1].value) / (c[2].value / self.p[2].value);
            let moved = if f.is_finite() {
                Predicted {
                    value: r.value * f,
                    err_params: r.err_params * f,
                    err_sim: r.err_sim * f,
                    fit_value: ((f - 1.0).abs() > 1e-12).then_some(r.value),
                    ..r
                }
            } else {
                r
            };
            discrepancy::widen_ratio(moved, (c[1].value, c[1].sigma), (c[2].value, c[2].sigma))
        });
        let faces = self.faces.as_ref().map(|f| {
            let labels: Vec<&str> = (0..f.len())
                .map(|k| self.labels.get(k).map_or("", |l| l.as_str()))
                .collect();
            shares(f, &labels).0
        });
        BlockPrediction {
            p,
            ratio,
            faces,
            discrepancy: Some(d.clone()),
            ..self
        }
    }
}

fn one() -> f64 {
    1.0
}

/// Posterior draws a prediction simulates when none are asked.
pub const DEFAULT_DRAWS: usize = 16;
/// Rolls a draw when none are asked.
pub const DEFAULT_ROLLS: u64 = 2000;

/// What to predict.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PredictConfig {
    /// The block.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// The surface whose e and μ to use (needed when the fit has them per surface).
    pub surface: Option<String>,
    /// The thrower whose throw to use (needed when the fit has several).
    pub thrower: Option<String>,
    /// Another surface's restitution e and friction μ, where the fit held them fixed (a die
    /// whose weight was fitted on one surface, predicted on another).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<[f64; 2]>,
    /// Posterior draws to simulate.
    pub draws: usize,
    /// Rolls per draw.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// Another die than the fit's, thrown by the same hand on the same table; `None`: the
    /// fit's own die (a fit of blocks: `block`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other: Option<Box<crate::model::die::Die>>,
    /// Counts of the die predicted, to score the prediction against (`fit --data`'s rows).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub counts: Vec<crate::calibration::data::DataRow>,
}

/// The block a prediction from `fit` simulates where none is given: a fit of a die of any
/// shape predicts that die (its rows' block is its bounding box); a fit of blocks needs one,
/// and so does a fit whose rows all name their own dice (which of them?).
pub fn own_block(fit: &FitResult) -> Option<Block> {
    fit.config.method.die.shape.as_ref()?;
    // A row of the fit's own die, not one that names another (a `die` column's).
    fit.config
        .rows
        .iter()
        .find(|r| r.die.is_none())
        .map(|r| r.block)
}

/// Which group a new row takes from the fit: the named one, or the only one there is.
pub fn group(
    fit: &FitResult,
    of_surface: bool,
    asked: &Option<String>,
    what: &str,
) -> Result<String> {
    let known: Vec<String> = fit
        .params
        .iter()
        .filter(|p| !p.kind.of_die() && p.kind.of_surface() == of_surface)
        .map(|p| p.group.clone())
        .fold(Vec::new(), |mut v, g| {
            if !v.contains(&g) {
                v.push(g);
            }
            v
        });
    let shared = known.is_empty() || known == ["all"];
    // The rows' own names: a fit with one set of values for all still saw only these.
    let seen: Vec<String> = fit
        .config
        .rows
        .iter()
        .map(|r| if of_surface { &r.surface } else { &r.thrower }.clone())
        .fold(Vec::new(), |mut v, g| {
            if !v.contains(&g) {
                v.push(g);
            }
            v
        });
    match asked {
        Some(s) if !shared && known.contains(s) => Ok(s.clone()),
        Some(s) if shared && (s == "all" || seen.contains(s)) => Ok("all".into()),
        Some(s) => Err(Error::Invalid(format!(
            "{what} '{}' is not in the fit (it has: {})",
            crate::calibration::data::shown(s),
            if shared { &seen } else { &known }.join(", ")
        ))),
        None if shared => Ok("all".into()),
        None if known.len() == 1 => Ok(known[0].clone()),
        None => Err(Error::Invalid(format!(
            "name the {what}: the fit has several ({})",
            known.join(", ")
        ))),
    }
}
