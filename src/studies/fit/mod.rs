//! `dicephys fit` and `predict`: the rolling behind a calibration ([`crate::calibration`]): each
//! block simulated over its design, the data simulated at a known truth for the recovery
//! check, and a new block simulated at the fit's posterior draws.

pub mod baseline;
pub mod check;
pub mod outputs;
pub mod predict;
pub mod recovery;
pub mod rolled;
pub mod simulate;

use crate::calibration::crossval::{leave_one_out, LooRow};
use crate::calibration::design::{self, Design};
use crate::calibration::discrepancy::Discrepancy;
use crate::calibration::params::Narrowed;
use crate::calibration::{cuts, estimate_with, same_box, tighten, widen};
use crate::calibration::{narrow, FitConfig, FitCost, FitResult, Pass, MAX_MORE_PASSES};
use crate::error::{Error, Field, Result};
use crate::run::cputime::process_cpu_seconds;
use crate::run::runner::{ChunkShare, Runner};
use serde::{Deserialize, Serialize};
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

/// What one pass simulated: its designs, and the rolls (and the unsettled rolls) of those the
/// session did not hold before it, which this pass made or read back from the checkpoints.
struct Simulated {
    designs: Vec<Design>,
    rolls: u64,
    unsettled: u64,
}

/// [`simulate`], counting what the pass itself cost. `None` as for [`simulate`].
fn simulate_pass(
    cfg: &FitConfig,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Simulated>> {
    let points = design::points(cfg.model.free.len(), cfg.design.points).len();
    let held: Vec<bool> = design::keys(&cfg.rows, &cfg.model)
        .iter()
        .map(|k| {
            session
                .held(k, cfg.seed, points, cfg.design.rolls)
                .is_some()
        })
        .collect();
    let Some(designs) = simulate(cfg, runner, dir, session)? else {
        return Ok(None);
    };
    // One design per key, in the keys' order.
    let new: Vec<&Design> = designs
        .iter()
        .zip(&held)
        .filter(|(_, &h)| !h)
        .map(|(d, _)| d)
        .collect();
    Ok(Some(Simulated {
        rolls: new.iter().map(|d| d.rolls).sum(),
        unsettled: new.iter().map(|d| d.unsettled).sum(),
        designs,
    }))
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
    /// Every pass: its box, its rolls, the parameters its box cut.
    pub passes: Vec<Pass>,
    /// Rolls made, over all passes.
    pub rolls: u64,
    /// Of which did not settle on a face.
    pub unsettled: u64,
    /// Why the passes did not settle, if they did not ([`FitResult::unresolved`]).
    pub unresolved: Option<String>,
    /// Every design rolled so far, over every pass (a later pass's surrogates borrow their
    /// points inside its box: [`design::borrowed`]).
    pub rolled: Vec<Design>,
}

impl Fitted {
    /// A first pass's result, read back as the fit the second pass goes on from.
    pub fn from_result(r: FitResult) -> Result<Fitted> {
        // A first pass written before passes were recorded: its one pass, over the whole box.
        let passes = if r.passes.is_empty() {
            vec![Pass::over(&r.params, r.cost.rolls)]
        } else {
            r.passes
        };
        Ok(Fitted {
            config: r.config,
            params: r.params,
            rolled: r.designs.clone(),
            designs: r.designs,
            estimate: r.estimate,
            first_pass: None,
            passes,
            rolls: r.cost.rolls,
            unsettled: r.cost.unsettled,
            unresolved: r.unresolved,
        })
    }
}

/// `f` dressed as a [`FitResult`], its cost measured from `wall` and `cpu` (CPU seconds).
pub fn result(f: Fitted, command_line: &str, wall: Instant, cpu: f64) -> FitResult {
    FitResult {
        loo: Vec::new(),
        discrepancy: None,
        loo_scores: None,
        loo_dice: Vec::new(),
        rolled: None,
        cost: FitCost {
            rolls: f.rolls,
            unsettled: f.unsettled,
            wall_s: wall.elapsed().as_secs_f64(),
            cpu_s: process_cpu_seconds() - cpu,
        },
        config: f.config,
        params: f.params,
        first_pass: f.first_pass,
        passes: f.passes,
        unresolved: f.unresolved,
        designs: f.designs,
        estimate: f.estimate,
        command_line: command_line.to_string(),
        dicephys_version: env!("CARGO_PKG_VERSION").into(),
        date_utc: crate::report::paper::utc_now(),
    }
}

/// The search of a first pass that a second will refine: its maximum and profiles only (the
/// second pass's box is drawn from them; the region and the draws are the last pass's).
fn first_pass_search(cfg: &FitConfig) -> crate::calibration::estimate::Search {
    if cfg.design.refine {
        crate::calibration::estimate::Search {
            bootstrap: 0,
            draws: 0,
            ..cfg.search
        }
    } else {
        cfg.search
    }
}

/// The first pass: every row's design simulated over its whole box, and estimated. `None` if
/// stopped early, or on a cluster task's share (its rolls are for the finishing job).
pub fn first_pass(
    cfg: &FitConfig,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Fitted>> {
    let Some(sim) = simulate_pass(cfg, runner, dir, session)? else {
        return Ok(None);
    };
    settled_enough(&sim.designs)?;
    let (params, estimate) = estimate_with(
        &cfg.rows,
        &cfg.model,
        &sim.designs,
        &first_pass_search(cfg),
        &runner.watch(),
    )?;
    Ok(Some(Fitted {
        config: cfg.clone(),
        rolls: sim.rolls,
        unsettled: sim.unsettled,
        passes: vec![Pass::of(&params, &estimate, sim.rolls)],
        params,
        rolled: sim.designs.clone(),
        designs: sim.designs,
        estimate,
        first_pass: None,
        unresolved: None,
    }))
}

/// The most of a fit's rolls that may end on no face (unconverged, failed) before its estimate
/// is refused: the rest are too few, and too odd a sample of the throws, to stand for the
/// block.
pub const MAX_UNSETTLED_SHARE: f64 = 0.1;

/// Refuses designs whose rolls mostly did not settle (`Error::Failed`, what to change).
fn settled_enough(designs: &[Design]) -> Result<()> {
    let rolls: u64 = designs.iter().map(|d| d.rolls).sum();
    let unsettled: u64 = designs.iter().map(|d| d.unsettled).sum();
    if rolls > 0 && unsettled as f64 > MAX_UNSETTLED_SHARE * rolls as f64 {
        return Err(Error::failed(crate::text![
            format!(
                "{unsettled} of the fit's {rolls} rolls ({:.1} %) did not settle on a face \
                 (more than {:.0} %): no estimate from them; raise ",
                100.0 * unsettled as f64 / rolls as f64,
                100.0 * MAX_UNSETTLED_SHARE
            ),
            Field::MaxSteps,
            " or use a finer ",
            Field::Dt
        ]));
    }
    Ok(())
}

/// The second pass over the box narrowed from `first` (a pass with nothing to narrow is the
/// last: it gets the full search, the bootstrap's region and the posterior draws `predict`
/// needs), then as many passes again as it takes, up to [`MAX_MORE_PASSES`], for the box to
/// settle: each widens a box that cut a parameter ([`cuts`], [`widen`]) or, until one has been
/// widened, tightens one looser than its region ([`tighten`]), until a pass's own estimate
/// asks for the box it was rolled over; each pass's surrogates are fitted through the earlier passes' points inside its box
/// as well ([`pooled`]). Passes that do not settle leave the fit unresolved, and say why.
/// `None` as for [`first_pass`].
pub fn second_pass(
    first: Fitted,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Fitted>> {
    let cfg = &first.config;
    let narrowed = narrow(&cfg.rows, &cfg.model, &first.params, &first.estimate);
    if narrowed.is_empty() {
        let (params, estimate) = estimate_with(
            &cfg.rows,
            &cfg.model,
            &first.designs,
            &cfg.search,
            &runner.watch(),
        )?;
        return Ok(Some(Fitted {
            params,
            estimate,
            ..first
        }));
    }
    let Some(mut out) = refined_pass(first, narrowed, runner, dir, session)? else {
        return Ok(None);
    };
    let own = own_rolls(runner);
    // Once a box has had to be widened, the passes only widen: tightened again, the paper's
    // κ and e[Thin Towel] went from box to box (cut, widened, tightened, cut) and never settled.
    let mut widened = false;
    for more in 0..=MAX_MORE_PASSES {
        let cut = cuts(&out.estimate);
        out.passes.last_mut().expect("a pass").cut = cut.clone();
        widened |= !cut.is_empty();
        let next = match () {
            _ if !cut.is_empty() => widen(&out.config.model, &out.estimate, &cut),
            _ if widened => out.config.model.narrowed.clone(),
            _ => tighten(&out.config.rows, &out.config.model, &out.estimate),
        };
        if same_box(&next, &out.config.model.narrowed) {
            break;
        }
        if more == MAX_MORE_PASSES {
            out.unresolved = Some(unsettled(&out, &next, &cut));
            break;
        }
        let Some(later) = refined_pass(out, next, &own, dir, session)? else {
            return Ok(None);
        };
        out = later;
    }
    Ok(Some(out))
}

/// Why the passes of `out` stop unsettled: no pass left, and the box `next` still asked for
/// because the last box cut `cut` (or, nothing cut, was looser than its region). A box an
/// earlier pass had is no cycle: its surrogates borrow every later pass's points inside it,
/// and the estimate moves on.
fn unsettled(
    out: &Fitted,
    next: &[crate::calibration::params::Narrowed],
    cut: &[crate::calibration::Cut],
) -> String {
    let names: Vec<&str> = if cut.is_empty() {
        next.iter()
            .filter(|n| !out.config.model.narrowed.contains(n))
            .map(|n| n.param.as_str())
            .collect()
    } else {
        cut.iter().map(|c| c.param.as_str()).collect()
    };
    let why = if cut.is_empty() {
        "is still looser than the region of"
    } else {
        "still cuts"
    };
    format!(
        "the passes did not settle in {}: the box {why} {}; the estimate is the last box's, \
         not the data's",
        out.passes.len(),
        names.join(", ")
    )
}

/// One refined pass: `prev`'s fit simulated again over the box `narrowed` (a design whose key
/// it leaves as it was is the session's already, not rolled again) and estimated with the full
/// search. `None` as for [`first_pass`].
fn refined_pass(
    prev: Fitted,
    narrowed: Vec<Narrowed>,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Fitted>> {
    let mut out = prev;
    out.config.model.narrowed = narrowed;
    let Some(sim) = simulate_pass(&out.config, runner, dir, session)? else {
        return Ok(None);
    };
    settled_enough(&sim.designs)?;
    out.rolls += sim.rolls;
    out.unsettled += sim.unsettled;
    let designs = pooled(&out.config, sim.designs, &mut out.rolled);
    let (params, estimate) = estimate_with(
        &out.config.rows,
        &out.config.model,
        &designs,
        &out.config.search,
        &runner.watch(),
    )?;
    out.passes.push(Pass::of(&params, &estimate, sim.rolls));
    let before = std::mem::replace(&mut out.estimate, estimate).params;
    out.first_pass.get_or_insert(before);
    out.params = params;
    out.designs = designs;
    Ok(Some(out))
}

/// A refined pass's `designs`, each with the points of the designs `rolled` before it that lie
/// inside its box ([`design::borrowed`]) and its surrogate fitted through them too; `designs`
/// join `rolled`. Not with common throws (`cfg.design.common`): one box's points share their
/// throws, and another's would not.
fn pooled(cfg: &FitConfig, designs: Vec<Design>, rolled: &mut Vec<Design>) -> Vec<Design> {
    let out = designs
        .iter()
        .map(|d| {
            let borrowed = design::borrowed(d, rolled);
            if borrowed.is_empty() || cfg.design.common {
                return d.clone();
            }
            let all: Vec<_> = d.points.iter().chain(&borrowed).cloned().collect();
            let key = design::Key::of_design(d);
            Design {
                surrogate: simulate::surrogate(
                    &all,
                    &key,
                    &cfg.method.for_die(key.die.as_deref()),
                    &cfg.design,
                ),
                borrowed,
                ..d.clone()
            }
        })
        .collect();
    rolled.extend(designs);
    out
}

/// The runner the widening passes roll with: `runner`, but in a cluster's finishing job, which
/// reads back what its tasks rolled and rolls nothing, one that rolls every chunk itself. A
/// widened box is drawn from the pass before it, which no task saw: the finishing job of the
/// second pass's stage rolls those passes on its own cores.
pub fn own_rolls<'a>(runner: &Runner<'a>) -> Runner<'a> {
    let own = runner.with_progress(runner.progress);
    match own.share {
        ChunkShare::Assemble { .. } => own.with_share(ChunkShare::All),
        _ => own,
    }
}

/// Simulates and estimates, in one pass or, refined (`cfg.design.refine`), two and as many
/// widening passes as the second needs. `None` if stopped early.
pub fn fit(
    cfg: &FitConfig,
    runner: &Runner,
    dir: Option<&Path>,
    session: &Session,
) -> Result<Option<Fitted>> {
    let Some(first) = first_pass(cfg, runner, dir, session)? else {
        return Ok(None);
    };
    if !cfg.design.refine {
        return Ok(Some(first));
    }
    second_pass(first, runner, dir, session)
}

/// `fit` as a study a cluster splits (`slurm fit`): the whole fit, or one of its two stages.
/// The second pass's box is narrowed from the first pass's result, so a cluster runs the
/// passes as two job arrays, the second started when the first has finished. The passes that
/// widen a box the second pass's cut are drawn from the pass before each: the second stage's
/// finishing job rolls them itself, after assembling the second pass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitStudy {
    /// What to fit.
    pub config: FitConfig,
    /// Which of it.
    pub stage: Stage,
}

/// `fit --recover`: counts simulated at `truth` (every free parameter's value, in the model's
/// order) for the rows of `config`, fitted back `repeats` times, each its own data and
/// simulations; it reports how often the 2σ region holds the truth.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RecoverStudy {
    /// What to fit (its rows give the blocks and numbers of throws).
    pub config: FitConfig,
    /// The truth.
    pub truth: Vec<f64>,
    /// Repetitions.
    pub repeats: usize,
}

/// `predict --block`: the fit simulated at a block it did not see, at its posterior draws.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PredictStudy {
    /// The fit, as its fit.json holds it.
    pub fit: FitResult,
    /// What to predict.
    pub config: crate::calibration::predict::PredictConfig,
}

/// `predict --blocks-file`: the fit simulated at each of many blocks, held against their
/// counts where measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BlocksStudy {
    /// The fit, as its fit.json holds it.
    pub fit: FitResult,
    /// The blocks, and the draws and rolls of each.
    pub config: BlocksConfig,
}

/// What `predict --blocks` predicts: the blocks, and the draws and rolls of each.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BlocksConfig {
    /// The blocks, with their counts where measured.
    pub rows: Vec<crate::calibration::heldout::BlockRow>,
    /// Dice of any shape (a counts file's `die` column): each its own prediction, another die
    /// than the fit's, scored against its row's counts.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dice: Vec<crate::calibration::predict::PredictConfig>,
    /// Posterior draws a block.
    pub draws: usize,
    /// Rolls a draw.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The fit's file, as given.
    pub fit: String,
}

/// Which part of a fit a study runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// The whole fit, every pass (or its one pass, unrefined).
    Whole,
    /// The first of two passes: its designs, and the maximum and profiles the second pass's box
    /// is drawn from, written as [`FIRST_PASS`].
    First,
    /// The second pass, over the box narrowed from the first pass's result in `first` (its
    /// tasks roll it), and the passes that widen it where it cut a parameter (its finishing
    /// job rolls those).
    Second {
        /// The first pass's [`FIRST_PASS`].
        first: std::path::PathBuf,
    },
}

impl Stage {
    /// Refuses a stage of a study that has one pass (no `refine`): nothing to split.
    pub fn check(&self, refine: bool) -> Result<()> {
        if *self != Stage::Whole && !refine {
            return Err(Error::field(
                Field::Refine,
                "",
                "a study of one pass has no passes to split",
            ));
        }
        Ok(())
    }
}

/// A first stage's sealed result, read back for the second: refused, saying why, if that
/// stage has not finished or the file is damaged.
pub fn read_first<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::Invalid(format!(
            "{}: the first pass has not finished ({e}): finish it, then run the second",
            path.display()
        ))
    })?;
    crate::run::seal::open(&text).map_err(|e| Error::Invalid(format!("{}: {e}", path.display())))
}

/// The file a first pass writes (a [`FitResult`] without the region or the draws).
pub const FIRST_PASS: &str = "first-pass.json";

impl FitStudy {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        self.config.validate()?;
        self.stage.check(self.config.design.refine)
    }

    /// The first pass's result, read back for the second (and checked to be this fit's).
    fn first(&self, path: &Path) -> Result<Fitted> {
        let r: FitResult = read_first(path)?;
        if r.config != self.config {
            return Err(Error::Invalid(format!(
                "{} is the first pass of another fit",
                path.display()
            )));
        }
        Fitted::from_result(r)
    }

    /// Runs its part: `None` if stopped early or on a cluster task's share.
    pub fn fit(&self, runner: &Runner, dir: Option<&Path>) -> Result<Option<Fitted>> {
        let session = Session::default();
        match &self.stage {
            Stage::Whole => fit(&self.config, runner, dir, &session),
            Stage::First => first_pass(&self.config, runner, dir, &session),
            Stage::Second { first } => {
                let first = self.first(first)?;
                // The first pass's designs are this session's: a key the narrowing left as it
                // was is taken from them, not rolled again (as on one machine).
                session.hold(self.config.seed, &first.designs);
                second_pass(first, runner, dir, &session)
            }
        }
    }
}

/// Runs the fit, or its part: simulates (resuming from `dir`), then estimates, refining if
/// asked. `None` if a stop request ended the simulations early, or on a cluster task's share.
pub fn run(
    study: &FitStudy,
    command_line: String,
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<FitResult>> {
    study.validate()?;
    let (wall, cpu) = (Instant::now(), process_cpu_seconds());
    let Some(f) = study.fit(runner, dir)? else {
        return Ok(None);
    };
    let mut loo = match study.stage {
        Stage::First => Vec::new(),
        _ => rows_without_themselves(&f, runner)?,
    };
    let mut discrepancy = Discrepancy::estimate(&loo, f.estimate.overdispersion);
    let phi = f.estimate.overdispersion;
    // The baselines roll on this process's own cores (a cluster's finishing job included).
    let loo_scores = if loo.is_empty() {
        None
    } else {
        match baseline::score_loo(&f.config, phi, &mut loo, &own_rolls(runner))? {
            Some(s) => Some(s),
            None => return Ok(None),
        }
    };
    if let (Some(d), Some(s)) = (discrepancy.as_mut(), loo_scores.as_ref()) {
        d.judge(s);
        // Each row's others are enough to learn one from, and none asked: nothing held out
        // gains from it (the steel dice's fit with a bounce threshold: all eight rows asked,
        // no seven did).
        let scored = loo.iter().filter(|r| !r.alone).count();
        if s.without_discrepancy.is_none() && scored > crate::calibration::discrepancy::MIN_ROWS {
            d.judge_none_learnt();
        }
    }
    let loo_dice = baseline::by_die(&loo);
    // The estimate rolled: every row at the fitted values, on throws of its own.
    let mut res = FitResult {
        loo,
        discrepancy,
        loo_scores,
        loo_dice,
        ..result(f, &command_line, wall, cpu)
    };
    if study.stage != Stage::First {
        match rolled::roll(&res, &own_rolls(runner))? {
            Some(r) => res.rolled = Some(r),
            None => return Ok(None),
        }
        // Its rolls are the fit's cost too.
        res.cost.wall_s = wall.elapsed().as_secs_f64();
        res.cost.cpu_s = process_cpu_seconds() - cpu;
    }
    Ok(Some(res))
}

/// The fewest rows a fit scores by leaving each out: with two, each row's prediction is a fit
/// of one.
const LOO_ROWS: usize = 3;

/// Every row of `f` predicted by a fit of the others, as the calibrated paper scores its
/// models (no rolls: the surrogates are `f`'s); none for a fit of fewer than [`LOO_ROWS`]. A
/// fit whose rows name their dice leaves each die out (its rows together), and does so from
/// two dice up: one die predicted from a fit of another is the question a die's designer asks.
fn rows_without_themselves(f: &Fitted, runner: &Runner) -> Result<Vec<LooRow>> {
    let rows = &f.config.rows;
    let enough = if rows.iter().any(|r| r.die.is_some()) {
        crate::calibration::crossval::held_out_groups(rows).len() >= 2
    } else {
        rows.len() >= LOO_ROWS
    };
    if !enough {
        return Ok(Vec::new());
    }
    leave_one_out(
        &f.config.rows,
        &f.designs,
        &f.config.model,
        &f.params,
        &f.config.search,
        &f.estimate,
        &runner.watch(),
    )
}
