//! `dicephys trace`: one throw's trajectory as CSV, for looking at a single roll; or, with
//! `--html`, a page that plays one or several throws in 3D (`report::view`).

use super::args::MaxSteps;
use super::args::{parse_engine, FlightArg, SceneArgs, ThrowArgs};
use super::error::Result;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::report::trace;
use dicephys::studies::trace::TraceStudy;
use dicephys::studies::StudyConfig;

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

/// Runs `dicephys trace`, as every study runs: the CSV's rows on stdout as they are made (or
/// the page written), each throw's ending line on stderr.
pub fn run(a: &TraceArgs) -> Result<()> {
    let scene = a.scene.scene()?;
    let throws = a
        .throw
        .spec_or(dicephys::model::throws::ThrowStyle::default_for(&scene))?;
    let study = TraceStudy {
        engine: a.engine,
        scene,
        throws,
        first: a.index.first,
        last: a.index.last,
        every: a.every,
        max_steps: a.max_steps.asked(),
        fast_flight: a.flight == FlightArg::Fast,
        html: a.html.clone(),
    };
    let place = super::study::here(None, None, 1, false)?;
    super::study::run(&StudyConfig::Trace(study), &place)
}
