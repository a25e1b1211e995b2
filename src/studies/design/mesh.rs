//! A mesh's shape as the design family (issue 73): `design --free facets` moves and tilts a
//! convex die's facets (each plane's offset, and its rim along two tangents, within the range
//! of its start) until the die thrown gives the target. The die is the solid its planes bound,
//! so every facet stays flat and keeps its label (moving vertices folds a flat side along a
//! diagonal, a crease the search sticks in). The exact quasi-static theory (`theory::basins`,
//! well under a millisecond a die) is the fast inner model and the simulation its correction:
//!
//! 1. **The start** is thrown (`rolls` throws).
//! 2. **A round** aims the quasi-static shares at the last shape's own plus [`GAIN`] times what
//!    its throws missed the target by, solves for the planes that give them (damped
//!    Gauss–Newton, Levenberg–Marquardt, the Jacobian by central differences from wide to
//!    fine; steps of at most [`MAX_STEP_MM`]), and throws the result at throws of its own.
//!    `rounds` rounds.
//! 3. **The design** is the solve for the aim after the last round; **the check** throws it
//!    and the start at one fresh seed, `check_rolls` throws each, and judges both against the
//!    target (and, for `2d6` over numbered faces, by class: 2|12 … 7), with the design's own
//!    error (the last round's throws', times the gain) beside the check's.
//!
//! A start that is mirror-symmetric about its body x = 0 plane stays so (a mirror pair of
//! facets moves as one), so that mirror faces keep equal shares.

use super::calibrated::Calibration;
use super::named::Named;
use super::{chi_square, faces_at, gathered, judge, Check};
use crate::error::{Error, Field, Result};
use crate::model::faces::Layout;
use crate::model::shape::{Face, Reads, Shape, Solid, SIDE_ANGLE};
use crate::run::runner::Runner;
use crate::run::spec::RunSpec;
use nalgebra::{DMatrix, DVector, Vector3};
use serde::Serialize;

/// Rounds of throws unless asked otherwise.
pub const DEFAULT_ROUNDS: usize = 5;
/// Throws a round rolls unless asked otherwise.
pub const DEFAULT_ROLLS: u64 = 20_000;
/// The share of a round's miss its next aim corrects: a thrown share moves by one to three
/// times its quasi-static share's move (measured on V1), so a full correction overshoots.
pub const GAIN: f64 = 0.5;
/// The largest move of any parameter in one step of the solve, mm: a step stays where the
/// linear model holds.
pub const MAX_STEP_MM: f64 = 0.25;
/// The rounds' seeds, apart from the scans' and the check's.
const ROUND_SEED: u64 = 0x6d65_7368_0073;
/// The check's seed, apart from the rounds'.
const CHECK_SEED: u64 = 0xc4ec_0000_0073;
/// The name of the family, as `--free` gives it.
pub const FACETS: &str = "facets";

/// What `design --free facets` asks for.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct MeshConfig {
    /// The die (a mesh), its scene and throws; its `rolls` the throws of each round.
    pub spec: RunSpec,
    /// How its numbers sit on its faces (a mesh's are its labels).
    pub layout: Layout,
    /// How far each facet may move from the start's, mm: its offset and its rim's two tilts
    /// each within [LO, HI], fixed before the search.
    pub range: [f64; 2],
    /// The target: each outcome's label and probability, summing to 1.
    pub target: Vec<(String, f64)>,
    /// Rounds of throws.
    pub rounds: usize,
    /// Throws of the check (the design's and the start's).
    pub check_rolls: u64,
    /// The named target `target` was made from, where one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub named_target: Option<Named>,
    /// The fit whose calibrated scene and throw `spec` is (`--fit`), where one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration: Option<Calibration>,
}

impl MeshConfig {
    /// The start die's name.
    fn die_name(&self) -> &str {
        self.spec
            .scene
            .die
            .as_shape()
            .map_or("the die", |s| s.name.as_str())
    }
}

/// One shape thrown: its quasi-static shares and its throws' per target outcome.
#[derive(Clone, Debug, Serialize)]
pub struct Round {
    /// The quasi-static shares the solve aimed at (the start: none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aimed: Option<Vec<f64>>,
    /// The shape's own quasi-static shares.
    pub quasi_static: Vec<f64>,
    /// Its throws' seed.
    pub seed: u64,
    /// Each target outcome's count.
    pub counts: Vec<u64>,
    /// The throws' shares, count / rolls at rest on a target outcome.
    pub p: Vec<f64>,
    /// Pearson's χ² of the counts against the target (outcomes − 1 degrees of freedom).
    pub chi2: f64,
    /// The largest move of a facet from the start's (its offset, or its rim by a tilt), mm.
    pub largest_move: f64,
}

/// The design: its mesh and labels, what it aimed at, and its check.
#[derive(Clone, Debug, Serialize)]
pub struct MeshDesign {
    /// The family, its range and the target.
    pub config: MeshConfig,
    /// The target's outcomes, in order.
    pub outcomes: Vec<String>,
    /// The start's mirror symmetry about its x = 0 plane was kept.
    pub mirror: bool,
    /// Parameters free (a mirror pair's counted once).
    pub free: usize,
    /// The start and each round, thrown.
    pub rounds: Vec<Round>,
    /// The quasi-static shares the design was solved for: the target less the pooled offset.
    pub aimed: Vec<f64>,
    /// The design's quasi-static shares (released at rest, no bounce).
    pub quasi_static: Vec<f64>,
    /// The design's vertices, mm, body axes from its centroid.
    pub vertices: Vec<[f64; 3]>,
    /// Its hull's triangles (indices of `vertices`, counter-clockwise seen from outside).
    pub triangles: Vec<[usize; 3]>,
    /// The facets it rests on and their labels (outward normal, body axes).
    pub faces: Vec<Face>,
    /// The largest move of a facet from the start's, mm.
    pub largest_move: f64,
    /// A parameter sits at its range's end (within 1 % of the range).
    pub at_range_end: bool,
    /// The design thrown at a fresh seed.
    pub check: Check,
    /// The start thrown at the same fresh seed, the same number of throws.
    pub start_check: Check,
    /// For `2d6` over numbered faces: the check by class (2|12, 3|11, 4|10, 5|9, 6|8, 7),
    /// the design's and the start's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub by_class: Option<ByClass>,
    /// The check hit the target (p ≥ 0.05).
    pub reachable: bool,
    /// The verdict, in a sentence.
    pub verdict: String,
}

/// A 2d6 die's check by class.
#[derive(Clone, Debug, Serialize)]
pub struct ByClass {
    /// The classes.
    pub classes: Vec<String>,
    /// Their target.
    pub target: Vec<f64>,
    /// The design's check by class.
    pub check: Check,
    /// The start's check by class.
    pub start_check: Check,
}

/// The start die and its free parameters.
struct Family {
    /// Its facets' planes (outward unit normal n, offset d, mm: n·x = d), body axes from its
    /// centroid, each with its printed label.
    start: Vec<(Vector3<f64>, f64, Option<String>)>,
    /// Each free parameter: (plane, what): 0 its offset, 1 and 2 its tilts, as its rim's
    /// move along `tangents`.
    free: Vec<(usize, usize)>,
    /// Each plane's two unit tangents (the first, x̂ × n, in the mirror plane's direction).
    tangents: Vec<[Vector3<f64>; 2]>,
    /// Each plane's mirror image (x → −x) among them, if the start is mirror-symmetric.
    mirror: Option<Vec<usize>>,
    /// The die's size, mm (its largest distance from the centroid): a tilt of a mm turns a
    /// facet by about a / size.
    size: f64,
    reads: Reads,
    name: String,
}

impl Family {
    fn of(shape: &Shape) -> std::result::Result<Family, String> {
        if !matches!(shape.solid, Solid::Hull { .. }) {
            return Err("its facets are free only on a mesh or a named polyhedron".into());
        }
        // Labels as printed: the die's own, or (numbered 1…N) each resting facet's.
        let printed = shape.printed.clone().unwrap_or_else(|| shape.faces.clone());
        let reads = if shape.printed.is_some() {
            shape.reads
        } else {
            Reads::Down
        };
        let start: Vec<(Vector3<f64>, f64, Option<String>)> = shape
            .planes()
            .into_iter()
            .map(|(n, d)| {
                let label = printed
                    .iter()
                    .map(|f| (Vector3::from(f.normal), &f.label))
                    .max_by(|a, b| n.dot(&a.0).total_cmp(&n.dot(&b.0)))
                    .filter(|(m, _)| n.dot(m) > SIDE_ANGLE.cos())
                    .map(|(_, l)| l.clone());
                (n, d * 1e3, label)
            })
            .collect();
        let size = shape.circumradius() * 1e3;
        let x = Vector3::x();
        let tangents = start
            .iter()
            .map(|(n, _, _)| {
                let u = x.cross(n);
                let u = if u.norm() > 1e-6 {
                    u.normalize()
                } else {
                    Vector3::y()
                };
                [u, n.cross(&u)]
            })
            .collect();
        let mirror: Option<Vec<usize>> = start
            .iter()
            .map(|(n, d, _)| {
                let m = Vector3::new(-n.x, n.y, n.z);
                start
                    .iter()
                    .position(|(o, e, _)| (o - m).norm() <= 1e-6 && (e - d).abs() <= 1e-6 * size)
            })
            .collect();
        let free = match &mirror {
            // A plane on the mirror (its own image) moves and tilts within it; of a pair, the
            // first moves both.
            Some(m) => (0..start.len())
                .flat_map(|i| {
                    let what: &[usize] = if m[i] == i {
                        &[0, 1]
                    } else if m[i] > i {
                        &[0, 1, 2]
                    } else {
                        &[]
                    };
                    what.iter().map(move |&w| (i, w))
                })
                .collect(),
            None => (0..start.len())
                .flat_map(|i| (0..3).map(move |w| (i, w)))
                .collect(),
        };
        Ok(Family {
            start,
            free,
            tangents,
            mirror,
            size,
            reads,
            name: shape.name.clone(),
        })
    }

    /// The planes (n, d mm) at the moves `theta` (mm) of the free parameters.
    fn planes(&self, theta: &[f64]) -> Vec<(Vector3<f64>, f64)> {
        let mut moved: Vec<(Vector3<f64>, f64)> =
            self.start.iter().map(|(n, d, _)| (*n, *d)).collect();
        let mut tilt = vec![Vector3::zeros(); self.start.len()];
        for (&(i, w), &v) in self.free.iter().zip(theta) {
            match w {
                0 => moved[i].1 += v,
                _ => tilt[i] += self.tangents[i][w - 1] * (v / self.size),
            }
        }
        for i in 0..moved.len() {
            moved[i].0 = (moved[i].0 + tilt[i]).normalize();
        }
        if let Some(m) = &self.mirror {
            for i in 0..moved.len() {
                if m[i] < i {
                    let (n, d) = moved[m[i]];
                    moved[i] = (Vector3::new(-n.x, n.y, n.z), d);
                }
            }
        }
        moved
    }

    /// The die at `theta`: the solid its planes bound, each plane's label on its facet.
    fn shape(&self, theta: &[f64]) -> std::result::Result<Shape, String> {
        let planes = self.planes(theta);
        let mesh = crate::model::polytope::inner_hull(&planes, 0.0)
            .ok_or("its facets' planes no longer bound a solid about its centre")?;
        let labels: Vec<(Vector3<f64>, String)> = planes
            .iter()
            .zip(&self.start)
            .filter_map(|((n, _), (_, _, l))| l.as_ref().map(|l| (*n, l.clone())))
            .collect();
        crate::model::shape::from_mesh(&mesh, self.name.clone(), Some(&labels), self.reads)
    }

    /// The die's mesh at `theta`: its corners, mm, from its centroid, and its triangles.
    fn mesh(&self, theta: &[f64]) -> std::result::Result<Corners, String> {
        let mesh = crate::model::polytope::inner_hull(&self.planes(theta), 0.0)
            .ok_or("its facets' planes no longer bound a solid")?;
        let c = mesh.mass_properties().centroid;
        Ok((
            mesh.vertices.iter().map(|v| (v - c).into()).collect(),
            mesh.triangles,
        ))
    }

    /// The die's quasi-static shares at `theta`, per target outcome.
    fn shares(
        &self,
        theta: &[f64],
        target: &[(String, f64)],
    ) -> std::result::Result<Vec<f64>, String> {
        let s = self.shape(theta)?;
        let by = crate::theory::quasi_static::shape_labels(&s, &Vector3::zeros())?;
        let (l, v): (Vec<String>, Vec<f64>) = by.into_iter().unzip();
        Ok(gathered(&l, &v, target))
    }

    /// The largest move of a facet from the start's, mm: its offset's, or its rim's by a tilt.
    fn largest_move(&self, theta: &[f64]) -> f64 {
        self.planes(theta)
            .iter()
            .zip(&self.start)
            .map(|((n, d), (n0, d0, _))| (d - d0).abs().max((n - n0).norm() * self.size))
            .fold(0.0, f64::max)
    }
}

/// A mesh's corners and its triangles (indices of the corners).
type Corners = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// Pearson's residuals of shares `q` against `aim`.
fn residuals(q: &[f64], aim: &[f64]) -> DVector<f64> {
    DVector::from_iterator(
        q.len(),
        q.iter().zip(aim).map(|(q, a)| (q - a) / a.max(1e-3).sqrt()),
    )
}

/// The moves (mm, each within `[lo, hi]`) nearest `from` whose quasi-static shares are `aim`,
/// by damped Gauss–Newton; returns them and the shares there.
fn solve(
    fam: &Family,
    aim: &[f64],
    target: &[(String, f64)],
    from: &[f64],
    [lo, hi]: [f64; 2],
) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
    let mut theta = from.to_vec();
    let mut q = fam.shares(&theta, target)?;
    let mut cost = residuals(&q, aim).norm_squared();
    let mut lambda = 1e-2;
    // The differences' step, mm: wide first, to see over the kinks where the flow's pattern
    // changes (the shares are smooth only piecewise), then finer each time the search stalls.
    let mut h = 0.1;
    for _ in 0..400 {
        if cost < 1e-14 {
            break;
        }
        if lambda > 1e6 {
            if h <= 1e-3 {
                break;
            }
            h /= 10.0;
            lambda = 1e-2;
        }
        let r = residuals(&q, aim);
        let mut jac = DMatrix::zeros(aim.len(), theta.len());
        for k in 0..theta.len() {
            // A central difference, one-sided at the range's ends or where a side's shape is
            // not a die.
            let side = |h: f64| {
                let mut t = theta.clone();
                t[k] += h;
                (lo..=hi)
                    .contains(&t[k])
                    .then(|| fam.shares(&t, target).ok())
                    .flatten()
                    .map(|v| residuals(&v, aim))
            };
            match (side(h), side(-h)) {
                (Some(f), Some(b)) => jac.set_column(k, &((f - b) / (2.0 * h))),
                (Some(f), None) => jac.set_column(k, &((f - &r) / h)),
                (None, Some(b)) => jac.set_column(k, &((&r - b) / h)),
                (None, None) => {}
            }
        }
        let jt = jac.transpose();
        let a = &jt * &jac + DMatrix::identity(theta.len(), theta.len()) * lambda;
        let g = &jt * &r;
        let Some(delta) = a.cholesky().map(|c| -c.solve(&g)) else {
            lambda *= 10.0;
            continue;
        };
        let big = delta.amax();
        let scale = if big > MAX_STEP_MM {
            MAX_STEP_MM / big
        } else {
            1.0
        };
        let trial: Vec<f64> = theta
            .iter()
            .zip(delta.iter())
            .map(|(t, d)| (t + scale * d).clamp(lo, hi))
            .collect();
        match fam.shares(&trial, target) {
            Ok(qt) if residuals(&qt, aim).norm_squared() < cost => {
                cost = residuals(&qt, aim).norm_squared();
                theta = trial;
                q = qt;
                lambda = (lambda / 3.0).max(1e-9);
            }
            _ => lambda *= 4.0,
        }
    }
    Ok((theta, q))
}

/// Checks `cfg` and finds its family: the die a mesh, uniform, its labels the target's.
fn family(cfg: &MeshConfig) -> Result<(Family, Vec<Vec<usize>>)> {
    let [lo, hi] = cfg.range;
    if !(lo.is_finite() && hi.is_finite() && lo <= 0.0 && 0.0 <= hi && lo < hi) {
        return Err(Error::field(
            Field::Range,
            format!("{FACETS}={lo}:{hi}"),
            "each facet's move from the start, mm: LO ≤ 0 ≤ HI, LO < HI",
        ));
    }
    if !(1..=20).contains(&cfg.rounds) {
        return Err(Error::field(
            Field::Points,
            cfg.rounds,
            "rounds: from 1 to 20",
        ));
    }
    if cfg.check_rolls == 0 || cfg.check_rolls > crate::run::spec::MAX_ROLLS {
        return Err(Error::field(
            Field::CheckRolls,
            cfg.check_rolls,
            format!(
                "the check's throws: from 1 to {}",
                crate::run::spec::MAX_ROLLS
            ),
        ));
    }
    let scene = &cfg.spec.scene;
    let Some(shape) = scene.die.as_shape() else {
        return Err(Error::field(
            Field::Free,
            FACETS,
            "the die has no facets to move: give a mesh (--die FILE, --mesh) or a named polyhedron (--shape)",
        ));
    };
    if !scene.features.is_default() {
        return Err(Error::field(
            Field::Free,
            FACETS,
            "a design of its facets is of a uniform die: its centre of mass moves with them \
             (leave out --com, --shell and the die file's load)",
        ));
    }
    if scene.mode != crate::model::scene::Mode::ThreeD {
        return Err(Error::field(Field::Free, FACETS, "a mesh is a 3D die"));
    }
    let fam = Family::of(shape).map_err(|e| Error::field(Field::Free, FACETS, e))?;
    let groups = super::groups(&cfg.target, &scene.labels(cfg.layout))?;
    Ok((fam, groups))
}

/// Checks `cfg` before anything rolls.
pub fn check(cfg: &MeshConfig) -> Result<()> {
    family(cfg).map(|_| ())
}

/// The run of `spec` with its die `shape`.
fn with_shape(spec: &RunSpec, shape: Shape, rolls: u64, seed: u64) -> Result<RunSpec> {
    let mut s = spec.clone();
    s.scene.die = crate::model::scene::Form::shape(shape);
    s.rolls = rolls;
    s.throws.seed = seed;
    s.validate(false)?;
    Ok(s)
}

/// Runs the design. `None` if a stop request ended it.
pub fn run(cfg: &MeshConfig, runner: &Runner) -> Result<Option<MeshDesign>> {
    let (fam, _) = family(cfg)?;
    let t: Vec<f64> = cfg.target.iter().map(|(_, p)| *p).collect();
    let n = cfg.spec.rolls;
    let at = |e: String| Error::field(Field::Free, FACETS, e);
    let mut done = 0u64;
    // A shape thrown `rolls` times at `seed`: each target outcome's count.
    let mut thrown = |shape: Shape, rolls: u64, seed: u64| -> Result<Option<Vec<u64>>> {
        let spec = with_shape(&cfg.spec, shape, rolls, seed)?;
        let base = done;
        let progress = |k| (runner.progress)(base + k);
        let got = faces_at(&spec, cfg.layout, &runner.with_progress(&progress))?;
        done += rolls;
        Ok(got.map(|(l, c)| gathered(&l, &c, &cfg.target)))
    };
    let round = |aimed, quasi_static, counts: Vec<u64>, seed, largest_move| {
        let nf = counts.iter().sum::<u64>().max(1) as f64;
        let p: Vec<f64> = counts.iter().map(|&c| c as f64 / nf).collect();
        let chi2 = chi_square(&p, &t, nf, &vec![0.0; t.len()]);
        Round {
            aimed,
            quasi_static,
            seed,
            counts,
            p,
            chi2,
            largest_move,
        }
    };
    let mut theta = vec![0.0; fam.free.len()];
    let seed0 = cfg.spec.throws.seed ^ ROUND_SEED;
    let q0 = fam.shares(&theta, &cfg.target).map_err(at)?;
    let Some(c0) = thrown(fam.shape(&theta).map_err(at)?, n, seed0)? else {
        return Ok(None);
    };
    let mut rounds = vec![round(None, q0, c0, seed0, 0.0)];
    for k in 1..=cfg.rounds {
        let aim = aim_of(rounds.last().expect("the start"), &t);
        let (next, q) = solve(&fam, &aim, &cfg.target, &theta, cfg.range).map_err(at)?;
        theta = next;
        let seed = seed0.wrapping_add(k as u64);
        let Some(c) = thrown(fam.shape(&theta).map_err(at)?, n, seed)? else {
            return Ok(None);
        };
        rounds.push(round(Some(aim), q, c, seed, fam.largest_move(&theta)));
    }
    let aimed = aim_of(rounds.last().expect("the start"), &t);
    let (theta, quasi_static) = solve(&fam, &aimed, &cfg.target, &theta, cfg.range).map_err(at)?;
    let design = fam.shape(&theta).map_err(at)?;
    // The design's own error: the last round's throws', as the gain passes it on.
    let design_err: Vec<f64> = t
        .iter()
        .map(|p| GAIN * (p * (1.0 - p) / n as f64).sqrt())
        .collect();
    let check_seed = cfg.spec.throws.seed ^ CHECK_SEED;
    let Some(counts) = thrown(design.clone(), cfg.check_rolls, check_seed)? else {
        return Ok(None);
    };
    let Some(start_counts) = thrown(
        fam.shape(&vec![0.0; theta.len()]).map_err(at)?,
        cfg.check_rolls,
        check_seed,
    )?
    else {
        return Ok(None);
    };
    let check = judge(check_seed, &counts, &t, &design_err);
    let none = vec![0.0; t.len()];
    let start_check = judge(check_seed, &start_counts, &t, &none);
    let outcomes: Vec<String> = cfg.target.iter().map(|(l, _)| l.clone()).collect();
    let by_class = (cfg.named_target == Some(Named::TwoD6))
        .then(|| classes(&outcomes))
        .flatten()
        .map(|c| by_class(c, &t, &design_err, check_seed, &counts, &start_counts));
    let [lo, hi] = cfg.range;
    let at_range_end = theta
        .iter()
        .any(|&d| (d - lo).min(hi - d) <= 0.01 * (hi - lo));
    let reachable = check.p_value >= 0.05;
    let (vertices, triangles) = fam.mesh(&theta).map_err(at)?;
    let mut d = MeshDesign {
        config: cfg.clone(),
        outcomes,
        mirror: fam.mirror.is_some(),
        free: fam.free.len(),
        largest_move: fam.largest_move(&theta),
        rounds,
        aimed,
        quasi_static,
        vertices,
        triangles,
        faces: design.faces.clone(),
        at_range_end,
        check,
        start_check,
        by_class,
        reachable,
        verdict: String::new(),
    };
    d.verdict = d.verdict_text();
    Ok(Some(d))
}

/// The next aim after round `r`: its shape's quasi-static shares moved by [`GAIN`] of what its
/// throws missed the target `t` by, kept positive, summing to 1.
fn aim_of(r: &Round, t: &[f64]) -> Vec<f64> {
    let a: Vec<f64> = (0..t.len())
        .map(|k| (r.quasi_static[k] + GAIN * (t[k] - r.p[k])).max(0.2 * t[k]))
        .collect();
    let s: f64 = a.iter().sum();
    a.iter().map(|x| x / s).collect()
}

/// The checks gathered by 2d6's `classes` (names and the outcomes each gathers): the target
/// `t`, the design's error `design_err`, the design's `counts` and the start's.
fn by_class(
    (classes, groups): (Vec<String>, Vec<Vec<usize>>),
    t: &[f64],
    design_err: &[f64],
    seed: u64,
    counts: &[u64],
    start_counts: &[u64],
) -> ByClass {
    let target: Vec<f64> = groups
        .iter()
        .map(|g| g.iter().map(|&i| t[i]).sum())
        .collect();
    let err: Vec<f64> = groups
        .iter()
        .map(|g| g.iter().map(|&i| design_err[i].powi(2)).sum::<f64>().sqrt())
        .collect();
    let gather = |c: &[u64]| -> Vec<u64> {
        groups
            .iter()
            .map(|g| g.iter().map(|&i| c[i]).sum())
            .collect()
    };
    ByClass {
        check: judge(seed, &gather(counts), &target, &err),
        start_check: judge(
            seed,
            &gather(start_counts),
            &target,
            &vec![0.0; target.len()],
        ),
        classes,
        target,
    }
}

/// 2d6's classes over numbered outcomes: s and 14 − s together (2|12 … 6|8), 7 alone.
/// `None` unless every outcome is one number from 2 to 12.
fn classes(outcomes: &[String]) -> Option<(Vec<String>, Vec<Vec<usize>>)> {
    let n: Vec<u32> = outcomes
        .iter()
        .map(|o| o.parse().ok().filter(|s| (2..=12).contains(s)))
        .collect::<Option<_>>()?;
    let mut names = Vec::new();
    let mut groups = Vec::new();
    for s in 2..=7u32 {
        let g: Vec<usize> = (0..n.len())
            .filter(|&i| n[i] == s || n[i] == 14 - s)
            .collect();
        if g.is_empty() {
            continue;
        }
        names.push(if s == 7 {
            "7".into()
        } else {
            format!("{s}|{}", 14 - s)
        });
        groups.push(g);
    }
    Some((names, groups))
}

impl MeshDesign {
    fn verdict_text(&self) -> String {
        let c = &self.check;
        let s = &self.start_check;
        let cls = self.by_class.as_ref().map_or(String::new(), |b| {
            format!(
                "; by class χ² {:.2} on {} (p {:.3}), the start's {:.2} (p {:.3})",
                b.check.chi2,
                b.check.dof,
                b.check.p_value,
                b.start_check.chi2,
                b.start_check.p_value
            )
        });
        let end = if self.at_range_end {
            ", a parameter at its range's end"
        } else {
            ""
        };
        if self.reachable {
            format!(
                "the design hits the target: χ² {:.2} on {} (p {:.3}) at {} fresh throws, its \
                 facets moved by up to {:.3} mm{end}; the start thrown the same way χ² {:.2} \
                 (p {:.3}){cls}",
                c.chi2, c.dof, c.p_value, c.n, self.largest_move, s.chi2, s.p_value
            )
        } else {
            format!(
                "unreachable in this family: the closest design, its facets moved by up to \
                 {:.3} mm{end}, gives χ² {:.2} on {} (p {:.3}) at {} fresh throws; the start \
                 thrown the same way χ² {:.2} (p {:.3}){cls}",
                self.largest_move, c.chi2, c.dof, c.p_value, c.n, s.chi2, s.p_value
            )
        }
    }

    /// The design as the terminal shows it (and `report.md` holds it).
    pub fn text(&self) -> String {
        use std::fmt::Write;
        let c = &self.config;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "design: the facets of {} ({}, {}), each moved and tilted {}–{} mm{}; {} rounds of \
             {} throws, the check {} throws at a fresh seed",
            c.die_name(),
            c.spec.engine.name(),
            c.spec.throws.style,
            c.range[0],
            c.range[1],
            if self.mirror {
                ", mirror-symmetric about x = 0"
            } else {
                ""
            },
            c.rounds,
            c.spec.rolls,
            c.check_rolls
        );
        if let Some(n) = c.named_target {
            let _ = writeln!(s, "target: {n}, over the die's labels");
        }
        let _ = writeln!(
            s,
            "\n  {:<6} {:>9} {:>8} {:>10}   (χ² of the throws against the target, {} dof)",
            "round",
            "moved mm",
            "χ²",
            "rolls",
            self.outcomes.len() - 1
        );
        for (k, r) in self.rounds.iter().enumerate() {
            let name = if k == 0 {
                "start".into()
            } else {
                k.to_string()
            };
            let _ = writeln!(
                s,
                "  {:<6} {:>9.3} {:>8.2} {:>10}",
                name,
                r.largest_move,
                r.chi2,
                r.counts.iter().sum::<u64>()
            );
        }
        let _ = writeln!(
            s,
            "\n  {:<8} {:>8} {:>8} {:>8} {:>17} {:>7} {:>17}",
            "outcome", "target", "aimed", "at rest", "check", "z", "start's check"
        );
        for (k, o) in self.outcomes.iter().enumerate() {
            let ch = &self.check;
            let st = &self.start_check;
            let _ = writeln!(
                s,
                "  {:<8} {:>8.4} {:>8.4} {:>8.4} {:>8.4} ± {:.4} {:>+7.2} {:>8.4} ± {:.4}",
                o,
                c.target[k].1,
                self.aimed[k],
                self.quasi_static[k],
                ch.p[k],
                ch.err[k].hypot(ch.design_err[k]),
                ch.z[k],
                st.p[k],
                st.err[k]
            );
        }
        let _ = writeln!(s, "\n{}", self.verdict);
        s
    }

    /// The design figure's bars, as a feature's.
    pub fn bars(&self) -> Vec<crate::report::figures::design::DesignBar> {
        super::bars(
            &self.outcomes,
            &self.config.target,
            &self.check,
            Some(&self.quasi_static),
        )
    }

    /// The design's mesh as OBJ, mm.
    pub fn obj(&self) -> String {
        use std::fmt::Write;
        let mut s = String::from("# dicephys design --free facets: the designed die, mm\n");
        for v in &self.vertices {
            let _ = writeln!(s, "v {:?} {:?} {:?}", v[0], v[1], v[2]);
        }
        for t in &self.triangles {
            let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        s
    }

    /// The design's die file (TOML): its mesh `obj` beside it, its density, each resting
    /// facet's label.
    pub fn die_file(&self, obj: &str) -> String {
        use std::fmt::Write;
        let c = &self.config;
        let reads = c.spec.scene.die.as_shape().map_or(Reads::Up, |s| {
            if s.printed.is_some() {
                s.reads
            } else {
                Reads::Down
            }
        });
        let mut s = format!(
            "# dicephys design --free facets ({} rounds, seed {}): {}\nmesh = \"{obj}\"\n\
             density = {:?}\nreads = {}\nlabels = [\n",
            c.rounds,
            c.spec.throws.seed,
            self.verdict,
            c.spec.scene.density,
            serde_json::to_string(&reads).unwrap_or_default()
        );
        for f in &self.faces {
            let _ = writeln!(
                s,
                "  {{ normal = [{:.6}, {:.6}, {:.6}], label = \"{}\" }},",
                f.normal[0], f.normal[1], f.normal[2], f.label
            );
        }
        s.push_str("]\n");
        s
    }
}

/// `design --out`'s files for a mesh design in `dir` (claimed by then): `design.json`,
/// `report.md` and `report.html`, the figure `design.svg`, `.png`, and the die: `design.obj`
/// and its die file `design.toml`.
pub fn write(dir: &std::path::Path, json: &str, d: &MeshDesign) -> Result<()> {
    let c = &d.config;
    let title = format!(
        "the facets of {}, {}, {}: {} fresh throws",
        c.die_name(),
        c.spec.engine.name(),
        c.spec.throws.style,
        d.check.n
    );
    crate::report::figures::design::design(dir, "design", &title, &d.bars())?;
    crate::run::io::write_atomic(&dir.join("design.obj"), d.obj().as_bytes())?;
    crate::run::io::write_atomic(
        &dir.join("design.toml"),
        d.die_file("design.obj").as_bytes(),
    )?;
    crate::run::io::write_atomic(&dir.join("design.json"), json.as_bytes())?;
    crate::report::html::write_text_report(dir, "Design", &d.text(), &["design"])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// V1 numbered as docs/results/real-dice/v1-numbers.toml numbers it, its mesh the copy in
    /// tests/data.
    fn v1() -> Shape {
        let root = env!("CARGO_MANIFEST_DIR");
        let text =
            std::fs::read_to_string(format!("{root}/docs/results/real-dice/v1-numbers.toml"))
                .unwrap()
                .lines()
                .map(|l| {
                    if l.starts_with("mesh = ") {
                        format!("mesh = \"{root}/tests/data/hendecahedron_v1.obj\"")
                    } else {
                        l.to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n");
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let file = std::env::temp_dir().join(format!("v1-numbers-{}-{k}.toml", std::process::id()));
        std::fs::write(&file, text).unwrap();
        let read: crate::model::mass::ReadFile = &crate::run::io::read_die_bytes;
        let shape = crate::model::mass::described_shape(Some(&file), None, None, None, read);
        let _ = std::fs::remove_file(&file);
        shape.unwrap().unwrap()
    }

    #[test]
    fn v1s_mirror_is_found_and_every_facet_keeps_its_label() {
        let shape = v1();
        let fam = Family::of(&shape).unwrap();
        // 18 planes, one a triangle (three sides are two triangles within the hull's coplanar
        // tolerance of each other, which the OBJ's printed digits keep apart), every one
        // labelled: 6 on the mirror plane (moved and tilted within it), 6 pairs (moved and
        // tilted both ways).
        assert_eq!(fam.start.len(), 18);
        assert!(fam.start.iter().all(|(_, _, l)| l.is_some()));
        assert!(fam.mirror.is_some());
        assert_eq!(fam.free.len(), 6 * 2 + 6 * 3);
        // Unmoved, the family's die is the start: the same outcomes and quasi-static shares.
        let again = fam.shape(&vec![0.0; fam.free.len()]).unwrap();
        let a = crate::theory::quasi_static::shape_labels(&shape, &Vector3::zeros()).unwrap();
        let b = crate::theory::quasi_static::shape_labels(&again, &Vector3::zeros()).unwrap();
        assert_eq!(a.len(), 11);
        assert_eq!(b.len(), 11);
        for (la, pa) in &a {
            let pb = b.iter().find(|(lb, _)| lb == la).map(|(_, p)| *p);
            assert!(
                pb.is_some_and(|pb| (pa - pb).abs() < 1e-9),
                "{la}: {pa} against {pb:?}"
            );
        }
    }

    #[test]
    fn the_solve_finds_facets_whose_quasi_static_shares_are_2d6() {
        // The quasi-static theory alone: V1 at rest is near 2d6 (2|12 0.070 against 0.056);
        // the solve brings every label to its 2d6 share, mirror faces equal.
        let shape = v1();
        let fam = Family::of(&shape).unwrap();
        let labels: Vec<String> = shape.outcome_labels();
        let target = Named::TwoD6.over(&labels).unwrap();
        let aim: Vec<f64> = target.iter().map(|(_, p)| *p).collect();
        let (theta, q) =
            solve(&fam, &aim, &target, &vec![0.0; fam.free.len()], [-3.0, 3.0]).unwrap();
        for ((l, t), q) in target.iter().zip(&q) {
            assert!((q - t).abs() < 1e-6, "{l}: {q} against {t}");
        }
        assert!(theta.iter().all(|d| d.abs() <= 3.0));
        assert!(fam.largest_move(&theta) > 0.01);
    }

    #[test]
    fn twod6_classes_pair_s_with_14_less_s() {
        let o: Vec<String> = ["7", "6", "8", "2", "12"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let (names, groups) = classes(&o).unwrap();
        assert_eq!(names, ["2|12", "6|8", "7"]);
        assert_eq!(groups, vec![vec![3, 4], vec![1, 2], vec![0]]);
        assert!(classes(&["2|12".to_string()]).is_none());
    }
}
