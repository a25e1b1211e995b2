//! `dicephys trace`: one throw's trajectory as CSV, for looking at a single roll; or, with
//! `--html`, a page that plays one or several throws in 3D (`report::view`).

use super::args::MaxSteps;
use super::args::{parse_engine, FlightArg, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::trace;
use dicephys::sim::roll::RollConfig;
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

fn parse_indices(s: &str) -> std::result::Result<Indices, String> {
    let (first, last) = trace::indices(s)?;
    Ok(Indices { first, last })
}

pub fn run(a: &TraceArgs) -> Result<()> {
    if a.html.is_some() {
        return html(a);
    }
    if a.index.first != a.index.last {
        return Err(Error::Usage(format!(
            "--index {}..{}: the CSV is one throw's; several are for --html",
            a.index.first, a.index.last
        )));
    }
    let scene = a.scene.scene()?;
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
    let out = std::io::stdout();
    // Both the rows and a stop request write to it (a stop flushes the rows so far).
    let out = std::cell::RefCell::new(std::io::BufWriter::new(out.lock()));
    writeln!(out.borrow_mut(), "{}", trace::HEADER)?;
    // The first failed write is kept and returned after the roll (a roll cannot be stopped
    // from its observer); later lines are not attempted.
    let mut failed: Option<std::io::Error> = None;
    let settle = settle(a, &scene);
    let record = trace::rows(
        a.engine,
        &scene,
        &throw,
        &settle,
        a.every,
        |l| {
            if failed.is_none() {
                failed = writeln!(out.borrow_mut(), "{l}").err();
            }
        },
        |step| {
            // A roll cannot be stopped from its observer: a stop request ends the process here,
            // the rows so far written, as every command stops (exit 130).
            if step.is_multiple_of(1024) && super::term::stop().requested() {
                let _ = out.borrow_mut().flush();
                let kept = dicephys::run::stop::Kept::Steps(step);
                eprintln!("dicephys: {}", dicephys::run::stop::interrupted(&kept));
                std::process::exit(130);
            }
        },
    )?;
    if let Some(e) = failed {
        return Err(e.into());
    }
    out.borrow_mut().flush()?;
    let labels = scene.shape.as_ref().map(|s| s.labels()).unwrap_or_default();
    eprintln!("{}", trace::ending(index, &throw, &record, &labels));
    if let Some(note) = trace::capped(&record, settle.max_steps, a.max_steps.asked().is_some()) {
        eprintln!("dicephys: {note}");
    }
    Ok(())
}

/// How a traced roll ends (`report::trace::config`): at `roll`'s step cap for the same die
/// unless one is asked, its flight as asked, the early stop taken.
fn settle(a: &TraceArgs, scene: &dicephys::model::scene::Scene) -> RollConfig {
    trace::config(
        scene,
        a.max_steps.asked(),
        a.flight == FlightArg::Fast,
        false,
    )
}

/// `--html FILE`: the throws `--index` names, each rolled as the CSV's throw is (with the
/// early stop audited: when it would have fired, without stopping), written as one page that
/// plays them (`report::trace::page`). Each throw's ending line goes to stderr as the CSV's.
fn html(a: &TraceArgs) -> Result<()> {
    let path = a.html.as_ref().expect("called with --html");
    if *a.max_steps == 0 {
        return Err(Error::Usage("--max-steps must be at least 1".into()));
    }
    // Checked before any roll: a page that cannot be written is refused at once.
    let out = dicephys::run::io::Output::check(path)?;
    let scene = a.scene.scene()?;
    let throw_spec = a
        .throw
        .spec_or(dicephys::model::throws::ThrowStyle::default_for(&scene))?;
    let page = dicephys::report::trace::page(
        a.engine,
        &scene,
        &throw_spec.source(a.index.last + 1),
        a.index.first..=a.index.last,
        dicephys::report::trace::Stepping {
            max_steps: a.max_steps.asked(),
            fast_flight: a.flight == FlightArg::Fast,
        },
        |ending, note| {
            eprintln!("{ending}");
            if let Some(note) = note {
                eprintln!("dicephys: {note}");
            }
        },
        |step| {
            if step.is_multiple_of(1024) && super::term::stop().requested() {
                eprintln!(
                    "dicephys: {}",
                    dicephys::run::stop::interrupted(&dicephys::run::stop::Kept::Nothing(None))
                );
                std::process::exit(130);
            }
        },
    )?;
    out.write(page.as_bytes())?;
    Ok(())
}
