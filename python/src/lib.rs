//! `dicephys._native`: the library's runs, fits and studies for Python (PyO3).
//!
//! Each function takes Python's values, builds the library's own types (the scene, the
//! throws, the roll, a fit's configuration) and hands them to the same library function the
//! command line calls, so the same seed gives the same counts. What comes back is the JSON
//! document the command line prints with `--json` (and, for a roll, its per-roll CSV bytes),
//! which the package around this module (`python/dicephys/`) turns into objects and arrays.
//!
//! Every run works on its own thread with Python's lock released; the calling thread wakes
//! ten times a second to pass progress and log lines to Python and to let Python handle
//! signals: Ctrl-C asks the run to stop at its next roll, and the call raises
//! `KeyboardInterrupt` once the run has ended, with nothing half-written.

use dicephys::calibration::{self, FitConfig};
use dicephys::engine::EngineKind;
use dicephys::error::parse_name;
use dicephys::error::Field;
use dicephys::model::block::Block;
use dicephys::model::faces::Layout;
use dicephys::model::scene::Mode;
use dicephys::model::throws::DEFAULT_SEED;
use dicephys::model::throws::{Range, ThrowRanges, ThrowStyle};
use dicephys::report::per_roll::PerRoll;
use dicephys::report::precision::Target;
use dicephys::run::request::{DieRequest, EndRequest, RollRequest, SceneRequest, ThrowRequest};
use dicephys::run::runner::{ChunkShare, Runner};
use dicephys::run::spec::RunSpec;
use dicephys::run::stop::Stop;
use dicephys::sim::roll::{RollRecord, Rule, DEFAULT_MARGIN, DEFAULT_MAX_STEPS};
use dicephys::studies::place::{Done, Hooks, Place};
use dicephys::studies::roll::RollStudy;
use dicephys::studies::StudyConfig;
use dicephys::Error;
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::path::PathBuf;
use std::sync::{Condvar, Mutex};
use std::time::Duration;

mod design;

/// The Python argument that sets a field of the library's configurations: most are the
/// field's own name (a die's `pips.depth` is `pips`); these are spelt otherwise.
fn argument(field: Field) -> &'static str {
    match field {
        Field::Style => "throw",
        Field::Kind => "source",
        Field::Range => "ranges",
        f => f.name().split('.').next().unwrap_or_default(),
    }
}

/// The library's error with each field it names named by its argument.
fn arguments_in(e: &Error) -> String {
    e.named(&|f| argument(f).to_string())
}

/// The library's error as Python's: bad input a `ValueError` naming the argument, a stop
/// `KeyboardInterrupt`, a file `OSError`, anything else `RuntimeError`.
fn py_err(e: Error) -> PyErr {
    match &e {
        Error::Stopped => PyKeyboardInterrupt::new_err("stopped before the end"),
        Error::Field { field, value, why } => {
            let why = why.named(&|f| argument(f).to_string());
            PyValueError::new_err(if value.is_empty() {
                format!("{}: {why}", argument(*field))
            } else {
                format!("{}={value}: {why}", argument(*field))
            })
        }
        Error::Io { .. } => PyOSError::new_err(e.to_string()),
        e if e.is_input() => PyValueError::new_err(arguments_in(e)),
        e => PyRuntimeError::new_err(arguments_in(e)),
    }
}

/// A bad value of the argument `arg`.
fn bad(arg: &str, value: impl std::fmt::Display, why: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{arg}={value}: {why}"))
}

/// A name the library knows (`engine`, `preset`, …), read for the argument `arg`.
fn named<T>(arg: &str, what: &str, s: &str) -> PyResult<T>
where
    T: std::str::FromStr + strum::VariantNames,
{
    parse_name(what, s).map_err(|e| bad(arg, format!("'{s}'"), e))
}

fn block(s: &str) -> PyResult<Block> {
    s.parse::<Block>()
        .map_err(|e| bad("block", format!("'{s}'"), e))
}

fn mode(s: &str) -> PyResult<Mode> {
    match s.to_ascii_lowercase().as_str() {
        "3d" => Ok(Mode::ThreeD),
        "2d" => Ok(Mode::TwoD),
        _ => Err(bad("mode", format!("'{s}'"), "give '3d' or '2d'")),
    }
}

fn threads(asked: usize) -> PyResult<usize> {
    dicephys::run::batch::checked_threads(asked).map_err(py_err)
}

/// A range of the throw: one number, or (low, high).
fn range(arg: &str, given: Option<&Bound<'_, PyAny>>, default: Range) -> PyResult<Range> {
    let Some(v) = given else { return Ok(default) };
    if let Ok(x) = v.extract::<f64>() {
        return Ok(Range { lo: x, hi: x });
    }
    let (lo, hi) = v
        .extract::<(f64, f64)>()
        .map_err(|_| bad(arg, v, "give a number or (low, high)"))?;
    Ok(Range { lo, hi })
}

/// A run as Python sees it: the stop it can request, and what it has to say while it goes.
struct Session {
    stop: Stop,
    /// Done and in all, in the run's unit.
    progress: Mutex<(f64, f64)>,
    /// Log lines not yet passed on.
    log: Mutex<Vec<String>>,
    /// The run has ended.
    over: (Mutex<bool>, Condvar),
}

impl Session {
    fn set(&self, done: f64, total: f64) {
        *self.progress.lock().unwrap() = (done, total);
    }

    fn say(&self, line: &str) {
        self.log.lock().unwrap().push(line.to_string());
    }

    /// Runs `f` with the hooks a study reports to.
    fn hooked<T>(&self, f: impl FnOnce(&Hooks) -> T) -> T {
        let log = |l: &str| self.say(l);
        let progress = |d, t| self.set(d, t);
        f(&Hooks {
            log: &log,
            print: &log,
            progress: &progress,
            stop: self.stop.clone(),
        })
    }

    /// Passes progress and log lines to Python's callbacks.
    fn report(
        &self,
        py: Python<'_>,
        progress: Option<&Bound<'_, PyAny>>,
        log: Option<&Bound<'_, PyAny>>,
        last: &mut (f64, f64),
    ) -> PyResult<()> {
        let now = *self.progress.lock().unwrap();
        if let Some(cb) = progress {
            if now != *last && now.1 > 0.0 {
                cb.call1((now.0, now.1))?;
                *last = now;
            }
        }
        let lines = std::mem::take(&mut *self.log.lock().unwrap());
        if let Some(cb) = log {
            for l in lines {
                cb.call1((l,))?;
            }
        }
        let _ = py;
        Ok(())
    }
}

/// Runs `work` on its own thread with Python's lock released, passing its progress and log
/// to the callbacks, and stopping it when Python has a signal to raise (Ctrl-C) or a callback
/// raises: that exception is raised once the run has ended.
fn detached<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    log: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Session) -> dicephys::Result<T> + Send,
) -> PyResult<T> {
    let session = Session {
        stop: Stop::new(),
        progress: Mutex::new((0.0, 0.0)),
        log: Mutex::new(Vec::new()),
        over: (Mutex::new(false), Condvar::new()),
    };
    let mut raised: Option<PyErr> = None;
    let mut last = (-1.0, -1.0);
    let result = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let r = work(&session);
            *session.over.0.lock().unwrap() = true;
            session.over.1.notify_all();
            r
        });
        loop {
            let over = py.detach(|| {
                let (lock, cv) = &session.over;
                let g = lock.lock().unwrap();
                let (g, _) = cv
                    .wait_timeout_while(g, Duration::from_millis(100), |o| !*o)
                    .unwrap();
                *g
            });
            let said = py
                .check_signals()
                .and_then(|()| session.report(py, progress, log, &mut last));
            if let (Err(e), None) = (said, &raised) {
                session.stop.request();
                raised = Some(e);
            }
            if over {
                break;
            }
        }
        worker.join()
    });
    if let Some(e) = raised {
        return Err(e);
    }
    match result {
        Ok(r) => r.map_err(py_err),
        Err(_) => Err(PyRuntimeError::new_err(
            "the run failed inside (a panic); nothing was returned",
        )),
    }
}

/// A call's keyword options, read by name: each taken once, with the library's default where
/// it is left out; a name no option has is refused, as Python would.
struct Options<'py> {
    given: Option<Bound<'py, PyDict>>,
}

impl<'py> Options<'py> {
    /// The option `name`, or `default`.
    fn get<T: FromPyObjectOwned<'py>>(&self, name: &str, default: T) -> PyResult<T> {
        Ok(self.maybe(name)?.unwrap_or(default))
    }

    /// The option `name` if given and not None.
    fn maybe<T: FromPyObjectOwned<'py>>(&self, name: &str) -> PyResult<Option<T>> {
        let Some(d) = &self.given else {
            return Ok(None);
        };
        let Some(v) = d.get_item(name)? else {
            return Ok(None);
        };
        d.del_item(name)?;
        if v.is_none() {
            return Ok(None);
        }
        v.extract::<T>().map(Some).map_err(|_| {
            bad(
                name,
                v.repr().map_or("?".into(), |r| r.to_string()),
                "not a value of its type",
            )
        })
    }

    /// The option `name` as Python gave it.
    fn object(&self, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        let Some(d) = &self.given else {
            return Ok(None);
        };
        let v = d.get_item(name)?;
        if v.is_some() {
            d.del_item(name)?;
        }
        Ok(v.filter(|v| !v.is_none()))
    }

    /// Refuses whatever option was not read.
    fn finish(self) -> PyResult<()> {
        match self.given.and_then(|d| d.keys().iter().next()) {
            Some(k) => Err(PyTypeError::new_err(format!(
                "roll() got an unexpected keyword argument '{k}'"
            ))),
            None => Ok(()),
        }
    }
}

/// The scene, the throws and the roll of `roll` and `fair` from their options (`dicephys
/// roll`'s, by the library's names and units: mm for the die as made): the library's request,
/// whose defaults and checks are the library's.
fn spec(
    block_: Option<&str>,
    o: &Options,
    layout: Option<Layout>,
    precision: bool,
) -> PyResult<RunSpec> {
    let request = RollRequest {
        scene: scene_of(block_, o, layout)?,
        throws: throws_of(o)?,
        end: end_of(o)?,
        engine: match o.maybe::<String>("engine")? {
            Some(e) => named::<EngineKind>("engine", "engine", &e)?,
            None => RollRequest::default().engine,
        },
        rolls: o.maybe("rolls")?,
        to_precision: precision,
        shard: None,
    };
    request.spec().map_err(py_err)
}

/// The option `name` read by the library's names (`named`), or `default`.
fn named_or<T>(o: &Options, name: &str, what: &str, default: T) -> PyResult<T>
where
    T: std::str::FromStr + strum::VariantNames,
{
    match o.maybe::<String>(name)? {
        Some(s) => named::<T>(name, what, &s),
        None => Ok(default),
    }
}

/// The die asked by `roll`'s names (shape, size, scale, die: a file or a mesh, density, com,
/// pips, edge_radius, shell), with its `block` and the faces' `layout`.
fn die_of(o: &Options, block: Option<Block>, layout: Option<Layout>) -> PyResult<DieRequest> {
    Ok(DieRequest {
        block,
        shape: o.maybe("shape")?,
        size: o.maybe("size")?,
        scale: o.maybe("scale")?,
        file: o.maybe("die")?,
        density: o.maybe("density")?,
        com: o.maybe("com")?,
        pips: o.maybe("pips")?,
        edge_radius: o.maybe("edge_radius")?,
        shell: o.maybe("shell")?,
        layout,
    })
}

/// The scene asked by `roll`'s options: the die (a block, a shape, a mesh or a die file) as
/// made, on its floor.
fn scene_of(block_: Option<&str>, o: &Options, layout: Option<Layout>) -> PyResult<SceneRequest> {
    let d = SceneRequest::default();
    Ok(SceneRequest {
        die: die_of(o, block_.map(block).transpose()?, layout)?,
        two_d: match o.maybe::<String>("mode")? {
            Some(m) => mode(&m)? == Mode::TwoD,
            None => d.two_d,
        },
        dt: o.get("dt", d.dt)?,
        friction: o.get("friction", d.friction)?,
        restitution: o.get("restitution", d.restitution)?,
        allow_restitution_above_one: d.allow_restitution_above_one,
        preset: named_or(o, "preset", "preset", d.preset)?,
        floor: named_or(o, "floor", "floor", d.floor)?,
        floor_thickness: o.maybe("floor_thickness")?,
        linear_damping: o.get("linear_damping", d.linear_damping)?,
        angular_damping: o.get("angular_damping", d.angular_damping)?,
        rolling_resistance_mm: o.maybe("rolling_resistance")?,
        bounce_threshold: o.get("bounce_threshold", d.bounce_threshold)?,
        contact_time_ms: o.get("contact_time", d.contact_time_ms)?,
        static_ratio: o.get("static_ratio", d.static_ratio)?,
        sleep: o.get("sleep", d.sleep)?,
    })
}

/// The throws asked by `roll`'s options: their source, seed, ranges and style.
fn throws_of(o: &Options) -> PyResult<ThrowRequest> {
    let d = ThrowRequest::default();
    Ok(ThrowRequest {
        source: named_or(o, "source", "throw source", d.source)?,
        seed: o.get("seed", d.seed)?,
        ranges: ThrowRanges {
            velocity: range(
                "velocity",
                o.object("velocity")?.as_ref(),
                d.ranges.velocity,
            )?,
            spin: range("spin", o.object("spin")?.as_ref(), d.ranges.spin)?,
            drop_height: range(
                "drop_height",
                o.object("drop_height")?.as_ref(),
                d.ranges.drop_height,
            )?,
        },
        style: o
            .maybe::<String>("throw")?
            .map(|t| named::<ThrowStyle>("throw", "throw style", &t))
            .transpose()?,
        kappa: o.maybe("kappa")?,
    })
}

/// How a roll ends, asked by `roll`'s options: the rest rule, the flight, the step cap.
fn end_of(o: &Options) -> PyResult<EndRequest> {
    let d = EndRequest::default();
    let settle =
        match o.maybe::<String>("settle")?.as_deref() {
            None => d.settle,
            Some("certificate") => Some(Rule::Certificate),
            Some("dicephys") => Some(Rule::Dicephys),
            Some(s) => return Err(bad(
                "settle",
                format!("'{s}'"),
                "give 'certificate' (the exact early stop) or 'dicephys' (DicePhys's rest rule)",
            )),
        };
    let fast_flight = match o.maybe::<String>("flight")?.as_deref() {
        None => d.fast_flight,
        Some("fast") => true,
        Some("stepped") => false,
        Some(s) => return Err(bad("flight", format!("'{s}'"), "give 'fast' or 'stepped'")),
    };
    Ok(EndRequest {
        settle,
        fast_flight,
        faithful: o.get("faithful", d.faithful)?,
        audit: d.audit,
        max_steps: o.maybe("max_steps")?,
        margin: o.get("margin", d.margin)?,
    })
}

/// Rolls `spec` as `dicephys roll` does: its summary's JSON document (numbered by `layout`)
/// and, if asked, the per-roll CSV's bytes.
fn rolled(
    py: Python<'_>,
    study: &RollStudy,
    layout: Layout,
    threads_: usize,
    per_roll: bool,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<(dicephys::report::summary::RunSummary, Option<Vec<u8>>)> {
    let threads = threads(threads_)?;
    let spec = &study.spec;
    if let Some((p, target)) = study.precision.map(|p| (p, study.target())) {
        if !(p > 0.0 && p < 1.0) {
            // fair's target is every face's probability, given as `within`.
            return Err(match target {
                Target::Faces => bad(
                    "within",
                    p,
                    "a probability in (0, 1): 0.005 is each face to ±0.005 at 2σ",
                ),
                _ => bad(
                    "precision",
                    p,
                    "a fraction in (0, 1): 0.02 is a relative 2σ of 2 %",
                ),
            });
        }
    }
    detached(py, progress, None, |session| {
        let expected = std::sync::atomic::AtomicU64::new(spec.indices().len());
        let tell = |n: u64| {
            let all = expected.load(std::sync::atomic::Ordering::Relaxed);
            session.set(n as f64, all as f64)
        };
        let expect = |n: u64| expected.store(n, std::sync::atomic::Ordering::Relaxed);
        let runner = Runner::new(threads, session.stop.clone());
        let runner = runner.with_progress(&tell);
        let mut csv = match per_roll {
            true => Some(PerRoll::new(Vec::new(), spec.scene.dt, layout)?),
            false => None,
        };
        let mut sink = |recs: &[RollRecord]| match csv.as_mut() {
            Some(c) => c.write(recs),
            None => Ok(()),
        };
        let summary = study.roll(&runner, None, &mut sink, &expect)?;
        if summary.partial {
            return Err(Error::Stopped);
        }
        let bytes = csv.map(PerRoll::finish).transpose()?;
        Ok((summary.with_layout(layout), bytes))
    })
}

/// `dicephys roll`: many throws of one block on one engine, with `roll`'s options by the
/// library's names (the package's `roll` lists them). Returns the `roll --json` document, the
/// text `roll` prints and, with `per_roll`, the `--per-roll` CSV's bytes; with `fair` (a
/// null), `fair --json`'s document and `fair`'s text.
#[pyfunction]
#[pyo3(signature = (block=None, **options))]
fn roll<'py>(
    py: Python<'py>,
    block: Option<&str>,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<(String, String, Option<Bound<'py, PyBytes>>)> {
    // The caller's dict is its own: read a copy.
    let o = Options {
        given: options.map(|d| d.copy()).transpose()?,
    };
    let layout = o
        .maybe::<String>("layout")?
        .map(|l| named::<Layout>("layout", "layout", &l))
        .transpose()?;
    let null_given = o.maybe::<String>("fair")?;
    let counts = o.object("counts")?;
    let vary = o.maybe::<String>("vary")?;
    let null = null_given
        .as_deref()
        .map(|n| {
            n.parse::<dicephys::studies::fair::Null>()
                .map_err(|e| bad("null", format!("'{n}'"), e))
        })
        .transpose()?;
    let precision = o.maybe::<f64>("precision")?;
    let threads = o.get("threads", 0usize)?;
    let per_roll = o.get("per_roll", false)?;
    let progress = o.object("progress")?;
    let spec = spec(block, &o, layout, precision.is_some())?;
    // The numbers: the layout given, else the die's own (a die file's map), else right.
    let layout = layout.unwrap_or(spec.scene.features.layout);
    o.finish()?;
    let null_or_uniform = null.clone().unwrap_or_default();
    if let Some(c) = counts {
        let counts = counts_given(&c, &spec)?;
        let fair =
            dicephys::studies::fair::assess_counts(&counts, &null_or_uniform, &spec.scene, layout)
                .map_err(py_err)?;
        let json = dicephys::run::seal::to_string(&serde_json::json!({ "fairness": fair }), true)
            .map_err(py_err)?;
        return Ok((
            json,
            format!("Is this die fair? {}", fair.counted_text()),
            None,
        ));
    }
    if null == Some(dicephys::studies::fair::Null::QuasiStatic) && spec.scene.mode == Mode::TwoD {
        return Err(bad(
            "null",
            format!("'{}'", null_given.as_deref().unwrap_or_default()),
            "the quasi-static theory is 3D; in 2D give 'uniform'",
        ));
    }
    if let Some(v) = vary {
        let (json, text) = varied(py, &spec, &v, &null_or_uniform, threads, progress)?;
        return Ok((json, text, None));
    }
    let study = RollStudy {
        spec,
        fair: null,
        precision,
        per_roll: None,
        resumed: false,
    };
    let (summary, csv) = rolled(py, &study, layout, threads, per_roll, progress.as_ref())?;
    // The document and the text the command line prints for it (`summary()` in Python).
    let (json, text) = study.render(&summary).map_err(py_err)?;
    Ok((json, text, csv.map(|b| PyBytes::new(py, &b))))
}

/// `fair`'s measured counts as Python gives them: the command line's text (`1=170,2=160,…`),
/// (label, count) pairs (a mapping's items), or counts in the faces' order (a numbered die's
/// 1 … N, other labels in the die's own order: a coin's heads, tails, edge); checked by the
/// library.
fn counts_given(c: &Bound<'_, PyAny>, spec: &RunSpec) -> PyResult<Vec<(String, u64)>> {
    use dicephys::studies::fair::{check_counts, parse_counts};
    let shown = c.repr().map_or("?".into(), |r| r.to_string());
    let pairs = if let Ok(text) = c.extract::<String>() {
        return parse_counts(&text).map_err(py_err);
    } else if let Ok(pairs) = c.extract::<Vec<(String, u64)>>() {
        pairs
    } else if let Ok(counts) = c.extract::<Vec<u64>>() {
        let labels: Vec<String> = match spec.scene.die.as_shape() {
            Some(shape) => {
                // Numbers in their order (a d6's 1 … 6, whatever its facets' order), other
                // labels in the die's (a coin's heads, tails, edge).
                let mut l = shape.outcome_labels();
                l.sort_by_key(|x| x.parse::<u32>().unwrap_or(u32::MAX));
                l
            }
            None => (1..=counts.len()).map(|k| k.to_string()).collect(),
        };
        if labels.len() != counts.len() {
            return Err(bad(
                "counts",
                &shown,
                format!(
                    "{} counts; the die has {} faces ({}): give one a face, in its order, or a \
                     mapping label → count",
                    counts.len(),
                    labels.len(),
                    labels.join(", ")
                ),
            ));
        }
        labels.into_iter().zip(counts).collect()
    } else {
        return Err(bad(
            "counts",
            &shown,
            "give whole numbers of throws, 0 or more: a mapping label → count ({'1': 170, \
             '2': 160, …}), counts in the faces' order, or the command line's text \
             '1=170,2=160,…'",
        ));
    };
    check_counts(pairs, &shown).map_err(py_err)
}

/// `fair --vary`: the die of `spec` at each value `vary` names (`NAME=LO:HI:N`), each judged
/// against `null` (`studies::bias::BiasStudy`): `fair --vary --json`'s document and its table.
fn varied(
    py: Python<'_>,
    spec: &RunSpec,
    vary: &str,
    null: &dicephys::studies::fair::Null,
    threads_: usize,
    progress: Option<Bound<'_, PyAny>>,
) -> PyResult<(String, String)> {
    use dicephys::studies::kind::Kind;
    let study = dicephys::studies::bias::BiasStudy {
        spec: spec.clone(),
        null: null.clone(),
        vary: vary.to_string(),
    };
    study.validate().map_err(py_err)?;
    let threads = threads(threads_)?;
    let points = detached(py, progress.as_ref(), None, |session| {
        let total = study.rolls()? as f64;
        let tell = |n: u64| session.set(n as f64, total);
        let runner = Runner::new(threads, session.stop.clone());
        let runner = runner.with_progress(&tell);
        study.points(&runner)?.ok_or(Error::Stopped)
    })?;
    study.render(&points).map_err(py_err)
}

/// One throw traced: its index, `trace`'s CSV (header and rows), its ending line and the
/// cap's note where the cap ended it.
type Traced = (u64, String, String, Option<String>);

/// `dicephys trace`: throws `index` (`I` or `A..B`, as `--index`) of the scene and throws
/// `roll`'s options describe (and `engine`, `max_steps`, `flight`), each as `trace` prints it
/// (every `every`th row), and the page `trace --html` writes for them, also written to `html`
/// if given.
#[pyfunction]
#[pyo3(signature = (block=None, **options))]
fn trace<'py>(
    py: Python<'py>,
    block: Option<&str>,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<(Vec<Traced>, String)> {
    use dicephys::report::trace;
    let o = Options {
        given: options.map(|d| d.copy()).transpose()?,
    };
    let index = o.get("index", "0".to_string())?;
    let (first, last) = trace::indices(&index).map_err(|e| bad("index", &index, e))?;
    let every = o.get("every", 1u64)?;
    if every == 0 {
        return Err(bad("every", every, "at least 1"));
    }
    let max_steps = o.maybe::<u64>("max_steps")?;
    if max_steps == Some(0) {
        return Err(bad("max_steps", 0, "at least 1"));
    }
    let fast_flight = match o.maybe::<String>("flight")?.as_deref() {
        None | Some("fast") => true,
        Some("stepped") => false,
        Some(s) => return Err(bad("flight", format!("'{s}'"), "give 'fast' or 'stepped'")),
    };
    let engine = match o.maybe::<String>("engine")? {
        Some(e) => named::<EngineKind>("engine", "engine", &e)?,
        None => EngineKind::Bullet,
    };
    let html = o.maybe::<PathBuf>("html")?;
    let scene = scene_of(block, &o, None)?.scene().map_err(py_err)?;
    let throws = throws_of(&o)?
        .spec_or(ThrowStyle::default_for(&scene))
        .map_err(py_err)?;
    o.finish()?;
    // Checked before any roll: a page that cannot be written is refused at once.
    let out = html
        .map(|p| dicephys::run::io::Output::check(&p))
        .transpose()
        .map_err(py_err)?;
    // Each throw's CSV is the study of that one throw; the page plays them all.
    let study = |first, last| dicephys::studies::trace::TraceStudy {
        engine,
        scene: scene.clone(),
        throws,
        first,
        last,
        every,
        max_steps,
        fast_flight,
        html: None,
    };
    let (traced, page) = detached(py, None, None, |session| {
        let abandon = || session.stop.requested();
        let mut traced = Vec::new();
        for index in first..=last {
            let mut csv = String::new();
            let line = |l: &str| {
                csv.push_str(l);
                csv.push('\n');
            };
            let (ending, note) = study(index, index)
                .csv(line, &abandon)?
                .map_err(|_| Error::Stopped)?;
            traced.push((index, csv, ending, note));
        }
        let page = study(first, last)
            .page(|_, _| {}, &abandon)?
            .ok_or(Error::Stopped)?;
        Ok((traced, page))
    })?;
    if let Some(out) = out {
        out.write(page.as_bytes()).map_err(py_err)?;
    }
    Ok((traced, page))
}

/// `dicephys theory --block … --json` (or `--table --json` without a block).
#[pyfunction]
#[pyo3(signature = (block=None, tolerance=0.1))]
fn theory(block: Option<&str>, tolerance: f64) -> PyResult<String> {
    use dicephys::report::table::{block_report, table_report};
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(bad("tolerance", tolerance, "a number of mm, 0 or more"));
    }
    let json = match block {
        Some(b) => serde_json::to_string_pretty(&block_report(&self::block(b)?, tolerance)),
        None => serde_json::to_string_pretty(&table_report().map_err(py_err)?),
    };
    json.map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// Where a study writes: `out` (its cells under `out/cells`), or nothing if `out` is None.
fn place(out: Option<PathBuf>, cells: &str, threads_: usize, call: &str) -> PyResult<Place> {
    let threads = threads(threads_)?;
    Ok(match out {
        Some(out) => {
            dicephys::run::owner::refuse_cluster_run(&out).map_err(py_err)?;
            Place {
                checkpoint: Some(out.join(cells)),
                out,
                threads,
                share: ChunkShare::All,
                json: true,
                command_line: format!("python: dicephys.{call}"),
            }
        }
        None => Place {
            out: ".".into(),
            checkpoint: None,
            threads,
            share: ChunkShare::All,
            json: true,
            command_line: format!("python: dicephys.{call}"),
        },
    })
}

/// A study's JSON result, or Python's exception if it was stopped.
fn finished(done: Done) -> PyResult<String> {
    match done.interrupted {
        Some(m) => Err(PyKeyboardInterrupt::new_err(m)),
        None => Ok(done.stdout.trim_end().to_string()),
    }
}

/// A study the command line runs (`paper`, `tradeoff`, `converge`, `stability`,
/// `crosscheck`, `fit`, `paper --calibrated`), from its configuration as a Slurm plan stores
/// it (JSON, tagged by `study`), writing into `out`. Returns its JSON result.
#[pyfunction]
#[pyo3(signature = (config, out, *, threads=0, progress=None, log=None))]
fn study(
    py: Python<'_>,
    config: &str,
    out: PathBuf,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
    log: Option<&Bound<'_, PyAny>>,
) -> PyResult<String> {
    let cfg: StudyConfig = serde_json::from_str(config)
        .map_err(|e| bad("config", "…", format!("not a study's configuration: {e}")))?;
    let call = cfg.name();
    run_study(py, &cfg, out, threads, (progress, log), call)
}

/// Runs a study into `out` (its cells beside its files, where the command line keeps them),
/// as `dicephys.<call>` with Python's `progress` and `log` callables; its JSON result.
fn run_study(
    py: Python<'_>,
    cfg: &StudyConfig,
    out: PathBuf,
    threads: usize,
    (progress, log): (Option<&Bound<'_, PyAny>>, Option<&Bound<'_, PyAny>>),
    call: &str,
) -> PyResult<String> {
    cfg.validate().map_err(py_err)?;
    let place = place(Some(out), cfg.cells(), threads, call)?;
    finished(detached(py, progress, log, |s| {
        s.hooked(|h| cfg.run(&place, h))
    })?)
}

/// The default configuration of the study `name` (`paper`, `fit`'s parts are built by
/// `fit_config`), as JSON, for Python to change and pass to `study`.
#[pyfunction]
#[pyo3(signature = (rolls, seed, engines, dt, max_steps, faithful))]
fn paper_config(
    rolls: u64,
    seed: u64,
    engines: Vec<String>,
    dt: f64,
    max_steps: u64,
    faithful: bool,
) -> PyResult<String> {
    let mut kinds = Vec::new();
    for e in &engines {
        kinds.push(named::<EngineKind>("engines", "engine", e)?);
    }
    kinds.dedup();
    let cfg = dicephys::studies::paper::PaperConfig {
        rolls,
        seed,
        engines: kinds,
        dt,
        max_steps,
        faithful,
    };
    cfg.validate().map_err(py_err)?;
    serde_json::to_string(&StudyConfig::Paper(cfg))
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// A fit's die from `roll`'s names (com, pips, edge_radius, die: a file or a mesh, layout,
/// density, shape, size, scale), as the library's request.
fn fit_die(die: Option<Bound<'_, PyDict>>) -> PyResult<DieRequest> {
    let o = Options {
        given: die.map(|d| d.copy()).transpose()?,
    };
    let layout = o
        .maybe::<String>("layout")?
        .map(|l| named::<Layout>("layout", "layout", &l))
        .transpose()?;
    let request = die_of(&o, None, layout)?;
    o.finish()?;
    Ok(request)
}

/// A fit's configuration (`dicephys fit`'s), from the counts (a CSV file, CSV text, or
/// "paper") and the model: the library's request, checked by the library; as JSON.
#[pyfunction]
#[pyo3(signature = (data, free, shared, ranges, restitution, friction, kappa, spin_scale,
    engine, dt, max_steps, points, point_rolls, degree, max_degree, refine, common_throws, seed,
    die=None))]
#[allow(clippy::too_many_arguments)]
fn fit_config<'py>(
    data: &str,
    free: Vec<String>,
    shared: Vec<String>,
    ranges: Vec<(String, f64, f64)>,
    restitution: f64,
    friction: f64,
    kappa: Option<f64>,
    spin_scale: f64,
    engine: &str,
    dt: f64,
    max_steps: u64,
    points: usize,
    point_rolls: u64,
    degree: Option<usize>,
    max_degree: Option<usize>,
    refine: bool,
    common_throws: bool,
    seed: u64,
    die: Option<Bound<'py, PyDict>>,
) -> PyResult<String> {
    use calibration::params::{FixedThrow, Kind};
    let kind = |arg: &str, s: &str| named::<Kind>(arg, "parameter", s);
    let rows = if data == "paper" {
        calibration::data::paper_rows()
    } else if data.contains('\n') {
        calibration::data::parse(data, "data")
    } else {
        calibration::data::read(std::path::Path::new(data), &Stop::new())
    }
    .map_err(|e| match e {
        Error::Io { .. } => py_err(e),
        e => PyValueError::new_err(format!("data: {}", arguments_in(&e))),
    })?;
    let request = calibration::request::FitRequest {
        rows,
        free: free
            .iter()
            .map(|s| kind("free", s))
            .collect::<PyResult<_>>()?,
        shared: shared
            .iter()
            .map(|s| kind("shared", s))
            .collect::<PyResult<_>>()?,
        ranges: ranges
            .iter()
            .map(|(name, lo, hi)| Ok((kind("ranges", name)?, Range { lo: *lo, hi: *hi })))
            .collect::<PyResult<_>>()?,
        restitution,
        friction,
        throw: kappa.map(FixedThrow::Hand),
        spin_scale,
        die: fit_die(die)?,
        engine: named::<EngineKind>("engine", "engine", engine)?,
        dt,
        max_steps,
        points,
        point_rolls,
        degree,
        max_degree,
        refine,
        common_throws,
        seed,
    };
    let cfg = request.config().map_err(py_err)?;
    serde_json::to_string(&cfg).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// `dicephys fit`: the fit of `config` (from `fit_config`), written into `out`; its JSON.
#[pyfunction]
#[pyo3(signature = (config, out, *, threads=0, progress=None, log=None))]
fn fit(
    py: Python<'_>,
    config: &str,
    out: PathBuf,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
    log: Option<&Bound<'_, PyAny>>,
) -> PyResult<String> {
    let config: FitConfig = serde_json::from_str(config)
        .map_err(|e| bad("config", "…", format!("not a fit's configuration: {e}")))?;
    let cfg = StudyConfig::Fit(dicephys::studies::fit::FitStudy {
        config,
        stage: dicephys::studies::fit::Stage::Whole,
    });
    run_study(py, &cfg, out, threads, (progress, log), "fit")
}

/// `dicephys fit --recover`: counts simulated at `truth` (the free parameters' values, in
/// the model's order), fitted back `repeats` times; the coverage's JSON.
#[pyfunction]
#[pyo3(signature = (config, truth, repeats, out, *, threads=0, progress=None, log=None))]
#[allow(clippy::too_many_arguments)]
fn recover(
    py: Python<'_>,
    config: &str,
    truth: Vec<(String, f64)>,
    repeats: usize,
    out: PathBuf,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
    log: Option<&Bound<'_, PyAny>>,
) -> PyResult<String> {
    use calibration::params::Kind;
    let cfg: FitConfig = serde_json::from_str(config)
        .map_err(|e| bad("config", "…", format!("not a fit's configuration: {e}")))?;
    let mut given = Vec::new();
    for (name, v) in &truth {
        let k = named::<Kind>("truth", "parameter", name)?;
        if !cfg.model.free.contains(&k) {
            return Err(bad("truth", name, "not among the free parameters"));
        }
        given.push((k, *v));
    }
    let values = cfg
        .model
        .free
        .iter()
        .map(|k| {
            given
                .iter()
                .find(|(g, _)| g == k)
                .map(|g| g.1)
                .ok_or_else(|| bad("truth", k, "give a value for every free parameter"))
        })
        .collect::<PyResult<Vec<f64>>>()?;
    let cfg = StudyConfig::Recover(dicephys::studies::fit::RecoverStudy {
        config: cfg,
        truth: values,
        repeats,
    });
    run_study(py, &cfg, out, threads, (progress, log), "recover")
}

/// `dicephys predict`: the fit (its `fit.json`'s text) simulated at a block it did not see;
/// the prediction's JSON.
/// A fit.json's text, given as the argument `arg`: sealed as written, and whole.
fn fit_of(text: &str, arg: &str) -> PyResult<calibration::FitResult> {
    let fit: calibration::FitResult = dicephys::run::seal::open(text)
        .map_err(|e| bad(arg, "…", format!("not a fit's fit.json as written: {e}")))?;
    fit.check().map_err(|e| bad(arg, "…", arguments_in(&e)))?;
    Ok(fit)
}

/// `dicephys compare --json`: two fits' fit.json texts (named `names`, as the files they came
/// from), compared by their rows' leave-one-out log scores.
#[pyfunction]
fn compare(first: &str, second: &str, names: [String; 2]) -> PyResult<String> {
    let (a, b) = (fit_of(first, "first")?, fit_of(second, "second")?);
    let c = calibration::compare::compare(&a, &b, [&names[0], &names[1]])
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    dicephys::run::seal::to_string(&c, true).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

#[pyfunction]
#[pyo3(signature = (fit, block=None, *, mode="3d", surface=None, thrower=None, draws=16,
    rolls=2000, seed=DEFAULT_SEED, threads=0, progress=None, contact=None, die=None,
    counts=None, discrepancy="auto"))]
#[allow(clippy::too_many_arguments)]
fn predict<'py>(
    py: Python<'py>,
    fit: &str,
    block: Option<&str>,
    mode: &str,
    surface: Option<String>,
    thrower: Option<String>,
    draws: usize,
    rolls: u64,
    seed: u64,
    threads: usize,
    progress: Option<&Bound<'_, PyAny>>,
    contact: Option<[f64; 2]>,
    die: Option<Bound<'py, PyDict>>,
    counts: Option<&str>,
    discrepancy: &str,
) -> PyResult<String> {
    let mut fit = fit_of(fit, "fit")?;
    let discrepancy: calibration::discrepancy::Use = discrepancy.parse().map_err(|_: String| {
        bad(
            "discrepancy",
            format!("'{discrepancy}'"),
            "give auto, on or off",
        )
    })?;
    if let Some(d) = fit.discrepancy.as_mut() {
        d.set_use(discrepancy);
    }
    let given = block.map(self::block).transpose()?;
    let other = other_die(&fit, given, die)?;
    // A fit of a die of any shape predicts that die; a fit of blocks needs the block; another
    // die of any shape is its own bounding box.
    let block = match (given, calibration::predict::own_block(&fit), &other) {
        (Some(b), _, _) | (None, Some(b), _) => b,
        (None, None, Some(o)) if o.shape.is_some() => {
            o.block(Block::from_mm(16.0, 16.0, 16.0).map_err(py_err)?)
        }
        (None, None, _) => return Err(bad("block", "None", "give the block to predict")),
    };
    let block = other.as_ref().map_or(block, |o| o.block(block));
    let shape = other
        .as_ref()
        .map_or(fit.config.method.die.shape.as_deref(), |o| {
            o.shape.as_deref()
        });
    let counts = match counts {
        Some(c) => counts_of(c, shape)?,
        None => Vec::new(),
    };
    let cfg = calibration::predict::PredictConfig {
        other: other.map(Box::new),
        counts,
        block,
        mode: self::mode(mode)?,
        surface,
        thrower,
        contact,
        draws,
        rolls,
        seed,
    };
    let cfg = StudyConfig::Predict(dicephys::studies::fit::PredictStudy { fit, config: cfg });
    let place = place(None, "", threads, "predict")?;
    finished(detached(py, progress, None, |s| {
        s.hooked(|h| cfg.run(&place, h))
    })?)
}

/// The die `predict` throws in place of the fit's (issue 71.2): `die`'s names as `fit`'s
/// (shape, die, size, scale, com, pips, edge_radius, density), or a block from a fit of a die
/// of any shape; `None`: the fit's own.
fn other_die(
    fit: &calibration::FitResult,
    block: Option<Block>,
    die: Option<Bound<'_, PyDict>>,
) -> PyResult<Option<dicephys::model::die::Die>> {
    let described = die.as_ref().is_some_and(|d| !d.is_empty());
    let block_of_shape_fit = block.is_some() && fit.config.method.die.shape.is_some();
    if !described && !block_of_shape_fit {
        return Ok(None);
    }
    let request = DieRequest {
        block,
        ..fit_die(die)?
    };
    request.resolve_resting().map(Some).map_err(py_err)
}

/// `predict`'s counts (a CSV file or CSV text in `fit`'s format), read against the die of any
/// shape predicted.
fn counts_of(
    counts: &str,
    shape: Option<&dicephys::model::shape::Shape>,
) -> PyResult<Vec<calibration::data::DataRow>> {
    let rows = if counts.contains('\n') {
        calibration::data::parse(counts, "counts")
    } else {
        calibration::data::read(std::path::Path::new(counts), &Stop::new())
    }
    .map_err(|e| match e {
        Error::Io { .. } => py_err(e),
        e => PyValueError::new_err(format!("counts: {}", arguments_in(&e))),
    })?;
    match shape {
        Some(s) => calibration::data::on_shape(&rows, s)
            .map_err(|e| PyValueError::new_err(format!("counts: {}", arguments_in(&e)))),
        None => Ok(rows),
    }
}

/// The library's version, as `dicephys --version` prints it.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(roll, m)?)?;
    m.add_function(wrap_pyfunction!(theory, m)?)?;
    m.add_function(wrap_pyfunction!(trace, m)?)?;
    m.add_function(wrap_pyfunction!(study, m)?)?;
    m.add_function(wrap_pyfunction!(paper_config, m)?)?;
    m.add_function(wrap_pyfunction!(fit_config, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(recover, m)?)?;
    m.add_function(wrap_pyfunction!(predict, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(design::design, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("DEFAULT_MAX_STEPS", DEFAULT_MAX_STEPS)?;
    m.add("DEFAULT_SEED", DEFAULT_SEED)?;
    m.add("DEFAULT_MARGIN", DEFAULT_MARGIN)?;
    // The library's other defaults, for the package's signatures to show.
    let (scene, fit) = (
        SceneRequest::default(),
        calibration::request::FitRequest::default(),
    );
    m.add("DEFAULT_DT", scene.dt)?;
    m.add("DEFAULT_FRICTION", scene.friction)?;
    m.add("DEFAULT_RESTITUTION", scene.restitution)?;
    m.add("DEFAULT_ROLLS", dicephys::run::request::DEFAULT_ROLLS)?;
    m.add("DEFAULT_SPIN_SCALE", fit.spin_scale)?;
    m.add("DEFAULT_POINTS", fit.points)?;
    m.add("DEFAULT_POINT_ROLLS", fit.point_rolls)?;
    m.add("DEFAULT_REPEATS", calibration::recovery::DEFAULT_REPEATS)?;
    m.add("DEFAULT_DRAWS", calibration::predict::DEFAULT_DRAWS)?;
    m.add("DEFAULT_PREDICT_ROLLS", calibration::predict::DEFAULT_ROLLS)?;
    use dicephys::studies::design as design_;
    m.add("DEFAULT_DESIGN_ROLLS", design_::DEFAULT_ROLLS)?;
    m.add("DEFAULT_DESIGN_POINTS", design_::DEFAULT_POINTS)?;
    m.add("DEFAULT_CHECK_ROLLS", design_::DEFAULT_CHECK_ROLLS)?;
    m.add("DEFAULT_FACETS_ROLLS", design_::mesh::DEFAULT_ROLLS)?;
    m.add("DEFAULT_FACETS_ROUNDS", design_::mesh::DEFAULT_ROUNDS)?;
    let engines: Vec<String> = dicephys::studies::paper::DEFAULT_ENGINES
        .iter()
        .map(|e| e.to_string())
        .collect();
    m.add("DEFAULT_ENGINES", engines)?;
    Ok(())
}
