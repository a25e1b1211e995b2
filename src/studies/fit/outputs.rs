//! `fit`, `fit --recover`, `predict` and `paper --calibrated` end to end: outputs checked
//! before anything rolls, the study run with its progress, its results rendered and written
//! whole (as [`crate::studies::outputs`] does for the other studies).

use super::{FitStudy, Stage, FIRST_PASS};
use crate::calibration::predict::PredictConfig;
use crate::calibration::{FitConfig, FitResult};
use crate::error::{Error, Result};
use crate::report::fit as report;
use crate::report::progress::Unit;
use crate::run::seal;
use crate::studies::calibrated::{self, CalibratedConfig, CalibratedStudy, FIRST_PASSES};
use crate::studies::place::{interrupted, to_json, Done, Hooks, Place};
use crate::studies::{Kind, StudyConfig};
use serde::Serialize;

impl Kind for FitStudy {
    fn name(&self) -> &'static str {
        "fit"
    }
    fn validate(&self) -> Result<()> {
        FitStudy::validate(self)
    }
    fn config(&self) -> StudyConfig {
        StudyConfig::Fit(self.clone())
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.design.rolls,
        }
    }
    fn cells(&self) -> &'static str {
        "cells"
    }
    /// A refined fit is two stages on a cluster: its first pass, then its second.
    fn at_stage(&self, stage: Stage) -> Option<(StudyConfig, &'static str)> {
        self.config.design.refine.then(|| {
            (
                StudyConfig::Fit(FitStudy {
                    config: self.config.clone(),
                    stage,
                }),
                FIRST_PASS,
            )
        })
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        fit(self, place, hooks)
    }
}

impl Kind for CalibratedStudy {
    fn name(&self) -> &'static str {
        "paper --calibrated"
    }
    fn validate(&self) -> Result<()> {
        CalibratedStudy::validate(self)
    }
    fn config(&self) -> StudyConfig {
        StudyConfig::Calibrated(self.clone())
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.design.rolls,
        }
    }
    fn cells(&self) -> &'static str {
        "calibration"
    }
    /// Refined, two stages: every model's first pass, then every model's second and the rest.
    fn at_stage(&self, stage: Stage) -> Option<(StudyConfig, &'static str)> {
        self.config.design.refine.then(|| {
            (
                StudyConfig::Calibrated(CalibratedStudy {
                    config: self.config.clone(),
                    stage,
                }),
                FIRST_PASSES,
            )
        })
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        calibrated_study(self, place, hooks)
    }
}

/// Claims `place.out` for this run (`run::owner`), once every value has been checked: refused
/// if another command or another run owns it, or if a Slurm run does (neither `fit --recover`
/// nor `paper --calibrated` runs on a cluster).
fn claim<T: Serialize>(place: &Place, command: &str, identity: &T) -> Result<()> {
    crate::studies::place::claim(
        &place.out,
        command,
        identity,
        crate::studies::place::Claimant::Here,
    )
}

/// A stop request met in the estimate (no rolls to keep there) ends the study as one met
/// between rolls does.
fn unless_stopped<T>(r: Result<Option<T>>) -> Result<Option<T>> {
    match r {
        Err(Error::Stopped) => Ok(None),
        r => r,
    }
}

/// `fit`: fit.json, report.md and its figures in `place.out`; the simulations' cells under
/// `place.checkpoint`. A first pass of two writes only `first-pass.json`; a cluster task's
/// share writes nothing.
pub fn fit(study: &FitStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
    study.validate()?;
    let first = study.stage == Stage::First;
    let files: &[&'static str] = if first {
        &[FIRST_PASS]
    } else {
        &["fit.json", "report.md"]
    };
    let outputs = place.outputs(files)?;
    let cfg = &study.config;
    // Two passes roll about as much as the first twice.
    let passes = match study.stage {
        Stage::Whole if cfg.design.refine => 2.0,
        _ => 1.0,
    };
    let total = cfg.total_rolls() as f64 * passes;
    // Passes that widen a cut box roll beyond the two reckoned: the total then grows with them.
    let progress = |n: u64| (hooks.progress)(n as f64, total.max(n as f64));
    let mut sim = place.study(&hooks.stop, &progress);
    sim.runner = sim.runner.with_say(hooks.log);
    let dir = sim.checkpoint.as_deref();
    let runner = &sim.runner;
    let res = unless_stopped(
        runner.install(|| super::run(study, place.command_line.clone(), runner, dir))?,
    )?;
    if place.partial() {
        return Ok(Done::default());
    }
    let Some(res) = res else {
        return Ok(place.interrupted());
    };
    (hooks.progress)(total, total);
    // Sealed: `predict`, a Slurm fit's second pass and anything else that reads it refuses
    // a damaged or edited file.
    let json = seal::to_string(&res, true)?;
    if first {
        outputs.write(FIRST_PASS, json.as_bytes())?;
        let mut done = place.done(&json, &report::first_pass_text(&res), FIRST_PASS);
        done.note = done.note.map(|_| {
            format!(
                "wrote {}/{FIRST_PASS}: the first pass, which the second narrows its box from",
                place.out.display()
            )
        });
        return Ok(done);
    }
    let figures = report::write_figures(&place.out, &res)?;
    let md = report::markdown(&res, &figures);
    outputs.write("fit.json", json.as_bytes())?;
    outputs.write("report.md", md.as_bytes())?;
    Ok(place.done(&json, &md, "fit.json"))
}

/// `fit --recover`: recovery.json in `place.out`, the coverage printed.
pub fn recover(
    cfg: &FitConfig,
    truth: &[f64],
    repeats: usize,
    place: &Place,
    hooks: &Hooks,
) -> Result<Done> {
    cfg.validate()?;
    super::recovery::check_truth(cfg, truth, repeats)?;
    claim(place, "fit --recover", &(cfg, truth, repeats))?;
    let outputs = place.outputs(&["recovery.json"])?;
    let data: u64 = cfg.rows.iter().map(|r| r.counts.iter().sum::<u64>()).sum();
    let passes = if cfg.design.refine { 2 } else { 1 };
    let total = ((passes * cfg.total_rolls() + data) * repeats as u64) as f64;
    let progress = |n: u64| (hooks.progress)(n as f64, total);
    let mut study = place.study(&hooks.stop, &progress);
    study.runner = study.runner.with_say(hooks.log);
    let runner = &study.runner;
    let res =
        unless_stopped(runner.install(|| super::recovery::run(cfg, truth, repeats, runner))?)?;
    // Its repetitions keep no cells.
    let Some(res) = res else {
        return Ok(interrupted(None));
    };
    (hooks.progress)(total, total);
    let json = to_json(&res)?;
    outputs.write("recovery.json", json.as_bytes())?;
    let text = report::recovery_text(&res);
    let mut done = place.done(&json, &text, "recovery.json");
    done.note = done
        .note
        .map(|_| format!("wrote {}/recovery.json", place.out.display()));
    Ok(done)
}

/// `predict`: the block's probabilities printed (no files).
pub fn predict(fit: &FitResult, cfg: &PredictConfig, place: &Place, hooks: &Hooks) -> Result<Done> {
    super::predict::check(fit, cfg)?;
    let total = (cfg.draws as u64 * cfg.rolls) as f64;
    let progress = |n: u64| (hooks.progress)(n as f64, total);
    let study = place.study(&hooks.stop, &progress);
    let runner = &study.runner;
    let p =
        unless_stopped(runner.install(|| super::predict::predict_block(fit, cfg, runner, None))?)?;
    let Some(p) = p else {
        return Ok(interrupted(None));
    };
    Ok(Done {
        stdout: if place.json {
            format!("{}\n", to_json(&p)?)
        } else {
            report::prediction_text(&p)
        },
        ..Done::default()
    })
}

/// What `predict --blocks` predicts: the blocks, and the draws and rolls of each.
#[derive(Clone, Debug, Serialize)]
pub struct BlocksConfig {
    /// The blocks, with their counts where measured.
    pub rows: Vec<crate::calibration::heldout::BlockRow>,
    /// Posterior draws a block.
    pub draws: usize,
    /// Rolls a draw.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The fit's file, as given.
    pub fit: String,
}

/// `predict --blocks`: predictions.json, predictions.csv, report.md and the figure
/// `predictions` in `place.out` (claimed as a study's); the table printed.
pub fn predict_blocks(
    fit: &FitResult,
    cfg: &BlocksConfig,
    place: &Place,
    hooks: &Hooks,
) -> Result<Done> {
    let (stem, files) = (
        "predictions",
        ["predictions.json", "predictions.csv", "report.md"],
    );
    // Every row checked before the directory is claimed.
    super::predict::check_blocks(fit, &cfg.rows, cfg.draws, cfg.rolls, cfg.seed)?;
    let identity = (cfg, &fit.config, &fit.estimate.x);
    claim(place, "predict --blocks", &identity)?;
    let outputs = place.outputs(&files)?;
    let total = (cfg.rows.len() as u64 * cfg.draws as u64 * cfg.rolls) as f64;
    let progress = |n: u64| (hooks.progress)(n as f64, total);
    let study = place.study(&hooks.stop, &progress);
    let runner = &study.runner;
    let rows = unless_stopped(runner.install(|| {
        super::predict::predict_blocks(fit, &cfg.rows, cfg.draws, cfg.rolls, cfg.seed, runner)
    })?)?;
    let Some(rows) = rows else {
        return Ok(interrupted(None));
    };
    let res =
        crate::calibration::heldout::collect(rows, cfg.fit.clone(), place.command_line.clone());
    report::predictions_figure(&place.out, stem, &res)?;
    let md = report::predictions_markdown(&res, stem);
    let json = to_json(&res)?;
    outputs.write("predictions.json", json.as_bytes())?;
    outputs.write("predictions.csv", report::predictions_csv(&res).as_bytes())?;
    outputs.write("report.md", md.as_bytes())?;
    let mut done = place.done(&json, &md, "predictions.json");
    done.note = done.note.map(|_| {
        format!(
            "wrote {}/predictions.json, predictions.csv, report.md and the figure",
            place.out.display()
        )
    });
    Ok(done)
}

/// `paper --calibrated` on one machine: its directory claimed (refused if a Slurm run owns
/// it), then [`calibrated_study`], whole.
pub fn calibrated(cfg: &CalibratedConfig, place: &Place, hooks: &Hooks) -> Result<Done> {
    cfg.validate()?;
    claim(place, "paper --calibrated", cfg)?;
    let study = CalibratedStudy {
        config: cfg.clone(),
        stage: Stage::Whole,
    };
    calibrated_study(&study, place, hooks)
}

/// `paper --calibrated`, or a stage of it on a cluster: calibrated.json, calibrated.md and
/// figures in `place.out`, the cells under `place.checkpoint`; the first stage writes only
/// every model's first pass ([`FIRST_PASSES`]); a cluster task's share writes nothing.
pub fn calibrated_study(study: &CalibratedStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
    study.validate()?;
    let cfg = &study.config;
    let first = study.stage == Stage::First;
    let files: &[&'static str] = if first {
        &[FIRST_PASSES]
    } else {
        &["calibrated.json", "calibrated.md"]
    };
    let outputs = place.outputs(files)?;
    let all = calibrated::total_rolls(cfg)? as f64;
    let firsts = calibrated::first_pass_rolls(cfg)? as f64;
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
    let figures = report::write_calibrated_figures(&place.out, &res)?;
    let md = report::calibrated_markdown(&res, &figures);
    let json = to_json(&res)?;
    outputs.write("calibrated.json", json.as_bytes())?;
    outputs.write("calibrated.md", md.as_bytes())?;
    let mut done = place.done(&json, &md, "calibrated.md");
    done.note = done.note.map(|_| {
        format!(
            "wrote {}/calibrated.md, calibrated.json and figures",
            place.out.display()
        )
    });
    Ok(done)
}
