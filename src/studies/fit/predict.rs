//! `dicephys predict`: a block the fit did not see, simulated at the fit's posterior draws.

use crate::calibration::design::point_seed;
use crate::calibration::heldout;
use crate::calibration::params::{Kind, Method};
use crate::calibration::predict::{group, BlockPrediction, PredictConfig, Predicted};
use crate::calibration::FitResult;
use crate::error::{Error, Field, Result};
use crate::model::die::Die;
use crate::run::runner::Runner;
use std::path::Path;

/// Checks a prediction before anything rolls: the fit whole, the draws and rolls in range, the
/// surface and thrower the fit's.
pub fn check(fit: &FitResult, cfg: &PredictConfig) -> Result<()> {
    fit.check()?;
    if cfg.draws < 2 || cfg.draws > fit.estimate.draws.len() {
        return Err(Error::field(
            Field::Draws,
            cfg.draws,
            format!(
                "from 2 to the fit's {} posterior draws",
                fit.estimate.draws.len()
            ),
        ));
    }
    if cfg.rolls == 0 || cfg.rolls > crate::run::spec::MAX_ROLLS {
        return Err(Error::field(
            Field::Rolls,
            cfg.rolls,
            format!("from 1 to {}", crate::run::spec::MAX_ROLLS),
        ));
    }
    group(fit, true, &cfg.surface, "surface")?;
    group(fit, false, &cfg.thrower, "thrower")?;
    if let Some(other) = &cfg.other {
        crate::calibration::other_die::check(other, fit)?;
        if other.shape.is_some() && cfg.mode != crate::model::scene::Mode::ThreeD {
            return Err(Error::field(
                Field::Shape,
                other.name(cfg.block),
                "a die of any shape is predicted in 3D",
            ));
        }
    } else if let (Some(s), Some(own)) = (
        &fit.config.method.die.shape,
        crate::calibration::predict::own_block(fit),
    ) {
        if cfg.block != own || cfg.mode != crate::model::scene::Mode::ThreeD {
            return Err(Error::field(
                Field::Block,
                format!("{} {}", cfg.block, cfg.mode.name()),
                format!(
                    "the fit is of {}: a prediction is of that die, in 3D (leave the block out)",
                    s.name
                ),
            ));
        }
    }
    let model = &fit.config.model;
    if let Some([e, mu]) = cfg.contact {
        if !((0.0..=1.0).contains(&e) && (0.0..=5.0).contains(&mu)) {
            return Err(Error::field(
                Field::Contact,
                format!("{e},{mu}"),
                "e must be in [0, 1] and μ in [0, 5]",
            ));
        }
    }
    if let (Some([e, mu]), true) = (
        cfg.contact,
        model.is_free(Kind::E) || model.is_free(Kind::Mu),
    ) {
        return Err(Error::field(
            Field::Contact,
            format!("{e},{mu}"),
            "the fit has e or μ free, fitted per surface: name one of its surfaces instead",
        ));
    }
    Ok(())
}

/// Where `block` lies outside what the fit's rows saw (each side's length, and the aspect
/// ratios width/breadth and breadth/length), by more than 1 %: a prediction there extrapolates.
pub fn extrapolation(fit: &FitResult, block: &crate::model::block::Block) -> Option<String> {
    let measures = |b: &crate::model::block::Block| {
        [
            ("length", b.length * 1000.0, "mm"),
            ("breadth", b.breadth * 1000.0, "mm"),
            ("width", b.width * 1000.0, "mm"),
            ("width/breadth", b.width / b.breadth, ""),
            ("breadth/length", b.breadth / b.length, ""),
        ]
    };
    let seen: Vec<_> = fit.config.rows.iter().map(|r| measures(&r.block)).collect();
    let out: Vec<String> = measures(block)
        .iter()
        .enumerate()
        .filter_map(|(i, (name, v, unit))| {
            let lo = seen.iter().map(|m| m[i].1).fold(f64::INFINITY, f64::min);
            let hi = seen
                .iter()
                .map(|m| m[i].1)
                .fold(f64::NEG_INFINITY, f64::max);
            (*v < lo * 0.99 || *v > hi * 1.01)
                .then(|| format!("{name} {v:.3}{unit} (the fit saw {lo:.3}–{hi:.3}{unit})"))
        })
        .collect();
    (!out.is_empty()).then(|| format!("outside the blocks the fit saw: {}", out.join(", ")))
}

/// True if a prediction gives the faces too: of a made die, a fit of faces or a die of any
/// shape, in 3D (`method` the prediction's: the fit's, or another die's).
fn predicts_faces(fit: &FitResult, cfg: &PredictConfig, method: &Method) -> bool {
    let faces_fit = cfg.other.is_none()
        && fit
            .config
            .rows
            .iter()
            .any(|r| r.outcomes == crate::calibration::data::Outcomes::Faces);
    cfg.mode == crate::model::scene::Mode::ThreeD
        && (!method.die.features.is_default() || method.die.shape.is_some() || faces_fit)
}

/// How the prediction throws: the fit's method, or the fit's with another die in place of its
/// own.
pub fn method_of(fit: &FitResult, cfg: &PredictConfig) -> Method {
    match &cfg.other {
        Some(o) => crate::calibration::other_die::method(o, &fit.config.method),
        None => fit.config.method.clone(),
    }
}

/// Rolls that did not settle, `what` of them, and what to change.
fn unsettled_error(what: String) -> Error {
    Error::failed(crate::text![
        what,
        "; raise ",
        Field::MaxSteps,
        " in the fit, or use a finer ",
        Field::Dt
    ])
}

/// Simulates `cfg.block` (or the fit's die of any shape) at posterior draws of `fit`, with
/// the fit's discrepancy where it has one. `None` if stopped early.
pub fn predict_block(
    fit: &FitResult,
    cfg: &PredictConfig,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<BlockPrediction>> {
    let Some(own) = fit_prediction(fit, cfg, runner, dir)? else {
        return Ok(None);
    };
    let p = own.clone().widened(fit.discrepancy.as_ref());
    if cfg.counts.is_empty() {
        return Ok(Some(p));
    }
    let method = method_of(fit, cfg);
    let Some(tests) = super::baseline::test_counts(fit, cfg, &method, (&own, &p), runner)? else {
        return Ok(None);
    };
    Ok(Some(BlockPrediction { tests, ..p }))
}

/// [`predict_block`] without the fit's discrepancy: the fit's own prediction.
fn fit_prediction(
    fit: &FitResult,
    cfg: &PredictConfig,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<BlockPrediction>> {
    check(fit, cfg)?;
    let surface = group(fit, true, &cfg.surface, "surface")?;
    let thrower = group(fit, false, &cfg.thrower, "thrower")?;
    let method = &method_of(fit, cfg);
    let shape = method.die.shape.as_deref();
    let with_faces = predicts_faces(fit, cfg, method);
    let mut freq: [Vec<f64>; 3] = Default::default();
    let mut face_freq: Vec<Vec<f64>> = vec![Vec::new(); method.die.outcomes()];
    let mut ratios = Vec::new();
    let mut unsettled = 0;
    for (m, spec) in draw_specs(fit, cfg, &surface, &thrower)?.iter().enumerate() {
        let ck = match dir {
            Some(d) => Some(runner.open_cell(&d.join(format!("draw-{m:04}")), spec)?),
            None => None,
        };
        let base = m as u64 * cfg.rolls;
        let progress = |n| (runner.progress)(base + n);
        let done = runner
            .with_progress(&progress)
            .run(spec, ck.as_ref(), &mut |_| Ok(()))?;
        if !done.complete {
            return Ok(None);
        }
        let c = &done.tally.counts;
        let settled = super::simulate::settled(&done.tally);
        unsettled += done.tally.rolls - settled;
        let sides = c.breadth + c.width;
        if settled == 0 || shape.is_none() && sides == 0 {
            return Err(unsettled_error(format!(
                "none of the {} rolls at posterior draw {m} settled on a {}: no probabilities to \
                 give",
                done.tally.rolls,
                if shape.is_some() { "face" } else { "side" }
            )));
        }
        if shape.is_none() {
            for (k, v) in [c.length, c.breadth, c.width].iter().enumerate() {
                freq[k].push(*v as f64 / settled as f64);
            }
            ratios.push(c.breadth as f64 / c.width.max(1) as f64);
        }
        if with_faces {
            let rolled = spec.scene.die.as_shape();
            let faces = super::simulate::outcome_counts(&done.tally, true, method, rolled)?;
            for (k, v) in faces.iter().enumerate() {
                face_freq[k].push(*v as f64 / settled as f64);
            }
        }
    }
    let all = cfg.draws as u64 * cfg.rolls;
    if unsettled as f64 > super::MAX_UNSETTLED_SHARE * all as f64 {
        return Err(unsettled_error(format!(
            "{unsettled} of the prediction's {all} rolls did not settle on a face: no \
             probabilities from them"
        )));
    }
    let n = cfg.rolls as f64;
    let binomial = |q: f64| q * (1.0 - q) / n;
    let faces = with_faces.then(|| face_freq.iter().map(|v| combine(v, &binomial)).collect());
    let ratio = shape.is_none().then(|| {
        combine(&ratios, &|r: f64| {
            // The paper's binomial error of a ratio r = q/(1 − q) of counts (q the breadth's
            // share of the side outcomes): Var r = q(1 − q)/(n (1 − q)⁴).
            let q = r / (1.0 + r);
            q * (1.0 - q) / n / (1.0 - q).powi(4)
        })
    });
    Ok(Some(BlockPrediction {
        block: cfg.block,
        mode: cfg.mode,
        shape: shape.map(|s| s.name.clone()),
        // A surface given by its e and μ is named by them.
        surface: match cfg.contact {
            Some([e, mu]) => format!("e {e}, μ {mu}"),
            None => surface,
        },
        thrower,
        p: freq
            .iter()
            .filter(|v| !v.is_empty())
            .map(|v| combine(v, &binomial))
            .collect(),
        ratio,
        labels: face_labels(shape, with_faces),
        faces,
        theory_ratio: shape
            .is_none()
            .then(|| crate::theory::ratio_from_r(cfg.block.r())),
        draws: cfg.draws,
        rolls: cfg.rolls,
        unsettled,
        overdispersion: fit.estimate.overdispersion,
        discrepancy: None,
        extrapolation: (shape.is_none() && fit.config.method.die.shape.is_none())
            .then(|| extrapolation(fit, &cfg.block))
            .flatten(),
        other_die: cfg.other.as_ref().map(|o| o.name(cfg.block)),
        tests: Vec::new(),
    }))
}

/// What a prediction's faces show: a die of any shape's labels, 1 to 6 for a cube's faces,
/// none without faces.
fn face_labels(shape: Option<&crate::model::shape::Shape>, with_faces: bool) -> Vec<String> {
    match shape {
        Some(s) => s.outcome_labels(),
        None if with_faces => (1..=6).map(|k| k.to_string()).collect(),
        None => Vec::new(),
    }
}

/// The runs of a prediction: `cfg.block` at `cfg.draws` of the fit's posterior draws, evenly
/// spaced, at the parameters of `surface` and `thrower` (or the surface `cfg.contact` gives),
/// each on its own keyed throws; checked.
fn draw_specs(
    fit: &FitResult,
    cfg: &PredictConfig,
    surface: &str,
    thrower: &str,
) -> Result<Vec<crate::run::spec::RunSpec>> {
    // The new row's coordinates: the fit's parameters of its surface and thrower.
    let row = FitResult::new_row(surface, thrower, cfg.block, cfg.mode);
    let method = method_of(fit, cfg);
    let step = fit.estimate.draws.len() / cfg.draws;
    (0..cfg.draws)
        .map(|m| {
            let mut values = fit.values_at(&row, &fit.estimate.draws[m * step]);
            if let Some([e, mu]) = cfg.contact {
                (values.e, values.mu) = (e, mu);
            }
            if cfg.other.is_some() {
                values = crate::calibration::other_die::without_die_params(values);
            }
            let seed = point_seed(cfg.seed, cfg.block, cfg.mode, m);
            let spec = method.spec(cfg.block, cfg.mode, &values, seed, cfg.rolls);
            spec.validate(false)?;
            Ok(spec)
        })
        .collect()
}

/// The mean over the draws of `v`, one value a draw, with its error: the draws' spread less
/// the rolls' noise (`noise(value)`, a value's variance from its rolls alone) is the
/// parameters' part; the mean's own simulation error adds (parameters + noise)/draws.
fn combine(v: &[f64], noise: &dyn Fn(f64) -> f64) -> Predicted {
    let m = v.len() as f64;
    let raw = Predicted::of(v, 0.0);
    let rolls_var = v.iter().map(|&x| noise(x)).sum::<f64>() / m;
    let params_var = (raw.err_params.powi(2) - rolls_var).max(0.0);
    let sim_var = (params_var + noise(raw.value)) / m;
    Predicted {
        value: raw.value,
        err: (params_var + sim_var).sqrt(),
        err_params: params_var.sqrt(),
        err_sim: sim_var.sqrt(),
        err_model: 0.0,
        fit_value: None,
    }
}

/// What to predict for `row` of a blocks file.
fn block_config(
    r: &crate::calibration::heldout::BlockRow,
    draws: usize,
    rolls: u64,
    seed: u64,
) -> PredictConfig {
    PredictConfig {
        block: r.block,
        mode: r.mode,
        surface: r.surface.clone(),
        thrower: r.thrower.clone(),
        contact: None,
        draws,
        rolls,
        seed,
        other: None,
        counts: Vec::new(),
    }
}

/// Each row of a counts file that names its die (its `die` column: a shape or a die file) as
/// a prediction of that die, another than the fit's, scored against the row's counts
/// (`draws` posterior draws × `rolls` throws a die, every die at `seed`). A row that names
/// none, or a die that cannot be had, is refused in one line naming the row.
pub fn die_configs(
    rows: Vec<crate::calibration::data::DataRow>,
    draws: usize,
    rolls: u64,
    seed: u64,
) -> Result<Vec<PredictConfig>> {
    let mut dice: Vec<(String, Die)> = Vec::new();
    rows.into_iter()
        .map(|row| {
            let at = |e: Error| Error::Invalid(format!("row '{}': {e}", row.label));
            let Some(name) = row.die.clone() else {
                return Err(at(Error::Invalid(
                    "names no die (a file of dice gives each row's in its die column)".into(),
                )));
            };
            let die = match dice.iter().find(|(n, _)| *n == name) {
                Some((_, d)) => d.clone(),
                None => {
                    let d = crate::calibration::dice::RowDie::resolve(&name)
                        .map_err(|e| at(Error::Invalid(format!("die '{name}': {e}"))))?
                        .die;
                    dice.push((name, d.clone()));
                    d
                }
            };
            let shape = die.shape.as_deref().expect("a die of any shape");
            let counts = crate::calibration::data::on_shape(std::slice::from_ref(&row), shape)
                .map_err(at)?;
            Ok(PredictConfig {
                block: die.block(row.block),
                mode: crate::model::scene::Mode::ThreeD,
                surface: Some(row.surface.clone()),
                thrower: (row.thrower != "all").then(|| row.thrower.clone()),
                contact: None,
                draws,
                rolls,
                seed,
                other: Some(Box::new(die)),
                counts,
            })
        })
        .collect()
}

/// Checks every row of a blocks file ([`check`]) before anything is written or rolled.
pub fn check_blocks(
    fit: &FitResult,
    rows: &[crate::calibration::heldout::BlockRow],
    draws: usize,
    rolls: u64,
    seed: u64,
) -> Result<()> {
    for r in rows {
        check(fit, &block_config(r, draws, rolls, seed))
            .map_err(|e| Error::Invalid(format!("row '{}': {e}", r.label)))?;
    }
    Ok(())
}

/// Each of `rows` predicted from `fit` (`draws` posterior draws × `rolls` throws a block), and
/// tested against its counts where it has them. Every row is checked before any rolls. `None`
/// if stopped early.
pub fn predict_blocks(
    fit: &FitResult,
    rows: &[crate::calibration::heldout::BlockRow],
    draws: usize,
    rolls: u64,
    seed: u64,
    runner: &Runner,
) -> Result<Option<Vec<crate::calibration::heldout::PredictedRow>>> {
    check_blocks(fit, rows, draws, rolls, seed)?;
    let cfg = |r| block_config(r, draws, rolls, seed);
    let per_row = draws as u64 * rolls;
    let mut out = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let base = i as u64 * per_row;
        let progress = |n| (runner.progress)(base + n);
        let in_row = |e| match e {
            Error::Failed(m) => Error::Failed(m.after(&format!("row '{}': ", r.label))),
            e => e,
        };
        let runner = runner.with_progress(&progress);
        let Some(own) = fit_prediction(fit, &cfg(r), &runner, None).map_err(in_row)? else {
            return Ok(None);
        };
        let p = own.clone().widened(fit.discrepancy.as_ref());
        let mut tested = crate::calibration::heldout::test(r, p);
        if let Some(scores) = tested.scores.as_mut() {
            if fit.discrepancy.as_ref().is_some_and(|d| d.in_force()) {
                scores.without_discrepancy =
                    heldout::score_against(r, &own.p, fit.estimate.overdispersion);
            }
            let Some((scene, theory)) = baselines(fit, &cfg(r), &runner).map_err(in_row)? else {
                return Ok(None);
            };
            scores.default_scene = heldout::score_against(r, &scene, 1.0);
            scores.quasi_static = theory.and_then(|q| heldout::score_against(r, &q, 1.0));
        }
        out.push(tested);
    }
    Ok(Some(out))
}

/// Rolls of the uncalibrated default scene, per prediction's roll of one draw: enough that its
/// own simulation error is well under the counts'.
pub const BASELINE_ROLLS_PER_DRAW_ROLLS: u64 = 4;

/// The default scene's shares and the quasi-static theory's, where it applies.
type Baselines = (Vec<Predicted>, Option<Vec<Predicted>>);

/// The baselines of `cfg`'s block ([`super::baseline`]): the default scene (the fit's fixed
/// values, its error the simulation's alone) and the quasi-static theory (3D), each as
/// P(length), P(breadth), P(width) vertical. `None` if stopped early.
pub fn baselines(
    fit: &FitResult,
    cfg: &PredictConfig,
    runner: &Runner,
) -> Result<Option<Baselines>> {
    let (method, fixed) = (&fit.config.method, &fit.config.model.fixed);
    let at = (cfg.block, cfg.mode, false);
    let rolls = cfg.rolls * BASELINE_ROLLS_PER_DRAW_ROLLS;
    let Some((shares, settled)) =
        super::baseline::shares_at(method, fixed, at, cfg.seed, rolls, runner)?
    else {
        return Ok(None);
    };
    let n = settled.max(1) as f64;
    let scene = shares
        .iter()
        .map(|&q| Predicted::of(&[q], q * (1.0 - q) / n))
        .collect();
    let theory = super::baseline::quasi_static(method, fixed, at)
        .map(|q| q.iter().map(|&v| Predicted::of(&[v], 0.0)).collect());
    Ok(Some((scene, theory)))
}
