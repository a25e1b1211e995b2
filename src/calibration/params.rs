//! What a fit varies: the contact's restitution e and friction μ (per surface, or shared by
//! all), and the throw's concentration κ and its spin, launch height and launch speed scales
//! (per thrower), each within a range, each mapped onto a unit coordinate in which the
//! surrogate and the search work.
//!
//! Coordinates: e and μ linearly; the spin, height and speed scales logarithmically; κ as log₁₀(1 + κ), which
//! runs from the tumble (κ = 0) through the hand's throws to nearly the paper's (κ = 10⁴: its
//! angles' spread is about 1/√κ ≈ 0.6°). The paper's throw itself, κ → ∞, is not a point of
//! that range but a model of its own (κ fixed: `--kappa paper`): measured, the outcomes jump
//! there (99.3x43.9x43.2: P(length vertical) 1.2 % with the paper's throw, 1.6 % at κ = 10⁵, 2 to
//! 3 % from κ = 10⁴ down), because a throw spun exactly about its horizontal long axis lands
//! flat along its whole length, and any tilt breaks that.

use crate::calibration::data::DataRow;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::model::die::Die;
use crate::model::mass::Features;
use crate::model::scene::{Form, Mode, Scene, MAX_ROLLING_RESISTANCE};
use crate::model::throws::{Range, ThrowRanges, ThrowStyle};
use crate::run::spec::{RunSpec, ThrowSpec, MAX_KAPPA};
use crate::sim::roll::{early_stop_exact, RollConfig, Rule};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// A kind of parameter.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Kind {
    /// The contact's coefficient of restitution e (per surface).
    E,
    /// The contact's coefficient of friction μ (per surface).
    Mu,
    /// The contact's rolling resistance, mm: the lever arm of the floor's push against a die
    /// rolling or turning on it (`Scene::rolling_resistance`; per surface; Bullet and Rapier in 3D).
    Rolling,
    /// The contact's bounce threshold, m/s: slower impacts do not bounce
    /// (`Scene::bounce_threshold`; per surface; Bullet only).
    Bounce,
    /// The contact time, ms: a soft table whose flat landing lasts this long
    /// (`Scene::contact_time`, `model::compliance`; per surface; Bullet only).
    ContactTime,
    /// Static friction over sliding friction, μs/μk (`Scene::static_ratio`; per surface;
    /// Bullet only).
    StaticRatio,
    /// The hand's concentration κ (per thrower).
    Kappa,
    /// A factor on the paper's spin range, 31 to 160 rad/s (per thrower).
    Spin,
    /// A factor on the paper's launch height, 0.2 to 0.4 m above the die's longest side (per
    /// thrower): below 1 a lower throw, landing slower.
    Height,
    /// A factor on the paper's launch speed, −0.2 to 0.2 m/s along the table (per thrower):
    /// above 1 a faster throw, sliding and rolling further.
    Speed,
    /// The die's centre of mass along its x (breadth) axis, mm from the geometric centre (one
    /// die for every row).
    ComX,
    /// … along y (width), mm.
    ComY,
    /// … along z (length), mm.
    ComZ,
    /// The depth of the die's pips, mm (its pips' diameter, shape and paint stay the die's).
    PipDepth,
    /// The die's edges' and corners' rounding, mm (a box's, `Features::edge_radius`; any other
    /// convex die's, `Shape::rounded`): one for every row.
    EdgeRadius,
    /// A printed die's infill fraction, 0 to 1, inside its wall (the die's own shell's, else a
    /// 1 mm one: `mass::DEFAULT_WALL`).
    Infill,
}

impl Kind {
    /// Every kind, in the order a row's coordinates take them.
    pub const ALL: [Kind; 16] = [
        Kind::E,
        Kind::Mu,
        Kind::Rolling,
        Kind::Bounce,
        Kind::ContactTime,
        Kind::StaticRatio,
        Kind::Kappa,
        Kind::Spin,
        Kind::Height,
        Kind::Speed,
        Kind::ComX,
        Kind::ComY,
        Kind::ComZ,
        Kind::PipDepth,
        Kind::EdgeRadius,
        Kind::Infill,
    ];

    /// "e", "mu", "rolling", "bounce", "contact_time", "static_ratio", "kappa", "spin", "height", "speed", "com_x", "com_y",
    /// "com_z", "pip_depth", "edge_radius" or "infill".
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// True for the surface's parameters (e, μ, rolling resistance); false for the throw's
    /// (κ, spin, height, speed).
    pub fn of_surface(self) -> bool {
        matches!(
            self,
            Kind::E
                | Kind::Mu
                | Kind::Rolling
                | Kind::Bounce
                | Kind::ContactTime
                | Kind::StaticRatio
        )
    }

    /// True for the die's parameters (its centre of mass, its pips' depth, its rounding, its
    /// infill): one die, shared by every row.
    pub fn of_die(self) -> bool {
        matches!(
            self,
            Kind::ComX | Kind::ComY | Kind::ComZ | Kind::PipDepth | Kind::EdgeRadius | Kind::Infill
        )
    }

    /// The widest range accepted: e in [0, 1], μ in [0, 5], a rolling resistance in [0, 1]
    /// mm (`MAX_ROLLING_RESISTANCE`), κ in [0, 10⁶], spin scale in
    /// [0.05, 20], height scale in [0.05, 10] (a drop of 1 to 4 cm up to 2 to 4 m), speed scale
    /// in [0.05, 50] (up to ±10 m/s), a centre of mass within ±1000 mm (the die's own sides bound it further:
    /// checked with the die), a pip depth in [0.001, 100] mm, an infill in [0, 1].
    pub fn limits(self) -> (f64, f64) {
        match self {
            Kind::E => (0.0, 1.0),
            Kind::Mu => (0.0, 5.0),
            Kind::Rolling => (0.0, MAX_ROLLING_RESISTANCE * 1e3),
            Kind::Bounce => (0.0, crate::model::scene::MAX_BOUNCE_THRESHOLD),
            Kind::ContactTime => (0.0, crate::model::scene::MAX_CONTACT_TIME * 1e3),
            Kind::StaticRatio => (1.0, crate::model::scene::MAX_STATIC_RATIO),
            Kind::Kappa => (0.0, MAX_KAPPA),
            Kind::Spin => (0.05, 20.0),
            Kind::Height => (0.05, 10.0),
            Kind::Speed => (0.05, 50.0),
            Kind::ComX | Kind::ComY | Kind::ComZ => (-1000.0, 1000.0),
            Kind::PipDepth => (0.001, 100.0),
            Kind::EdgeRadius => (0.0, 100.0),
            Kind::Infill => (0.0, 1.0),
        }
    }

    /// The default range a free parameter is searched in. e stops at 0.8: above it a long
    /// block bounces end over end for seconds (measured, 782x25x18 at dt = 1/1000: 1 ms a roll
    /// at e = 0.8, 14–20 ms at 0.9), and no surface in the paper comes near it.
    pub fn default_range(self) -> Range {
        match self {
            Kind::E => Range::new(0.05, 0.8),
            Kind::Mu => Range::new(0.1, 1.0),
            // None (0, the rigid contact of the paper's engines) to 1 mm, a die rolling on
            // cloth: a rolling-resistance coefficient δ/r of 0.1 for a 16 mm die. A hard die on
            // a hard table is nearer 0.01 mm (δ/r ≈ 10⁻³, steel on steel).
            Kind::Rolling => Range::new(0.0, 1.0),
            Kind::Kappa => Range::new(0.0, 1e4),
            // A quarter to three times the paper's spin (31–160 rad/s): a fit of real throws
            // (steel blocks on one table, issue 49) ended on 0.5–2's upper end. Not four: at
            // 4 × 160 rad/s a long block thrown in a tumble spins on the table for seconds
            // (measured, 140x24x20 at e 0.75, μ 0.12, dt 1/250: 129 ms a roll against 0.4 ms
            // at 3 ×), and a fit's design stalls in that corner.
            Kind::Spin => Range::new(0.25, 3.0),
            // From a tenth of the paper's drop (a release 2 to 4 cm above the table, a die
            // rolled from a low hand) to twice it.
            Kind::Height => Range::new(0.1, 2.0),
            // From a quarter of the paper's speed along the table to ten times it (±2 m/s).
            Kind::Speed => Range::new(0.25, 10.0),
            // A hidden weight of a few percent of a 16 mm die's mass moves its centre by about a
            // millimetre (docs/results/dice.md: 0.25 mm is seen in ~5,000 throws).
            Kind::ComX | Kind::ComY | Kind::ComZ => Range::new(-2.0, 2.0),
            Kind::PipDepth => Range::new(0.2, 1.5),
            // Sharp (a machined or printed edge, 0) to 2 mm: a casino die's edges are nearly
            // sharp, a mass-made 16 mm d6's rounded by 1 to 2 mm; past 2 mm a 16 mm die turns
            // into a pebble. Fixed before the first fit (issue 72's fifth round).
            Kind::EdgeRadius => Range::new(0.0, 2.0),
            // From a hollow shell to the solid: a slicer's 10 to 30 % lies inside.
            Kind::Infill => Range::new(0.0, 1.0),
            // None (every impact bounces, the paper's engines) to 1 m/s, half a throw's first
            // impact (a drop of 20 cm lands at 2 m/s): the settling bounces, not the landing.
            Kind::Bounce => Range::new(0.0, 1.0),
            // Two steps of the fits' 1 ms (a shorter contact is not resolved, and 0, the rigid
            // contact, is not its limit: backward Euler's damping takes the bounce first) to
            // 10 ms, a die landing on thick felt or cloth; a hard table's 0.1 ms lies below.
            Kind::ContactTime => Range::new(2.0, 10.0),
            // One friction (1, the paper's engines) to static friction twice the sliding: the
            // handbooks' dry pairs lie inside (steel on steel 0.74/0.57 = 1.3, rubber on
            // concrete 1.25, wood on wood 1.25 to 2). Fixed before the first fit (issue 72's
            // sixth round).
            Kind::StaticRatio => Range::new(1.0, 2.0),
        }
    }

    fn warp(self, v: f64) -> f64 {
        match self {
            Kind::E
            | Kind::Mu
            | Kind::Rolling
            | Kind::ComX
            | Kind::ComY
            | Kind::ComZ
            | Kind::PipDepth
            | Kind::EdgeRadius
            | Kind::Infill
            | Kind::Bounce
            | Kind::ContactTime
            | Kind::StaticRatio => v,
            Kind::Kappa => (1.0 + v).log10(),
            Kind::Spin | Kind::Height | Kind::Speed => v.ln(),
        }
    }

    fn unwarp(self, w: f64) -> f64 {
        match self {
            Kind::E
            | Kind::Mu
            | Kind::Rolling
            | Kind::ComX
            | Kind::ComY
            | Kind::ComZ
            | Kind::PipDepth
            | Kind::EdgeRadius
            | Kind::Infill
            | Kind::Bounce
            | Kind::ContactTime
            | Kind::StaticRatio => w,
            Kind::Kappa => 10f64.powf(w) - 1.0,
            Kind::Spin | Kind::Height | Kind::Speed => w.exp(),
        }
    }

    /// The value at unit coordinate `u` of `range`.
    pub fn value(self, range: Range, u: f64) -> f64 {
        let (a, b) = (self.warp(range.lo), self.warp(range.hi));
        let v = self.unwarp(a + u.clamp(0.0, 1.0) * (b - a));
        v.clamp(range.lo, range.hi)
    }

    /// The unit coordinate of `v` in `range`.
    pub fn coordinate(self, range: Range, v: f64) -> f64 {
        let (a, b) = (self.warp(range.lo), self.warp(range.hi));
        if b == a {
            return 0.5;
        }
        (self.warp(v) - a) / (b - a)
    }
}

/// The throw when κ is not free: the paper's, or a hand's with this κ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FixedThrow {
    /// The paper's throw (κ → ∞).
    Paper,
    /// A hand's throw with this κ.
    Hand(f64),
    /// The tumble: a random orientation and spin axis (the throw of a die of any shape, which
    /// has no long axis for the paper's or a hand's throw to spin it about).
    Tumble,
    /// A hand's toss (`ThrowStyle::Toss`): the tumble's directions, its magnitudes drawn with
    /// scales (the spin, height and speed kinds scale them) rather than from uniform ranges.
    Toss,
    /// Released at rest touching the floor (`ThrowStyle::Rest`): the published predictions'
    /// drop from rest, no spin, height or speed to scale.
    Rest,
    /// A hand's toss in a hand's directions with this κ: the toss's magnitudes, the hand's
    /// turn of the paper's throw (`ThrowStyle::Toss` with κ). A toss whose κ is free is this.
    HandToss(f64),
    /// A flip (`ThrowStyle::Flip`): a spin about one of the die's diameters, the toss's
    /// magnitudes.
    Flip,
}

/// Values of the parameters that are not free.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fixed {
    /// e.
    pub e: f64,
    /// μ.
    pub mu: f64,
    /// The rolling resistance, mm (0: none, the paper's).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rolling: f64,
    /// The bounce threshold, m/s (0: none, the paper's).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bounce: f64,
    /// The contact time, ms (0: the rigid contact, the paper's).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub contact_time: f64,
    /// Static friction over sliding friction (1: one friction, the paper's).
    #[serde(default = "unit", skip_serializing_if = "is_unit")]
    pub static_ratio: f64,
    /// The throw.
    pub throw: FixedThrow,
    /// The spin scale.
    pub spin: f64,
    /// The launch height's scale (1: the paper's 0.2 to 0.4 m).
    #[serde(default = "unit", skip_serializing_if = "is_unit")]
    pub height: f64,
    /// The launch speed's scale (1: the paper's ±0.2 m/s).
    #[serde(default = "unit", skip_serializing_if = "is_unit")]
    pub speed: f64,
    /// The die's centre of mass where a fit frees it, mm, per body axis (`None`: the die's
    /// own, as its description gives it).
    #[serde(default, skip_serializing_if = "is_none3")]
    pub com: [Option<f64>; 3],
    /// The die's pips' depth where a fit frees it, mm (`None`: the die's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pip_depth: Option<f64>,
    /// The die's infill fraction where a fit frees it (`None`: the die's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub infill: Option<f64>,
    /// The die's edges' rounding where a fit frees it, mm (`None`: the die's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_radius: Option<f64>,
}

fn unit() -> f64 {
    1.0
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_unit(v: &f64) -> bool {
    *v == 1.0
}

fn is_none3(c: &[Option<f64>; 3]) -> bool {
    c.iter().all(Option::is_none)
}

impl Default for Fixed {
    /// The paper's MDF values (μ = 0.29 measured, e = 0.5 estimated) and its throw.
    fn default() -> Self {
        Fixed {
            e: 0.5,
            mu: 0.29,
            rolling: 0.0,
            bounce: 0.0,
            contact_time: 0.0,
            static_ratio: 1.0,
            throw: FixedThrow::Paper,
            spin: 1.0,
            height: 1.0,
            speed: 1.0,
            com: [None; 3],
            pip_depth: None,
            infill: None,
            edge_radius: None,
        }
    }
}

/// Which parameters a fit varies, where, and how they are shared.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelSpec {
    /// The free kinds, in [`Kind::ALL`]'s order.
    pub free: Vec<Kind>,
    /// Surface kinds shared by every surface (one e, or one μ, for all).
    pub shared: Vec<Kind>,
    /// The ranges of the free kinds, one per `free` entry.
    pub ranges: Vec<Range>,
    /// The values of the kinds not free.
    pub fixed: Fixed,
    /// Ranges of single parameters, narrower than their kind's (a refined fit's second pass).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub narrowed: Vec<Narrowed>,
}

/// One parameter's own range, by its name ("e[MDF]").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Narrowed {
    /// The parameter's name.
    pub param: String,
    /// Its range.
    pub range: Range,
}

/// A design's coordinates: each free kind with its range, in [`Kind::ALL`]'s order.
pub type Axes = Vec<(Kind, Range)>;

/// The physical values at unit coordinates `x` on `axes`, the rest as `fixed`.
pub fn values(fixed: &Fixed, axes: &[(Kind, Range)], x: &[f64]) -> Fixed {
    let mut v = *fixed;
    for ((kind, range), &u) in axes.iter().zip(x) {
        let value = kind.value(*range, u);
        match kind {
            Kind::E => v.e = value,
            Kind::Mu => v.mu = value,
            Kind::Rolling => v.rolling = value,
            Kind::Bounce => v.bounce = value,
            Kind::ContactTime => v.contact_time = value,
            Kind::StaticRatio => v.static_ratio = value,
            // A toss's κ turns its directions a hand's way; any other throw's makes it a hand's.
            Kind::Kappa => {
                v.throw = match v.throw {
                    FixedThrow::Toss | FixedThrow::HandToss(_) => FixedThrow::HandToss(value),
                    _ => FixedThrow::Hand(value),
                }
            }
            Kind::Spin => v.spin = value,
            Kind::Height => v.height = value,
            Kind::Speed => v.speed = value,
            Kind::ComX => v.com[0] = Some(value),
            Kind::ComY => v.com[1] = Some(value),
            Kind::ComZ => v.com[2] = Some(value),
            Kind::PipDepth => v.pip_depth = Some(value),
            Kind::Infill => v.infill = Some(value),
            Kind::EdgeRadius => v.edge_radius = Some(value),
        }
    }
    v
}

/// One free parameter: a kind, for one surface or thrower (or "all").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Param {
    /// Its kind.
    pub kind: Kind,
    /// The surface (e, μ) or thrower (κ, spin) it belongs to, or "all" when shared; "die"
    /// for the die's own (its centre of mass, its pips).
    pub group: String,
    /// The range it is searched in (its kind's, or narrower after a first pass).
    pub range: Range,
    /// Its kind's whole range: a region that reaches a face of `range` inside this was cut by
    /// the narrowing, not bounded by the physics.
    pub whole: Range,
}

impl Param {
    /// "e[MDF]", "kappa[all]".
    pub fn name(&self) -> String {
        format!("{}[{}]", self.kind, self.group)
    }
}

impl ModelSpec {
    /// `kinds` free over their default ranges, one per surface and thrower, the rest at
    /// [`Fixed::default`].
    pub fn free(kinds: &[Kind]) -> ModelSpec {
        ModelSpec {
            free: kinds.to_vec(),
            shared: vec![],
            ranges: kinds.iter().map(|k| k.default_range()).collect(),
            fixed: Fixed::default(),
            narrowed: vec![],
        }
    }

    /// Checks the model: kinds not repeated, ranges inside their limits and not empty, fixed
    /// values physical.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::Invalid(m));
        if self.free.len() != self.ranges.len() {
            return bad("one range per free parameter".into());
        }
        for (i, k) in self.free.iter().enumerate() {
            if self.free[..i].contains(k) {
                return bad(format!("free parameter {k} named twice"));
            }
            let (lo, hi) = k.limits();
            let r = self.ranges[i];
            if !(r.lo >= lo && r.hi <= hi && r.lo < r.hi) {
                return bad(format!(
                    "range of {k} {r}: must be LO:HI with {lo} <= LO < HI <= {hi}"
                ));
            }
        }
        for k in &self.shared {
            if !k.of_surface() {
                return bad(format!(
                    "shared {k}: only the surface's e and mu are per surface or shared"
                ));
            }
        }
        let f = self.fixed;
        for (k, v) in [
            (Kind::E, f.e),
            (Kind::Mu, f.mu),
            (Kind::Rolling, f.rolling),
            (Kind::Bounce, f.bounce),
            (Kind::ContactTime, f.contact_time),
            (Kind::StaticRatio, f.static_ratio),
            (Kind::Spin, f.spin),
            (Kind::Height, f.height),
            (Kind::Speed, f.speed),
        ] {
            let (lo, hi) = k.limits();
            if !(v >= lo && v <= hi) {
                return bad(format!("{k} {v}: must be in [{lo}, {hi}]"));
            }
        }
        if let FixedThrow::Hand(k) | FixedThrow::HandToss(k) = f.throw {
            if !(0.0..=MAX_KAPPA).contains(&k) {
                return bad(format!("kappa {k}: must be in [0, {MAX_KAPPA:e}]"));
            }
        }
        for n in &self.narrowed {
            let kind = self
                .free
                .iter()
                .find(|k| n.param.starts_with(&format!("{k}[")))
                .ok_or_else(|| {
                    Error::Invalid(format!("narrowed {}: not a free parameter", n.param))
                })?;
            let r = self.range(*kind);
            if !(n.range.lo >= r.lo && n.range.hi <= r.hi && n.range.lo < n.range.hi) {
                return bad(format!(
                    "narrowed {} {}: must lie inside {kind}'s range {r}",
                    n.param, n.range
                ));
            }
        }
        Ok(())
    }

    /// True if `kind` is free.
    pub fn is_free(&self, kind: Kind) -> bool {
        self.free.contains(&kind)
    }

    /// The range of a free kind.
    pub fn range(&self, kind: Kind) -> Range {
        let i = self
            .free
            .iter()
            .position(|k| *k == kind)
            .expect("free kind");
        self.ranges[i]
    }

    fn group_of(&self, kind: Kind, row: &DataRow) -> String {
        if kind.of_die() {
            "die".into()
        } else if kind.of_surface() {
            if self.shared.contains(&kind) {
                "all".into()
            } else {
                row.surface.clone()
            }
        } else {
            row.thrower.clone()
        }
    }

    /// The free parameters `rows` need, kinds in order, groups in first-seen order.
    pub fn params(&self, rows: &[DataRow]) -> Vec<Param> {
        let mut out: Vec<Param> = Vec::new();
        for &kind in &self.free {
            for r in rows {
                let group = self.group_of(kind, r);
                if out.iter().any(|p| p.kind == kind && p.group == group) {
                    continue;
                }
                let name = format!("{kind}[{group}]");
                let whole = self.range(kind);
                let range = self
                    .narrowed
                    .iter()
                    .find(|n| n.param == name)
                    .map_or(whole, |n| n.range);
                out.push(Param {
                    kind,
                    group,
                    range,
                    whole,
                });
            }
        }
        out
    }

    /// For `row`, the index into `params` of each of its coordinates (the free kinds, in order).
    pub fn row_dims(&self, params: &[Param], row: &DataRow) -> Vec<usize> {
        self.free
            .iter()
            .map(|&kind| {
                let group = self.group_of(kind, row);
                params
                    .iter()
                    .position(|p| p.kind == kind && p.group == group)
                    .expect("params() covers every row")
            })
            .collect()
    }

    /// A row's axes: its parameters' kinds and ranges, in order.
    pub fn axes(&self, params: &[Param], dims: &[usize]) -> Axes {
        dims.iter()
            .map(|&d| (params[d].kind, params[d].range))
            .collect()
    }

    /// The kinds' whole ranges as axes (a design before any narrowing).
    pub fn whole_axes(&self) -> Axes {
        self.free
            .iter()
            .copied()
            .zip(self.ranges.iter().copied())
            .collect()
    }
}

/// How each throw is simulated: the engine, the time step, and what ends a roll.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Method {
    /// The engine.
    pub engine: EngineKind,
    /// The time step, s.
    pub dt: f64,
    /// The step cap per roll.
    pub max_steps: u64,
    /// The die thrown, where it is not the paper's ideal block: a die of any shape
    /// (`model::shape`) in place of every row's block, whose rows count its faces by label
    /// ([`crate::calibration::data::on_shape`]), thrown in a tumble; what departs from the
    /// uniform solid (a centre of mass off centre, pips, rounded edges, its faces' numbers;
    /// 3D only); its density where it is not the paper's. Written as its fields.
    #[serde(flatten)]
    pub die: Die,
    /// The rows' own dice, where a `die` column names them (`calibration::dice`): a row is
    /// simulated as its die (`Method::for_die`), the rest as above.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dice: Vec<crate::calibration::dice::RowDie>,
}

impl Method {
    /// How a row of die `die` is simulated: this method with that die's shape, features and
    /// density in place of the fit's own (`None`, or a die it does not hold: the fit's own).
    pub fn for_die(&self, die: Option<&str>) -> Cow<'_, Method> {
        match die.and_then(|n| self.dice.iter().find(|d| d.name == n)) {
            None => Cow::Borrowed(self),
            Some(d) => Cow::Owned(Method {
                die: d.die.clone(),
                dice: Vec::new(),
                ..self.clone()
            }),
        }
    }

    /// How `row` is simulated: as its own die ([`Method::for_die`]).
    pub fn of_row(&self, row: &DataRow) -> Cow<'_, Method> {
        self.for_die(row.die.as_deref())
    }

    /// How each roll is carried out: the fast defaults, ended by the exact early stop where it
    /// is exact (`roll::EARLY_STOP_MAX_DT`), else by DicePhys's rest rule.
    pub fn roll(&self) -> RollConfig {
        RollConfig {
            max_steps: self.max_steps,
            rule: if early_stop_exact(self.dt) {
                Rule::Certificate
            } else {
                Rule::Dicephys
            },
            ..RollConfig::fast()
        }
    }

    /// The die at the values `v`: a free centre of mass given outright (its components not
    /// free from the die's description, else 0), a free pip depth on the die's pips, a free
    /// infill in the die's shell (else a `DEFAULT_WALL` one).
    pub fn die_at(&self, v: &Fixed) -> Features {
        let mut die = self.die.features;
        for (axis, mm) in v.com.iter().enumerate() {
            if let Some(mm) = mm {
                die = die.with_com_on(axis, mm / 1000.0);
            }
        }
        if let Some(h) = v.pip_depth {
            die = die.with_pip_depth(h / 1000.0).unwrap_or(die);
        }
        if let Some(f) = v.infill {
            die = die.with_infill(f);
        }
        if let Some(r) = v.edge_radius {
            die.edge_radius = r / 1000.0;
        }
        die
    }

    /// The run that simulates `block` in `mode` at the values `v`, `rolls` throws keyed by
    /// `seed`.
    pub fn spec(&self, block: Block, mode: Mode, v: &Fixed, seed: u64, rolls: u64) -> RunSpec {
        let mut scene = Scene::paper(block, mode);
        scene.die = self.die.form(block);
        scene.dt = self.dt;
        scene.restitution = v.e;
        scene.friction = v.mu;
        scene.rolling_resistance = v.rolling / 1000.0;
        // A coin at 0 takes its own default, as `roll` gives it one where the engine has
        // rolling resistance: with none, a coin rolling on its rim never stops (a fit's 0 is
        // no rolling resistance measured).
        if v.rolling == 0.0 && scene.die.is_coin() && self.engine.resists_rolling(scene.mode) {
            scene.rolling_resistance = crate::model::scene::COIN_ROLLING_RESISTANCE;
        }
        scene.bounce_threshold = v.bounce;
        scene.contact_time = v.contact_time / 1000.0;
        scene.static_ratio = v.static_ratio;
        scene.features = self.die_at(v);
        if let Some(d) = self.die.density {
            scene.density = d;
        }
        // A die of any shape but a box takes its rounding in its hull (`mass::take_rounding`;
        // a rounding it cannot take stays in the features, which the scene's checks refuse),
        // and rests on the facets it rests on at this centre of mass, each labelled as the
        // rows count it.
        let _ = crate::model::mass::take_rounding(scene.die.shape_mut(), &mut scene.features);
        if let Some(base) = scene.die.as_shape() {
            let com = crate::model::mass::MassProps::compute(&scene).com;
            if let Ok(at) = base.resting_at_keeping(&com) {
                scene.die = Form::shape(at);
            }
        }
        let mut throws = match v.throw {
            FixedThrow::Paper => ThrowSpec::keyed(seed),
            FixedThrow::Hand(k) => ThrowSpec::hand(seed, k),
            FixedThrow::Tumble => ThrowSpec::keyed_style(seed, ThrowStyle::Tumble),
            FixedThrow::Toss => ThrowSpec::keyed_style(seed, ThrowStyle::Toss),
            FixedThrow::HandToss(k) => ThrowSpec {
                kappa: Some(k),
                ..ThrowSpec::keyed_style(seed, ThrowStyle::Toss)
            },
            FixedThrow::Flip => ThrowSpec::keyed_style(seed, ThrowStyle::Flip),
            FixedThrow::Rest => ThrowSpec::keyed_style(seed, ThrowStyle::Rest),
        };
        if v.throw == FixedThrow::Rest {
            // A rest has no ranges to scale (and refuses any but the paper's, unused).
            return RunSpec {
                engine: self.engine,
                scene,
                throws,
                roll: self.roll(),
                rolls,
                shard: None,
            };
        }
        let paper = ThrowRanges::default();
        let scaled = |r: Range, k: f64| Range::new(r.lo * k, r.hi * k);
        throws.ranges.spin = scaled(paper.spin, v.spin);
        throws.ranges.drop_height = scaled(paper.drop_height, v.height);
        throws.ranges.velocity = scaled(paper.velocity, v.speed);
        RunSpec {
            engine: self.engine,
            scene,
            throws,
            roll: self.roll(),
            rolls,
            shard: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_invert_and_warp() {
        for kind in Kind::ALL {
            let r = kind.default_range();
            for u in [0.0, 0.25, 0.5, 1.0] {
                let v = kind.value(r, u);
                assert!((kind.coordinate(r, v) - u).abs() < 1e-12, "{kind} {u}");
            }
            // The range's lower end, to the rounding of its warp and back (exp(ln 0.1)).
            assert!((kind.value(r, 0.0) - r.lo).abs() <= 1e-15 * r.lo.abs().max(1.0));
        }
        // κ: the middle of 0..10⁴ in log₁₀(1 + κ) is κ = √10001 − 1 ≈ 99.
        let r = Kind::Kappa.default_range();
        assert!((Kind::Kappa.value(r, 0.5) - (10001f64.sqrt() - 1.0)).abs() < 1e-9);
    }

    #[test]
    fn rows_map_to_their_surface_and_thrower() {
        let rows = crate::calibration::data::paper_rows().unwrap();
        let m = ModelSpec::free(&[Kind::E, Kind::Mu, Kind::Kappa]);
        m.validate().unwrap();
        let params = m.params(&rows);
        // Five surfaces, each its e and μ, and one κ.
        assert_eq!(params.len(), 11);
        let dims = m.row_dims(&params, &rows[6]);
        assert_eq!(params[dims[0]].name(), "e[MDF]");
        assert_eq!(params[dims[2]].name(), "kappa[all]");
        let shared = ModelSpec {
            shared: vec![Kind::E, Kind::Mu],
            ..m.clone()
        };
        assert_eq!(shared.params(&rows).len(), 3);
        let bad = ModelSpec {
            ranges: vec![Range::new(0.5, 1.5), m.ranges[1], m.ranges[2]],
            ..m
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("range of e"));
    }

    #[test]
    fn a_method_writes_its_die_as_a_fit_always_has_and_reads_it_back() {
        let mut m = bullet_at_1ms();
        m.die = Die {
            shape: Some(std::sync::Arc::new(
                crate::model::shape::named("d8", None).unwrap(),
            )),
            features: Features::default().with_com_on(2, -1e-3),
            density: Some(1200.0),
        };
        let v = serde_json::to_value(&m).unwrap();
        // Its features under `die`, its shape and density beside them: a fit's directory
        // and `fit.json` read as before the die became one value.
        assert_eq!(v["die"]["com"], serde_json::json!([0.0, 0.0, -1e-3]), "{v}");
        assert_eq!(v["density"], 1200.0);
        assert_eq!(v["shape"]["name"], "d8");
        assert!(v.get("features").is_none(), "{v}");
        assert_eq!(serde_json::from_value::<Method>(v).unwrap(), m);
        // The cuboid's plain die writes none of them.
        let plain = serde_json::to_value(bullet_at_1ms()).unwrap();
        for k in ["die", "shape", "density", "dice"] {
            assert!(plain.get(k).is_none(), "{plain}");
        }
    }

    /// Bullet at the fits' 1 ms step, the plain die, 1,000 steps a roll.
    fn bullet_at_1ms() -> Method {
        Method {
            engine: EngineKind::Bullet,
            dt: 1e-3,
            max_steps: 1000,
            die: Default::default(),
            dice: vec![],
        }
    }

    #[test]
    fn rolling_resistance_is_the_surfaces_and_reaches_the_scene() {
        // Issue 72: a contact that resists rolling, per surface like e and μ, in mm.
        let rows = crate::calibration::data::paper_rows().unwrap();
        let m = ModelSpec::free(&[Kind::E, Kind::Rolling]);
        m.validate().unwrap();
        let names: Vec<String> = m.params(&rows).iter().map(Param::name).collect();
        assert!(names.contains(&"rolling[MDF]".to_string()), "{names:?}");
        let axes = [(Kind::Rolling, Kind::Rolling.default_range())];
        let v = values(&Fixed::default(), &axes, &[0.25]);
        assert_eq!(v.rolling, 0.25);
        let method = bullet_at_1ms();
        let spec = method.spec(rows[0].block, rows[0].mode, &v, 1, 10);
        assert!((spec.scene.rolling_resistance - 0.25e-3).abs() < 1e-18);
        // Not free and not given: none, as before (the paper's scenes are unchanged).
        let plain = method.spec(rows[0].block, rows[0].mode, &Fixed::default(), 1, 10);
        assert_eq!(plain.scene.rolling_resistance, 0.0);
        assert!(!serde_json::to_string(&Fixed::default())
            .unwrap()
            .contains("rolling"));
    }

    #[test]
    fn the_contact_time_is_the_surfaces_and_reaches_the_scene() {
        // Issue 72: a soft table, per surface like e and μ, in ms; its range (fixed before
        // any fit) from two of the fits' 1 ms steps to 10 ms.
        let rows = crate::calibration::data::paper_rows().unwrap();
        let m = ModelSpec::free(&[Kind::E, Kind::ContactTime]);
        m.validate().unwrap();
        let names: Vec<String> = m.params(&rows).iter().map(Param::name).collect();
        assert!(
            names.contains(&"contact_time[MDF]".to_string()),
            "{names:?}"
        );
        assert_eq!(Kind::ContactTime.default_range(), Range::new(2.0, 10.0));
        let axes = [(Kind::ContactTime, Kind::ContactTime.default_range())];
        let v = values(&Fixed::default(), &axes, &[0.5]);
        assert_eq!(v.contact_time, 6.0);
        let method = bullet_at_1ms();
        let spec = method.spec(rows[0].block, rows[0].mode, &v, 1, 10);
        assert!((spec.scene.contact_time - 6e-3).abs() < 1e-18);
        spec.validate(false).unwrap();
        let plain = method.spec(rows[0].block, rows[0].mode, &Fixed::default(), 1, 10);
        assert_eq!(plain.scene.contact_time, 0.0);
        assert!(!serde_json::to_string(&Fixed::default())
            .unwrap()
            .contains("contact"));
    }

    #[test]
    fn the_throws_height_and_speed_scale_its_launch_as_spin_scales_its_spin() {
        // Issue 49: a thrower who throws lower or faster. Free, they are per thrower, searched
        // logarithmically, and each scales its range of the paper's throw.
        let rows = crate::calibration::data::paper_rows().unwrap();
        let m = ModelSpec::free(&[Kind::E, Kind::Height, Kind::Speed]);
        m.validate().unwrap();
        let names: Vec<String> = m.params(&rows).iter().map(Param::name).collect();
        assert!(names.contains(&"height[all]".to_string()), "{names:?}");
        assert!(names.contains(&"speed[all]".to_string()), "{names:?}");
        let r = Kind::Height.default_range();
        assert!((Kind::Height.value(r, 0.5) - (0.1f64 * 2.0).sqrt()).abs() < 1e-12);
        let axes = [
            (Kind::Height, Kind::Height.default_range()),
            (Kind::Speed, Kind::Speed.default_range()),
        ];
        let v = values(&Fixed::default(), &axes, &[0.0, 1.0]);
        assert!((v.height - 0.1).abs() < 1e-15 && v.speed == 10.0, "{v:?}");
        let method = bullet_at_1ms();
        let block = Block::from_mm(140.0, 24.0, 20.0).unwrap();
        let spec = method.spec(block, Mode::ThreeD, &v, 1, 10);
        let (h, u) = (spec.throws.ranges.drop_height, spec.throws.ranges.velocity);
        assert!(
            (h.lo - 0.02).abs() < 1e-12 && (h.hi - 0.04).abs() < 1e-12,
            "{h}"
        );
        assert!(
            (u.lo + 2.0).abs() < 1e-12 && (u.hi - 2.0).abs() < 1e-12,
            "{u}"
        );
        // At the paper's (1, 1) the throw is the paper's, and a fit.json without them reads so.
        let paper = method.spec(block, Mode::ThreeD, &Fixed::default(), 1, 10);
        assert_eq!(paper.throws.ranges, ThrowRanges::default());
        let old: Fixed =
            serde_json::from_str(r#"{"e":0.5,"mu":0.29,"spin":1.0,"throw":"paper"}"#).unwrap();
        assert_eq!(old, Fixed::default());
        assert!(!serde_json::to_string(&old).unwrap().contains("height"));
    }
}
