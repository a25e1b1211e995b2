//! `roll`, and the rolling of `fair`, as a study: one die thrown on one engine, its chunks kept
//! in a checkpoint if asked (a run there is continued), one CSV row a throw if asked, rolled to
//! a precision if asked, and its faces judged against a fair die's (`fair`) if asked. The
//! command line runs it as every study runs ([`super::StudyConfig::run`]); the Python package
//! and a cluster's finishing job render its result the same one way ([`RollStudy::render`]).

use super::kind::Kind;
use super::place::{Done, Hooks, Place};
use crate::error::{Error, Field, Result};
use crate::report::fair::{Fairness, Null};
use crate::report::per_roll::PerRoll;
use crate::report::precision::Target;
use crate::report::progress::Unit;
use crate::report::summary::{Cost, RunSummary};
use crate::run::cputime::process_cpu_seconds;
use crate::run::io::Output;
use crate::run::runner::{Checkpoint, Runner};
use crate::run::spec::RunSpec;
use crate::sim::roll::RollRecord;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::Instant;

/// One run of one die: `roll`, or with a null `fair`. Its chunks are kept in its place's
/// `checkpoint`, if any; `fair`'s files go into its place's `out`, if one is named.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RollStudy {
    /// What is rolled: the die, the scene, the throws, the engine, how many.
    pub spec: RunSpec,
    /// `fair`: the faces judged against this null (absent: `roll`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fair: Option<Null>,
    /// Roll to this precision, a fraction (`roll`: the ratio's relative 2σ error; `fair`:
    /// every face's probability's 2σ), tested at each chunk's end; `spec.rolls` the cap.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub precision: Option<f64>,
    /// One CSV row per throw into this file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_roll: Option<PathBuf>,
    /// Continues a checkpointed run (its specification read from there): the command that
    /// continues an interrupted one says `--resume`, and a `fair` run keeps its null there
    /// only when it starts.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub resumed: bool,
}

/// The file in a `fair` run's checkpoint that keeps its null, for `--resume`.
const NULL_FILE: &str = "fair-null.json";

impl RollStudy {
    /// `spec` rolled once, to its rolls, kept nowhere; judged against `fair` if given.
    pub fn new(spec: RunSpec, fair: Option<Null>) -> RollStudy {
        RollStudy {
            spec,
            fair,
            precision: None,
            per_roll: None,
            resumed: false,
        }
    }

    /// What its precision is of: every face's probability for `fair`, the ratio for `roll`.
    pub fn target(&self) -> Target {
        match self.fair {
            Some(_) => Target::Faces,
            None => Target::Ratio,
        }
    }

    /// Its command.
    pub fn command(&self) -> &'static str {
        match self.fair {
            Some(_) => "fair",
            None => "roll",
        }
    }

    /// The JSON document `--json` prints and the text printed without it: the run's summary
    /// (`roll`), or its faces judged and the summary beside (`fair`). The one rendering of a
    /// roll, here, in Python and in a cluster's finishing job.
    pub fn render(&self, summary: &RunSummary) -> Result<(String, String)> {
        match &self.fair {
            None => Ok((crate::run::seal::to_string(summary, true)?, summary.human())),
            Some(null) => judged(summary, null).map(|(_, doc, text)| (doc, text)),
        }
    }

    /// What makes two runs of it one, for `fair --out`'s directory: the specification, the
    /// null and the numbers on the faces (as `fair` has always claimed it).
    pub fn identity(&self) -> serde_json::Value {
        serde_json::json!({
            "spec": self.spec,
            "null": self.fair.as_ref().map(Null::spec),
            "layout": self.spec.scene.features.layout,
        })
    }

    /// Rolls it with `runner`, its chunks kept in `checkpoint` if given, every finished
    /// chunk's records handed to `sink` in throw order, `expect` told the rolls expected in
    /// all as a run to a precision goes; the summary numbered by the die's layout.
    pub fn roll(
        &self,
        runner: &Runner,
        checkpoint: Option<&Path>,
        sink: &mut dyn FnMut(&[RollRecord]) -> Result<()>,
        expect: &dyn Fn(u64),
    ) -> Result<RunSummary> {
        let precision = self.precision.map(|p| (p, self.target(), expect));
        let summary = roll_into(&self.spec, checkpoint, sink, precision, runner)?;
        Ok(summary.with_layout(self.spec.scene.features.layout))
    }

    /// The notes said before it rolls: a roll that may not end, the paper's throw on a cube
    /// (`roll`), a die that rolls on its hull, a loaded die's engine; `json` quiets the notes
    /// (not the warnings).
    fn notes(&self, json: bool) -> Vec<String> {
        let spec = &self.spec;
        let mut lines = Vec::new();
        if let Some(w) = self
            .fair
            .is_none()
            .then(|| paper_throw_warning(spec))
            .flatten()
        {
            lines.push(format!("dicephys: warning: {w}"));
        }
        if let Some(w) = spec.endless_roll_warning() {
            lines.push(format!("dicephys: warning: {w}"));
        }
        let hull = spec.scene.die.as_shape().and_then(|s| s.hull_note());
        let loaded = spec.loaded_die_note(&[spec.engine]);
        if !json {
            lines.extend(
                [hull, loaded]
                    .into_iter()
                    .flatten()
                    .map(|n| format!("dicephys: note: {n}")),
            );
        }
        lines
    }

    /// A `fair` run's null checked against the one its checkpoint keeps (refused if another).
    fn check_kept_null(&self, checkpoint: Option<&Path>) -> Result<()> {
        let (Some(null), Some(dir)) = (&self.fair, checkpoint) else {
            return Ok(());
        };
        if !dir.join(NULL_FILE).exists() {
            return Ok(());
        }
        let kept = kept_null(dir)?;
        if kept != *null {
            return Err(Error::Mismatch(format!(
                "--checkpoint {}: it holds a fair run against {kept}, not {null}: resume that \
                 run (dicephys fair --resume {}), or use a new directory",
                dir.display(),
                dir.display()
            )));
        }
        Ok(())
    }

    /// Keeps a `fair` run's null in its checkpoint (opened by now) for `--resume`.
    fn keep_null(&self, checkpoint: Option<&Path>) -> Result<()> {
        let (Some(against), Some(dir), false) = (&self.fair, checkpoint, self.resumed) else {
            return Ok(());
        };
        if !dir.join("spec.json").exists() {
            return Ok(());
        }
        let json = serde_json::to_string(&serde_json::json!({ "null": against }))
            .map_err(|e| Error::failed(e.to_string()))?;
        crate::run::io::write_atomic(&dir.join(NULL_FILE), json.as_bytes())
    }

    /// What an interrupted run says: what it rolled and how to continue it.
    fn interrupted(&self, rolled: u64, checkpoint: Option<&Path>) -> String {
        // The flag that set the precision: fair's target is its faces (--within).
        let flag = match self.target() {
            Target::Ratio => "--precision",
            Target::Faces => "--within",
        };
        let resume = checkpoint.map(|d| {
            format!(
                "dicephys {} --resume {}{}",
                self.command(),
                d.display(),
                self.precision
                    .map_or(String::new(), |p| format!(" {flag} {}", 100.0 * p))
            )
        });
        crate::run::stop::interrupted(&crate::run::stop::Kept::Rolls {
            done: rolled,
            of: self.spec.indices().len(),
            resume,
        })
    }

    /// What it prints once rolled, and whether it failed after printing: a die none of whose
    /// rolls came to rest on a face has no shares to give (`roll`) and no verdict (`fair`).
    fn done(&self, summary: &RunSummary, place: &Place) -> Result<Done> {
        let json = place.json;
        let print = |doc: &str, text: &str| match json {
            true => format!("{doc}\n"),
            false => text.to_string(),
        };
        // The run's summary as printed: its JSON or its text, only the one asked for (the text
        // works out the theory beside the counts, which `--json` does not print).
        let summary_printed = || -> Result<String> {
            Ok(match json {
                true => format!("{}\n", crate::run::seal::to_string(summary, true)?),
                false => summary.human(),
            })
        };
        let unsettled = match summary.partial {
            true => None,
            false => crate::report::shape_outcomes::check_settled(&summary.tally).err(),
        };
        // Broken physics says so on the terminal too, whatever goes to stdout.
        let warnings = json.then(|| {
            let lines: Vec<String> = summary
                .warnings
                .iter()
                .map(|w| format!("dicephys: warning: {w}"))
                .collect();
            lines.join("\n")
        });
        let warnings = warnings.filter(|w| !w.is_empty()).map(Into::into);
        let mut written: Option<String> = None;
        if self.fair.is_some() {
            if let Some(e) = unsettled {
                return Ok(Done {
                    stdout: summary_printed()?,
                    failed: Some(format!("no verdict: {e}")),
                    ..Done::default()
                });
            }
        }
        let stdout = match &self.fair {
            None => summary_printed()?,
            Some(null) => {
                let (fair, doc, text) = judged(summary, null)?;
                let out = &place.out;
                if !out.as_os_str().is_empty() && !summary.partial {
                    super::fair::write(out, &doc, &fair, summary)?;
                    crate::report::html::write_text_report(
                        out,
                        "Is this die fair?",
                        &text,
                        &["die_map", "faces"],
                    )?;
                    if !json {
                        written = Some(format!(
                            "wrote {}/fairness.json, report.md, report.html and die_map.svg, .png",
                            out.display()
                        ));
                    }
                }
                print(&doc, &text)
            }
        };
        let note = written.map(Into::into).or(warnings);
        // A die of any shape none of whose rolls came to rest on a face: `roll` prints what
        // it rolled, then fails.
        let nothing = summary.shape.as_ref().is_some_and(|s| {
            !summary.partial && summary.rolls > 0 && s.faces.iter().all(|f| f.count == 0)
        });
        let failed = (self.fair.is_none() && nothing).then(|| {
            unsettled.map_or_else(
                || "no roll came to rest on a face".into(),
                |e| e.to_string(),
            )
        });
        Ok(Done {
            stdout,
            note,
            failed,
            ..Done::default()
        })
    }
}

/// `summary`'s faces judged against `null`, and `fair`'s JSON document and text of it.
fn judged(summary: &RunSummary, null: &Null) -> Result<(Fairness, String, String)> {
    let fair = super::fair::assess(summary, null)?;
    let doc = serde_json::json!({ "fairness": fair, "summary": summary });
    let doc = crate::run::seal::to_string(&doc, true)?;
    let text = fair.text(summary);
    Ok((fair, doc, text))
}

/// The null a checkpointed `fair` run keeps (a `roll` checkpoint keeps none: uniform).
pub fn kept_null(dir: &Path) -> Result<Null> {
    let file = dir.join(NULL_FILE);
    if !file.exists() {
        return Ok(Null::default());
    }
    let text = std::fs::read_to_string(&file).map_err(|e| Error::io(&file, e))?;
    #[derive(serde::Deserialize)]
    struct Kept {
        null: Null,
    }
    serde_json::from_str::<Kept>(&text)
        .map(|k| k.null)
        .map_err(|e| Error::Invalid(format!("{} is damaged ({e})", file.display())))
}

impl Kind for RollStudy {
    fn name(&self) -> &'static str {
        self.command()
    }

    fn validate(&self) -> Result<()> {
        if let Some(p) = self.precision.filter(|p| !(*p > 0.0 && *p < 1.0)) {
            return Err(Error::Invalid(format!(
                "precision {p}: a fraction in (0, 1) (0.02 is a relative 2σ of 2 %)"
            )));
        }
        if let Some(null) = &self.fair {
            super::fair::check_null(&self.spec, null)?;
        }
        Ok(())
    }

    fn unit(&self) -> Unit {
        Unit::Rolls { per_cell: 0 }
    }

    /// `fair --out`'s directory, if one is named (a roll's checkpoint is its run's by its
    /// specification, `run::runner::Checkpoint`).
    fn owns<'a>(&self, place: &'a Place) -> Option<&'a Path> {
        let out = place.out.as_path();
        (self.fair.is_some() && !out.as_os_str().is_empty()).then_some(out)
    }

    fn check_splittable(&self) -> Result<()> {
        match self.precision {
            Some(_) => Err(Error::field(
                Field::Precision,
                "",
                crate::text![
                    "decides how far to roll from every roll so far, which no task sees; give ",
                    Field::Rolls,
                    " instead"
                ],
            )),
            None => Ok(()),
        }
    }

    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        let checkpoint = place.checkpoint.as_deref();
        self.check_kept_null(checkpoint)?;
        for line in self.notes(place.json) {
            (hooks.log)(&line);
        }
        // Under a precision the total is the rolls expected so far, not the cap.
        let expected = AtomicU64::new(self.spec.indices().len());
        let progress = |n: u64| (hooks.progress)(n as f64, expected.load(Relaxed) as f64);
        let expect = |n: u64| expected.store(n, Relaxed);
        let runner = Runner::new(place.threads, hooks.stop.clone())
            .with_share(place.share.clone())
            .with_progress(&progress);
        let layout = self.spec.scene.features.layout;
        let per_roll = match &self.per_roll {
            Some(p) => Some((Output::check(p)?, layout)),
            None => None,
        };
        let precision = self
            .precision
            .map(|p| (p, self.target(), &expect as &dyn Fn(u64)));
        let summary =
            roll(&self.spec, checkpoint, per_roll, precision, &runner)?.with_layout(layout);
        self.keep_null(checkpoint)?;
        let mut done = self.done(&summary, place)?;
        if summary.partial {
            done.interrupted = Some(self.interrupted(summary.rolls, checkpoint));
        }
        Ok(done)
    }
}

/// A warning when the paper's throw meets a block whose long axis is not unique (a cube): the
/// throw spins it about body z, so the two z faces come up less often than a tester's throw
/// would show them (issue 50: "a fair cube that looks loaded").
fn paper_throw_warning(spec: &RunSpec) -> Option<String> {
    let b = spec.scene.die.block();
    let paper = spec.throws.style == crate::model::throws::ThrowStyle::Paper;
    (paper && spec.scene.die.as_shape().is_none() && b.length <= b.breadth * (1.0 + 1e-9)).then(
        || {
            format!(
                "the paper's throw spins the block about its length, and {} has no longer length: \
             faces 1 and 6 will come up less often than on a tester's throw; --throw tumble \
             throws it without a preferred axis",
                b
            )
        },
    )
}

/// A precision to roll to: the fraction, what it is of, and a hook told the rolls expected in
/// all as the run goes.
pub type Precision<'a> = (f64, Target, &'a dyn Fn(u64));

/// One run, its chunks kept in `checkpoint` if given (a run there is continued), one CSV row
/// per throw into `per_roll` if given (grown chunk by chunk in a temporary file, put in place
/// at the end). Its summary is partial if a stop request ended it; a resumed run's cost is the
/// sum over its segments (the resumed chunks carry theirs). With `precision`, the run stops at
/// the first chunk boundary where the ratio's relative 2σ error (or every face's 2σ) is at
/// most that, `spec.rolls` its cap (`studies::precision`).
pub fn roll(
    spec: &RunSpec,
    checkpoint: Option<&Path>,
    per_roll: Option<(Output, crate::model::faces::Layout)>,
    precision: Option<Precision>,
    runner: &Runner,
) -> Result<RunSummary> {
    let mut csv = match &per_roll {
        Some((out, layout)) => Some(PerRoll::for_scene(out.writer()?, &spec.scene, *layout)?),
        None => None,
    };
    let mut sink = |recs: &[RollRecord]| -> Result<()> {
        match csv.as_mut() {
            Some(c) => c.write(recs),
            None => Ok(()),
        }
    };
    let summary = roll_into(spec, checkpoint, &mut sink, precision, runner)?;
    if let Some(c) = csv {
        c.finish()?.commit()?;
    }
    Ok(summary)
}

/// [`roll`] with every finished chunk's records, in throw order, handed to `sink` (the
/// per-roll CSV, or a caller's own table: the Python package's arrays are these same rows).
pub fn roll_into(
    spec: &RunSpec,
    checkpoint: Option<&Path>,
    sink: &mut dyn FnMut(&[RollRecord]) -> Result<()>,
    precision: Option<Precision>,
    runner: &Runner,
) -> Result<RunSummary> {
    let checkpoint = checkpoint.map(|d| Checkpoint::open(d, spec)).transpose()?;
    let wall = Instant::now();
    let cpu = process_cpu_seconds();
    let (done, reached) = match precision {
        Some((p, target, expect)) => {
            let (done, reached) = super::precision::roll_to_precision(
                runner,
                spec,
                checkpoint.as_ref(),
                p,
                target,
                expect,
                sink,
            )?;
            (done, Some(reached))
        }
        None => (runner.run(spec, checkpoint.as_ref(), sink)?, None),
    };
    let cost = Cost {
        wall_s: wall.elapsed().as_secs_f64() + done.resumed_wall_s,
        cpu_s: process_cpu_seconds() - cpu + done.resumed_cpu_s,
        threads: runner.threads,
    };
    let mut summary = RunSummary::new(spec, &done.tally, cost);
    summary.partial = !done.complete;
    summary.precision = reached;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::request::RollRequest;
    use crate::run::runner::ChunkShare;
    use crate::studies::StudyConfig;

    /// 60 throws of the default die, seed 5.
    fn spec() -> RunSpec {
        let mut r = RollRequest {
            rolls: Some(60),
            ..RollRequest::default()
        };
        r.throws.seed = 5;
        r.spec().unwrap()
    }

    fn run(study: RollStudy, json: bool) -> Done {
        let place = Place {
            out: PathBuf::new(),
            checkpoint: None,
            threads: 2,
            share: ChunkShare::All,
            json,
            command_line: String::new(),
        };
        let hooks = Hooks {
            log: &|_| {},
            print: &|_| {},
            progress: &|_, _| {},
            stop: crate::run::stop::Stop::new(),
        };
        StudyConfig::Roll(study).run(&place, &hooks).unwrap()
    }

    /// `roll` and `fair` run as studies print what the library's one rendering of the same
    /// rolls says: the counts, and fair's verdict on them (its text, costs apart, equal).
    #[test]
    fn a_roll_run_as_a_study_prints_its_rolls_rendered_the_one_way() {
        let runner = Runner::new(1, crate::run::stop::Stop::new());
        let direct = RollStudy::new(spec(), None)
            .roll(&runner, None, &mut |_| Ok(()), &|_| {})
            .unwrap();
        let done = run(RollStudy::new(spec(), None), true);
        let printed: serde_json::Value = crate::run::seal::open(&done.stdout).unwrap();
        let faces = |v: &serde_json::Value| v["tally"]["faces"].clone();
        let direct_json = serde_json::to_value(&direct).unwrap();
        assert_eq!(faces(&printed), faces(&direct_json));
        assert_eq!(printed["rolls"], 60);
        assert!(done.interrupted.is_none() && done.failed.is_none());
        // fair: its text is the verdict on these same rolls (the one rendering).
        let fair = RollStudy::new(spec(), Some(Null::Uniform));
        let done = run(fair.clone(), false);
        assert_eq!(done.stdout, fair.render(&direct).unwrap().1);
        assert!(done.stdout.contains("fair"), "{}", done.stdout);
    }

    /// A `fair --out` directory made before keeps its owner: the identity is the one `fair`
    /// always claimed it with (its specification, null and layout), not the study's fields.
    #[test]
    fn fair_claims_its_directory_by_the_identity_it_always_had() {
        let s = spec();
        let study = RollStudy {
            precision: Some(0.01),
            ..RollStudy::new(s.clone(), Some(Null::Uniform))
        };
        let before = serde_json::json!({
            "spec": s, "null": (Null::Uniform.spec()), "layout": s.scene.features.layout
        });
        assert_eq!(StudyConfig::Roll(study.clone()).identity(), before);
        // Serialized as a study (what a plan or Python would store) and read back, the same.
        let back: StudyConfig =
            serde_json::from_value(serde_json::to_value(StudyConfig::Roll(study)).unwrap())
                .unwrap();
        assert_eq!(back.name(), "fair");
        assert_eq!(back.identity(), before);
    }
}
