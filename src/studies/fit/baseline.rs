//! The baselines a calibrated prediction is scored beside (issue 71.3): the uncalibrated
//! default scene (every parameter the fit frees at the value `fit` takes when it is not free,
//! simulated; its error the simulation's alone) and the quasi-static theory (exact, no error;
//! a die of any shape only), and the fit's leave-one-out rows scored with both beside them.

use crate::calibration::crossval::LooRow;
use crate::calibration::data::DataRow;
use crate::calibration::data::Outcomes;
use crate::calibration::design::point_seed;
use crate::calibration::discrepancy::{self, Discrepancy};
use crate::calibration::params::{Fixed, Method};
use crate::calibration::predict::Predicted;
use crate::calibration::predict::{BlockPrediction, PredictConfig};
use crate::calibration::proper::{self, DieScores, Score, Scores};
use crate::calibration::scores::CountsTest;
use crate::calibration::scores::LOO_BASELINE_POINTS;
use crate::calibration::{FitConfig, FitResult};
use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::model::scene::Mode;
use crate::run::runner::Runner;

/// A seed of the baselines' own, apart from every design's and prediction's.
const BASELINE_SEED: u64 = 0x0ba5_e11e;

/// `block` in `mode` simulated at `v` with `rolls` throws: each outcome's share of the settled
/// rolls (length, breadth, width vertical, or, `faces`, each face or label as a fit counts
/// them) and the rolls that settled. `None` if stopped early.
pub fn shares_at(
    method: &Method,
    v: &Fixed,
    (block, mode, faces): (Block, Mode, bool),
    seed: u64,
    rolls: u64,
    runner: &Runner,
) -> Result<Option<(Vec<f64>, u64)>> {
    let spec = method.spec(
        block,
        mode,
        v,
        point_seed(seed ^ BASELINE_SEED, block, mode, 0),
        rolls,
    );
    spec.validate(false)?;
    let silent = |_| {};
    let done = runner
        .with_progress(&silent)
        .run(&spec, None, &mut |_| Ok(()))?;
    if !done.complete {
        return Ok(None);
    }
    let counts =
        super::simulate::outcome_counts(&done.tally, faces, method, spec.scene.die.as_shape())?;
    let settled: u64 = counts.iter().sum();
    let n = settled.max(1) as f64;
    Ok(Some((
        counts.iter().map(|&k| k as f64 / n).collect(),
        settled,
    )))
}

/// The quasi-static theory's shares (exact, released at rest): each of a die of any shape's
/// labels in its outcome order at the centre of mass of `v`, or a block's length, breadth and
/// width vertical in 3D (the solid angles its inner box's faces subtend at its centre of mass;
/// body axes x breadth, y width, z length); `None` for a block in 2D, a block's faces, or
/// where the theory fails.
pub fn quasi_static(
    method: &Method,
    v: &Fixed,
    (block, mode, faces): (Block, Mode, bool),
) -> Option<Vec<f64>> {
    let spec = method.spec(block, Mode::ThreeD, v, 0, 1);
    let Some(shape) = method.die.shape.as_deref() else {
        if mode != Mode::ThreeD || faces {
            return None;
        }
        let up =
            crate::theory::quasi_static::faces_up(&crate::model::die::DieBody::of(&spec.scene));
        return Some(vec![up[4] + up[5], up[0] + up[1], up[2] + up[3]]);
    };
    let com = crate::model::mass::MassProps::compute(&spec.scene).com;
    let by_label = crate::theory::quasi_static::shape_labels(shape, &com).ok()?;
    let total: f64 = by_label.iter().map(|(_, q)| q).sum();
    Some(
        shape
            .outcome_labels()
            .iter()
            .map(|l| {
                by_label
                    .iter()
                    .find(|(m, _)| m == l)
                    .map_or(0.0, |(_, q)| q / total)
            })
            .collect(),
    )
}

/// `shares` (in a row's counts' order) summed over the row's groups, each with the binomial
/// error of `settled` rolls (0 for the theory's `None`).
pub fn grouped(row: &DataRow, shares: &[f64], settled: Option<u64>) -> Vec<Predicted> {
    let p: Vec<f64> = row
        .groups
        .iter()
        .map(|g| {
            g.iter()
                .map(|&k| shares.get(k).copied().unwrap_or(0.0))
                .sum()
        })
        .collect();
    let norm: f64 = p.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    p.iter()
        .map(|q| {
            let q = q / norm;
            let var = settled.map_or(0.0, |n| q * (1.0 - q) / n.max(1) as f64);
            Predicted::of(&[q], var)
        })
        .collect()
}

/// The scores of `p` (one per group) against `counts` from a fit of overdispersion `phi`.
pub fn score_of(counts: &[u64], p: &[Predicted], phi: f64) -> Score {
    let values: Vec<f64> = p.iter().map(|q| q.value).collect();
    let sigma: Vec<f64> = p.iter().map(|q| q.err).collect();
    proper::score(counts, &values, &sigma, phi)
}

/// Row `r` of `loo` as a discrepancy learnt from the other rows (not from itself, nor from
/// its die's other rows where a `die` column names it) leaves it: `None` where they ask for
/// none.
fn with_others_discrepancy(loo: &[LooRow], r: usize, phi: f64) -> Option<Vec<Predicted>> {
    let own = |i: usize| i == r || loo[r].die.is_some() && loo[i].die == loo[r].die;
    let others: Vec<LooRow> = loo
        .iter()
        .enumerate()
        .filter(|(i, _)| !own(*i))
        .map(|(_, row)| row.clone())
        .collect();
    let d = Discrepancy::estimate(&others, phi).filter(Discrepancy::any)?;
    let row = &loo[r];
    let names: Vec<&str> = row.outcomes.iter().map(String::as_str).collect();
    let values: Vec<f64> = row.p.iter().map(|q| q.value).collect();
    let c = d.correct(&names, &values);
    Some(
        row.p
            .iter()
            .zip(c)
            .map(|(q, c)| discrepancy::apply(*q, c))
            .collect(),
    )
}

/// Scores every leave-one-out row of a fit of `cfg` in place, beside the baselines (each row's
/// default scene simulated with [`LOO_BASELINE_POINTS`] design points' rolls), and returns the total. The rows'
/// predictions are the fits without them, on their own errors (φ = 1: the overdispersion of a
/// fit without the row is not kept); the discrepancy's, one learnt from the other rows' misses
/// (`phi` the whole fit's, as the fit learns its own). `None` if stopped early.
pub fn score_loo(
    cfg: &FitConfig,
    phi: f64,
    loo: &mut [LooRow],
    runner: &Runner,
) -> Result<Option<Scores>> {
    let (method, fixed) = (&cfg.method, &cfg.model.fixed);
    let with_d: Vec<Option<Vec<Predicted>>> = (0..loo.len())
        .map(|r| with_others_discrepancy(loo, r, phi))
        .collect();
    // Beside a discrepancy any row has, every row's score without it: the totals compare.
    let any_d = with_d.iter().any(Option::is_some);
    let mut all = Vec::new();
    for (r, with_d) in with_d.iter().enumerate() {
        let row = &cfg.rows[r];
        let counts = loo[r].counts.clone();
        let faces = row.outcomes == crate::calibration::data::Outcomes::Faces;
        // The row's own die, where it names one.
        let method = &*method.of_row(row);
        let Some((shares, settled)) = shares_at(
            method,
            fixed,
            (row.block, row.mode, faces),
            cfg.seed.wrapping_add(r as u64),
            cfg.design.rolls * LOO_BASELINE_POINTS,
            runner,
        )?
        else {
            return Ok(None);
        };
        let own = score_of(&counts, &loo[r].p, 1.0);
        let scores = Scores {
            prediction: Some(with_d.as_ref().map_or(own, |p| score_of(&counts, p, 1.0))),
            without_discrepancy: any_d.then_some(own),
            default_scene: Some(score_of(
                &counts,
                &grouped(row, &shares, Some(settled)),
                1.0,
            )),
            quasi_static: quasi_static(method, fixed, (row.block, row.mode, faces))
                .map(|q| score_of(&counts, &grouped(row, &q, None), 1.0)),
        };
        loo[r].scores = Some(scores.clone());
        all.push(scores);
    }
    let refs: Vec<&Scores> = all.iter().collect();
    Ok(Some(Scores::total(&refs)))
}

/// The leave-one-out rows' scores summed per die, where a `die` column names them (each die's
/// rows were predicted together by a fit of the other dice); none for rows of no die.
pub fn by_die(loo: &[LooRow]) -> Vec<DieScores> {
    let mut out: Vec<DieScores> = Vec::new();
    let mut dice: Vec<&str> = Vec::new();
    for d in loo.iter().filter_map(|r| r.die.as_deref()) {
        if !dice.contains(&d) {
            dice.push(d);
        }
    }
    for die in dice {
        let rows: Vec<&LooRow> = loo
            .iter()
            .filter(|r| r.die.as_deref() == Some(die))
            .collect();
        let scores: Vec<&Scores> = rows.iter().filter_map(|r| r.scores.as_ref()).collect();
        if scores.len() != rows.len() {
            continue;
        }
        out.push(DieScores {
            die: die.to_string(),
            rows: rows.iter().map(|r| r.label.clone()).collect(),
            scores: Scores::total(&scores),
        });
    }
    out
}

/// Each group of `row`'s outcomes predicted: `p` (in the row's counts' order) summed over the
/// group, the errors in quadrature.
fn by_group(row: &DataRow, p: &[Predicted]) -> Vec<Predicted> {
    row.groups
        .iter()
        .map(|g| {
            let v: f64 = g.iter().map(|&k| p.get(k).map_or(0.0, |q| q.value)).sum();
            let var: f64 = g
                .iter()
                .map(|&k| p.get(k).map_or(0.0, |q| q.err * q.err))
                .sum();
            Predicted::of(&[v], var)
        })
        .collect()
}

/// `predict --counts`: the prediction (`own` without the fit's discrepancy, `p` with it)
/// scored against each row of `cfg.counts` beside the default scene (simulated with as many
/// rolls as the prediction) and the quasi-static theory. `None` if stopped early.
pub fn test_counts(
    fit: &FitResult,
    cfg: &PredictConfig,
    method: &Method,
    (own, p): (&BlockPrediction, &BlockPrediction),
    runner: &Runner,
) -> Result<Option<Vec<CountsTest>>> {
    let faces =
        method.die.shape.is_some() || cfg.counts.iter().any(|r| r.outcomes == Outcomes::Faces);
    if faces && own.faces.is_none() {
        return Err(Error::Invalid(
            "--counts counts faces, and this prediction gives none (a block in 2D?)".into(),
        ));
    }
    let mut fixed = fit.config.model.fixed;
    if cfg.other.is_some() {
        fixed = crate::calibration::other_die::without_die_params(fixed);
    }
    if let Some([e, mu]) = cfg.contact {
        (fixed.e, fixed.mu) = (e, mu);
    }
    let rolls = cfg.rolls * cfg.draws as u64;
    let at = (cfg.block, cfg.mode, faces);
    let Some((shares, settled)) = shares_at(method, &fixed, at, cfg.seed, rolls, runner)? else {
        return Ok(None);
    };
    let theory = quasi_static(method, &fixed, at);
    let phi = fit.estimate.overdispersion;
    let has_d = fit.discrepancy.as_ref().is_some_and(Discrepancy::in_force);
    let of = |b: &BlockPrediction, row: &DataRow| {
        by_group(
            row,
            if faces {
                b.faces.as_deref().unwrap_or(&[])
            } else {
                &b.p
            },
        )
    };
    let tests = cfg
        .counts
        .iter()
        .map(|row| {
            let counts = row.grouped();
            let predicted = of(p, row);
            let scores = Scores {
                prediction: Some(score_of(&counts, &predicted, phi)),
                without_discrepancy: has_d.then(|| score_of(&counts, &of(own, row), phi)),
                default_scene: Some(score_of(
                    &counts,
                    &grouped(row, &shares, Some(settled)),
                    1.0,
                )),
                quasi_static: theory
                    .as_ref()
                    .map(|q| score_of(&counts, &grouped(row, q, None), 1.0)),
            };
            CountsTest {
                label: row.label.clone(),
                outcomes: row.group_names(),
                counts,
                predicted,
                scores,
            }
        })
        .collect();
    Ok(Some(tests))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn method() -> Method {
        Method {
            engine: crate::engine::EngineKind::Bullet,
            dt: 1.0 / 250.0,
            max_steps: 20_000,
            die: Default::default(),
            dice: Vec::new(),
        }
    }

    #[test]
    fn the_quasi_static_block_is_a_cubes_thirds_and_a_long_blocks_sides() {
        let v = Fixed::default();
        let cube = Block::from_mm(16.0, 16.0, 16.0).unwrap();
        let q = quasi_static(&method(), &v, (cube, Mode::ThreeD, false)).unwrap();
        for p in &q {
            assert!((p - 1.0 / 3.0).abs() < 1e-12, "{q:?}");
        }
        // A long block rarely stands on its end, and the theory has no 2D or faces' answer.
        let long = Block::from_mm(42.4, 16.0, 16.0).unwrap();
        let q = quasi_static(&method(), &v, (long, Mode::ThreeD, false)).unwrap();
        assert!(
            q[0] < 0.1
                && (q[1] - q[2]).abs() < 1e-12
                && (q.iter().sum::<f64>() - 1.0).abs() < 1e-12
        );
        assert!(quasi_static(&method(), &v, (long, Mode::TwoD, false)).is_none());
        assert!(quasi_static(&method(), &v, (long, Mode::ThreeD, true)).is_none());
    }
}
