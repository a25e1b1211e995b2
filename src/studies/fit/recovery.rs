//! Does the fit recover known parameters? Counts simulated at a chosen truth, in the shape of
//! the real data (the same blocks, modes and numbers of throws), fitted back, many times over
//! fixed seeds: the truth should fall inside the joint 2σ region in about 95 % of repetitions.
//! Each repetition simulates its own data and its own designs (fresh keyed throws), so the
//! surrogates' noise is part of what is checked.

use crate::calibration::data::{DataRow, Outcomes};
use crate::calibration::design::point_seed;
use crate::calibration::estimate::Likelihood;
use crate::calibration::params::Fixed;
use crate::calibration::recovery::{Recovery, Repetition};
use crate::calibration::FitConfig;
use crate::error::{Error, Field, Result};
use crate::run::runner::Runner;
use crate::studies::fit::simulate::outcome_counts;

/// Counts of `rows`' blocks simulated at `truth` with as many throws as each row counts.
pub fn simulate_data(
    cfg: &FitConfig,
    truth: &Fixed,
    seed: u64,
    runner: &Runner,
) -> Result<Option<Vec<DataRow>>> {
    let mut out = Vec::new();
    let mut before = 0;
    for (i, row) in cfg.rows.iter().enumerate() {
        let n = row.counts.iter().sum::<u64>();
        // The row's own die, where it names one.
        let method = cfg.method.of_row(row);
        let spec = method.spec(
            row.block,
            row.mode,
            truth,
            point_seed(seed, row.block, row.mode, i),
            n,
        );
        // Each row's run counts from naught; the progress goes on from the rows before it.
        let progress = |k: u64| (runner.progress)(before + k);
        let done = runner
            .with_progress(&progress)
            .run(&spec, None, &mut |_| Ok(()))?;
        before += n;
        if !done.complete {
            return Ok(None);
        }
        let faces = row.outcomes == Outcomes::Faces;
        let counts = outcome_counts(&done.tally, faces, &method, spec.scene.die.as_shape())?;
        // Merged groups keep their count in the first member, as the data file does.
        let grouped: Vec<u64> = row
            .groups
            .iter()
            .map(|g| g.iter().map(|&k| counts[k]).sum())
            .collect();
        out.push(row.with_grouped(&grouped));
    }
    Ok(Some(out))
}

/// Checks the truth (a value for every free parameter, inside its range) and the repeats,
/// before anything is written or rolled.
pub fn check_truth(cfg: &FitConfig, truth: &[f64], repeats: usize) -> Result<()> {
    let model = &cfg.model;
    if repeats == 0 {
        return Err(Error::field(
            Field::Repeats,
            0,
            "need at least one repetition",
        ));
    }
    if truth.len() != model.free.len() {
        return Err(Error::Invalid(format!(
            "the truth gives {} values for {} free parameters",
            truth.len(),
            model.free.len()
        )));
    }
    for ((kind, range), v) in model.free.iter().zip(&model.ranges).zip(truth) {
        if !(range.lo..=range.hi).contains(v) {
            return Err(Error::field(
                Field::Recover,
                format!("{kind}={v}"),
                crate::text![
                    format!("outside its range {range} ("),
                    Field::Range,
                    " sets it)"
                ],
            ));
        }
    }
    Ok(())
}

/// Runs `repeats` repetitions at `truth` (the free parameters' values, one per kind in
/// `cfg.model.free`'s order, shared by every surface and thrower). `None` if stopped early.
pub fn run(
    cfg: &FitConfig,
    truth: &[f64],
    repeats: usize,
    runner: &Runner,
) -> Result<Option<Recovery>> {
    cfg.validate()?;
    check_truth(cfg, truth, repeats)?;
    let model = &cfg.model;
    let coords: Vec<f64> = model
        .free
        .iter()
        .zip(&model.ranges)
        .zip(truth)
        .map(|((k, r), v)| k.coordinate(*r, *v))
        .collect();
    let truth_values =
        crate::calibration::params::values(&model.fixed, &model.whole_axes(), &coords);
    let mut reps = Vec::new();
    let mut rolls = 0u64;
    let mut data_rolls = 0u64;
    let mut names = Vec::new();
    let mut region = 0.0;
    let session = super::Session::default();
    for rep in 0..repeats {
        let seed = cfg.seed.wrapping_add(1_000_003 * rep as u64);
        // The session counts the fits' rolls over every repetition; the data's are counted
        // here, so the progress goes on from all rolled so far (the data's run used to start
        // it again at 0 % each repetition).
        let (fits, data_before) = (session.rolled(), data_rolls);
        let progress = |n: u64| (runner.progress)(fits + data_before + n);
        let at = runner.with_progress(&progress);
        let Some(rows) = simulate_data(cfg, &truth_values, seed ^ 0x5eed_da7a, &at)? else {
            return Ok(None);
        };
        data_rolls += rows
            .iter()
            .map(|r| r.counts.iter().sum::<u64>())
            .sum::<u64>();
        let data_cfg = FitConfig {
            rows,
            seed,
            ..cfg.clone()
        };
        let data_so_far = data_rolls;
        let progress = |n: u64| (runner.progress)(data_so_far + n);
        let at = runner.with_progress(&progress);
        let Some(fitted) = super::fit(&data_cfg, &at, None, &session)? else {
            return Ok(None);
        };
        rolls += fitted.rolls + data_rolls - data_before;
        let est = &fitted.estimate;
        names = est.params.iter().map(|p| p.name.clone()).collect();
        region = est.region_delta;
        reps.push(judged(&data_cfg, &fitted, truth, seed));
    }
    let n = reps.len().max(1) as f64;
    let coverage = reps.iter().filter(|r| r.covered).count() as f64 / n;
    let interval_coverage = (0..names.len())
        .map(|j| reps.iter().filter(|r| r.in_interval[j]).count() as f64 / n)
        .collect();
    Ok(Some(Recovery {
        truth: names
            .iter()
            .enumerate()
            .map(|(j, _)| {
                let kind = model.params(&cfg.rows)[j].kind;
                truth[model.free.iter().position(|k| *k == kind).expect("free")]
            })
            .collect(),
        names,
        region_delta: region,
        repetitions: reps,
        coverage,
        interval_coverage,
        rolls,
    }))
}

/// One repetition judged: the truth's Δ(−2 ln L) from the fit's maximum (each parameter at its
/// own coordinate; outside its narrowed box: not covered), and each 2σ interval's hold on it.
fn judged(data: &FitConfig, fitted: &super::Fitted, truth: &[f64], seed: u64) -> Repetition {
    let model = &data.model;
    let (params, est) = (&fitted.params, &fitted.estimate);
    let lik = Likelihood::new(&data.rows, &fitted.designs, &fitted.config.model, params)
        .holding(est.concentrations.clone());
    let value_of = |kind| truth[model.free.iter().position(|k| *k == kind).expect("free")];
    let x_true: Vec<f64> = params
        .iter()
        .map(|p| p.kind.coordinate(p.range, value_of(p.kind)))
        .collect();
    let inside = x_true.iter().all(|u| (-1e-12..=1.0 + 1e-12).contains(u));
    let delta = if inside {
        lik.minus_two_ln_l(&x_true) - est.minus_two_ln_l
    } else {
        f64::INFINITY
    };
    let in_interval = est
        .params
        .iter()
        .map(|p| {
            let v = value_of(p.param.kind);
            // Ends interpolated on the profile's grid: a truth at a face is inside an open
            // side.
            p.two_sigma[0] - 1e-12 <= v && v <= p.two_sigma[1] + 1e-12
        })
        .collect();
    Repetition {
        seed,
        truth_delta: delta,
        covered: delta <= est.region_delta,
        in_interval,
        values: est.params.iter().map(|p| p.value).collect(),
    }
}
