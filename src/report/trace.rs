//! One throw's trajectory as CSV (`trace`): step, time, position, orientation, velocities,
//! energies, and the line that says how the throw ended.

use crate::model::die::DieBody;
use crate::model::faces::Outcome;
use crate::model::state::BodyState;
use crate::model::throws::Throw;
use crate::sim::roll::{Fate, RollRecord};

/// The CSV's header.
pub const HEADER: &str =
    "step,time_s,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,kinetic_j,potential_j,total_j,sleeping";

/// The CSV row of the state after `step` steps of `dt`.
pub fn row(die: &DieBody, dt: f64, step: u64, s: &BodyState) -> String {
    let q = s.rotation.quaternion();
    let (k, p) = (die.kinetic(s), die.potential(s));
    format!(
        "{},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9e},{:.9e},{:.9e},{}",
        step,
        step as f64 * dt,
        s.position.x,
        s.position.y,
        s.position.z,
        q.w,
        q.i,
        q.j,
        q.k,
        s.linear_velocity.x,
        s.linear_velocity.y,
        s.linear_velocity.z,
        s.angular_velocity.x,
        s.angular_velocity.y,
        s.angular_velocity.z,
        k,
        p,
        k + p,
        s.sleeping as u8
    )
}

/// How throw `index` ended, in one line; a die of any shape's face named by `labels`.
pub fn ending(index: u64, throw: &Throw, record: &RollRecord, labels: &[&str]) -> String {
    // A die of any shape's face by its label; a cuboid's (no labels) by its side.
    let shown = |o: Outcome| match (o, labels.is_empty()) {
        (Outcome::Face(k), false) => Err(*labels.get(usize::from(k)).unwrap_or(&"?")),
        _ => Ok(o.side().name()),
    };
    let fate = match record.fate {
        Fate::Settled(o) => match shown(o) {
            Err(label) => format!("settled, showing {label}"),
            Ok(side) => format!("settled, {side} vertical"),
        },
        Fate::Unconverged(o) => match shown(o) {
            Err(label) => format!("unconverged (showing {label} at the cap)"),
            Ok(side) => format!("unconverged ({side} vertical at the cap)"),
        },
        Fate::Failed(f) => format!("failed: {}", f.name()),
    };
    format!(
        "throw {index}: drop {:.4} m, v {:.4} m/s, spin {:.3} rad/s: {fate} after {} steps",
        throw.drop_height, throw.velocity, throw.spin, record.steps
    )
}

/// When the step cap ended the trace (the die not at rest after `cap` steps), one line that
/// says so: the cap, whose it was (`asked`: `--max-steps`, else the die's default) and how to
/// move it. `None` when the roll ended otherwise.
pub fn capped(record: &RollRecord, cap: u64, asked: bool) -> Option<String> {
    if !matches!(record.fate, Fate::Unconverged(_)) {
        return None;
    }
    let whose = if asked {
        "as asked".to_string()
    } else if cap == crate::sim::roll::SHAPE_MAX_STEPS {
        "a die of any shape's default, as `roll`'s; --max-steps sets another".to_string()
    } else {
        "DicePhys's default; --max-steps sets another".to_string()
    };
    Some(format!(
        "the step cap ended the trace: the die was not at rest after {cap} steps ({whose})"
    ))
}

/// How a traced roll ends: at `roll`'s step cap for the same die unless `max_steps` asks
/// another (a coin on its edge on a floor without rolling resistance rolls for ever, and traced
/// to DicePhys's 20,000,000 steps it wrote gigabytes; issue 69.10), its flight fast (in closed
/// form where it is ballistic, as `roll` flies it) or stepped; `audit`: the early stop noted
/// where it would fire, the roll carried on to rest (the page's), else taken (the CSV's).
pub fn config(
    scene: &crate::model::scene::Scene,
    max_steps: Option<u64>,
    fast_flight: bool,
    audit: bool,
) -> crate::sim::roll::RollConfig {
    crate::sim::roll::RollConfig {
        max_steps: crate::run::request::EndRequest {
            max_steps,
            ..crate::run::request::EndRequest::default()
        }
        .cap(scene),
        fast_flight,
        audit,
        ..crate::sim::roll::RollConfig::default()
    }
}

/// `throw` rolled on a new engine of `kind` as `trace` rolls it, each step's state passed to
/// `observe`: its record (a die still moving at the cap with the face it was on then, for the
/// ending's line). [`Ended::Stopped`] where `abandon` said so (asked every 4,096 steps: a stop
/// request).
pub fn roll(
    kind: crate::engine::EngineKind,
    scene: &crate::model::scene::Scene,
    throw: &Throw,
    settle: &crate::sim::roll::RollConfig,
    mut observe: impl FnMut(u64, &BodyState),
    abandon: &dyn Fn() -> bool,
) -> crate::Result<Ended> {
    let mut engine = crate::engine::new_engine(kind, scene)?;
    let mut last = 0;
    let record = crate::sim::roll::roll_observed_or_abandon(
        engine.as_mut(),
        scene,
        throw,
        settle,
        |step, s| {
            last = step;
            observe(step, s);
        },
        abandon,
    );
    let Some(ended) = record else {
        return Ok(Ended::Stopped { step: last });
    };
    Ok(Ended::Rolled(ended))
}

/// How a traced throw ended: rolled to its end, or stopped (a stop request) after `step` steps.
#[derive(Clone, Copy, Debug)]
pub enum Ended {
    /// Its record.
    Rolled(RollRecord),
    /// Abandoned: the last step observed.
    Stopped {
        /// The last step observed.
        step: u64,
    },
}

/// The CSV's rows of `throw` (`trace`'s, without the header), each passed to `line`: every
/// `every`th step's, and the last's (not when stopped: the rows up to the stop are written).
pub fn rows(
    kind: crate::engine::EngineKind,
    scene: &crate::model::scene::Scene,
    throw: &Throw,
    settle: &crate::sim::roll::RollConfig,
    every: u64,
    mut line: impl FnMut(&str),
    abandon: &dyn Fn() -> bool,
) -> crate::Result<Ended> {
    let die = DieBody::of(scene);
    let mut last = None;
    let ended = roll(
        kind,
        scene,
        throw,
        settle,
        |step, s| {
            let l = row(&die, scene.dt, step, s);
            if step % every == 0 {
                line(&l);
                last = None;
            } else {
                last = Some(l);
            }
        },
        abandon,
    )?;
    if let (Some(l), Ended::Rolled(_)) = (last, ended) {
        line(&l);
    }
    Ok(ended)
}

/// How `trace` steps its throws: the step cap asked (`None`: the scene's own) and whether free
/// flight is flown in closed form (fast) or stepped.
#[derive(Clone, Copy, Debug)]
pub struct Stepping {
    /// The step cap asked.
    pub max_steps: Option<u64>,
    /// Free flight flown in closed form.
    pub fast_flight: bool,
}

/// The page (`report::view`) that plays throws `indices` of `throws` of `scene` on `kind`,
/// each rolled as `trace --html` rolls it (the early stop audited: noted where it would have
/// fired, the roll carried on to rest); each throw's ending line, with the cap's note where
/// the cap ended it (`capped`), passed to `say`. `None` if `abandon` stopped it.
pub fn page(
    kind: crate::engine::EngineKind,
    scene: &crate::model::scene::Scene,
    throws: &crate::model::throws::Throws,
    indices: std::ops::RangeInclusive<u64>,
    stepping: Stepping,
    mut say: impl FnMut(&str, Option<&str>),
    abandon: &dyn Fn() -> bool,
) -> crate::Result<Option<String>> {
    use crate::report::view::{self, DieView, Recorder, ThrowView};
    let Stepping {
        max_steps,
        fast_flight,
    } = stepping;
    let die = DieBody::of(scene);
    let settle = config(scene, max_steps, fast_flight, true);
    let labels: Vec<String> = scene
        .die
        .as_shape()
        .map(|s| s.labels().into_iter().map(String::from).collect())
        .unwrap_or_default();
    let label_refs: Vec<&str> = labels.iter().map(String::as_str).collect();
    let mut views = Vec::new();
    for index in indices {
        let throw = throws.get(index);
        let mut rec = Recorder::new(scene.dt);
        let observe = |step, s: &BodyState| rec.push(&die, step, s);
        let Ended::Rolled(record) = roll(kind, scene, &throw, &settle, observe, abandon)? else {
            return Ok(None);
        };
        let ending = ending(index, &throw, &record, &label_refs);
        say(
            &ending,
            capped(&record, settle.max_steps, max_steps.is_some()).as_deref(),
        );
        views.push(ThrowView::of(
            index,
            ending,
            &record,
            scene.dt,
            &labels,
            rec.finish(&die),
        ));
    }
    Ok(Some(view::page(
        &DieView::of(scene, &die),
        scene.dt,
        kind.into(),
        &views,
    )))
}

/// The most throws one page plays.
pub const MAX_ON_A_PAGE: u64 = 16;

/// The throws `trace --index` names, (first, last): `I`, or `A..B` (both included, as the
/// shell's {A..B}; also `A..=B`), at most [`MAX_ON_A_PAGE`]; else why not.
pub fn indices(s: &str) -> std::result::Result<(u64, u64), String> {
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
    Ok((first, last))
}
