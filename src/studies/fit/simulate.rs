//! Rolling the designs of a fit: each parameter point a cell of its own (resumable, keyed).

use crate::calibration::design::{points, Design, DesignSpec, Key};
use crate::calibration::params::{self, Method, ModelSpec};
use crate::error::{Error, Result};
use crate::inference::surrogate::{DesignPoint, Surrogate};
use crate::model::scene::Mode;
use crate::run::runner::Runner;
use crate::run::tally::Tally;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// What the fits of one command share: the rolls made so far (the progress reported goes on
/// from one fit to the next) and the designs already simulated, by key (a design is a pure
/// function of its key and the seed, so a second model that needs it takes it as it is).
#[derive(Default)]
pub struct Session {
    rolled: AtomicU64,
    cache: Mutex<Vec<(Key, u64, Design)>>,
}

impl Session {
    /// Rolls made so far in this session.
    pub fn rolled(&self) -> u64 {
        self.rolled.load(Ordering::Relaxed)
    }

    /// Holds `designs`, simulated with `seed`, as this session's own.
    pub fn hold(&self, seed: u64, designs: &[Design]) {
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        for d in designs {
            cache.push((Key::of_design(d), seed, d.clone()));
        }
    }

    /// The design of `key` this session holds, simulated with `seed` at `points` points of
    /// `rolls` throws each.
    pub fn held(&self, key: &Key, seed: u64, points: usize, rolls: u64) -> Option<Design> {
        self.cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
            .find(|(k, s, d)| {
                k == key
                    && *s == seed
                    && d.points.len() == points
                    && d.rolls == points as u64 * rolls
            })
            .map(|c| c.2.clone())
    }
}

/// Everything `simulate` needs.
pub struct Plan<'a> {
    /// The model (which parameters are free, their ranges).
    pub model: &'a ModelSpec,
    /// How each throw is simulated.
    pub method: &'a Method,
    /// How densely.
    pub design: &'a DesignSpec,
    /// The run's seed.
    pub seed: u64,
    /// The session it belongs to.
    pub session: &'a Session,
}

impl Plan<'_> {
    /// The rolls `simulate` makes for `keys`.
    pub fn total_rolls(&self, keys: usize) -> u64 {
        let dims = self.model.free.len();
        keys as u64 * points(dims, self.design.points).len() as u64 * self.design.rolls
    }
}

/// Simulates every key over the design (each point a cell of its own under `dir`, resumed
/// from there) and fits its surrogate. `None` if a stop request ended it early (what was rolled
/// is kept in `dir`), or on a cluster task's share: its rolls are kept for the finishing job,
/// which reads them all back.
pub fn simulate(
    plan: &Plan,
    keys: &[Key],
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<Vec<Design>>> {
    let dims = plan.model.free.len();
    let xs = points(dims, plan.design.points);
    let mut out = Vec::new();
    for key in keys {
        if let Some(d) = plan
            .session
            .held(key, plan.seed, xs.len(), plan.design.rolls)
        {
            out.push(d);
            continue;
        }
        let (block, mode) = (key.block, key.mode);
        // The key's own die, where a row names one.
        let method = plan.method.for_die(key.die.as_deref());
        let mut design_points = Vec::new();
        let (mut unsettled, mut rolls) = (0u64, 0u64);
        for (g, x) in xs.iter().enumerate() {
            let values = params::values(&plan.model.fixed, &key.axes, x);
            // Common random numbers: every point the throws of the first.
            let seed = key.seed(plan.seed, if plan.design.common { 0 } else { g });
            let spec = method.spec(block, mode, &values, seed, plan.design.rolls);
            spec.validate(false)?;
            let ck = match dir {
                Some(d) => Some(
                    runner.open_cell(&d.join(key.tag()).join(format!("point-{g:05}")), &spec)?,
                ),
                None => None,
            };
            let base = plan.session.rolled();
            let progress = |n| (runner.progress)(base + n);
            let done = runner
                .with_progress(&progress)
                .run(&spec, ck.as_ref(), &mut |_| Ok(()))?;
            plan.session
                .rolled
                .fetch_add(plan.design.rolls, Ordering::Relaxed);
            if !done.complete {
                return Ok(None);
            }
            if runner.share.is_partial() {
                continue;
            }
            let t = &done.tally;
            unsettled += t.rolls - settled(t);
            rolls += t.rolls;
            design_points.push(DesignPoint {
                x: x.clone(),
                counts: outcome_counts(t, key.faces, &method, spec.scene.die.as_shape())?,
            });
        }
        if runner.share.is_partial() {
            continue;
        }
        let surrogate = surrogate(&design_points, key, &method, plan.design);
        let design = Design {
            block,
            mode,
            axes: key.axes.clone(),
            faces: key.faces,
            die: key.die.clone(),
            points: design_points,
            borrowed: vec![],
            unsettled,
            rolls,
            surrogate,
        };
        plan.session
            .cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((key.clone(), plan.seed, design.clone()));
        out.push(design);
    }
    Ok((!runner.share.is_partial()).then_some(out))
}

/// The surrogate through a design's `points` (its own, and any borrowed from earlier passes:
/// [`crate::calibration::design::borrowed`]): over the faces of a die counted by faces, over
/// the three sides in 3D, over breadth and width in 2D (a 2D block has no length outcome).
pub fn surrogate(
    points: &[DesignPoint],
    key: &Key,
    method: &Method,
    spec: &DesignSpec,
) -> Surrogate {
    let dims = key.axes.len();
    let (outcomes, pts): (usize, Vec<DesignPoint>) = match key.mode {
        _ if key.faces => (method.die.outcomes(), points.to_vec()),
        Mode::ThreeD => (3, points.to_vec()),
        Mode::TwoD => (
            2,
            points
                .iter()
                .map(|p| DesignPoint {
                    x: p.x.clone(),
                    counts: p.counts[1..].to_vec(),
                })
                .collect(),
        ),
    };
    Surrogate::fit_best(&pts, dims, outcomes, spec.degree, spec.max_degree)
}

/// Rolls of a tally that settled on a side, a number or (a die of any shape) a face.
pub fn settled(t: &Tally) -> u64 {
    let c = &t.counts;
    c.length + c.breadth + c.width + c.face
}

/// A tally's outcomes as a fit counts them: length, breadth and width vertical, or (`faces`)
/// how often each number 1 to 6 came up on the die's layout, or each label of a die of any
/// shape in its order (`Shape::outcome_labels`). `rolled` is the die the tally's rolls were
/// of (its outcomes at the point's centre of mass), where it is a die of any shape.
pub fn outcome_counts(
    t: &Tally,
    faces: bool,
    method: &Method,
    rolled: Option<&crate::model::shape::Shape>,
) -> Result<Vec<u64>> {
    if !faces {
        return Ok(vec![t.counts.length, t.counts.breadth, t.counts.width]);
    }
    if let Some(shape) = &method.die.shape {
        // Each facet's count under its label (the tally keeps faces up to the last that came
        // up: the rest are 0).
        let labels = shape.outcome_labels();
        let rolled = rolled.unwrap_or(shape);
        let mut out = vec![0; labels.len()];
        for (k, &n) in t.faces.iter().enumerate() {
            let at = rolled
                .faces
                .get(k)
                .and_then(|f| labels.iter().position(|l| *l == f.label));
            if let Some(i) = at {
                out[i] += n;
            }
        }
        return Ok(out);
    }
    if !t.faces_complete() {
        return Err(Error::Invalid(
            "the checkpoint holds rolls written before faces were kept: roll it afresh \
             (another --dir)"
                .into(),
        ));
    }
    let numbers = method.die.features.layout.numbers();
    let (up, mut out) = (t.by_direction(), vec![0; 6]);
    for (d, &n) in numbers.iter().enumerate() {
        out[usize::from(n) - 1] = up[d];
    }
    Ok(out)
}
