//! `fit`, `fit --recover`, `predict` and `paper --calibrated` end to end: outputs checked
//! before anything rolls, the study run with its progress, its results rendered and written
//! whole (as [`crate::studies::outputs`] does for the other studies).

use super::{BlocksStudy, FitStudy, PredictStudy, RecoverStudy, Stage, FIRST_PASS};
use crate::error::Error;
use crate::error::Result;
use crate::report::fit as report;
use crate::report::progress::Unit;
use crate::report::Report;
use crate::run::seal;
use crate::studies::kind::Kind;
use crate::studies::place::{interrupted, to_json, unless_stopped, Done, Hooks, Place};

impl Kind for FitStudy {
    fn name(&self) -> &'static str {
        "fit"
    }
    fn validate(&self) -> Result<()> {
        FitStudy::validate(self)
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.design.rolls,
        }
    }
    fn cells(&self) -> &'static str {
        "cells"
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        fit(self, place, hooks)
    }
}

impl Kind for RecoverStudy {
    fn name(&self) -> &'static str {
        "fit --recover"
    }
    fn validate(&self) -> Result<()> {
        self.config.validate()?;
        super::recovery::check_truth(&self.config, &self.truth, self.repeats)
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.design.rolls,
        }
    }
    /// A fit's directory name (its repetitions keep no cells there).
    fn cells(&self) -> &'static str {
        "cells"
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        recover(self, place, hooks)
    }
}

impl Kind for PredictStudy {
    fn name(&self) -> &'static str {
        "predict"
    }
    fn validate(&self) -> Result<()> {
        super::predict::check(&self.fit, &self.config)
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.rolls,
        }
    }
    /// It writes nothing.
    fn owns<'a>(&self, _place: &'a Place) -> Option<&'a std::path::Path> {
        None
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        predict(self, place, hooks)
    }
}

impl Kind for BlocksStudy {
    fn name(&self) -> &'static str {
        "predict --blocks"
    }
    fn validate(&self) -> Result<()> {
        let c = &self.config;
        super::predict::check_blocks(&self.fit, &c.rows, c.draws, c.rolls, c.seed)?;
        for d in &c.dice {
            let label = d.counts.first().map_or("", |r| r.label.as_str());
            super::predict::check(&self.fit, d)
                .map_err(|e| Error::Invalid(format!("row '{label}': {e}")))?;
        }
        Ok(())
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.config.rolls,
        }
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        predict_blocks(self, place, hooks)
    }
}

/// `fit`: fit.json, report.md and its figures in `place.out`; the simulations' cells under
/// `place.checkpoint`. A first pass of two writes only `first-pass.json`; a cluster task's
/// share writes nothing.
fn fit(study: &FitStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
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
            .into()
        });
        return Ok(done);
    }
    let figures = res.write_figures(&place.out)?;
    let md = res.markdown(&figures);
    outputs.write("fit.json", json.as_bytes())?;
    outputs.write("report.md", md.as_bytes())?;
    Ok(place.done(&json, &md, "fit.json"))
}

/// `fit --recover`: recovery.json in `place.out`, the coverage printed.
fn recover(study: &RecoverStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
    let (cfg, truth, repeats) = (&study.config, &study.truth, study.repeats);
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
        .map(|_| format!("wrote {}/recovery.json", place.out.display()).into());
    Ok(done)
}

/// `predict`: the block's probabilities printed (no files).
fn predict(study: &PredictStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
    let (fit, cfg) = (&study.fit, &study.config);
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

/// `predict --blocks`: predictions.json, predictions.csv, report.md and the figure
/// `predictions` in `place.out` (claimed as a study's); the table printed.
fn predict_blocks(study: &BlocksStudy, place: &Place, hooks: &Hooks) -> Result<Done> {
    let (fit, cfg) = (&study.fit, &study.config);
    let stem = "predictions";
    let mut files = vec!["predictions.json", "report.md"];
    if !cfg.rows.is_empty() {
        files.push("predictions.csv");
    }
    if !cfg.dice.is_empty() {
        files.push("dice.csv");
    }
    let outputs = place.outputs(&files)?;
    let per_row = cfg.draws as u64 * cfg.rolls;
    let total = ((cfg.rows.len() + cfg.dice.len()) as u64 * per_row) as f64;
    let progress = |n: u64| (hooks.progress)(n as f64, total);
    let study = place.study(&hooks.stop, &progress);
    let runner = &study.runner;
    let rows = unless_stopped(runner.install(|| {
        super::predict::predict_blocks(fit, &cfg.rows, cfg.draws, cfg.rolls, cfg.seed, runner)
    })?)?;
    let Some(rows) = rows else {
        return Ok(interrupted(None));
    };
    let mut dice = Vec::new();
    for (i, d) in cfg.dice.iter().enumerate() {
        let base = ((cfg.rows.len() + i) as u64 * per_row) as f64;
        let progress = |n: u64| (hooks.progress)(base + n as f64, total);
        let runner = runner.with_progress(&progress);
        let label = d.counts.first().map_or("", |r| r.label.as_str());
        let in_row = |e| match e {
            Error::Failed(m) => Error::Failed(m.after(&format!("row '{label}': "))),
            e => e,
        };
        let predicted =
            unless_stopped(runner.install(|| {
                super::predict::predict_block(fit, d, &runner, None).map_err(in_row)
            })?)?;
        let Some(prediction) = predicted else {
            return Ok(interrupted(None));
        };
        dice.push(crate::calibration::heldout::PredictedDie {
            label: label.to_string(),
            die: d
                .counts
                .first()
                .and_then(|r| r.die.clone())
                .unwrap_or_default(),
            prediction,
        });
    }
    let res = crate::calibration::heldout::collect(
        rows,
        dice,
        cfg.fit.clone(),
        place.command_line.clone(),
    );
    if !res.rows.is_empty() {
        report::predictions_figure(&place.out, stem, &res)?;
    }
    if !res.dice.is_empty() {
        outputs.write("dice.csv", report::dice_csv(&res).as_bytes())?;
    }
    let md = report::predictions_markdown(&res, stem);
    let json = to_json(&res)?;
    outputs.write("predictions.json", json.as_bytes())?;
    if !res.rows.is_empty() {
        outputs.write("predictions.csv", report::predictions_csv(&res).as_bytes())?;
    }
    outputs.write("report.md", md.as_bytes())?;
    let mut done = place.done(&json, &md, "predictions.json");
    done.note = done.note.map(|_| {
        format!(
            "wrote {}/{}",
            place.out.display(),
            match (res.rows.is_empty(), res.dice.is_empty()) {
                (false, true) => "predictions.json, predictions.csv, report.md and the figure",
                (true, false) => "predictions.json, dice.csv and report.md",
                _ => "predictions.json, predictions.csv, dice.csv, report.md and the figure",
            }
        )
        .into()
    });
    Ok(done)
}
