//! Calibration: what restitution, friction and throw make the simulator match measured
//! counts, how sure that is, and what it then predicts. The statistics of it, with no rolling
//! (that is [`crate::studies::fit`]'s):
//!
//! 1. [`data`]: the counts, one row per block and surface.
//! 2. [`params`]: the free parameters (e, μ per surface or shared; κ and the spin scale per
//!    thrower), their ranges and unit coordinates, and the simulation method.
//! 3. [`design`]: the fixed parameter points each block is simulated at, and the result: its
//!    counts and a surrogate (a polynomial multinomial logit) through them.
//! 4. [`estimate`]: the Dirichlet-multinomial likelihood of every row (the surrogate's noise
//!    folded in), its maximum, profile-likelihood intervals, the joint 2σ region, χ², and
//!    posterior draws.
//! 5. [`predict`]: probabilities at posterior draws, with an error from the parameters and one
//!    from the simulation.
//!
//! Why independent throws at each design point rather than common random numbers (the same
//! keyed throws at every point): the surrogate averages over the points, and common throws
//! give every point the same noise, so averaging removes none of it; independent throws give
//! the surrogate's level the noise of all the points' rolls together. Common throws help a
//! method that compares points one by one (a grid search, a finite difference); a surrogate
//! does not. Measured (`fit --common-throws`, docs/results/calibration.md): on 20 paired
//! recoveries no difference is resolved, and none favours common throws.

pub mod bootstrap;
pub mod check;
pub mod compare;
pub mod crossval;
pub mod data;
pub mod design;
pub mod dice;
pub mod discrepancy;
pub mod estimate;
pub mod heldout;
pub mod other_die;
pub mod paper;
pub mod params;
pub mod predict;
pub mod proper;
pub mod recovery;
pub mod request;
pub mod rolled;
pub mod scores;

use crate::error::{Error, Field, Result};
use crate::model::throws::Range;
use data::DataRow;
use design::{Design, DesignSpec};
use estimate::{Estimate, Likelihood, Search};
use params::{Method, ModelSpec, Param};
use serde::{Deserialize, Serialize};

/// What to fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitConfig {
    /// The measured counts.
    pub rows: Vec<DataRow>,
    /// What is free, where.
    pub model: ModelSpec,
    /// How each throw is simulated.
    pub method: Method,
    /// How densely each block is simulated.
    pub design: DesignSpec,
    /// The search's settings.
    pub search: Search,
    /// The throws' seed.
    pub seed: u64,
}

impl FitConfig {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        self.model.validate()?;
        self.design.validate(self.model.free.len())?;
        if self.rows.is_empty() {
            return Err(Error::Invalid("no rows to fit".into()));
        }
        let params = self.model.params(&self.rows);
        if params.len() > 40 {
            return Err(Error::Invalid(format!(
                "{} free parameters: at most 40 (share e or mu across surfaces?)",
                params.len()
            )));
        }
        let cells: usize = self.rows.iter().map(|r| r.groups.len() - 1).sum();
        if params.len() > cells {
            return Err(Error::Invalid(format!(
                "{} free parameters from {cells} independent counts: the data cannot fix them \
                 (fewer free parameters, or shared ones)",
                params.len()
            )));
        }
        self.check_shape()?;
        if self.model.fixed.throw == params::FixedThrow::Rest {
            if let Some(k) = self.model.free.iter().find(|k| {
                matches!(
                    k,
                    params::Kind::Kappa
                        | params::Kind::Spin
                        | params::Kind::Height
                        | params::Kind::Speed
                )
            }) {
                return Err(Error::field(
                    Field::Free,
                    k.name(),
                    "a die released at rest has no spin, height, speed or κ to fit",
                ));
            }
        }
        if self.model.fixed.throw == params::FixedThrow::Flip
            && self.model.is_free(params::Kind::Kappa)
        {
            return Err(Error::field(
                Field::Free,
                "kappa",
                "a flip spins the die about a diameter, not near its long axis: it has no κ",
            ));
        }
        self.check_contact_laws()?;
        self.check_dice()?;
        self.check_pips()?;
        self.check_rounding()?;
        let com_free = [params::Kind::ComX, params::Kind::ComY, params::Kind::ComZ]
            .into_iter()
            .filter(|&k| self.model.is_free(k));
        for kind in com_free {
            let r = self.model.range(kind);
            let axis = kind as usize - params::Kind::ComX as usize;
            for row in &self.rows {
                let half = 500.0 * [row.block.breadth, row.block.width, row.block.length][axis];
                if r.lo <= -half || r.hi >= half {
                    return Err(Error::field(
                        Field::Range,
                        format!("{kind}={r}"),
                        format!(
                            "the centre of mass must stay inside the die: within ±{half} mm on \
                             {} (row '{}')",
                            row.block,
                            data::shown(&row.label)
                        ),
                    ));
                }
            }
        }
        // The method (engine, step, roll) and the die for every row's block, at the box's
        // centre and its lowest and highest corners (a centre of mass or a pip depth at the
        // box's ends must still fit inside the die).
        let dims = self.model.free.len();
        for r in &self.rows {
            // The ends first: a die refused there is named by the range's own numbers.
            for u in [0.0, 1.0, 0.5] {
                let v = params::values(&self.model.fixed, &self.model.whole_axes(), &vec![u; dims]);
                self.method
                    .of_row(r)
                    .spec(r.block, r.mode, &v, self.seed, self.design.rolls)
                    .validate(false)
                    .map_err(|e| self.at_box_end(e))?;
            }
        }
        Ok(())
    }

    /// A die refused at the end of a free parameter's box, named by that box (`--range
    /// com_z=-7.9:7.9`), not by the flag that gives the die outright, which the user may not
    /// have written (reliability round 5, class G).
    fn at_box_end(&self, e: Error) -> Error {
        let Error::Field { field, value, why } = &e else {
            return e;
        };
        if *field == Field::ShellWall && self.model.is_free(params::Kind::Infill) {
            // The wall a free infill fills: the die's own, or one the user never wrote.
            return Error::field(
                Field::Free,
                "infill",
                format!(
                    "fills the die's shell wall, {value} mm (its own, else {} mm), which {why}: \
                     give the die a thinner wall (--shell WALL,INFILL)",
                    crate::model::mass::DEFAULT_WALL * 1e3
                ),
            );
        }
        let kinds: &[params::Kind] = match field {
            Field::Com => &[params::Kind::ComX, params::Kind::ComY, params::Kind::ComZ],
            Field::PipsDepth => &[params::Kind::PipDepth],
            _ => return e,
        };
        let boxes: Vec<String> = kinds
            .iter()
            .filter(|k| self.model.is_free(**k))
            .map(|k| format!("{k}={}", self.model.range(*k)))
            .collect();
        if boxes.is_empty() {
            return e;
        }
        let what = match field {
            Field::Com => "centre of mass",
            _ => "pip depth",
        };
        Error::field(
            Field::Range,
            boxes.join(","),
            format!("the die at the box's end, its {what} {value} mm, {why}; narrow the range"),
        )
    }

    /// A free pip depth needs a die with pips, a cuboid's (one die for every row by now:
    /// several dice are refused it, [`FitConfig::check_dice`]); a free pip depth or infill
    /// cannot be told from a free centre of mass.
    fn check_pips(&self) -> Result<()> {
        let method = self.method.of_row(&self.rows[0]);
        if self.model.is_free(params::Kind::PipDepth)
            && method
                .die
                .shape
                .as_deref()
                .is_some_and(|s| s.as_box().is_none())
        {
            return Err(Error::field(
                Field::Free,
                "pip_depth",
                "a die of any shape has no pips (they are drilled in a cuboid's faces): free \
                 com_x, com_y or com_z",
            ));
        }
        if self.model.is_free(params::Kind::PipDepth) && method.die.features.pips.is_none() {
            return Err(Error::field(
                Field::Free,
                "pip_depth",
                "the die has no pips to vary: give them (--pips D,H or a die file's [pips])",
            ));
        }
        let com_free = [params::Kind::ComX, params::Kind::ComY, params::Kind::ComZ]
            .into_iter()
            .filter(|&k| self.model.is_free(k));
        if self.model.is_free(params::Kind::PipDepth) && com_free.clone().count() > 0 {
            return Err(Error::field(
                Field::Free,
                "pip_depth",
                "and a free centre of mass cannot be told apart: pips bias a die through the \
                 centre of mass they move, and a free centre is given outright; free one or \
                 the other",
            ));
        }
        if self.model.is_free(params::Kind::Infill) && com_free.clone().count() > 0 {
            return Err(Error::field(
                Field::Free,
                "infill",
                "and a free centre of mass cannot be told apart: the infill biases a die \
                 through the centre of mass it moves, and a free centre is given outright; free \
                 one or the other",
            ));
        }
        Ok(())
    }

    /// A free rounding: on a box its closed forms take any radius below its half sides (the
    /// scene's checks, at the box's ends below); any other convex die must take the range's
    /// largest radius in its hull and be a die its rounding has not been given already.
    fn check_rounding(&self) -> Result<()> {
        if !self.model.is_free(params::Kind::EdgeRadius) {
            return Ok(());
        }
        let hi = self.model.range(params::Kind::EdgeRadius).hi;
        for row in &self.rows {
            let method = self.method.of_row(row);
            let Some(shape) = method.die.shape.as_deref().filter(|s| s.as_box().is_none()) else {
                continue;
            };
            let why = if shape.radius > 0.0 {
                Some(format!(
                    "{} is rounded already ({} mm, --edge-radius): leave its rounding to the \
                     fit",
                    shape.name,
                    shape.radius * 1e3
                ))
            } else {
                shape
                    .rounded(hi / 1000.0)
                    .err()
                    .map(|why| format!("{}: {why}", shape.name))
            };
            if let Some(why) = why {
                return Err(Error::field(
                    Field::Range,
                    format!("edge_radius={}", self.model.range(params::Kind::EdgeRadius)),
                    why,
                ));
            }
        }
        Ok(())
    }

    /// The contact's own laws (a bounce threshold, a soft table, static friction) are
    /// Bullet's, rolling resistance Bullet's and Rapier's; a soft table's range must last two
    /// steps of the fit's.
    fn check_contact_laws(&self) -> Result<()> {
        use crate::engine::EngineKind;
        let engine = self.method.engine;
        // Rolling resistance where the engine has it in 3D (a 2D row on Rapier's 2D body is
        // refused by its run's own specification).
        let rolling = engine.resists_rolling(crate::model::scene::Mode::ThreeD);
        let bullet = engine == EngineKind::Bullet;
        for (kind, what, has) in [
            (params::Kind::Rolling, "rolling resistance", rolling),
            (params::Kind::Bounce, "bounce threshold", bullet),
            (params::Kind::ContactTime, "soft contact", bullet),
            (
                params::Kind::StaticRatio,
                "static friction apart from sliding friction",
                bullet,
            ),
        ] {
            if self.model.is_free(kind) && !has {
                return Err(Error::field(
                    Field::Free,
                    kind.name(),
                    format!("{} has no {what}: give --engine bullet", self.method.engine),
                ));
            }
        }
        if self.model.is_free(params::Kind::ContactTime) {
            // A soft contact shorter than two steps is not resolved: the scene refuses it at
            // every design point below, so the range is checked against the step here.
            let lo = self.model.range(params::Kind::ContactTime).lo;
            let least = crate::model::scene::MIN_CONTACT_STEPS * self.method.dt * 1e3;
            if lo < least {
                return Err(Error::field(
                    Field::Range,
                    format!("contact_time={lo}"),
                    format!(
                        "a soft contact must last at least two steps: from {least} ms at a step \
                         of {} s",
                        self.method.dt
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Several dice (a `die` column naming more than one, or one beside the command line's):
    /// the surface's and the thrower's parameters are shared across them, but a die's own
    /// centre of mass or pip depth would belong to one die, and is refused (a free infill is
    /// the printer's setting, each die's in its own wall, and is kept).
    fn check_dice(&self) -> Result<()> {
        let mut dice: Vec<String> = dice::names(&self.rows)
            .into_iter()
            .map(String::from)
            .collect();
        if let Some(s) = self
            .rows
            .iter()
            .find(|r| r.die.is_none())
            .and(self.method.die.shape.as_ref())
        {
            dice.push(s.name.clone());
        }
        if dice.len() < 2 {
            return Ok(());
        }
        let own = [
            params::Kind::ComX,
            params::Kind::ComY,
            params::Kind::ComZ,
            params::Kind::PipDepth,
        ];
        match own.iter().find(|k| self.model.is_free(**k)) {
            Some(k) => {
                Err(Error::field(
                    Field::Free,
                    k.name(),
                    format!(
                    "is one die's own, and the rows name {} dice ({}): free it in a fit of one \
                     die",
                    dice.len(),
                    dice.iter().map(|d| data::shown(d)).collect::<Vec<_>>().join(", ")
                ),
                ))
            }
            None => Ok(()),
        }
    }

    /// Each die of any shape and its rows agree: every row counts its die's faces by label, in
    /// its order ([`data::on_shape`]), and a die of any shape is thrown in a tumble or a toss
    /// (it has no long axis for the paper's or a hand's throw, so no κ); a row of no die of any
    /// shape counts no faces by label.
    fn check_shape(&self) -> Result<()> {
        let mut shaped = None;
        for r in &self.rows {
            let method = self.method.of_row(r);
            let Some(shape) = &method.die.shape else {
                if r.of_shape() {
                    return Err(Error::Invalid(format!(
                        "row '{}' counts the faces of a die of any shape (face_{}…): give the \
                         die (--shape, a mesh --die, or the row's die column)",
                        data::shown(&r.label),
                        r.labels[0]
                    )));
                }
                continue;
            };
            if r.labels != shape.outcome_labels() {
                return Err(Error::Invalid(format!(
                    "row '{}' does not count {}'s faces in its order (read the rows with \
                     calibration::data::on_shape)",
                    data::shown(&r.label),
                    shape.name
                )));
            }
            shaped.get_or_insert(shape.name.clone());
        }
        let Some(name) = shaped else {
            return Ok(());
        };
        let why = format!(
            "{name} is thrown in a tumble or a toss: the paper's and a hand's throw spin a die \
             about its long axis, which it has not"
        );
        if self.model.is_free(params::Kind::Kappa) {
            return Err(Error::field(Field::Free, "kappa", why));
        }
        if !matches!(
            self.model.fixed.throw,
            params::FixedThrow::Tumble
                | params::FixedThrow::Toss
                | params::FixedThrow::Rest
                | params::FixedThrow::Flip
        ) {
            let throw = match self.model.fixed.throw {
                params::FixedThrow::Hand(k) | params::FixedThrow::HandToss(k) => k.to_string(),
                _ => "paper".into(),
            };
            return Err(Error::field(Field::Kappa, throw, why));
        }
        Ok(())
    }

    /// The rolls the first pass makes.
    pub fn total_rolls(&self) -> u64 {
        let per_key = design::points(self.model.free.len(), self.design.points).len() as u64;
        design::keys(&self.rows, &self.model).len() as u64 * per_key * self.design.rolls
    }
}

/// What a fit cost.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct FitCost {
    /// Rolls simulated (or read back from the checkpoints).
    pub rolls: u64,
    /// Of which did not settle on a face (unknown, unconverged, failed): left out.
    pub unsettled: u64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// CPU seconds of this process.
    pub cpu_s: f64,
}

/// A fit's result: everything `predict` needs, and what the report shows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitResult {
    /// What was fitted.
    pub config: FitConfig,
    /// The free parameters, in the estimate's order (with the second pass's ranges).
    pub params: Vec<Param>,
    /// The first pass's parameters, when a second pass refined them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_pass: Option<Vec<estimate::ParamFit>>,
    /// Every pass, in order: the first over the whole ranges, a second over the box narrowed
    /// from it, and any that widened a box that cut a parameter or tightened one looser than
    /// its region (a fit.json from before passes were recorded has none).
    #[serde(default)]
    pub passes: Vec<Pass>,
    /// Why the passes did not settle, if they did not: after the last pass, a box still cutting
    /// a parameter or still looser than its region (the estimate is then where the passes
    /// stopped, not an answer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unresolved: Option<String>,
    /// The blocks simulated, with their surrogates.
    pub designs: Vec<Design>,
    /// The estimate.
    pub estimate: Estimate,
    /// Every row predicted by a fit of the others (leave one out; empty for a fit of fewer
    /// than three rows, a first pass, or a fit.json written before fits scored their rows):
    /// what `dicephys compare` sets two models' fits side by side by.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub loo: Vec<scores::LooRow>,
    /// How far the rows predicted without themselves miss beyond their errors, outcome by
    /// outcome, which widens every prediction of a block the fit did not see (`null` where
    /// fewer than three rows were scored).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub discrepancy: Option<discrepancy::Discrepancy>,
    /// The leave-one-out rows' proper scores summed, beside the baselines' (each row's are in
    /// `loo[].scores`); left out where there are none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loo_scores: Option<proper::Scores>,
    /// Where the rows name their dice: each die's rows, predicted by a fit of the other dice,
    /// their proper scores summed per die (`loo_scores` sums them all).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub loo_dice: Vec<proper::DieScores>,
    /// Every row rolled afresh at the estimate, its counts' Pearson χ² against those shares:
    /// the model's goodness of fit at its estimate, not the surrogate's (none for a first
    /// pass, or a fit written before 2026-12-03).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rolled: Option<rolled::Rolled>,
    /// What it cost.
    pub cost: FitCost,
    /// The command line that made it.
    pub command_line: String,
    /// This program's version.
    pub dicephys_version: String,
    /// When it ended, UTC.
    pub date_utc: String,
}

/// One pass of a fit: the box its designs were simulated over, and what it rolled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pass {
    /// Each free parameter's range in this pass, by name.
    #[serde(rename = "box")]
    pub bounds: Vec<params::Narrowed>,
    /// Rolls made for it (or read back from the checkpoints). A design an earlier pass already
    /// simulated (its block's parameters' ranges unchanged) is taken from that pass, not rolled
    /// again, and costs none.
    pub rolls: u64,
    /// The parameters whose maximum or 2σ interval reached a face of this pass's box that is
    /// not their range's own (the next pass widened them there; the last pass's, after
    /// [`MAX_MORE_PASSES`], were left cut).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cut: Vec<Cut>,
    /// Each parameter's maximum in this pass, in the order of `bounds` (empty in a fit.json
    /// written before passes recorded their estimates).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub values: Vec<f64>,
    /// Each parameter's 1σ profile interval in this pass.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub one_sigma: Vec<[f64; 2]>,
}

impl Pass {
    /// A pass over `params`' ranges that rolled `rolls`, nothing cut (yet), no estimate.
    pub fn over(params: &[Param], rolls: u64) -> Pass {
        Pass {
            bounds: params
                .iter()
                .map(|p| params::Narrowed {
                    param: p.name(),
                    range: p.range,
                })
                .collect(),
            rolls,
            cut: vec![],
            values: vec![],
            one_sigma: vec![],
        }
    }

    /// [`Pass::over`], with the estimate `est` made over its box.
    pub fn of(params: &[Param], est: &Estimate, rolls: u64) -> Pass {
        Pass {
            values: est.params.iter().map(|p| p.value).collect(),
            one_sigma: est.params.iter().map(|p| p.one_sigma).collect(),
            ..Pass::over(params, rolls)
        }
    }
}

/// A parameter a narrowed box cut, and on which side.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cut {
    /// The parameter's name.
    pub param: String,
    /// Cut at the box's lower face (which is above its range's lower end).
    pub lower: bool,
    /// Cut at the box's upper face (which is below its range's upper end).
    pub upper: bool,
}

/// Passes after the second at most, each widening a box that cut a parameter or tightening
/// one looser than its region asks ([`tighten`]). In unit coordinates of the range, [`widen`]
/// moves a cut face out by the old box's width plus at least 0.05, and the box grows by at
/// least 0.1 a pass (unless it reaches an end of the range); so four passes move a cut face by
/// at least 0.8 plus four times the second pass's box width (at least 0.05 wide as [`narrow`]
/// draws it), which takes it to the range's end: a region that lies off one face is met within
/// four. One that jumps from face to face (a surrogate too poor to place it) may not be; the
/// fit then says it is unresolved, and why.
pub const MAX_MORE_PASSES: usize = 4;

/// How close, in a box's unit coordinate, a maximum or an interval's end must come to a face
/// to be on it (the search clamps to the faces, and an open side of a profile interval ends on
/// its grid's end point, so on a face they sit within rounding of it).
const ON_FACE: f64 = 1e-6;

/// The parameters of a refined pass's estimate that its box cut: their maximum, or an end of
/// their 2σ profile interval, on a face of a narrowed range that is not their kind's own face.
/// There the likelihood may go on rising, or the region on, past the face: the value or the
/// interval printed would be the box's, not the data's.
pub fn cuts(est: &Estimate) -> Vec<Cut> {
    let mut out = Vec::new();
    for (fit, &x) in est.params.iter().zip(&est.x) {
        let p = &fit.param;
        let u = |v: f64| p.kind.coordinate(p.range, v);
        // Where the box's faces are on the whole range: a face within rounding of the range's
        // end is that end (a fit.json whose narrowed κ ends at 9999.999999999998).
        let w = |v: f64| p.kind.coordinate(p.whole, v);
        let lower =
            w(p.range.lo) > ON_FACE && (x <= ON_FACE || u(fit.box_interval()[0]) <= ON_FACE);
        let upper = w(p.range.hi) < 1.0 - ON_FACE
            && (x >= 1.0 - ON_FACE || u(fit.box_interval()[1]) >= 1.0 - ON_FACE);
        if lower || upper {
            out.push(Cut {
                param: p.name(),
                lower,
                upper,
            });
        }
    }
    out
}

/// The next pass's box after `est`, whose box (`model`'s narrowed ranges) cut the parameters
/// in `cut`. A parameter not cut keeps its range exactly, so that the designs of the blocks
/// that only it and others like it touch keep their keys and are not rolled again. A cut one
/// gets the box [`narrow`] would draw around its new 2σ interval (which holds its new
/// maximum: the box is recentred on it), pushed out on each cut side by the old box's width
/// as well: past a cut face the region's end is unseen, so the next pass looks as far again
/// beyond it as the box spanned, and each pass reaches further than the last (the bound is at
/// [`MAX_MORE_PASSES`]) until the range's own end stops it. A box that then covers 80 % of the
/// range takes it all, as in [`narrow`].
pub fn widen(model: &ModelSpec, est: &Estimate, cut: &[Cut]) -> Vec<params::Narrowed> {
    let mut out = model.narrowed.clone();
    for c in cut {
        let Some(fit) = est.params.iter().find(|f| f.name == c.param) else {
            continue;
        };
        let p = &fit.param;
        // Coordinates on the kind's whole range, where the boxes are drawn.
        let w = |v: f64| p.kind.coordinate(p.whole, v).clamp(0.0, 1.0);
        let [lo, hi] = fit.box_interval().map(w);
        let width = w(p.range.hi) - w(p.range.lo);
        let pad = pad(lo, hi);
        let a = (lo - pad - if c.lower { width } else { 0.0 }).max(0.0);
        let b = (hi + pad + if c.upper { width } else { 0.0 }).min(1.0);
        out.retain(|n| n.param != c.param);
        if b - a < 0.8 {
            out.push(params::Narrowed {
                param: c.param.clone(),
                range: sub_range(p.kind, p.whole, a, b),
            });
        }
    }
    out
}

/// How far a box reaches past each end of a 2σ interval from `lo` to `hi` (unit coordinates):
/// half the interval's width, and at least 0.05.
fn pad(lo: f64, hi: f64) -> f64 {
    (0.5 * (hi - lo)).max(0.05)
}

/// The box drawn around a 2σ interval from `lo` to `hi` (unit coordinates of a range): the
/// interval widened by half its width on each side, and by at least 0.05, within the range;
/// `None` where that covers 80 % of the range, which then keeps it all.
fn around(lo: f64, hi: f64) -> Option<(f64, f64)> {
    let pad = pad(lo, hi);
    let (a, b) = ((lo - pad).max(0.0), (hi + pad).min(1.0));
    (b - a < 0.8).then_some((a, b))
}

/// How many rows inform each of `params` (a parameter only one row of several informs is not
/// narrowed: [`narrow`]).
fn uses(rows: &[DataRow], model: &ModelSpec, params: &[Param]) -> Vec<usize> {
    let mut uses = vec![0usize; params.len()];
    for r in rows {
        for d in model.row_dims(params, r) {
            uses[d] += 1;
        }
    }
    uses
}

/// How much wider a box may be than the one [`around`] draws from its own pass's 2σ interval
/// before the next pass tightens it. A surrogate is a polynomial over its box, least biased
/// where the box is about the region: counts rolled in a tumble (80,000 on eight blocks),
/// fitted for e, μ and κ from three first boxes at three seeds, put μ at 0.308 ± 0.063 (the nine
/// estimates' standard deviation, against a median 1σ of 0.027) when the passes stopped at the
/// first box that cut nothing, and at 0.281 ± 0.020 (1σ 0.019) with the boxes tightened, for
/// 1.8 times the rolls (docs/results/calibration.md).
pub const LOOSE: f64 = 1.5;

/// The next pass's box after `est`, whose box cut nothing: a parameter whose box is more than
/// [`LOOSE`] times as wide (on its whole range) as the one [`around`] draws from its 2σ interval
/// gets that box, recentred on the region; every other keeps its range exactly, so the designs
/// it alone touches are not rolled again. The same box as `model`'s means the passes have
/// settled: the box holds the region, and is no looser than the region asks.
pub fn tighten(rows: &[DataRow], model: &ModelSpec, est: &Estimate) -> Vec<params::Narrowed> {
    let params: Vec<Param> = est.params.iter().map(|f| f.param.clone()).collect();
    let uses = uses(rows, model, &params);
    let mut out = model.narrowed.clone();
    for (fit, &n) in est.params.iter().zip(&uses) {
        let p = &fit.param;
        if n < 2 && rows.len() > 1 {
            continue;
        }
        let w = |v: f64| p.kind.coordinate(p.whole, v).clamp(0.0, 1.0);
        let [lo, hi] = fit.box_interval().map(w);
        let Some((a, b)) = around(lo, hi) else {
            continue;
        };
        if w(p.range.hi) - w(p.range.lo) <= LOOSE * (b - a) {
            continue;
        }
        out.retain(|x| x.param != fit.name);
        out.push(params::Narrowed {
            param: fit.name.clone(),
            range: sub_range(p.kind, p.whole, a, b),
        });
    }
    out
}

/// True if `a` and `b` narrow the same parameters to the same ranges, in any order.
pub fn same_box(a: &[params::Narrowed], b: &[params::Narrowed]) -> bool {
    a.len() == b.len() && a.iter().all(|x| b.contains(x))
}

/// The second pass's box: each parameter's first-pass 2σ profile interval, widened by half its
/// width on each side (and to at least a tenth of its range), within its range. A parameter
/// whose widened interval still covers 80 % of its range keeps the whole range, and so does one
/// that only one row of several informs: a fit that leaves that row out (a leave-one-out
/// prediction) must then know nothing of it, not a box the row itself chose. A fit of one row
/// (a die counted once) has no row to leave out, and narrows every parameter: without it a
/// loaded d20's centre of mass came back from the first pass's wide box biased towards the
/// centre (−1.39 mm, 2σ −1.47 to −1.32, from 6,000 throws at −1.5).
pub fn narrow(
    rows: &[DataRow],
    model: &ModelSpec,
    params: &[Param],
    first: &Estimate,
) -> Vec<params::Narrowed> {
    let uses = uses(rows, model, params);
    let mut out = Vec::new();
    for ((p, fit), &n) in params.iter().zip(&first.params).zip(&uses) {
        if n < 2 && rows.len() > 1 {
            continue;
        }
        let u = |v: f64| p.kind.coordinate(p.range, v).clamp(0.0, 1.0);
        let [lo, hi] = fit.box_interval().map(u);
        let Some((a, b)) = around(lo, hi) else {
            continue;
        };
        out.push(params::Narrowed {
            param: p.name(),
            range: sub_range(p.kind, p.range, a, b),
        });
    }
    out
}

/// The part of `whole` from unit coordinate `a` to `b`, its ends `whole`'s own, to the bit, at 0
/// and 1: κ's and the spin's warped coordinates do not give them back exactly (κ's upper end
/// came back 9999.999999999998), and a box's edge a rounding inside its range's end would pass
/// for an edge the narrowing drew, which cuts.
fn sub_range(kind: params::Kind, whole: Range, a: f64, b: f64) -> Range {
    let at = |u: f64| match u {
        u if u <= 0.0 => whole.lo,
        u if u >= 1.0 => whole.hi,
        u => kind.value(whole, u),
    };
    Range::new(at(a), at(b))
}

/// Fits `rows` with the designs already simulated (the cheap part: no rolls).
pub fn estimate_with(
    rows: &[DataRow],
    model: &ModelSpec,
    designs: &[Design],
    search: &Search,
    watch: &crate::run::stop::Watch,
) -> Result<(Vec<Param>, Estimate)> {
    let params = model.params(rows);
    let lik = Likelihood::new(rows, designs, model, &params).stopped_by(watch.stop);
    let est = estimate::estimate(&lik, &params, search, watch)?;
    Ok((params, est))
}

/// The largest `fit.json` read (a fit of hundreds of rows is a few megabytes).
pub const MAX_FIT_BYTES: u64 = 64 << 20;

/// Reads a fit's `fit.json` and checks it: sealed (a damaged or edited file is refused, by
/// name), of a fit this version can use, and whole (its draws in its parameters' box).
pub fn read_fit(path: &std::path::Path, stop: &crate::run::stop::Stop) -> Result<FitResult> {
    let name = path.display();
    let bytes = crate::run::io::read_capped(path, MAX_FIT_BYTES, stop)?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::Invalid(format!("{name}: not UTF-8, not a fit's fit.json")))?;
    let fit: FitResult = crate::run::seal::open(text)
        .map_err(|e| Error::Invalid(format!("{name}: not a fit's fit.json as written: {e}")))?;
    fit.check()
        .map_err(|e| Error::Invalid(format!("{name}: {e}")))?;
    Ok(fit)
}

impl FitResult {
    /// Every parameter's value at the unit coordinates `x` (the maximum, a posterior draw) for
    /// `row`'s surface and thrower, the rest as the model fixes them.
    pub fn values_at(&self, row: &DataRow, x: &[f64]) -> params::Fixed {
        let model = &self.config.model;
        let dims = model.row_dims(&self.params, row);
        let axes = model.axes(&self.params, &dims);
        let local: Vec<f64> = dims.iter().map(|&d| x[d]).collect();
        params::values(&model.fixed, &axes, &local)
    }

    /// A row of no counts at `block` in `mode` on `surface`, thrown by `thrower`: where a new
    /// block's or die's parameters are read (`values_at`).
    pub fn new_row(
        surface: &str,
        thrower: &str,
        block: crate::model::block::Block,
        mode: crate::model::scene::Mode,
    ) -> DataRow {
        DataRow {
            label: "predicted".into(),
            surface: surface.into(),
            thrower: thrower.into(),
            block,
            mode,
            outcomes: Default::default(),
            counts: vec![0, 1, 1],
            groups: vec![vec![1], vec![2]],
            labels: Vec::new(),
            die: None,
        }
    }

    /// Checks that the fit is whole: its configuration valid, its parameters those of its
    /// model, its posterior draws there and inside the unit box.
    pub fn check(&self) -> Result<()> {
        self.config.validate()?;
        let dims = self.params.len();
        if self.config.model.params(&self.config.rows).len() != dims {
            return Err(Error::Invalid(format!(
                "{dims} parameters where its model has {}",
                self.config.model.params(&self.config.rows).len()
            )));
        }
        let d = &self.estimate.draws;
        if d.is_empty() {
            return Err(Error::Invalid(
                "no posterior draws (a first pass, or a damaged fit): nothing to predict from"
                    .into(),
            ));
        }
        let bad = d
            .iter()
            .chain(std::iter::once(&self.estimate.x))
            .any(|x| x.len() != dims || x.iter().any(|u| !(0.0..=1.0).contains(u)));
        if bad {
            return Err(Error::Invalid(format!(
                "its draws are not points of its {dims} parameters' box"
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use estimate::{Identified, ParamFit};
    use params::{Kind, Narrowed};

    /// A fit of e on surface `group` at `value`, 2σ `two`, searched in `range`.
    fn fit_of(group: &str, range: Range, value: f64, two: [f64; 2]) -> (ParamFit, f64) {
        fit_kind(Kind::E, group, range, value, two)
    }

    fn fit_kind(
        kind: Kind,
        group: &str,
        range: Range,
        value: f64,
        two: [f64; 2],
    ) -> (ParamFit, f64) {
        let param = Param {
            kind,
            group: group.into(),
            range,
            whole: kind.default_range(),
        };
        let x = kind.coordinate(range, value);
        let fit = ParamFit {
            asks_for_more: None,
            name: param.name(),
            param,
            value,
            one_sigma: two,
            two_sigma: two,
            identified: Identified::Yes,
            profile: vec![],
            box_two_sigma: None,
        };
        (fit, x)
    }

    fn estimate_of(fits: Vec<(ParamFit, f64)>) -> Estimate {
        Estimate {
            x: fits.iter().map(|f| f.1).collect(),
            minus_two_ln_l: 0.0,
            params: fits.into_iter().map(|f| f.0).collect(),
            rows: vec![],
            chi2: 0.0,
            dof: 0,
            p_value: None,
            region_delta: 0.0,
            bartlett: 1.0,
            other_maxima: vec![],
            maxima: vec![],
            islands: vec![],
            draws: vec![],
            concentrations: vec![],
            bootstrap: None,
            overdispersion: 1.0,
        }
    }

    #[test]
    fn a_box_much_wider_than_its_region_is_tightened_around_it_and_one_that_fits_is_kept() {
        let row = DataRow {
            label: "a".into(),
            surface: "A".into(),
            thrower: "all".into(),
            block: "140x24x20".parse().unwrap(),
            mode: crate::model::scene::Mode::ThreeD,
            outcomes: Default::default(),
            counts: vec![0, 1, 2],
            groups: vec![vec![0], vec![1], vec![2]],
            labels: vec![],
            die: None,
        };
        let rows = [row];
        let model = ModelSpec::free(&[Kind::E]);
        // e over its whole range 0.05–0.8, its 2σ interval 0.425–0.5 (unit coordinates 0.5–0.6):
        // the box drawn around it is 0.45–0.65, e 0.3875–0.5375, a fifth of the range.
        let loose = estimate_of(vec![fit_of(
            "A",
            Kind::E.default_range(),
            0.46,
            [0.425, 0.5],
        )]);
        let next = tighten(&rows, &model, &loose);
        assert_eq!(next.len(), 1, "{next:?}");
        let r = next[0].range;
        assert!(
            (r.lo - 0.3875).abs() < 1e-12 && (r.hi - 0.5375).abs() < 1e-12,
            "{r:?}"
        );
        // Over that box, the same interval asks for the same box: the passes have settled.
        let tight = ModelSpec {
            narrowed: next.clone(),
            ..model.clone()
        };
        let fits = estimate_of(vec![fit_of("A", r, 0.46, [0.425, 0.5])]);
        assert!(same_box(&tighten(&rows, &tight, &fits), &next));
        // An interval whose drawn box would cover 80 % of the range keeps the whole range.
        let wide = estimate_of(vec![fit_of("A", Kind::E.default_range(), 0.4, [0.2, 0.6])]);
        assert!(tighten(&rows, &model, &wide).is_empty());
    }

    #[test]
    fn a_box_that_cut_a_parameter_is_widened_on_that_side_and_no_other_box_moves() {
        let boxed = Range::new(0.6125, 0.7575);
        let own_end = Range::new(0.05, 0.3);
        let model = ModelSpec {
            narrowed: vec![
                Narrowed {
                    param: "e[A]".into(),
                    range: boxed,
                },
                Narrowed {
                    param: "e[C]".into(),
                    range: own_end,
                },
            ],
            ..ModelSpec::free(&[Kind::E])
        };
        let est = estimate_of(vec![
            // On the box's lower edge, which is inside the range: cut.
            fit_of("A", boxed, 0.6125, [0.6125, 0.62]),
            // Interior, on the whole range: not cut.
            fit_of("B", Kind::E.default_range(), 0.3, [0.2, 0.4]),
            // On the lower edge of a box that is the range's own: bounded by the range, not cut.
            fit_of("C", own_end, 0.05, [0.05, 0.2]),
        ]);
        let cut = cuts(&est);
        assert_eq!(
            cut,
            vec![Cut {
                param: "e[A]".into(),
                lower: true,
                upper: false
            }]
        );
        let wider = widen(&model, &est, &cut);
        // e[C] as it was; e[A] moved down by its old width (0.145) and the pad (0.05 of the
        // range's 0.75) past its cut edge, and up to its interval plus the pad.
        assert_eq!(wider.len(), 2);
        assert!(wider.contains(&model.narrowed[1]), "{wider:?}");
        let a = wider.iter().find(|n| n.param == "e[A]").unwrap().range;
        assert!((a.lo - (0.6125 - 0.145 - 0.0375)).abs() < 1e-9, "{a}");
        assert!((a.hi - (0.62 + 0.0375)).abs() < 1e-9, "{a}");
        // A region that runs past both edges of a wide box: widened to 80 % of the range or
        // more, the box takes the whole range.
        let wide = Range::new(0.2, 0.6);
        let both = estimate_of(vec![fit_of("A", wide, 0.4, [0.2, 0.6])]);
        let cut = cuts(&both);
        assert!(cut.len() == 1 && cut[0].lower && cut[0].upper, "{cut:?}");
        let wider = widen(&model, &both, &cut);
        assert!(!wider.iter().any(|n| n.param == "e[A]"), "{wider:?}");
        // κ's warp does not give its range's end back to the bit (9999.999999999998): a box
        // that reaches it is not cut there, and a widened one ends on it exactly.
        let top = Kind::Kappa.value(Kind::Kappa.default_range(), 1.0);
        let near_top = Range::new(1000.0, top);
        let k = estimate_of(vec![fit_kind(
            Kind::Kappa,
            "all",
            near_top,
            top,
            [3000.0, top],
        )]);
        assert!(cuts(&k).is_empty(), "{:?}", cuts(&k));
        let low = Range::new(1000.0, 3000.0);
        let k = estimate_of(vec![fit_kind(
            Kind::Kappa,
            "all",
            low,
            3000.0,
            [2000.0, 3000.0],
        )]);
        let cut = cuts(&k);
        let kappa = ModelSpec::free(&[Kind::Kappa]);
        let wider = widen(&kappa, &k, &cut);
        assert_eq!(wider[0].range.hi, 1e4, "{wider:?}");
    }
}
