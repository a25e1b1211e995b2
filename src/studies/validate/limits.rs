//! The limit cases: a die released at rest, e = 0, high friction, heavy damping (or the
//! damping lifted), against eq. (InElasK) in 2D and the solid angles in 3D.

use super::rows::Rows;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::model::block::{Block, Side};
use crate::model::scene::{Mode, Scene};
use crate::model::throws::ThrowStyle;
use crate::report::validate::Config;
use crate::report::validate::{Case, Faces, LimitCell, Row, Verdict, Z_PASS};
use crate::run::cputime::process_cpu_seconds;
use crate::run::io::write_atomic;
use crate::run::runner::Checkpoint;
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::run::tally::Tally;
use crate::sim::roll::{Fate, RollConfig, RollRecord, Rule};
use crate::studies::study::Study;
use crate::theory;
use serde::{Deserialize, Serialize};

impl LimitCell {
    pub(super) fn empty(spec: &RunSpec) -> LimitCell {
        LimitCell {
            engine: spec.engine,
            mode: spec.scene.mode,
            block: spec.scene.die.block().to_string(),
            damping: spec.scene.linear_damping,
            tally: Tally::default(),
            at_rest: Faces::default(),
            moving_at_cap: Faces::default(),
            unknown: 0,
            failed: 0,
            ended_on_a_face: 0,
            ended_where_started: 0,
            outcomes: String::new(),
            cpu_s: 0.0,
        }
    }

    pub(super) fn add(&mut self, scene: &Scene, r: &RollRecord) -> Result<()> {
        // The paper's blocks, counted by the side standing vertical.
        self.tally.add(r, true)?;
        let face = match r.fate {
            Fate::Settled(o) => {
                self.at_rest.add(o.side());
                o.side()
            }
            Fate::Unconverged(_) => match r.certified {
                Some((_, o)) => {
                    self.moving_at_cap.add(o.side());
                    o.side()
                }
                None => Side::Unknown,
            },
            Fate::Failed(_) => {
                self.failed += 1;
                self.outcomes.push('x');
                return Ok(());
            }
        };
        if face == Side::Unknown {
            self.unknown += 1;
        } else {
            self.ended_on_a_face += 1;
            self.ended_where_started += (face == start_face(scene, &r.throw.start(scene))) as u64;
        }
        self.outcomes.push(match face {
            Side::Breadth => 'b',
            Side::Width => 'w',
            Side::Length => 'l',
            Side::Unknown => '?',
        });
        Ok(())
    }
}

/// The limit cases' scene: the paper's, released on a floor with e = 0, the config's μ, its
/// damping (or none), and the engine's sleeping off.
pub fn limit_scene(cfg: &Config, block: Block, mode: Mode, damped: bool) -> Scene {
    let mut s = Scene::paper(block, mode);
    s.restitution = 0.0;
    s.friction = cfg.friction;
    let d = if damped { cfg.damping } else { 0.0 };
    s.linear_damping = d;
    s.angular_damping = d;
    s.sleeping = false;
    s
}

/// The limit cases' rolls: DicePhys's rest rule, every step stepped, the certificate audited
/// (it names the face region of a die still moving at the cap).
pub fn limit_roll(max_steps: u64) -> RollConfig {
    RollConfig {
        max_steps,
        rule: Rule::Dicephys,
        audit: true,
        fast_flight: false,
        ..RollConfig::default()
    }
}

/// A limit cell as kept under the study's checkpoint, with its per-throw faces.
#[derive(Serialize, Deserialize)]
struct Kept {
    cell: LimitCell,
    outcomes: String,
}

/// Rolls a limit cell, or reads it back from the study's checkpoint.
pub fn measure_limit(spec: &RunSpec, study: &Study) -> Result<LimitCell> {
    let cpu = process_cpu_seconds();
    let dir = study
        .checkpoint
        .as_ref()
        .map(|root| root.join(format!("validate-{}-{}", spec.engine, spec.key())));
    let kept = dir.as_ref().map(|d| d.join("limit.json"));
    if let Some(k) = kept
        .as_ref()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .and_then(|t| serde_json::from_str::<Kept>(&t).ok())
    {
        return Ok(LimitCell {
            outcomes: k.outcomes,
            ..k.cell
        });
    }
    let ck = match &dir {
        Some(d) => Some(Checkpoint::open_fresh(d, spec)?),
        None => None,
    };
    let mut cell = LimitCell::empty(spec);
    let run = study.runner.run(spec, ck.as_ref(), &mut |recs| {
        recs.iter().try_for_each(|r| cell.add(&spec.scene, r))
    })?;
    if !run.complete {
        return Err(Error::Stopped);
    }
    cell.cpu_s = process_cpu_seconds() - cpu + run.resumed_cpu_s;
    if let Some(f) = &kept {
        let k = Kept {
            cell: cell.clone(),
            outcomes: cell.outcomes.clone(),
        };
        let json = serde_json::to_string(&k).map_err(|e| Error::failed(e.to_string()))?;
        write_atomic(f, json.as_bytes())?;
    }
    Ok(cell)
}

/// The face whose solid angle the downward vertical from the centre passes through in state
/// `s`: the body axis i (of x, y in 2D) with the largest |uᵢ|/sᵢ, u the vertical in body axes
/// and sᵢ the half sides; the face a die released there at rest, without momentum, ends on.
pub fn start_face(scene: &Scene, s: &crate::model::state::BodyState) -> Side {
    let die = crate::model::die::DieBody::of(scene);
    let up = crate::model::die::up_in_body(&s.rotation);
    let (i, _) = die.face_region(&up);
    [Side::Breadth, Side::Width, Side::Length][i]
}

/// The 2D case: per engine and block, over-damped, then the damping lifted, on the same throws;
/// their rows pushed as they are measured. The cells, in that order.
pub(super) fn no_bounce_2d(cfg: &Config, study: &Study, rows: &mut Rows) -> Result<Vec<LimitCell>> {
    let mut cells = Vec::new();
    for &engine in &cfg.engines {
        for block in &cfg.blocks_2d {
            let p = theory::no_bounce_2d(block.r()).breadth_vertical;
            let damped = measure_limit(
                &spec(cfg, engine, limit_scene(cfg, *block, Mode::TwoD, true)),
                study,
            )?;
            let free = measure_limit(
                &spec(cfg, engine, limit_scene(cfg, *block, Mode::TwoD, false)),
                study,
            )?;
            for (case, c) in [(Case::NoBounce2d, &damped), (Case::Momentum2d, &free)] {
                let f = c.faces();
                let mut r = probability_row(
                    cfg,
                    case,
                    engine,
                    subject_2d(block),
                    "P(breadth vertical)",
                    p,
                    (f.breadth, f.total()),
                );
                r.note = cell_note(c, cfg.max_steps);
                if case == Case::Momentum2d {
                    let same = format!(
                        "same face as over-damped for {:.1} % of throws",
                        100.0 * c.same_outcome(&damped)
                    );
                    r.note = [same, r.note]
                        .into_iter()
                        .filter(|s| !s.is_empty())
                        .collect::<Vec<_>>()
                        .join("; ");
                }
                rows.push(r);
            }
            cells.push(damped);
            cells.push(free);
        }
    }
    Ok(cells)
}

/// The 3D case: per engine and block, over-damped, Haar-random orientations; its rows pushed
/// as they are measured.
pub(super) fn quasi_static_3d(
    cfg: &Config,
    study: &Study,
    rows: &mut Rows,
) -> Result<Vec<LimitCell>> {
    let mut cells = Vec::new();
    for &engine in &cfg.engines {
        for block in &cfg.blocks_3d {
            let (p, _) = theory::simpson_3d(block);
            let c = measure_limit(
                &spec(cfg, engine, limit_scene(cfg, *block, Mode::ThreeD, true)),
                study,
            )?;
            let f = c.faces();
            for (o, q) in SIDES {
                let want = match o {
                    Side::Breadth => p.breadth_vertical,
                    Side::Width => p.width_vertical,
                    _ => p.length_vertical,
                };
                let mut r = probability_row(
                    cfg,
                    Case::QuasiStatic3d,
                    engine,
                    block.to_string(),
                    q,
                    want,
                    (f.of(o), f.total()),
                );
                r.note = cell_note(&c, cfg.max_steps);
                rows.push(r);
            }
            cells.push(c);
        }
    }
    Ok(cells)
}

/// A limit cell's run: released at rest, the limit cases' rolls.
pub(super) fn spec(cfg: &Config, engine: EngineKind, scene: Scene) -> RunSpec {
    RunSpec {
        engine,
        scene,
        throws: ThrowSpec::keyed_style(cfg.seed, ThrowStyle::Rest),
        roll: limit_roll(cfg.max_steps),
        rolls: cfg.rolls,
        shard: None,
    }
}

/// A probability measured as k of n against the closed form p: the row, with z from the
/// closed form's binomial error √(p(1−p)/n).
fn probability_row(
    cfg: &Config,
    case: Case,
    engine: EngineKind,
    subject: String,
    quantity: &str,
    p: f64,
    (k, n): (u64, u64),
) -> Row {
    let measured = k as f64 / n.max(1) as f64;
    let err = crate::theory::stats::binomial_err(p, n.max(1));
    let z = if n == 0 {
        f64::NAN
    } else {
        (measured - p) / err
    };
    let verdict = if z.abs() <= Z_PASS {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
    Row {
        case,
        engine: engine.name().into(),
        subject,
        quantity: quantity.into(),
        closed_form: p,
        measured,
        err,
        n,
        z,
        verdict,
        note: String::new(),
        rolls_to_resolve: rolls_to_resolve(p, n, cfg.resolve),
    }
}

/// Rolls for 3σ of a proportion near p to be at most `resolve`, if n does not already make it.
pub fn rolls_to_resolve(p: f64, n: u64, resolve: f64) -> Option<u64> {
    let need = (9.0 * p * (1.0 - p) / (resolve * resolve)).ceil() as u64;
    (need > n).then_some(need)
}

/// What a limit cell's dice did besides coming to rest on a face, for its rows' notes.
fn cell_note(c: &LimitCell, max_steps: u64) -> String {
    let mut v = vec![format!(
        "{} of {} on the face they started over",
        c.ended_where_started, c.ended_on_a_face
    )];
    let moving = c.moving_at_cap.total();
    if moving > 0 {
        v.push(format!(
            "{moving} of {} still moving on a face at the {} s cap (counted on it)",
            c.tally.rolls,
            max_steps as f64 * 0.001
        ));
    }
    if c.unknown > 0 {
        v.push(format!("{} on no face", c.unknown));
    }
    if c.failed > 0 {
        v.push(format!("{} failed", c.failed));
    }
    if c.tally.certified_wrong > 0 {
        v.push(format!(
            "{} left the region they were certified in",
            c.tally.certified_wrong
        ));
    }
    v.join("; ")
}

fn subject_2d(block: &Block) -> String {
    format!("{block} (R {:.3})", block.r())
}

const SIDES: [(Side, &str); 3] = [
    (Side::Breadth, "P(breadth vertical)"),
    (Side::Width, "P(width vertical)"),
    (Side::Length, "P(length vertical)"),
];
