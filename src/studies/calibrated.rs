//! `dicephys paper --calibrated`: all 19 rows of the paper's table simulated, with the
//! contact's e and μ (per surface) and the throw's κ fitted to the measured counts; every row
//! predicted by a fit that did not see it, beside the paper's theory on the same rows; the
//! models that the data might prefer compared by the same leave-one-out scores; and the
//! simulation method checked against a finer step at the fitted values.
//!
//! The models:
//! - `hand` (the main one): e and μ per surface, a hand's throw with κ free, one thrower;
//! - `paper-throw`: the same with the paper's own throw (κ → ∞), which its simulations used;
//! - `shared`: one e and one μ for every surface, κ free;
//! - `long-2d`: as `hand`, with the three long pine blocks (≥ 300 mm) in the paper's 2D model.

use crate::calibration::crossval::{leave_one_out, likelihood_ratio, LooRow, ModelScore};
use crate::calibration::data::{paper_rows, DataRow};
use crate::calibration::design::DesignSpec;
use crate::calibration::estimate::Search;
use crate::calibration::paper::{CalibratedPaper, Decision, TheoryRow};
use crate::calibration::params::{self, Kind, Method, ModelSpec};
use crate::calibration::{FitConfig, FitCost, FitResult};
use crate::error::{Error, Result};
use crate::model::scene::Mode;
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::Runner;
use crate::studies::fit::{self, Fitted, Session};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// What to simulate.
#[derive(Clone, Debug, Serialize)]
pub struct CalibratedConfig {
    /// How each throw is simulated.
    pub method: Method,
    /// How densely each block is simulated.
    pub design: DesignSpec,
    /// The search's settings.
    pub search: Search,
    /// The throws' seed.
    pub seed: u64,
    /// Throws per block in the method check.
    pub check_rolls: u64,
    /// The method check's reference time step, s.
    pub reference_dt: f64,
}

impl CalibratedConfig {
    /// Checks every value before anything runs, each named by its field (`point_rolls`,
    /// `points`, `reference_dt`, `check_rolls`, `dt`, `max_steps`).
    pub fn validate(&self) -> Result<()> {
        let max = crate::run::spec::MAX_ROLLS;
        if self.design.rolls == 0 || self.design.rolls > max {
            return Err(Error::field(
                "point_rolls",
                self.design.rolls,
                format!("from 1 to {max}"),
            ));
        }
        if self.check_rolls == 0 || self.check_rolls > max {
            return Err(Error::field(
                "check_rolls",
                self.check_rolls,
                format!("from 1 to {max}"),
            ));
        }
        crate::model::scene::check_dt("reference_dt", self.reference_dt)?;
        crate::model::scene::check_dt("dt", self.method.dt)?;
        if self.method.max_steps == 0 {
            return Err(Error::field("max_steps", 0, "need at least one step"));
        }
        let rows = paper_rows()?;
        for (_, _, model, rows) in models(&rows) {
            let dims = model.free.len();
            self.design.validate(dims).map_err(|e| match e {
                Error::Invalid(m) if m.starts_with("points ") => Error::field(
                    "points",
                    self.design.points,
                    m.split_once(": ").map_or(m.clone(), |p| p.1.to_string()),
                ),
                e => e,
            })?;
            FitConfig {
                rows,
                model,
                method: self.method,
                design: self.design,
                search: self.search,
                seed: self.seed,
            }
            .validate()?;
        }
        Ok(())
    }
}

/// Rows of this length or longer are the "long blocks" the `long-2d` model simulates in 2D.
pub const LONG_MM: f64 = 300.0;

/// The models compared: name, description, model, rows.
pub fn models(rows: &[DataRow]) -> Vec<(&'static str, &'static str, ModelSpec, Vec<DataRow>)> {
    let hand = ModelSpec::free(&[Kind::E, Kind::Mu, Kind::Kappa]);
    let paper_throw = ModelSpec::free(&[Kind::E, Kind::Mu]);
    let shared = ModelSpec {
        shared: vec![Kind::E, Kind::Mu],
        ..hand.clone()
    };
    let long_2d: Vec<DataRow> = rows
        .iter()
        .map(|r| {
            if r.block.length * 1000.0 >= LONG_MM {
                DataRow {
                    mode: Mode::TwoD,
                    groups: vec![vec![1], vec![2]],
                    ..r.clone()
                }
            } else {
                r.clone()
            }
        })
        .collect();
    vec![
        (
            "hand",
            "e and μ per surface; a hand's throw, κ free",
            hand.clone(),
            rows.to_vec(),
        ),
        (
            "paper-throw",
            "e and μ per surface; the paper's throw (κ → ∞)",
            paper_throw,
            rows.to_vec(),
        ),
        (
            "shared",
            "one e and one μ for every surface; κ free",
            shared,
            rows.to_vec(),
        ),
        (
            "long-2d",
            "as hand, the long pine blocks (≥ 300 mm) in 2D",
            hand,
            long_2d,
        ),
    ]
}

/// The rolls the study makes, about: the first passes twice (the second passes roll about as
/// many again), and the method check's two methods on every block.
pub fn total_rolls(cfg: &CalibratedConfig) -> Result<u64> {
    let blocks = crate::calibration::design::blocks(&paper_rows()?).len() as u64;
    Ok(2 * first_pass_rolls(cfg)? + 2 * cfg.check_rolls * blocks)
}

/// The rolls the first passes make.
fn first_pass_rolls(cfg: &CalibratedConfig) -> Result<u64> {
    let rows = paper_rows()?;
    Ok(models(&rows)
        .into_iter()
        .map(|(_, _, model, rows)| {
            FitConfig {
                rows,
                model,
                method: cfg.method,
                design: cfg.design,
                search: cfg.search,
                seed: cfg.seed,
            }
            .total_rolls()
        })
        .sum())
}

/// The richer model's gain in summed log score over the simpler's, with its standard error over
/// the rows.
fn gain(simple: &[LooRow], rich: &[LooRow], sides: bool) -> (f64, f64) {
    let d: Vec<f64> = simple
        .iter()
        .zip(rich)
        .map(|(s, r)| {
            if sides {
                r.side_log_score - s.side_log_score
            } else {
                r.log_score - s.log_score
            }
        })
        .filter(|v| v.is_finite())
        .collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (d.iter().sum(), (n * var).sqrt())
}

/// How far from nothing a held-out gain must stand for a model decision, in its σ.
const RESOLVED_SIGMA: f64 = 3.0;

/// The rows the gains are summed over (the paper's table).
const ROWS: f64 = 19.0;

fn verdict(
    question: &str,
    simpler: &str,
    richer: &str,
    g: (f64, f64),
    lr: Option<(f64, usize, f64)>,
) -> Decision {
    let (gain, err) = g;
    // A model is chosen only when its held-out gain stands 3σ from nothing: at 2σ, a gain
    // near that size flips between seeds (seeds 1–3 of the default run did), and a decision
    // that moves with the seed is not a result. Otherwise it is unresolved, with the rows it
    // would take were the gain per row to stay as measured (the error grows as √rows).
    let rows = |n: f64| (n * (RESOLVED_SIGMA * err / gain).powi(2)).ceil();
    let (outcome, text) = if gain > RESOLVED_SIGMA * err {
        (
            "richer",
            format!(
                "{richer} predicts the rows it did not see better (log score +{gain:.1} ± \
                 {err:.1}, {:.1}σ): it earns its place",
                gain / err
            ),
        )
    } else if gain < -RESOLVED_SIGMA * err {
        (
            "simpler",
            format!(
                "{simpler} predicts better ({gain:+.1} ± {err:.1} for {richer}, {:.1}σ): \
                 {richer}'s extra freedom costs",
                gain.abs() / err
            ),
        )
    } else {
        let lr = lr.map_or(String::new(), |(_, _, p)| {
            format!("; on all rows, the likelihood ratio gives p = {p:.3}")
        });
        let need = if gain.abs() > 0.0 && err > 0.0 {
            format!(
                "; about {:.0} rows like these would resolve it at {RESOLVED_SIGMA:.0}σ if the \
                 gain per row held",
                rows(ROWS)
            )
        } else {
            String::new()
        };
        (
            "unresolved",
            format!(
                "unresolved: the rows it did not see do not separate them ({gain:+.1} ± \
                 {err:.1} for {richer}){lr}{need}; {simpler} is the default"
            ),
        )
    };
    Decision {
        question: question.into(),
        simpler: simpler.into(),
        richer: richer.into(),
        score_gain: gain,
        score_gain_err: err,
        lr_test: lr,
        outcome: outcome.into(),
        verdict: text,
    }
}

/// Runs everything; `dir` keeps the simulations' cells (resumable). `None` if stopped early.
pub fn run(
    cfg: &CalibratedConfig,
    command_line: String,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<CalibratedPaper>> {
    let (wall, cpu) = (Instant::now(), process_cpu_seconds());
    let rows = paper_rows()?;
    let session = Session::default();
    let mut fits: Vec<(&str, &str, Fitted, Vec<LooRow>)> = Vec::new();
    for (name, description, model, model_rows) in models(&rows) {
        // The models compared need their maxima and leave-one-out scores, not the main
        // model's bootstrap and posterior draws.
        let search = if name == "hand" {
            cfg.search
        } else {
            Search {
                bootstrap: 0,
                draws: 0,
                ..cfg.search
            }
        };
        let fc = FitConfig {
            rows: model_rows,
            model,
            method: cfg.method,
            design: cfg.design,
            search,
            seed: cfg.seed,
        };
        fc.validate()?;
        let Some(f) = fit::fit(&fc, runner, dir, &session)? else {
            return Ok(None);
        };
        let loo = leave_one_out(
            &f.config.rows,
            &f.designs,
            &f.config.model,
            &f.params,
            &cfg.search,
            &f.estimate.x,
            &runner.watch(),
        )?;
        fits.push((name, description, f, loo));
    }
    let models: Vec<ModelScore> = fits
        .iter()
        .map(|(name, description, f, loo)| {
            ModelScore::of(
                name,
                description,
                f.params.len(),
                f.estimate.minus_two_ln_l,
                loo,
            )
        })
        .collect();
    let by = |name: &str| fits.iter().position(|f| f.0 == name).expect("model");
    let (hand, paper_throw, shared, long_2d) =
        (by("hand"), by("paper-throw"), by("shared"), by("long-2d"));
    let decisions = vec![
        verdict(
            "κ: does a hand's throw, spread by κ, predict better than the paper's throw?",
            "paper-throw",
            "hand",
            gain(&fits[paper_throw].3, &fits[hand].3, false),
            // Nested at the boundary κ → ∞: the χ²₁ p-value is conservative (twice the
            // boundary's ½χ²₀ + ½χ²₁ mixture).
            Some(likelihood_ratio(&models[paper_throw], &models[hand])),
        ),
        verdict(
            "e and μ: one pair per surface, or one pair for all?",
            "shared",
            "hand",
            gain(&fits[shared].3, &fits[hand].3, false),
            Some(likelihood_ratio(&models[shared], &models[hand])),
        ),
        verdict(
            "The long blocks: 3D, or the paper's 2D model (scored on the side outcomes)?",
            "long-2d",
            "hand",
            gain(&fits[long_2d].3, &fits[hand].3, true),
            None,
        ),
    ];
    // The method at the main fit's values, each block's row at its own surface's e and μ.
    let main = &fits[hand].2;
    let at = |row: &DataRow| {
        let dims = main.config.model.row_dims(&main.params, row);
        let axes = main.config.model.axes(&main.params, &dims);
        let x: Vec<f64> = dims.iter().map(|&d| main.estimate.x[d]).collect();
        params::values(&main.config.model.fixed, &axes, &x)
    };
    let Some(check) = fit::check::run(
        &main.config.rows,
        &cfg.method,
        cfg.reference_dt,
        &at,
        cfg.check_rolls,
        cfg.seed,
        runner,
        session.rolled(),
    )?
    else {
        return Ok(None);
    };
    let table = crate::report::table::table_report()?;
    let theory = table
        .rows
        .iter()
        .map(|t| TheoryRow {
            label: format!("row {}", t.row),
            ratio: t.theory_ratio,
            z: t.z,
        })
        .collect();
    let mut single: Vec<String> = Vec::new();
    for r in &rows {
        if rows.iter().filter(|o| o.surface == r.surface).count() == 1 {
            single.push(r.surface.clone());
        }
    }
    let rolls = session.rolled() + check.blocks.iter().map(|b| 2 * b.rolls).sum::<u64>();
    let (name, _, main, loo) = fits.swap_remove(hand);
    let _ = name;
    let wall_s = wall.elapsed().as_secs_f64();
    let cpu_s = process_cpu_seconds() - cpu;
    Ok(Some(CalibratedPaper {
        fit: FitResult {
            cost: FitCost {
                rolls: main.rolls,
                unsettled: main.unsettled,
                wall_s,
                cpu_s,
            },
            config: main.config,
            params: main.params,
            first_pass: main.first_pass,
            passes: main.passes,
            designs: main.designs,
            estimate: main.estimate,
            command_line,
            dicephys_version: env!("CARGO_PKG_VERSION").into(),
            date_utc: crate::report::paper::utc_now(),
        },
        loo,
        theory,
        models,
        decisions,
        check,
        single_row_surfaces: single,
        rolls,
        wall_s,
        cpu_s,
    }))
}
