//! A study end to end, the same on one machine and on a cluster: its output files checked
//! before it rolls anything, the study run, its results rendered (`report`) and written whole.
//! A cluster task rolls its share and writes nothing; the finishing job writes the result.
//! What the caller should print comes back as [`Done`].

use super::kind::Kind;
use super::place::{to_json, Outputs};
pub use super::place::{Done, Hooks, Place};
use super::study::Study;
use super::StudyConfig;
use crate::error::{Error, Field, Result};
use crate::report;
pub use crate::report::progress::Unit;
use crate::report::Report;
use crate::run::runner::ChunkShare;
use crate::run::slurm::{Layout, Plan};

use crate::studies;
use serde::Serialize;
use std::path::Path;

impl Kind for studies::paper::PaperConfig {
    fn name(&self) -> &'static str {
        "paper"
    }
    fn validate(&self) -> Result<()> {
        studies::paper::PaperConfig::validate(self)
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.rolls,
        }
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        paper(self, place, hooks)
    }
}

impl Kind for studies::crosscheck::Config {
    fn name(&self) -> &'static str {
        "crosscheck"
    }
    fn validate(&self) -> Result<()> {
        studies::crosscheck::Config::validate(self)
    }
    fn unit(&self) -> Unit {
        Unit::Rolls {
            per_cell: self.spec.indices().len(),
        }
    }
    fn owns<'a>(&self, place: &'a Place) -> Option<&'a Path> {
        place.checkpoint.as_deref()
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        crosscheck(self, place, hooks)
    }
}

impl Kind for studies::converge::Config {
    fn name(&self) -> &'static str {
        "converge"
    }
    fn validate(&self) -> Result<()> {
        studies::converge::Config::validate(self)
    }
    fn unit(&self) -> Unit {
        if self.precision.is_some() {
            Unit::Cpu
        } else {
            Unit::Cells
        }
    }
    fn check_splittable(&self) -> Result<()> {
        if self.precision.is_some() {
            return Err(Error::field(
                Field::Precision,
                "",
                crate::text![
                    "decides each cell's rounds from all its rolls, which no task sees; give ",
                    Field::Rolls,
                    " instead (a run to a precision prints the rolls each cell needs)"
                ],
            ));
        }
        Ok(())
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        converge(self, place, hooks)
    }
}

impl Kind for studies::tradeoff::Config {
    fn name(&self) -> &'static str {
        "tradeoff"
    }
    fn validate(&self) -> Result<()> {
        studies::tradeoff::Config::validate(self)
    }
    fn unit(&self) -> Unit {
        Unit::Cpu
    }
    fn check_splittable(&self) -> Result<()> {
        if self.preroll_chunks.is_none() {
            return Err(Error::field(
                Field::PrerollChunks,
                "",
                crate::text![
                    "needed: the rounds are decided from every roll so far, which no task sees, \
                     so the tasks roll the first throws of every stream ahead and the finishing \
                     job runs the study, reading them back and rolling on itself where a method \
                     needs more (a plan, ",
                    Field::PlanOnly,
                    ", prints the rolls each needs)"
                ],
            ));
        }
        Ok(())
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        tradeoff(self, place, hooks)
    }
}

impl Kind for studies::stability::Config {
    fn name(&self) -> &'static str {
        "stability"
    }
    fn validate(&self) -> Result<()> {
        studies::stability::Config::validate(self)
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        stability(self, place, hooks)
    }
}

impl Kind for studies::validate::Config {
    fn name(&self) -> &'static str {
        "validate"
    }
    fn validate(&self) -> Result<()> {
        studies::validate::Config::validate(self)
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        validate(self, place, hooks)
    }
}

impl Kind for studies::bench::Config {
    fn name(&self) -> &'static str {
        "bench"
    }
    fn validate(&self) -> Result<()> {
        studies::bench::Config::validate(self)
    }
    /// Its rows, printed as they are measured, are its progress.
    fn unit(&self) -> Unit {
        Unit::Rows
    }
    fn owns<'a>(&self, _: &'a Place) -> Option<&'a Path> {
        None
    }
    fn check_splittable(&self) -> Result<()> {
        Err(Error::Invalid(
            "bench times the methods side by side on one machine: a cluster's tasks would \
             time each on another"
                .into(),
        ))
    }
    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        bench(self, place, hooks)
    }
}

/// `bench`: each measurement's row printed as it is made (not with `--json`), then the
/// whole result as JSON, or the peak memory.
fn bench(cfg: &studies::bench::Config, place: &Place, hooks: &Hooks) -> Result<Done> {
    let quiet = place.json;
    if !quiet {
        (hooks.print)(&report::bench::header());
    }
    let b = studies::bench::run(cfg, &hooks.stop, &|line| {
        if !quiet {
            (hooks.print)(line)
        }
    })?;
    Ok(Done {
        stdout: match place.json {
            true => format!("{}\n", to_json(&b)?),
            false => format!("peak RSS {:.1} MB\n", b.peak_rss_mb),
        },
        ..Done::default()
    })
}

/// The study stored in a cluster run's plan, where it runs (on all its chunks: a task narrows
/// the share) and the run's tasks.
pub fn planned(lay: &Layout) -> Result<(StudyConfig, Place, u64)> {
    let Plan::Study {
        config,
        json,
        command_line,
        threads,
        tasks,
    } = lay.read_plan()?
    else {
        return Err(Error::Invalid(format!(
            "{} is a roll's run, not a study's",
            lay.dir.display()
        )));
    };
    let cfg = serde_json::from_value(config)
        .map_err(|e| Error::Invalid(format!("{} is damaged ({e})", lay.plan().display())))?;
    let place = Place::cluster(lay, threads, json, ChunkShare::All, &command_line);
    Ok((cfg, place, tasks))
}

/// `paper`: results.json, results.csv, report.md and the figures, in `place.out`; its cells
/// under `place.checkpoint`, so that the same study run again continues where it stopped.
fn paper(cfg: &studies::paper::PaperConfig, place: &Place, hooks: &Hooks) -> Result<Done> {
    let outputs = place.outputs(&["results.json", "results.csv", "report.md"])?;
    let total = studies::paper::total_rolls(cfg)? as f64;
    let progress = |n: u64| (hooks.progress)(n as f64, total);
    let res = studies::paper::run(
        cfg,
        place.command_line.clone(),
        &place.study(&hooks.stop, &progress),
    )?;
    if place.partial() {
        return Ok(Done::default());
    }
    if res.partial {
        // A partial run leaves the last complete outputs alone: its report goes to stdout.
        let figures = ["master_graph", "prob_2d", "len_graph", "dreidel"].map(String::from);
        return Ok(Done {
            stdout: format!("{}\n", res.markdown(&figures)),
            interrupted: place.interrupted().interrupted,
            ..Done::default()
        });
    }
    let figures = res.write_figures(&place.out)?;
    let md = res.markdown(&figures);
    let json = to_json(&res)?;
    outputs.write("results.json", json.as_bytes())?;
    outputs.write("results.csv", report::paper::results_csv(&res)?.as_bytes())?;
    outputs.write("report.md", md.as_bytes())?;
    // On the terminal the verdict, not the report: the report is the file's.
    let mut done = place.done(
        &json,
        &report::paper::verdict(&res, &place.out),
        "report.md",
    );
    done.note = done.note.map(|_| {
        format!(
            "wrote {}/report.md, results.json, results.csv and figures",
            place.out.display()
        )
        .into()
    });
    Ok(done)
}

/// `crosscheck`: each engine's run and each against the baseline, printed (no files).
fn crosscheck(cfg: &studies::crosscheck::Config, place: &Place, hooks: &Hooks) -> Result<Done> {
    let rolls = cfg.spec.indices().len();
    let total = (rolls * cfg.engines.len() as u64) as f64;
    // The runner counts each engine's run from 0: the runs before it are whole.
    let engine = std::sync::atomic::AtomicU64::new(0);
    let progress = |n: u64| {
        let before = engine.load(std::sync::atomic::Ordering::Relaxed) * rolls;
        if n == rolls {
            engine.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        (hooks.progress)((before + n) as f64, total);
    };
    let res = match studies::crosscheck::run(cfg, &place.study(&hooks.stop, &progress)) {
        Err(Error::Stopped) => return Ok(place.interrupted()),
        r => r?,
    };
    if place.partial() {
        // A cluster task's share: its chunks are kept for the finishing job; nothing to compare.
        return Ok(Done::default());
    }
    Ok(Done {
        stdout: if place.json {
            format!("{}\n", to_json(&res)?)
        } else {
            report::crosscheck::human(&res)
        },
        ..Done::default()
    })
}

/// `converge`: converge.json, report.md and its figure.
fn converge(cfg: &studies::converge::Config, place: &Place, hooks: &Hooks) -> Result<Done> {
    let outputs = place.outputs(&["converge.json", "report.md"])?;
    let Some(res) = logged(place, hooks, &report::converge::header(), |study, log| {
        studies::converge::run(cfg, study, log, hooks.progress)
    })?
    else {
        return Ok(Done::default());
    };
    let rep = report::converge::ConvergeReport {
        res: &res,
        precision: cfg.precision,
    };
    write(place, &outputs, &rep, &res, "converge.json")
}

/// `tradeoff`: tradeoff.json, report.md and its figure; or the plan; or the rolls ahead. A run
/// on one block writes that block's study; on several, each block's and the summary across.
fn tradeoff(cfg: &studies::tradeoff::Config, place: &Place, hooks: &Hooks) -> Result<Done> {
    let outputs = place.outputs(&["tradeoff.json", "report.md"])?;
    let Some(res) = logged(place, hooks, &report::tradeoff::header(), |study, log| {
        studies::tradeoff::run(cfg, study, log, hooks.progress)
    })?
    else {
        return Ok(Done::default());
    };
    let one = match res.per_block.as_slice() {
        [one] => Some(one),
        _ => None,
    };
    if cfg.plan_only {
        let stdout = match (place.json, one) {
            (false, _) => String::new(),
            (true, Some(one)) => format!("{}\n", to_json(one)?),
            (true, None) => format!("{}\n", to_json(&res)?),
        };
        return Ok(Done {
            stdout,
            ..Done::default()
        });
    }
    if let Some(k) = cfg.preroll_chunks {
        return Ok(Done {
            note: Some(crate::text![
                format!(
                    "rolled the first {} throws of every stream into {}/checkpoint ({:.0} CPU \
                     s); the same study without ",
                    k * crate::run::runner::CHUNK_ROLLS,
                    place.out.display(),
                    res.cpu_s
                ),
                Field::PrerollChunks,
                " reads them back"
            ]),
            ..Done::default()
        });
    }
    match one {
        Some(one) => write(place, &outputs, one, one, "tradeoff.json"),
        None => write(place, &outputs, &res, &res, "tradeoff.json"),
    }
}

/// `stability`: stability.json, report.md and its heat maps.
fn stability(cfg: &studies::stability::Config, place: &Place, hooks: &Hooks) -> Result<Done> {
    let outputs = place.outputs(&["stability.json", "report.md"])?;
    let Some(res) = logged(place, hooks, &report::stability::header(), |study, log| {
        studies::stability::run(cfg, study, log, hooks.progress)
    })?
    else {
        return Ok(Done::default());
    };
    write(place, &outputs, &res, &res, "stability.json")
}

/// `validate`: validate.json, report.md and its figures.
fn validate(cfg: &studies::validate::Config, place: &Place, hooks: &Hooks) -> Result<Done> {
    let outputs = place.outputs(&["validate.json", "report.md"])?;
    let Some(res) = logged(place, hooks, &report::validate::header(), |study, log| {
        studies::validate::run(cfg, study, log, hooks.progress)
    })?
    else {
        return Ok(Done::default());
    };
    write(place, &outputs, &res, &res, "validate.json")
}

/// Writes a study's report (its figures, then `report.md`, [`Report`]) and its results' JSON
/// into the outputs checked before the run.
fn write<T: Serialize>(
    place: &Place,
    outputs: &Outputs,
    report: &dyn Report,
    res: &T,
    file: &str,
) -> Result<Done> {
    let figures = report.write_figures(&place.out)?;
    let md = report.markdown(&figures);
    let json = to_json(res)?;
    outputs.write(file, json.as_bytes())?;
    outputs.write("report.md", md.as_bytes())?;
    Ok(place.done(&json, &md, file))
}

/// Runs a sweep, logging its header and each cell unless the output is JSON. A cluster task's
/// share runs silently and gives None: it is for the finishing job to assemble, not to report.
fn logged<T>(
    place: &Place,
    hooks: &Hooks,
    header: &str,
    run: impl FnOnce(&Study, &(dyn Fn(&str) + Sync)) -> Result<T>,
) -> Result<Option<T>> {
    let quiet = place.json || place.partial();
    if !quiet {
        (hooks.log)(header);
    }
    let silent = |_: &str| {};
    let log: &(dyn Fn(&str) + Sync) = if quiet { &silent } else { hooks.log };
    let res = run(&place.study(&hooks.stop, &|_| {}), log)?;
    Ok((!place.partial()).then_some(res))
}
