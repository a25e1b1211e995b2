//! `dicephys design` for Python: the die and its scene by `roll`'s names, the feature, its
//! range and the target by the command line's, handed to the library's `studies::design`.

use super::{bad, detached, end_of, named, py_err, scene_of, threads, throws_of, Options};
use dicephys::engine::EngineKind;
use dicephys::model::faces::Layout;
use dicephys::model::throws::ThrowStyle;
use dicephys::run::request::RollRequest;
use dicephys::run::runner::Runner;
use dicephys::studies::bias::Varied;
use dicephys::studies::design::mesh::{self, MeshConfig};
use dicephys::studies::design::named::Named;
use dicephys::studies::design::study::DesignStudy;
use dicephys::studies::design::{self as design_, DesignConfig};
use dicephys::studies::fair::Null;
use dicephys::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// What a fit's calibration sets: refused beside `fit`, as the command line refuses its flags.
const FIT_SETS: [&str; 24] = [
    "engine",
    "mode",
    "dt",
    "friction",
    "restitution",
    "preset",
    "floor",
    "floor_thickness",
    "linear_damping",
    "angular_damping",
    "rolling_resistance",
    "bounce_threshold",
    "contact_time",
    "static_ratio",
    "sleep",
    "source",
    "velocity",
    "spin",
    "drop_height",
    "throw",
    "kappa",
    "max_steps",
    "settle",
    "faithful",
];

/// A target's (label, probability) pairs and the name of the law they came from.
type Target = (Vec<(String, f64)>, Option<Named>);

/// The target `text` asks over the die of `spec`: `LABEL=P,…`, or a named law (`2d6`,
/// `binomial:N`) set over the die's labels.
fn target_of(text: &str, spec: &dicephys::run::spec::RunSpec, layout: Layout) -> PyResult<Target> {
    let shown = format!("'{text}'");
    if let Some(n) = Named::parse(text).map_err(|e| bad("target", &shown, e))? {
        let labels = spec.scene.labels(layout);
        let t = n.over(&labels).map_err(|e| bad("target", &shown, e))?;
        return Ok((t, Some(n)));
    }
    match text.parse::<Null>().map_err(|e| bad("target", &shown, e))? {
        Null::Target(t) => Ok((t, None)),
        _ => Err(bad(
            "target",
            &shown,
            "give each label's probability, 'LABEL=P,…', or a named law, '2d6' or 'binomial:N'",
        )),
    }
}

/// `dicephys design`: the value of one feature of the die (`free`, within `range` (LO, HI)
/// mm) that gives `target` thrown, checked at a fresh seed; the die, scene and throw by
/// `roll`'s names (a tumble unless `throw` says), or a fit's calibration (`fit`: its
/// fit.json's text, `fit_name` its path). Returns `design --json`'s document and the text
/// `design` prints; with `out`, writes what `design --out` writes.
#[pyfunction]
#[pyo3(signature = (block=None, **options))]
pub fn design<'py>(
    py: Python<'py>,
    block: Option<&str>,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<(String, String)> {
    let o = Options {
        given: options.map(|d| d.copy()).transpose()?,
    };
    let out = o.maybe::<PathBuf>("out")?;
    let threads = threads(o.get("threads", 0usize)?)?;
    let progress = o.object("progress")?;
    let cfg = config(block, o)?;
    // The range is `range` here (a fit's are `ranges`).
    cfg.check().map_err(|e| match e {
        Error::Field {
            field: dicephys::error::Field::Range,
            value,
            why,
        } => bad("range", value, why),
        e => py_err(e),
    })?;
    detached(py, progress.as_ref(), None, |session| {
        let _held = match &out {
            Some(dir) => {
                std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
                Some(cfg.claim(dir)?)
            }
            None => None,
        };
        let total = cfg.rolls() as f64;
        let tell = |n: u64| session.set(n as f64, total);
        let runner = Runner::new(threads, session.stop.clone());
        let runner = runner.with_progress(&tell);
        cfg.make(&runner, out.as_deref())?.ok_or(Error::Stopped)
    })
}

/// Refuses `points` beside the facets (they roll rounds) and `rounds` beside a feature (it
/// scans).
fn scans_or_rounds(facets: bool, points: Option<usize>, rounds: Option<usize>) -> PyResult<()> {
    match (facets, points, rounds) {
        (true, Some(_), _) => Err(bad(
            "points",
            "…",
            "a design of the facets rolls rounds (rounds), not scans",
        )),
        (false, _, Some(_)) => Err(bad(
            "rounds",
            "…",
            "only free='facets' rolls rounds; a feature's design scans (points)",
        )),
        _ => Ok(()),
    }
}

/// The design the options ask for (every one read: any other is refused): the die and its
/// scene by `roll`'s names, or in a fit's calibration; the target set over its labels.
fn config(block: Option<&str>, o: Options) -> PyResult<DesignStudy> {
    let free = o
        .maybe::<String>("free")?
        .ok_or_else(|| bad("free", "None", "name the feature to design"))?;
    let facets = free.trim() == mesh::FACETS;
    let what: Option<Varied> = if facets {
        None
    } else {
        Some(named("free", "feature", &free)?)
    };
    let range = o
        .maybe::<(f64, f64)>("range")?
        .ok_or_else(|| bad("range", "None", "give (LO, HI), mm"))?;
    let target = o
        .maybe::<String>("target")?
        .ok_or_else(|| bad("target", "None", "give the probabilities wanted"))?;
    let points = o.maybe::<usize>("points")?;
    let rounds = o.maybe::<usize>("rounds")?;
    scans_or_rounds(facets, points, rounds)?;
    let default_rolls = if facets {
        mesh::DEFAULT_ROLLS
    } else {
        design_::DEFAULT_ROLLS
    };
    let check_rolls = o.get("check_rolls", design_::DEFAULT_CHECK_ROLLS)?;
    let fit = o.maybe::<String>("fit")?;
    let fit_name = o.get("fit_name", "fit".to_string())?;
    let surface = o.maybe::<String>("surface")?;
    let thrower = o.maybe::<String>("thrower")?;
    if let (Some(_), Some(d)) = (&fit, &o.given) {
        for k in FIT_SETS {
            if d.get_item(k)?.is_some_and(|v| !v.is_none()) {
                return Err(bad(
                    k,
                    "…",
                    "the fit's calibration sets it: leave it out beside fit",
                ));
            }
        }
    }
    let layout = o
        .maybe::<String>("layout")?
        .map(|l| named::<Layout>("layout", "layout", &l))
        .transpose()?;
    let request = RollRequest {
        scene: scene_of(block, &o, layout)?,
        throws: throws_of(&o)?,
        end: end_of(&o)?,
        engine: match o.maybe::<String>("engine")? {
            Some(e) => named::<EngineKind>("engine", "engine", &e)?,
            None => RollRequest::default().engine,
        },
        rolls: Some(o.maybe::<u64>("rolls")?.unwrap_or(default_rolls)),
        to_precision: false,
        shard: None,
    };
    o.finish()?;
    let mut spec = request.spec_or(ThrowStyle::Tumble).map_err(py_err)?;
    let layout = spec.scene.features.layout;
    let calibration = match fit {
        Some(text) => {
            let fit = super::fit_of(&text, "fit")?;
            let (s, c) =
                design_::calibrated::calibrated(&fit, &fit_name, &spec, &surface, &thrower)
                    .map_err(|e| bad("fit", &fit_name, super::arguments_in(&e)))?;
            spec = s;
            Some(c)
        }
        None => None,
    };
    let (target, named_target) = target_of(&target, &spec, layout)?;
    Ok(match what {
        Some(what) => DesignStudy::Feature(DesignConfig {
            layout,
            spec,
            what,
            range: [range.0, range.1],
            target,
            points: points.unwrap_or(design_::DEFAULT_POINTS),
            check_rolls,
            named_target,
            calibration,
        }),
        None => DesignStudy::Facets(MeshConfig {
            layout,
            spec,
            range: [range.0, range.1],
            target,
            rounds: rounds.unwrap_or(mesh::DEFAULT_ROUNDS),
            check_rolls,
            named_target,
            calibration,
        }),
    })
}
