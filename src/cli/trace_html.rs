//! `dicephys trace --html FILE`: the throws `--index` names, each rolled as `trace` rolls it
//! (with the early stop audited: when it would have fired, without stopping), written as one
//! page that plays them (`report::trace::page`). Each throw's ending line goes to stderr as
//! `trace`'s.

use super::args::FlightArg;
use super::error::{Error, Result};
use super::trace::TraceArgs;

pub fn run(a: &TraceArgs) -> Result<()> {
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
