//! `dicephys trace --html FILE`: the throws `--index` names, each rolled as `trace` rolls it
//! (with the early stop audited: when it would have fired, without stopping), written as one
//! page that plays them (`report::view`). Each throw's ending line goes to stderr as `trace`'s.

use super::error::{Error, Result};
use super::trace::TraceArgs;
use dicephys::engine::new_engine;
use dicephys::model::block::Outcome;
use dicephys::model::die::DieShape;
use dicephys::report::trace;
use dicephys::report::view::{self, DieView, Recorder, ThrowView};
use dicephys::sim::roll::{roll_observed, Fate, RollConfig, RollRecord};

pub fn run(a: &TraceArgs) -> Result<()> {
    let path = a.html.as_ref().expect("called with --html");
    if *a.max_steps == 0 {
        return Err(Error::Usage("--max-steps must be at least 1".into()));
    }
    // Checked before any roll: a page that cannot be written is refused at once.
    let out = dicephys::run::io::Output::check(path)?;
    let scene = a.scene.scene()?;
    let die = DieShape::of(&scene);
    let throw_spec = a
        .throw
        .spec_or(dicephys::model::throws::ThrowStyle::default_for(&scene))?;
    let throws = throw_spec.source(a.index.last + 1);
    let settle = RollConfig {
        audit: true,
        ..super::trace::settle(a, &scene)
    };
    let labels: Vec<String> = scene
        .shape
        .as_ref()
        .map(|s| s.labels().into_iter().map(String::from).collect())
        .unwrap_or_default();
    let label_refs: Vec<&str> = labels.iter().map(String::as_str).collect();
    let mut views = Vec::new();
    for index in a.index.first..=a.index.last {
        let throw = throws.get(index);
        let mut engine = new_engine(a.engine, &scene)?;
        let mut rec = Recorder::new(scene.dt);
        let mut end_state = None;
        let record = roll_observed(engine.as_mut(), &scene, &throw, &settle, |step, s| {
            if step.is_multiple_of(1024) && super::term::stop().requested() {
                eprintln!(
                    "dicephys: {}",
                    dicephys::run::stop::interrupted(&dicephys::run::stop::Kept::Nothing(None))
                );
                std::process::exit(130);
            }
            end_state = Some(*s);
            rec.push(&die, step, s);
        });
        let mut ended = record;
        if let (Fate::Unconverged(_), Some(s)) = (record.fate, end_state) {
            ended.up = die.outcome(&s).1;
        }
        let ending = trace::ending(index, &throw, &ended, &label_refs);
        eprintln!("{ending}");
        if let Some(note) = trace::capped(&record, settle.max_steps, a.max_steps.asked().is_some())
        {
            eprintln!("dicephys: {note}");
        }
        views.push(ThrowView {
            index,
            ending,
            outcome: outcome(&ended, &labels),
            early_stop: early_stop(&record, scene.dt, &labels),
            frames: rec.finish(&die),
        });
    }
    let page = view::page(&DieView::of(&scene, &die), scene.dt, engine_name(a), &views);
    out.write(page.as_bytes())?;
    Ok(())
}

fn engine_name(a: &TraceArgs) -> &'static str {
    a.engine.into()
}

/// The outcome a roll ended on, as the page's die names its outcomes.
fn outcome(r: &RollRecord, labels: &[String]) -> Option<String> {
    match r.fate {
        Fate::Settled(o) | Fate::Unconverged(o) => named(o, r.up, labels),
        Fate::Failed(_) => None,
    }
}

/// When the early stop would have ended the roll (s), and the outcome it named.
fn early_stop(r: &RollRecord, dt: f64, labels: &[String]) -> Option<(f64, String)> {
    let (step, o) = r.certified?;
    Some((step as f64 * dt, named(o, r.certified_face, labels)?))
}

fn named(o: Outcome, face: Option<u8>, labels: &[String]) -> Option<String> {
    match o {
        Outcome::Face => face.and_then(|k| labels.get(usize::from(k)).cloned()),
        Outcome::Unknown => None,
        o => Some(format!("{} vertical", o.name())),
    }
}
