//! Two fits of the same counts by different models (different `--free`), set side by side by
//! how well each predicts the rows it did not see: each row's leave-one-out log predictive
//! probability under each (from the fits' own `loo`), the richer model's gain summed over the
//! rows with its standard error over them, and the decision the calibrated paper makes between
//! its models ([`crossval::decide`]): a model earns its place only when its held-out gain
//! stands 3σ from nothing; otherwise the question is unresolved, and the rows it would take are
//! said.

use crate::calibration::crossval::{self, Decision, ModelScore};
use crate::calibration::params::Kind;
use crate::calibration::FitResult;
use crate::error::{Error, Result};
use serde::Serialize;

/// One row's log score under each model, and the richer's gain.
#[derive(Clone, Debug, Serialize)]
pub struct RowGain {
    /// The row's label.
    pub label: String,
    /// Its leave-one-out log score under the simpler model, then the richer.
    pub log_scores: [f64; 2],
    /// The richer's less the simpler's.
    pub gain: f64,
}

/// Two models' fits compared on the rows they share.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The simpler model (fewer free parameters), then the richer: each named by its free
    /// parameters, with its scores.
    pub models: [ModelScore; 2],
    /// The files they came from, in the same order.
    pub files: [String; 2],
    /// Each row's scores.
    pub rows: Vec<RowGain>,
    /// What the rows decide.
    pub decision: Decision,
}

/// A fit's free parameters' kinds, each once, in its order.
fn kinds(f: &FitResult) -> Vec<Kind> {
    let mut kinds = Vec::new();
    for p in &f.params {
        if !kinds.contains(&p.kind) {
            kinds.push(p.kind);
        }
    }
    kinds
}

/// A model named by its kinds ("e,mu,kappa").
fn model_name(kinds: &[Kind]) -> String {
    kinds
        .iter()
        .map(Kind::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

/// Refuses a fit with no rows scored without themselves, saying why it has none.
fn scored<'a>(f: &'a FitResult, file: &str) -> Result<&'a FitResult> {
    if f.loo.is_empty() {
        return Err(Error::Invalid(format!(
            "{file}: no row was predicted without itself (a fit of fewer than three rows, or one \
             written before fits scored their rows): nothing to compare by"
        )));
    }
    Ok(f)
}

/// The fits `a` and `b` (from `files`) of the same rows compared: the one with fewer free
/// parameters is the simpler (`a` if they have as many). Refused unless both scored the same
/// rows with the same counts.
pub fn compare(a: &FitResult, b: &FitResult, files: [&str; 2]) -> Result<Comparison> {
    let (a, b) = (scored(a, files[0])?, scored(b, files[1])?);
    let same = a.loo.len() == b.loo.len()
        && a.loo
            .iter()
            .zip(&b.loo)
            .all(|(x, y)| x.label == y.label && x.counts == y.counts);
    if !same {
        return Err(Error::Invalid(format!(
            "{} and {} are fits of different rows (labels or counts differ): a comparison \
             needs two models of the same counts",
            files[0], files[1]
        )));
    }
    let (simple, rich, files) = if b.params.len() < a.params.len() {
        (b, a, [files[1], files[0]])
    } else {
        (a, b, files)
    };
    let score = |f: &FitResult| {
        ModelScore::of(
            &model_name(&kinds(f)),
            &format!("{} free parameters", f.params.len()),
            f.params.len(),
            f.estimate.minus_two_ln_l,
            &f.loo,
        )
    };
    let models = [score(simple), score(rich)];
    let (sn, rn) = (models[0].name.clone(), models[1].name.clone());
    // Nested when every kind the simpler frees the richer frees too: then the likelihood ratio
    // on all rows is a second opinion (its χ² p-value ignores the surrogates' own noise).
    let nested = kinds(simple).iter().all(|k| kinds(rich).contains(k));
    let lr = nested
        .then(|| crossval::likelihood_ratio(&models[0], &models[1]))
        .filter(|t| t.1 > 0);
    let decision = crossval::decide(
        &format!("does freeing {rn} predict the rows it did not see better than {sn}?"),
        &sn,
        &rn,
        crossval::gain(&simple.loo, &rich.loo, false),
        lr,
        simple.loo.len(),
    );
    let rows = simple
        .loo
        .iter()
        .zip(&rich.loo)
        .map(|(s, r)| RowGain {
            label: s.label.clone(),
            log_scores: [s.log_score, r.log_score],
            gain: r.log_score - s.log_score,
        })
        .collect();
    Ok(Comparison {
        models,
        files: files.map(String::from),
        rows,
        decision,
    })
}
