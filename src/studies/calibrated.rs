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

use crate::calibration::crossval::{
    decide, gain, leave_one_out, likelihood_ratio, LooRow, ModelScore,
};
use crate::calibration::data::{paper_rows, DataRow};
use crate::calibration::design::DesignSpec;
use crate::calibration::estimate::Search;
use crate::calibration::paper::{CalibratedPaper, Decision, TheoryRow};
use crate::calibration::params::{self, Kind, Method, ModelSpec};
use crate::calibration::{FitConfig, FitResult};
use crate::error::{Error, Field, Result};
use crate::model::scene::Mode;
use crate::report::fit as report;
use crate::report::progress::Unit;
use crate::report::Report;
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::Runner;
use crate::run::seal;
use crate::studies::fit::{self, Fitted, Session, Stage};
use crate::studies::kind;
use crate::studies::place::{to_json, unless_stopped, Done, Hooks, Place};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// Throws a block in the method check when none are asked.
pub const DEFAULT_CHECK_ROLLS: u64 = 4000;

/// The method check's reference step when none is asked, s: a fifth of a millisecond.
pub const DEFAULT_REFERENCE_DT: f64 = 1.0 / 5000.0;

/// What to simulate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
                Field::PointRolls,
                self.design.rolls,
                format!("from 1 to {max}"),
            ));
        }
        if self.check_rolls == 0 || self.check_rolls > max {
            return Err(Error::field(
                Field::CheckRolls,
                self.check_rolls,
                format!("from 1 to {max}"),
            ));
        }
        if self.search.bootstrap > MAX_BOOTSTRAP {
            return Err(Error::field(
                Field::Bootstrap,
                self.search.bootstrap,
                format!("from 0 to {MAX_BOOTSTRAP}"),
            ));
        }
        if !(1..=MAX_STARTS).contains(&self.search.starts) {
            return Err(Error::field(
                Field::Starts,
                self.search.starts,
                format!("from 1 to {MAX_STARTS}"),
            ));
        }
        if !(5..=MAX_PROFILE_POINTS).contains(&self.search.profile_points) {
            return Err(Error::field(
                Field::ProfilePoints,
                self.search.profile_points,
                format!("from 5 to {MAX_PROFILE_POINTS}"),
            ));
        }
        crate::model::scene::check_dt(Field::ReferenceDt, self.reference_dt)?;
        crate::model::scene::check_dt(Field::Dt, self.method.dt)?;
        if self.method.max_steps == 0 {
            return Err(Error::field(Field::MaxSteps, 0, "need at least one step"));
        }
        let rows = paper_rows()?;
        for (_, _, model, rows) in models(&rows) {
            let dims = model.free.len();
            self.design.validate(dims)?;
            FitConfig {
                rows,
                model,
                method: self.method.clone(),
                design: self.design,
                search: self.search,
                seed: self.seed,
            }
            .validate()?;
        }
        Ok(())
    }
}

/// The most data sets the bootstrap draws (each a fit of every parameter).
pub const MAX_BOOTSTRAP: usize = 100_000;

/// The most starting points a search may take.
pub const MAX_STARTS: usize = 1000;

/// The most grid points a profile may take.
pub const MAX_PROFILE_POINTS: usize = 1001;

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
pub fn first_pass_rolls(cfg: &CalibratedConfig) -> Result<u64> {
    let rows = paper_rows()?;
    Ok(models(&rows)
        .into_iter()
        .map(|(_, _, model, rows)| {
            FitConfig {
                rows,
                model,
                method: cfg.method.clone(),
                design: cfg.design,
                search: cfg.search,
                seed: cfg.seed,
            }
            .total_rolls()
        })
        .sum())
}

/// The fit of one model, as the study runs it: the models compared need their maxima and
/// leave-one-out scores, not the main model's bootstrap and posterior draws.
fn fit_config(
    cfg: &CalibratedConfig,
    name: &str,
    model: ModelSpec,
    rows: Vec<DataRow>,
) -> Result<FitConfig> {
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
        rows,
        model,
        method: cfg.method.clone(),
        design: cfg.design,
        search,
        seed: cfg.seed,
    };
    fc.validate()?;
    Ok(fc)
}

/// A model's fit: its name, its description, the fit.
type ModelFit = (&'static str, &'static str, Fitted);

/// Runs everything; `dir` keeps the simulations' cells (resumable). `None` if stopped early.
pub fn run(
    cfg: &CalibratedConfig,
    command_line: String,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<CalibratedPaper>> {
    let began = (Instant::now(), process_cpu_seconds());
    let session = Session::default();
    let mut fits = Vec::new();
    for (name, description, model, rows) in models(&paper_rows()?) {
        let fc = fit_config(cfg, name, model, rows)?;
        let Some(f) = fit::fit(&fc, runner, dir, &session)? else {
            return Ok(None);
        };
        fits.push((name, description, f));
    }
    conclude(cfg, fits, command_line, runner, began)
}

/// `paper --calibrated` as a cluster runs it (`slurm paper --calibrated`): the whole study on
/// one machine, or one of its two stages. A model's second pass narrows its box from its first
/// pass's result, so a cluster rolls every model's first pass as one job array
/// ([`Stage::First`], written as [`FIRST_PASSES`]), then every model's second pass as another
/// ([`Stage::Second`]), whose finishing job rolls the passes that widen a cut box and the
/// method check itself (both are drawn from results no task saw), and runs the leave-one-out
/// fits and the comparisons. The result is the one machine's, bit for bit: every design is a
/// pure function of its key and the seed, and the models are fitted in the same order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibratedStudy {
    /// What to run.
    pub config: CalibratedConfig,
    /// Which part of it.
    pub stage: Stage,
}

/// The file the first stage writes: every model's first pass.
pub const FIRST_PASSES: &str = "first-passes.json";

/// The first stage's result: the study it belongs to, and each model's first pass.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FirstPasses {
    /// The study's configuration (the second stage refuses another's).
    pub config: CalibratedConfig,
    /// Each model's first pass, by name, in the models' order.
    pub passes: Vec<(String, FitResult)>,
}

impl CalibratedStudy {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        self.config.validate()?;
        self.stage.check(self.config.design.refine)
    }

    /// Every model's first pass (`None` if stopped early, or on a cluster task's share, which
    /// rolls its share of every model's cells).
    pub fn first_passes(
        &self,
        command_line: &str,
        runner: &Runner,
        dir: Option<&Path>,
    ) -> Result<Option<FirstPasses>> {
        let cfg = &self.config;
        let session = Session::default();
        let mut passes = Vec::new();
        for (name, _, model, rows) in models(&paper_rows()?) {
            let (wall, cpu) = (Instant::now(), process_cpu_seconds());
            let fc = fit_config(cfg, name, model, rows)?;
            match fit::first_pass(&fc, runner, dir, &session)? {
                Some(f) => passes.push((name.to_string(), fit::result(f, command_line, wall, cpu))),
                // A task's share: on to the next model's cells.
                None if runner.share.is_partial() && !runner.stop.requested() => continue,
                None => return Ok(None),
            }
        }
        Ok((!runner.share.is_partial()).then(|| FirstPasses {
            config: cfg.clone(),
            passes,
        }))
    }

    /// The first stage's result, read back and checked to be this study's.
    fn read_first(&self, path: &Path) -> Result<Vec<Fitted>> {
        let first: FirstPasses = fit::read_first(path)?;
        let names: Vec<&str> = models(&paper_rows()?).iter().map(|m| m.0).collect();
        let theirs: Vec<&str> = first.passes.iter().map(|p| p.0.as_str()).collect();
        if first.config != self.config || names != theirs {
            return Err(Error::Invalid(format!(
                "{} is the first stage of another study",
                path.display()
            )));
        }
        first
            .passes
            .into_iter()
            .map(|(_, r)| Fitted::from_result(r))
            .collect()
    }

    /// Runs its part: `None` if stopped early or on a cluster task's share (the first stage
    /// comes back through [`CalibratedStudy::first_passes`]).
    pub fn run(
        &self,
        command_line: String,
        runner: &Runner,
        dir: Option<&Path>,
    ) -> Result<Option<CalibratedPaper>> {
        let first = match &self.stage {
            Stage::Whole => return run(&self.config, command_line, runner, dir),
            Stage::First => {
                return Err(Error::Invalid(
                    "the first stage writes first passes, not the study".into(),
                ))
            }
            Stage::Second { first } => first,
        };
        let began = (Instant::now(), process_cpu_seconds());
        let firsts = self.read_first(first)?;
        let session = Session::default();
        let mut fits = Vec::new();
        for ((name, description, ..), first) in models(&paper_rows()?).into_iter().zip(firsts) {
            // As on one machine, where this model's first pass was rolled just before its
            // second: its designs are the session's (a key the narrowing left as it was is
            // taken from them, not rolled again).
            session.hold(self.config.seed, &first.designs);
            match fit::second_pass(first, runner, dir, &session)? {
                Some(f) => fits.push((name, description, f)),
                None if runner.share.is_partial() && !runner.stop.requested() => continue,
                None => return Ok(None),
            }
        }
        if runner.share.is_partial() {
            return Ok(None);
        }
        conclude(&self.config, fits, command_line, runner, began)
    }
}

/// The three model decisions, each the richer model's held-out gain over the simpler one's
/// (with the likelihood ratio where they are nested).
fn decisions(fits: &[(&str, &str, Fitted, Vec<LooRow>)], models: &[ModelScore]) -> Vec<Decision> {
    let by = |name: &str| fits.iter().position(|f| f.0 == name).expect("model");
    let (hand, paper_throw, shared, long_2d) =
        (by("hand"), by("paper-throw"), by("shared"), by("long-2d"));
    let rows = fits[hand].3.len();
    vec![
        decide(
            "κ: does a hand's throw, spread by κ, predict better than the paper's throw?",
            "paper-throw",
            "hand",
            gain(&fits[paper_throw].3, &fits[hand].3, false),
            // Nested at the boundary κ → ∞: the χ²₁ p-value is conservative (twice the
            // boundary's ½χ²₀ + ½χ²₁ mixture).
            Some(likelihood_ratio(&models[paper_throw], &models[hand])),
            rows,
        ),
        decide(
            "e and μ: one pair per surface, or one pair for all?",
            "shared",
            "hand",
            gain(&fits[shared].3, &fits[hand].3, false),
            Some(likelihood_ratio(&models[shared], &models[hand])),
            rows,
        ),
        decide(
            "The long blocks: 3D, or the paper's 2D model (scored on the side outcomes)?",
            "long-2d",
            "hand",
            gain(&fits[long_2d].3, &fits[hand].3, true),
            None,
            rows,
        ),
    ]
}

/// Everything after the fits: each model's leave-one-out scores, the decisions, the method
/// check at the main fit's values (rolled here, on all of this process's cores, even in a
/// cluster's finishing job: it is drawn from the fit's result, which no task saw), the theory
/// beside it. `None` if stopped early.
fn conclude(
    cfg: &CalibratedConfig,
    fits: Vec<ModelFit>,
    command_line: String,
    runner: &Runner,
    (wall, cpu): (Instant, f64),
) -> Result<Option<CalibratedPaper>> {
    let rows = paper_rows()?;
    let mut scored: Vec<(&str, &str, Fitted, Vec<LooRow>)> = Vec::new();
    for (name, description, f) in fits {
        let loo = leave_one_out(
            &f.config.rows,
            &f.designs,
            &f.config.model,
            &f.params,
            &cfg.search,
            &f.estimate,
            &runner.watch(),
        )?;
        scored.push((name, description, f, loo));
    }
    let mut fits = scored;
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
    let decisions = decisions(&fits, &models);
    let hand = fits.iter().position(|f| f.0 == "hand").expect("model");
    // The method at the main fit's values, each block's row at its own surface's e and μ.
    let main = &fits[hand].2;
    let at = |row: &DataRow| {
        let dims = main.config.model.row_dims(&main.params, row);
        let axes = main.config.model.axes(&main.params, &dims);
        let x: Vec<f64> = dims.iter().map(|&d| main.estimate.x[d]).collect();
        params::values(&main.config.model.fixed, &axes, &x)
    };
    let fitted: u64 = fits.iter().map(|f| f.2.rolls).sum();
    let method_check = fit::check::Check {
        method: &cfg.method,
        reference_dt: cfg.reference_dt,
        rolls: cfg.check_rolls,
        seed: cfg.seed,
    };
    let Some(check) = fit::check::run(
        &main.config.rows,
        &method_check,
        &at,
        &fit::own_rolls(runner),
        fitted,
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
    let rolls = fitted + check.blocks.iter().map(|b| 2 * b.rolls).sum::<u64>();
    let (_, _, main, loo) = fits.swap_remove(hand);
    let fit = fit::result(main, &command_line, wall, cpu);
    Ok(Some(CalibratedPaper {
        wall_s: fit.cost.wall_s,
        cpu_s: fit.cost.cpu_s,
        fit,
        loo,
        theory,
        models,
        decisions,
        check,
        single_row_surfaces: single,
        rolls,
    }))
}

impl kind::Kind for CalibratedStudy {
    fn name(&self) -> &'static str {
        "paper --calibrated"
    }
    fn validate(&self) -> Result<()> {
        CalibratedStudy::validate(self)
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.design.rolls,
        }
    }
    fn cells(&self) -> &'static str {
        "calibration"
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        run_study(self, place, hooks)
    }
}

/// `paper --calibrated`, or a stage of it on a cluster: calibrated.json, calibrated.md and
/// figures in `place.out`, the cells under `place.checkpoint`; the first stage writes only
/// every model's first pass ([`FIRST_PASSES`]); a cluster task's share writes nothing.
fn run_study(study: &CalibratedStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
    let cfg = &study.config;
    let first = study.stage == Stage::First;
    let files: &[&'static str] = if first {
        &[FIRST_PASSES]
    } else {
        &["calibrated.json", "calibrated.md"]
    };
    let outputs = place.outputs(files)?;
    let all = total_rolls(cfg)? as f64;
    let firsts = first_pass_rolls(cfg)? as f64;
    let total = match study.stage {
        Stage::Whole => all,
        Stage::First => firsts,
        Stage::Second { .. } => all - firsts,
    };
    let progress = |n: u64| (hooks.progress)(n as f64, total.max(n as f64));
    let mut sim = place.study(&hooks.stop, &progress);
    sim.runner = sim.runner.with_say(hooks.log);
    let (runner, dir) = (&sim.runner, sim.checkpoint.as_deref());
    let command_line = place.command_line.clone();
    if first {
        let res =
            unless_stopped(runner.install(|| study.first_passes(&command_line, runner, dir))?)?;
        if place.partial() {
            return Ok(Done::default());
        }
        let Some(res) = res else {
            return Ok(place.interrupted());
        };
        (hooks.progress)(total, total);
        let json = seal::to_string(&res, true)?;
        outputs.write(FIRST_PASSES, json.as_bytes())?;
        let text: String = res
            .passes
            .iter()
            .map(|(name, r)| format!("model {name}:\n{}", report::first_pass_text(r)))
            .collect();
        let mut done = place.done(&json, &text, FIRST_PASSES);
        done.note = done.note.map(|_| {
            format!(
                "wrote {}/{FIRST_PASSES}: every model's first pass, which its second narrows \
                 its box from",
                place.out.display()
            )
            .into()
        });
        return Ok(done);
    }
    let res = unless_stopped(runner.install(|| study.run(command_line, runner, dir))?)?;
    if place.partial() {
        return Ok(Done::default());
    }
    let Some(res) = res else {
        return Ok(place.interrupted());
    };
    (hooks.progress)(total, total);
    let figures = res.write_figures(&place.out)?;
    let md = res.markdown(&figures);
    let json = to_json(&res)?;
    outputs.write("calibrated.json", json.as_bytes())?;
    outputs.write("calibrated.md", md.as_bytes())?;
    let mut done = place.done(&json, &md, "calibrated.md");
    done.note = done.note.map(|_| {
        format!(
            "wrote {}/calibrated.md, calibrated.json and figures",
            place.out.display()
        )
        .into()
    });
    Ok(done)
}
