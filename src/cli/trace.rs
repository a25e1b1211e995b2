//! `dicephys trace`: one throw's trajectory as CSV, for looking at a single roll; or, with
//! `--html`, a page that plays one or several throws in 3D (`report::view`).

use super::args::MaxSteps;
use super::args::{parse_engine, FlightArg, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use clap::Args;
use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::die::DieShape;
use dicephys::model::state::BodyState;
use dicephys::report::trace;
use dicephys::run::request::EndRequest;
use dicephys::sim::roll::{roll_observed, Fate, RollConfig};
use std::io::Write;

/// `dicephys trace`'s arguments.
#[derive(Args, Debug)]
pub struct TraceArgs {
    /// Physics engine: bullet, rapier (in 2D a true 2D body), rapier-locked (in 2D a locked 3D
    /// body, as DicePhys).
    #[arg(long, default_value = "bullet", value_parser = parse_engine)]
    pub engine: EngineKind,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub throw: ThrowArgs,
    /// Which throw; with --html, also several: A..B, throws A to B, both included (as the
    /// shell's {A..B}), at most 16.
    #[arg(long, default_value = "0", value_parser = parse_indices)]
    pub index: Indices,
    /// Write a page that plays the throw(s) in 3D (self-contained HTML: opens with no
    /// network) instead of printing the CSV.
    #[arg(long, value_name = "FILE")]
    pub html: Option<std::path::PathBuf>,
    /// Print every Nth step (the first and the last are always printed). The CSV's: a page
    /// (--html) keeps its own frames.
    #[arg(long, default_value_t = 1, conflicts_with = "html")]
    pub every: u64,
    /// The step cap.
    #[command(flatten)]
    pub max_steps: MaxSteps,
    /// Free flight: fast (integrated in closed form where the engine's flight is ballistic, as
    /// `roll` does, so that the trace is the roll's; the flown steps are printed too) or
    /// stepped (every step by the engine).
    #[arg(long, value_enum, default_value = "fast")]
    pub flight: FlightArg,
}

/// The throws `--index` names: `first..=last`.
#[derive(Clone, Copy, Debug)]
pub struct Indices {
    pub first: u64,
    pub last: u64,
}

/// The most throws one page plays.
const MAX_ON_A_PAGE: u64 = 16;

fn parse_indices(s: &str) -> std::result::Result<Indices, String> {
    let n = |p: &str| {
        p.trim()
            .parse::<u64>()
            .map_err(|_| format!("'{}' is not a throw's index (0, 1, …)", p.trim()))
    };
    let (first, last) = match s.split_once("..") {
        Some((a, b)) => (n(a)?, n(b.strip_prefix('=').unwrap_or(b))?),
        None => (n(s)?, n(s)?),
    };
    if last < first {
        return Err(format!("{s}: the range runs backwards"));
    }
    if last - first >= MAX_ON_A_PAGE {
        return Err(format!(
            "{s}: {} throws; a page plays at most {MAX_ON_A_PAGE}",
            (last - first).saturating_add(1)
        ));
    }
    last.checked_add(1)
        .ok_or_else(|| format!("{s}: too large"))?;
    Ok(Indices { first, last })
}

pub fn run(a: &TraceArgs) -> Result<()> {
    if a.html.is_some() {
        return super::trace_html::run(a);
    }
    if a.index.first != a.index.last {
        return Err(Error::Usage(format!(
            "--index {}..{}: the CSV is one throw's; several are for --html",
            a.index.first, a.index.last
        )));
    }
    let scene = a.scene.scene()?;
    let die = DieShape::of(&scene);
    let throw_spec = a
        .throw
        .spec_or(dicephys::model::throws::ThrowStyle::default_for(&scene))?;
    if a.every == 0 || *a.max_steps == 0 {
        return Err(Error::Usage(
            "--every and --max-steps must be at least 1".into(),
        ));
    }
    let index = a.index.first;
    let throws = throw_spec.source(index + 1);
    let throw = throws.get(index);
    let mut engine = new_engine(a.engine, &scene)?;
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    writeln!(out, "{}", trace::HEADER)?;
    // The first failed write is kept and returned after the roll (a roll cannot be stopped
    // from its observer); later lines are not attempted.
    let mut failed: Option<std::io::Error> = None;
    let mut last = None;
    let mut end_state = None;
    let line = |step: u64, s: &BodyState| trace::row(&die, scene.dt, step, s);
    // The step cap `roll` takes for the same die: a die of any shape's unless asked (a coin
    // on its edge on a floor without rolling resistance rolls for ever, and traced to
    // DicePhys's 20,000,000 steps it wrote gigabytes; issue 69.10).
    let settle = settle(a, &scene);
    let record = roll_observed(engine.as_mut(), &scene, &throw, &settle, |step, s| {
        // A roll cannot be stopped from its observer: a stop request ends the process here,
        // the rows so far written, as every command stops (exit 130).
        if step.is_multiple_of(1024) && super::term::stop().requested() {
            let _ = out.flush();
            let kept = dicephys::run::stop::Kept::Steps(step);
            eprintln!("dicephys: {}", dicephys::run::stop::interrupted(&kept));
            std::process::exit(130);
        }
        end_state = Some(*s);
        let l = line(step, s);
        if step % a.every == 0 {
            if failed.is_none() {
                failed = writeln!(out, "{l}").err();
            }
            last = None;
        } else {
            last = Some(l);
        }
    });
    if let Some(e) = failed {
        return Err(e.into());
    }
    if let Some(l) = last {
        writeln!(out, "{l}")?;
    }
    out.flush()?;
    let labels = scene.shape.as_ref().map(|s| s.labels()).unwrap_or_default();
    // A die still moving at the cap: the face it was on then, for the ending's line (a
    // record keeps a face only for a settled roll).
    let mut ended = record;
    if let (Fate::Unconverged(_), Some(s)) = (record.fate, end_state) {
        ended.up = die.outcome(&s).1;
    }
    eprintln!("{}", trace::ending(index, &throw, &ended, &labels));
    if let Some(note) = trace::capped(&record, settle.max_steps, a.max_steps.asked().is_some()) {
        eprintln!("dicephys: {note}");
    }
    Ok(())
}

/// How a traced roll ends: at `roll`'s step cap for the same die unless one is asked (a coin
/// on its edge on a floor without rolling resistance rolls for ever, and traced to DicePhys's
/// 20,000,000 steps it wrote gigabytes; issue 69.10), its flight as asked. The HTML page's
/// trace too (`trace_html`).
pub fn settle(a: &TraceArgs, scene: &dicephys::model::scene::Scene) -> RollConfig {
    RollConfig {
        max_steps: EndRequest {
            max_steps: a.max_steps.asked(),
            ..EndRequest::default()
        }
        .cap(scene),
        fast_flight: a.flight == FlightArg::Fast,
        ..RollConfig::default()
    }
}
