//! Throws: the initial conditions of each roll, drawn from the paper's ranges
//! (its table of initial conditions) by one of two sources.
//!
//! - `keyed`: every throw is a pure function of (seed, throw index): its numbers come from a
//!   ChaCha8 stream chosen by the index, so any thread count, order, shard or resumed run
//!   gives the same throws.
//! - `dicephys`: the exact sequence DicePhys draws from glibc's `rand()` after `srand(seed)`,
//!   drawn up front, so that dicephys can be compared with DicePhys throw for throw.
//!
//! And in one of four styles ([`ThrowStyle`]): the paper's (the default: length along z, spin
//! about it, velocity along x), a tumble (any orientation, any spin axis, any horizontal
//! direction), a hand's throw between the two (the paper's throw turned at random by angles
//! whose spread a concentration κ sets: κ → ∞ is the paper's throw, κ = 0 the tumble), or a
//! release at rest touching the floor (the quasi-static limit). Every style draws its
//! directions from the same keyed stream, so each is a pure function of (seed, index).

use crate::error::Field;
use crate::model::glibc::GlibcRand;
use crate::model::scene::{Mode, Scene};
use crate::model::state::BodyState;
pub use crate::model::turns::{
    alignment, haar_quaternion, hand_turn, kappa_of_alignment, unit_vector, Turn,
};
use nalgebra::{UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// The seed of every command that is not given one: DicePhys's own (its `srand(2385)`), so
/// that a default run is the paper's throws. The command line and Python take it from here.
pub const DEFAULT_SEED: u64 = 2385;

/// A closed interval `lo..=hi` to draw uniformly from; `lo == hi` fixes the value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Range {
    /// The lower end.
    pub lo: f64,
    /// The upper end.
    pub hi: f64,
}

impl Range {
    /// The interval `lo..=hi`, unchecked (parsing refuses high to low).
    pub fn new(lo: f64, hi: f64) -> Range {
        Range { lo, hi }
    }

    fn draw(&self, u: f64) -> f64 {
        self.lo + (self.hi - self.lo) * u
    }
}

impl FromStr for Range {
    type Err = crate::Error;
    /// `LO:HI`, or one number for a fixed value. High-to-low and non-finite are refused.
    fn from_str(s: &str) -> crate::Result<Range> {
        let num = |p: &str| -> crate::Result<f64> {
            let v: f64 = p
                .trim()
                .parse()
                .map_err(|_| crate::Error::Invalid(format!("'{p}' is not a number")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(crate::Error::Invalid(format!("'{p}' is not finite")))
            }
        };
        let r = match s.split_once(':') {
            Some((lo, hi)) => Range::new(num(lo)?, num(hi)?),
            None => {
                let v = num(s)?;
                Range::new(v, v)
            }
        };
        if r.lo > r.hi {
            return Err(crate::Error::Invalid(format!(
                "range {s} runs high to low; write LO:HI"
            )));
        }
        Ok(r)
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.lo == self.hi {
            write!(f, "{}", self.lo)
        } else {
            write!(f, "{}:{}", self.lo, self.hi)
        }
    }
}

/// The ranges throws are drawn from; default: the paper's table of initial conditions.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThrowRanges {
    /// Linear velocity along x, m/s.
    pub velocity: Range,
    /// Angular velocity about the length axis (z), rad/s.
    pub spin: Range,
    /// Height added to the longest side for the centre's starting height, m.
    pub drop_height: Range,
}

impl ThrowRanges {
    /// Checks the ranges: spin and drop height not negative, no magnitude absurdly large.
    pub fn validate(&self) -> crate::Result<()> {
        let bad = |field, r: Range, why: String| Err(crate::Error::field(field, r, why));
        // Checked here, not only where the command line parses them (reliability round 5,
        // class I: Python's velocity=(2, 1) used to run).
        for (name, r) in [
            (Field::Velocity, self.velocity),
            (Field::Spin, self.spin),
            (Field::DropHeight, self.drop_height),
        ] {
            if !(r.lo.is_finite() && r.hi.is_finite()) {
                return bad(name, r, "must be finite".into());
            }
            if r.lo > r.hi {
                return bad(name, r, "runs from high to low: give LOW:HIGH".into());
            }
        }
        if self.spin.lo < 0.0 {
            return bad(Field::Spin, self.spin, "must be >= 0 rad/s".into());
        }
        if self.drop_height.lo < 0.0 {
            return bad(Field::DropHeight, self.drop_height, "must be >= 0 m".into());
        }
        for (name, r, max) in [
            (Field::Velocity, self.velocity, 100.0),
            (Field::Spin, self.spin, 10_000.0),
            (Field::DropHeight, self.drop_height, 100.0),
        ] {
            if r.lo.abs() > max || r.hi.abs() > max {
                return bad(name, r, format!("magnitudes above {max} are not accepted"));
            }
        }
        Ok(())
    }
}

impl Default for ThrowRanges {
    fn default() -> Self {
        ThrowRanges {
            velocity: Range::new(-0.2, 0.2),
            spin: Range::new(31.0, 160.0),
            drop_height: Range::new(0.2, 0.4),
        }
    }
}

/// How a die is thrown.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum ThrowStyle {
    /// The paper's: identity orientation (length along z), velocity along x, spin about z.
    #[default]
    Paper,
    /// Any cuboid, any way: a uniformly random orientation (Haar measure), a spin axis
    /// uniform on the sphere with its magnitude from the spin range, and the velocity from
    /// the velocity range along a uniformly random horizontal direction. In 2D: a uniform
    /// angle about z, spin ± about z, velocity ± along x.
    Tumble,
    /// A hand's throw, between the paper's and the tumble, set by one concentration κ ≥ 0
    /// ([`hand_turn`]): the paper's throw whose long axis is tilted from z, whose roll about
    /// that axis is turned, whose spin axis leaves the long axis and whose heading leaves x,
    /// each by a random angle whose mean cosine is the Langevin function L(κ) = coth κ − 1/κ.
    /// κ → ∞ is the paper's throw; κ = 0 draws the tumble's distribution.
    Hand,
    /// Released at rest in a uniformly random orientation (in 2D, angle about z) with its
    /// lowest corner just touching the floor: the quasi-static limit. No range is used.
    Rest,
    /// A hand's toss: a uniformly random orientation, its lowest point released a height
    /// above the floor, moving along a random horizontal heading and spinning about a random
    /// axis, each magnitude drawn from a distribution with a scale rather than from a uniform
    /// range, so that gentle releases are as possible as hard ones ([`toss_magnitudes`]):
    /// the spin vector an isotropic Gaussian whose root-mean-square magnitude is the middle of
    /// the spin range (Maxwell-distributed magnitude); the height and the speed half-normal,
    /// the height's mean the middle of the drop-height range, the speed's root mean square the
    /// larger end of the velocity range. Every range 0 is the release at rest, throw for throw.
    /// Given a concentration κ, a hand's toss: the toss's magnitudes in a hand's directions
    /// ([`hand_turn`]: the paper's throw turned by angles that κ spreads), so that the spin keeps
    /// near the die's long axis as a hand's does.
    Toss,
    /// A flip: a spin about one of the die's diameters (an axis through it across its z axis:
    /// a coin's diameter, a long block end over end), the toss's magnitudes. The spin axis is
    /// horizontal, its azimuth uniform; the die's z axis starts vertical, turned about the spin
    /// axis by a uniform phase and about itself by a uniform angle; the heading uniform
    /// ([`flip_turn`]). In 2D the spin is about z, as every 2D throw's.
    Flip,
}

impl ThrowStyle {
    /// "paper", "tumble", "hand", "rest", "toss" or "flip".
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// True for the paper's style (the default, left out of a specification's JSON).
    pub fn is_paper(&self) -> bool {
        *self == ThrowStyle::Paper
    }

    /// The throw a scene's die gets when none is asked: the paper's for the cuboid, a tumble
    /// for a die of any shape (it has no long axis to spin about).
    pub fn default_for(scene: &crate::model::scene::Scene) -> ThrowStyle {
        if scene.die.as_shape().is_some() {
            ThrowStyle::Tumble
        } else {
            ThrowStyle::Paper
        }
    }
}

/// One throw's drawn numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Throw {
    /// The throw's index in the run, from 0.
    pub index: u64,
    /// Height added to the longest side for the centre's start, m (0 at rest).
    pub drop_height: f64,
    /// Linear velocity along x (a tumble: along its heading), m/s.
    pub velocity: f64,
    /// The spin's z component as the engine receives it (a tumble: its magnitude), rad/s.
    pub spin: f64,
    /// How the die is thrown; the paper's is left out of the JSON (so a chunk of paper throws
    /// reads and writes as before).
    #[serde(default, skip_serializing_if = "ThrowStyle::is_paper")]
    pub style: ThrowStyle,
    /// A tumble's or a rest's directions; none for the paper's throw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turn: Option<Turn>,
}

impl Throw {
    /// The die's starting state.
    ///
    /// - Paper: identity orientation (length along z), centre at (0, longest side + drop
    ///   height, 0), velocity (v, 0, 0), spin (0, 0, ω).
    /// - Tumble: the turn's orientation, the same centre (the longest side is more than the
    ///   half diagonal, so the die starts clear of the floor however it is turned), velocity
    ///   v (cos h, 0, sin h), spin ω times the turn's axis. In 2D: the angle about z, velocity
    ///   (±v, 0, 0) by the sign of cos h, spin (0, 0, ±ω) by the sign of the axis's z.
    /// - Rest: the turn's orientation, at rest, its centre at the height where its lowest
    ///   corner (in 2D, edge) touches the floor's top face.
    /// - Toss and flip: the turn's orientation, its centre the drop height above where its
    ///   lowest corner would touch the floor, velocity and spin as a tumble's.
    pub fn start(&self, scene: &Scene) -> BodyState {
        let paper = BodyState {
            position: Vector3::new(0.0, scene.drop_base() + self.drop_height, 0.0),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::new(self.velocity, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, 0.0, self.spin),
            sleeping: false,
        };
        let Some(turn) = self.turn.filter(|_| !self.style.is_paper()) else {
            return paper;
        };
        let rotation = turn.orientation(scene.mode);
        let [sx, sy, sz] = turn.spin_axis;
        let sign = |v: f64| if v < 0.0 { -1.0 } else { 1.0 };
        // A tumble's, a hand's and a toss's motion: along the heading, about the spin axis.
        let (linear_velocity, angular_velocity) = match scene.mode {
            Mode::ThreeD => (
                self.velocity * Vector3::new(turn.heading.cos(), 0.0, turn.heading.sin()),
                self.spin * Vector3::new(sx, sy, sz),
            ),
            Mode::TwoD => (
                Vector3::new(sign(turn.heading.cos()) * self.velocity, 0.0, 0.0),
                Vector3::new(0.0, 0.0, sign(sz) * self.spin),
            ),
        };
        match self.style {
            ThrowStyle::Paper => paper,
            ThrowStyle::Tumble | ThrowStyle::Hand => BodyState {
                rotation,
                linear_velocity,
                angular_velocity,
                ..paper
            },
            ThrowStyle::Rest | ThrowStyle::Toss | ThrowStyle::Flip => {
                let at_zero = BodyState {
                    position: Vector3::zeros(),
                    rotation,
                    linear_velocity: Vector3::zeros(),
                    angular_velocity: Vector3::zeros(),
                    sleeping: false,
                };
                // In 2D the rotation is about z only, so the 1 m depth adds nothing here. The
                // position is the centre of mass's (`DieBody::lowest_point`).
                let touching = -crate::model::die::DieBody::of(scene).lowest_point(&at_zero);
                if self.style == ThrowStyle::Rest {
                    return BodyState {
                        position: Vector3::new(0.0, touching, 0.0),
                        ..at_zero
                    };
                }
                BodyState {
                    position: Vector3::new(0.0, touching + self.drop_height, 0.0),
                    linear_velocity,
                    angular_velocity,
                    ..at_zero
                }
            }
        }
    }
}

/// Where throws' numbers come from.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum ThrowKind {
    /// Each throw from (seed, index).
    Keyed,
    /// DicePhys's glibc `rand()` sequence.
    Dicephys,
}

impl ThrowKind {
    /// "keyed" or "dicephys".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Where throws come from.
#[derive(Clone, Debug)]
pub enum Throws {
    /// Each throw a pure function of (seed, index): ChaCha8 seeded by `seed`, on stream `index`.
    Keyed {
        /// The run's seed.
        seed: u64,
        /// The ranges every throw is drawn from.
        ranges: ThrowRanges,
        /// How each die is thrown.
        style: ThrowStyle,
        /// The hand's concentration κ (a hand's throw's, or a toss's where it is a hand's).
        kappa: Option<f64>,
    },
    /// DicePhys's sequence. It is sequential, so the generator's state is kept at every
    /// `DICEPHYS_MARK`-th throw (drawn up front, 152 bytes each: 15 MB for 10⁸ throws) and a
    /// throw is drawn from the mark before it: memory stays small however many throws.
    Dicephys {
        /// The ranges every throw is drawn from.
        ranges: ThrowRanges,
        /// The generator just before throws 0, M, 2M, … (M = `DICEPHYS_MARK`).
        marks: Vec<GlibcRand>,
    },
}

/// How often the DicePhys sequence keeps its generator's state, in throws.
pub const DICEPHYS_MARK: u64 = 1024;

impl Throws {
    /// A throw source of the paper's throws that can give throws `0..n`.
    pub fn new(kind: ThrowKind, seed: u64, ranges: ThrowRanges, n: u64) -> Throws {
        Throws::styled(kind, ThrowStyle::Paper, None, seed, ranges, n)
    }

    /// A throw source that can give throws `0..n` thrown in `style` (a hand's, or a hand's
    /// toss, with concentration `kappa`). DicePhys's sequence has the paper's throw only
    /// (`ThrowSpec::validate` refuses another style with it).
    pub fn styled(
        kind: ThrowKind,
        style: ThrowStyle,
        kappa: Option<f64>,
        seed: u64,
        ranges: ThrowRanges,
        n: u64,
    ) -> Throws {
        match kind {
            ThrowKind::Keyed => Throws::Keyed {
                seed,
                ranges,
                style,
                kappa,
            },
            ThrowKind::Dicephys => {
                let mut g = GlibcRand::new(seed as u32);
                g.uniform(0.0, 1.0);
                let mut marks = Vec::with_capacity(n.div_ceil(DICEPHYS_MARK) as usize);
                for i in 0..n {
                    if i % DICEPHYS_MARK == 0 {
                        marks.push(g.clone());
                    }
                    dicephys_next(&mut g, &ranges, i);
                }
                Throws::Dicephys { ranges, marks }
            }
        }
    }

    /// Throw `index`; a `Dicephys` source panics past the `n` it was made for.
    pub fn get(&self, index: u64) -> Throw {
        match self {
            Throws::Keyed {
                seed,
                ranges,
                style,
                kappa,
            } => keyed_styled(*style, *kappa, *seed, ranges, index),
            Throws::Dicephys { ranges, marks } => {
                let first = index - index % DICEPHYS_MARK;
                let mut g = marks[(index / DICEPHYS_MARK) as usize].clone();
                for i in first..index {
                    dicephys_next(&mut g, ranges, i);
                }
                dicephys_next(&mut g, ranges, index)
            }
        }
    }
}

/// Throw `index` of the keyed source, the paper's throw: ChaCha8 seeded by `seed`, on stream
/// `index`.
pub fn keyed(seed: u64, ranges: &ThrowRanges, index: u64) -> Throw {
    keyed_styled(ThrowStyle::Paper, None, seed, ranges, index)
}

/// Throw `index` of the keyed source in `style` (a hand's, or a hand's toss, with
/// concentration `kappa`): ChaCha8 seeded by `seed`, on stream `index`. The paper's throw draws
/// drop height, velocity and spin, in that order; a tumble draws the same three, then its
/// orientation (three deviates), spin axis (two) and heading (one); a hand's throw draws the
/// same three, then six deviates for its turn ([`hand_turn`]); a rest draws only its
/// orientation; a toss and a flip draw six deviates for their directions, then six for their
/// magnitudes. A hand's throw without κ is a tumble's (κ = 0 is its distribution).
pub fn keyed_styled(
    style: ThrowStyle,
    kappa: Option<f64>,
    seed: u64,
    ranges: &ThrowRanges,
    index: u64,
) -> Throw {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let mut u = || rng.random::<f64>();
    match style {
        ThrowStyle::Paper | ThrowStyle::Tumble | ThrowStyle::Hand => {
            let drop_height = ranges.drop_height.draw(u());
            let velocity = ranges.velocity.draw(u());
            let spin = ranges.spin.draw(u());
            let turn = match style {
                ThrowStyle::Tumble => Some(tumble_turn([u(), u(), u(), u(), u(), u()])),
                ThrowStyle::Hand => Some(hand_turn(
                    kappa.unwrap_or(0.0),
                    [u(), u(), u(), u(), u(), u()],
                )),
                _ => None,
            };
            Throw {
                index,
                drop_height,
                velocity,
                spin,
                style,
                turn,
            }
        }
        ThrowStyle::Rest => Throw {
            index,
            drop_height: 0.0,
            velocity: 0.0,
            spin: 0.0,
            style,
            turn: Some(Turn {
                rotation: haar_quaternion(u(), u(), u()),
                spin_axis: [0.0; 3],
                heading: 0.0,
            }),
        },
        ThrowStyle::Toss | ThrowStyle::Flip => {
            // The orientation first, as a rest draws it, so that a toss with every scale 0 is
            // the release at rest throw for throw.
            let d = [u(), u(), u(), u(), u(), u()];
            let turn = match (style, kappa) {
                (ThrowStyle::Flip, _) => flip_turn(d),
                (_, Some(k)) => hand_turn(k, d),
                _ => tumble_turn(d),
            };
            let [drop_height, velocity, spin] =
                toss_magnitudes(ranges, [u(), u(), u(), u(), u(), u()]);
            Throw {
                index,
                drop_height,
                velocity,
                spin,
                style,
                turn: Some(turn),
            }
        }
    }
}

/// A tumble's directions from six uniform deviates: a uniformly random orientation (three),
/// a spin axis uniform on the sphere (two) and a horizontal heading (one). A toss draws the
/// same.
fn tumble_turn(u: [f64; 6]) -> Turn {
    Turn {
        rotation: haar_quaternion(u[0], u[1], u[2]),
        spin_axis: unit_vector(u[3], u[4]),
        heading: std::f64::consts::TAU * u[5],
    }
}

/// A flip's directions from six uniform deviates (the last unused): the spin axis horizontal
/// at azimuth 2πu₀; the die's z axis turned to the vertical, then about the spin axis by the
/// phase 2πu₁, after a turn about itself by 2πu₂; the heading 2πu₃. So the spin axis is always
/// a diameter of the die (square to its z axis), and the phase makes which face is up when it
/// leaves the hand uniform over the flip's circle.
pub fn flip_turn(u: [f64; 6]) -> Turn {
    use std::f64::consts::{FRAC_PI_2, TAU};
    let (s, c) = (TAU * u[0]).sin_cos();
    let axis = Vector3::new(c, 0.0, s);
    let q = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(axis), TAU * u[1])
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -FRAC_PI_2)
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), TAU * u[2]);
    let qq = q.quaternion();
    Turn {
        rotation: [qq.w, qq.i, qq.j, qq.k],
        spin_axis: [axis.x, axis.y, axis.z],
        heading: TAU * u[3],
    }
}

/// A toss's height above touching, speed and spin magnitude from six uniform deviates (three
/// Box–Muller pairs, five standard normals g₁…g₅): the height |g₁| h̄ √(π/2), whose mean is
/// h̄, the middle of the drop-height range; the speed |g₂| v̄, whose root mean square is v̄, the
/// larger end of the velocity range in magnitude; the spin ω̄ √((g₃² + g₄² + g₅²)/3), the
/// magnitude of an isotropic Gaussian vector whose root mean square is ω̄, the middle of the
/// spin range.
pub fn toss_magnitudes(ranges: &ThrowRanges, u: [f64; 6]) -> [f64; 3] {
    // 1 − u lies in (0, 1], so the logarithm is finite.
    let pair = |a: f64, b: f64| {
        let r = (-2.0 * (1.0 - a).ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * b).sin_cos();
        [r * c, r * s]
    };
    let [g1, g2] = pair(u[0], u[1]);
    let [g3, g4] = pair(u[2], u[3]);
    let [g5, _] = pair(u[4], u[5]);
    let mid = |r: Range| 0.5 * (r.lo + r.hi);
    let h = g1.abs() * mid(ranges.drop_height) * (std::f64::consts::PI / 2.0).sqrt();
    let v = g2.abs() * ranges.velocity.lo.abs().max(ranges.velocity.hi.abs());
    let w = mid(ranges.spin) * ((g3 * g3 + g4 * g4 + g5 * g5) / 3.0).sqrt();
    [h, v, w]
}

/// DicePhys's throws 0..n: `srand(seed)`, one discarded draw, then per roll, in this order,
/// drop height, linear velocity, the spin axis's z component, spin magnitude.
pub fn dicephys_sequence(seed: u32, ranges: &ThrowRanges, n: u64) -> Vec<Throw> {
    let mut g = GlibcRand::new(seed);
    g.uniform(0.0, 1.0);
    (0..n)
        .map(|index| dicephys_next(&mut g, ranges, index))
        .collect()
}

/// The next throw of DicePhys's sequence (throw `index`) from its generator.
fn dicephys_next(g: &mut GlibcRand, ranges: &ThrowRanges, index: u64) -> Throw {
    let drop_height = g.uniform(ranges.drop_height.lo, ranges.drop_height.hi);
    let velocity = g.uniform(ranges.velocity.lo, ranges.velocity.hi);
    let z = g.uniform(0.0, 1.0);
    let magnitude = g.uniform(ranges.spin.lo, ranges.spin.hi);
    // btVector3(0, 0, z).normalize() * magnitude, as Bullet evaluates it: a division by the
    // length is a multiplication by its reciprocal, so z·(1/|z|) need not be 1.
    let unit = z * (1.0 / (0.0 + 0.0 + z * z).sqrt());
    Throw {
        index,
        drop_height,
        velocity,
        spin: unit * magnitude,
        style: ThrowStyle::Paper,
        turn: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyed_throws_depend_only_on_seed_and_index() {
        let r = ThrowRanges::default();
        assert_eq!(keyed(7, &r, 12345), keyed(7, &r, 12345));
        assert_ne!(keyed(7, &r, 1), keyed(7, &r, 2));
        assert_ne!(keyed(7, &r, 1), keyed(8, &r, 1));
        for i in 0..1000 {
            let t = keyed(1, &r, i);
            assert!((0.2..=0.4).contains(&t.drop_height));
            assert!((-0.2..=0.2).contains(&t.velocity));
            assert!((31.0..=160.0).contains(&t.spin));
        }
    }

    #[test]
    fn ranges_parse() {
        assert_eq!("1:2".parse::<Range>().unwrap(), Range::new(1.0, 2.0));
        assert_eq!("3".parse::<Range>().unwrap(), Range::new(3.0, 3.0));
        assert!("2:1".parse::<Range>().is_err());
        assert!("a:1".parse::<Range>().is_err());
        assert!("nan".parse::<Range>().is_err());
    }

    #[test]
    fn fixed_ranges_fix_the_value() {
        let r = ThrowRanges {
            velocity: Range::new(0.1, 0.1),
            spin: Range::new(50.0, 50.0),
            drop_height: Range::new(0.3, 0.3),
        };
        let t = keyed(3, &r, 9);
        assert_eq!((t.velocity, t.spin, t.drop_height), (0.1, 50.0, 0.3));
    }

    #[test]
    fn dicephys_throws_from_marks_are_the_sequence() {
        let ranges = ThrowRanges::default();
        let n = 3 * DICEPHYS_MARK + 17;
        let all = dicephys_sequence(2385, &ranges, n);
        let source = Throws::new(ThrowKind::Dicephys, 2385, ranges, n);
        for i in [
            0,
            1,
            DICEPHYS_MARK - 1,
            DICEPHYS_MARK,
            2 * DICEPHYS_MARK + 5,
            n - 1,
        ] {
            assert_eq!(source.get(i), all[i as usize], "throw {i}");
        }
    }

    #[test]
    fn paper_throws_are_unchanged_by_the_styles() {
        // The paper's throw draws exactly what it drew before the styles: three deviates.
        let r = ThrowRanges::default();
        let t = keyed(7, &r, 3);
        assert_eq!(t, keyed_styled(ThrowStyle::Paper, None, 7, &r, 3));
        assert!(t.turn.is_none());
        let json = serde_json::to_string(&t).unwrap();
        assert!(!json.contains("style") && !json.contains("turn"), "{json}");
        // A tumble shares the paper's first three numbers, then draws its directions.
        let u = keyed_styled(ThrowStyle::Tumble, None, 7, &r, 3);
        assert_eq!(
            (u.drop_height, u.velocity, u.spin),
            (t.drop_height, t.velocity, t.spin)
        );
        assert_eq!(u, keyed_styled(ThrowStyle::Tumble, None, 7, &r, 3));
        let back: Throw = serde_json::from_str(&serde_json::to_string(&u).unwrap()).unwrap();
        assert_eq!(back, u);
    }

    #[test]
    fn haar_rotations_are_uniform() {
        // Under the Haar measure every rotated axis is uniform on the sphere: its components'
        // squares average 1/3, |cos| to the vertical averages 1/2; and the quaternion's
        // components' squares average 1/4. 20,000 draws: standard errors about 0.002.
        let n = 20_000;
        let r = ThrowRanges::default();
        let (mut sq, mut cos, mut w2) = (Vector3::zeros(), 0.0, 0.0);
        for i in 0..n {
            let t = keyed_styled(ThrowStyle::Rest, None, 11, &r, i);
            let turn = t.turn.unwrap();
            let q = turn.orientation(Mode::ThreeD);
            let x = q * Vector3::x();
            sq += x.component_mul(&x);
            cos += (q * Vector3::z()).y.abs();
            w2 += turn.rotation[0].powi(2);
        }
        let nf = n as f64;
        for v in (sq / nf).iter() {
            assert!((v - 1.0 / 3.0).abs() < 0.01, "{v}");
        }
        assert!((cos / nf - 0.5).abs() < 0.01, "{}", cos / nf);
        assert!((w2 / nf - 0.25).abs() < 0.01, "{}", w2 / nf);
        for u in [0.0, 0.3, 0.999] {
            let q = haar_quaternion(u, 0.7, 0.1);
            assert!((q.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-15);
            let a = unit_vector(u, 0.4);
            assert!((a.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn a_rest_throw_touches_the_floor_at_rest() {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("40x30x20".parse().unwrap(), mode);
            let half = Vector3::from(scene.body_sides()) / 2.0;
            for i in 0..100 {
                let t = keyed_styled(ThrowStyle::Rest, None, 5, &ThrowRanges::default(), i);
                let s = t.start(&scene);
                assert!(crate::model::die::lowest_point(&half, &s).abs() < 1e-15);
                assert_eq!(s.linear_velocity, Vector3::zeros());
                assert_eq!(s.angular_velocity, Vector3::zeros());
                if mode == Mode::TwoD {
                    let q = s.rotation.quaternion();
                    assert_eq!((q.i, q.j), (0.0, 0.0));
                }
            }
        }
    }

    #[test]
    fn a_tumble_starts_clear_of_the_floor_with_its_drawn_motion() {
        let r = ThrowRanges::default();
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
            let half = Vector3::from(scene.body_sides()) / 2.0;
            for i in 0..200 {
                let t = keyed_styled(ThrowStyle::Tumble, None, 9, &r, i);
                let s = t.start(&scene);
                assert!(crate::model::die::lowest_point(&half, &s) > 0.0);
                assert!((s.angular_velocity.norm() - t.spin).abs() < 1e-9 * t.spin);
                assert!((s.linear_velocity.norm() - t.velocity.abs()).abs() < 1e-12);
                assert_eq!(s.linear_velocity.y, 0.0);
                if mode == Mode::TwoD {
                    let q = s.rotation.quaternion();
                    assert_eq!((q.i, q.j), (0.0, 0.0));
                    assert_eq!(s.linear_velocity.z, 0.0);
                    assert_eq!((s.angular_velocity.x, s.angular_velocity.y), (0.0, 0.0));
                }
            }
        }
    }

    #[test]
    fn a_toss_with_every_scale_zero_is_the_rest_throw_for_throw() {
        let zero = Range::new(0.0, 0.0);
        let r = ThrowRanges {
            velocity: zero,
            spin: zero,
            drop_height: zero,
        };
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("40x30x20".parse().unwrap(), mode);
            for i in 0..100 {
                let rest = keyed_styled(ThrowStyle::Rest, None, 5, &ThrowRanges::default(), i);
                let toss = keyed_styled(ThrowStyle::Toss, None, 5, &r, i);
                assert_eq!(toss.turn.unwrap().rotation, rest.turn.unwrap().rotation);
                assert_eq!(toss.start(&scene), rest.start(&scene), "throw {i}");
            }
        }
    }

    #[test]
    fn a_toss_draws_its_magnitudes_with_their_scales() {
        // The paper's ranges as scales: the height's mean 0.3 m, the speed's RMS 0.2 m/s, the
        // spin's RMS 95.5 rad/s. 20,000 throws; tolerances 4 standard errors (the height's
        // σ/mean is √(π/2 − 1) = 0.76, so its mean's relative error is 0.0053; the squared
        // speed's σ/mean is √2, the squared spin's √(2/3): 0.010 and 0.0058).
        let (n, r) = (20_000u64, ThrowRanges::default());
        let scene = Scene::paper("40x30x20".parse().unwrap(), Mode::ThreeD);
        let half = Vector3::from(scene.body_sides()) / 2.0;
        let (mut h, mut v2, mut w2) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let t = keyed_styled(ThrowStyle::Toss, None, 3, &r, i);
            let s = t.start(&scene);
            let above = crate::model::die::lowest_point(&half, &s);
            assert!(
                (above - t.drop_height).abs() < 1e-12,
                "{above} {}",
                t.drop_height
            );
            assert!((s.angular_velocity.norm() - t.spin).abs() < 1e-9 * t.spin.max(1.0));
            assert!((s.linear_velocity.norm() - t.velocity).abs() < 1e-12);
            assert_eq!(s.linear_velocity.y, 0.0);
            h += t.drop_height;
            v2 += t.velocity * t.velocity;
            w2 += t.spin * t.spin;
        }
        let nf = n as f64;
        let rel = |got: f64, want: f64, se: f64| {
            assert!((got / want - 1.0).abs() < 4.0 * se, "{got} against {want}");
        };
        rel(h / nf, 0.3, 0.76 / nf.sqrt());
        rel(v2 / nf, 0.04, 2f64.sqrt() / nf.sqrt());
        rel(w2 / nf, 95.5f64.powi(2), (2.0f64 / 3.0).sqrt() / nf.sqrt());
    }

    #[test]
    fn the_alignment_inverts() {
        assert_eq!(alignment(0.0), 0.0);
        for k in [1e-6, 0.01, 0.5, 1.0, 3.0, 10.0, 39.0, 41.0, 1e3, 1e5] {
            let a = alignment(k);
            assert!((0.0..1.0).contains(&a), "{k}: {a}");
            let back = kappa_of_alignment(a);
            assert!((back - k).abs() <= 1e-7 * k.max(1.0), "{k}: {a} -> {back}");
        }
        // L(2) = coth 2 − 1/2.
        assert!((alignment(2.0) - (1.0 / 2f64.tanh() - 0.5)).abs() < 1e-15);
        assert_eq!(kappa_of_alignment(1.0), f64::INFINITY);
    }

    #[test]
    fn a_hand_spreads_every_angle_with_mean_cosine_l_kappa() {
        // κ = 2: L(κ) = 0.5373. The long axis's cosine to z, the roll's cosine, the spin
        // axis's cosine to the long axis and the heading's cosine each average L(κ); 20,000
        // throws give standard errors under 0.005, and the test allows 4 of them.
        let (r, kappa, n) = (ThrowRanges::default(), 2.0, 20_000u64);
        let (mut tilt, mut spin, mut heading) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let t = keyed_styled(ThrowStyle::Hand, Some(kappa), 4, &r, i);
            let turn = t.turn.unwrap();
            let q = turn.orientation(Mode::ThreeD);
            let long = q * Vector3::z();
            tilt += long.z;
            spin += long.dot(&Vector3::from(turn.spin_axis));
            heading += turn.heading.cos();
        }
        let l = alignment(kappa);
        for (what, sum) in [("tilt", tilt), ("spin", spin), ("heading", heading)] {
            let mean = sum / n as f64;
            assert!((mean - l).abs() < 0.02, "{what}: {mean} against L(κ) = {l}");
        }
    }

    #[test]
    fn a_hand_at_zero_tumbles_and_at_large_kappa_is_the_papers_throw() {
        let r = ThrowRanges::default();
        // κ = 0: orientation Haar (each rotated axis uniform: squares 1/3, |cos| to the
        // vertical 1/2) and spin axis uniform in the world (components average 0).
        let n = 20_000;
        let (mut sq, mut cos, mut axis) = (Vector3::zeros(), 0.0, Vector3::zeros());
        for i in 0..n {
            let turn = keyed_styled(ThrowStyle::Hand, None, 6, &r, i).turn.unwrap();
            let q = turn.orientation(Mode::ThreeD);
            let x = q * Vector3::x();
            sq += x.component_mul(&x);
            cos += (q * Vector3::z()).y.abs();
            axis += Vector3::from(turn.spin_axis);
        }
        let nf = n as f64;
        for v in (sq / nf).iter() {
            assert!((v - 1.0 / 3.0).abs() < 0.01, "{v}");
        }
        assert!((cos / nf - 0.5).abs() < 0.01);
        for v in (axis / nf).iter() {
            assert!(v.abs() < 0.02, "{v}");
        }
        // κ large: the paper's start to within the angles' spread, 1/√κ.
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
            for i in 0..50 {
                let hand = keyed_styled(ThrowStyle::Hand, Some(1e8), 8, &r, i).start(&scene);
                let paper = keyed(8, &r, i).start(&scene);
                assert_eq!(hand.position, paper.position);
                assert!(hand.rotation.angle_to(&paper.rotation) < 1e-2);
                assert!((hand.angular_velocity - paper.angular_velocity).norm() < 1e-2 * 160.0);
                assert!((hand.linear_velocity - paper.linear_velocity).norm() < 1e-2);
            }
        }
    }

    #[test]
    fn a_hands_throws_move_smoothly_with_kappa() {
        // One keyed stream, two nearby κ: every throw moves by a small angle (the throws of a
        // fit's neighbouring parameter points are the same throws, slightly turned).
        let r = ThrowRanges::default();
        let scene = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
        for i in 0..200 {
            let a = keyed_styled(ThrowStyle::Hand, Some(5.0), 2, &r, i).start(&scene);
            let b = keyed_styled(ThrowStyle::Hand, Some(5.05), 2, &r, i).start(&scene);
            assert!(a.rotation.angle_to(&b.rotation) < 0.05, "throw {i}");
        }
    }

    #[test]
    fn a_hands_toss_is_the_tosss_magnitudes_in_a_hands_directions() {
        // The same deviates: the first six turn the throw as a hand's with κ, the next six are
        // the toss's magnitudes, exactly. κ at its largest is the paper's directions (the die
        // upright, spinning about its long axis, moving along x); κ = 0 spreads the spin axis
        // as the tumble's (its cosine to the long axis uniform: mean 0, mean square 1/3, each
        // within 4 standard errors of 20,000 throws: 0.0041 and 0.0021).
        let r = ThrowRanges::default();
        let scene = Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD);
        for i in 0..200 {
            let toss = keyed_styled(ThrowStyle::Toss, None, 4, &r, i);
            let hand = keyed_styled(ThrowStyle::Toss, Some(3.0), 4, &r, i);
            assert_eq!(
                (hand.drop_height, hand.velocity, hand.spin),
                (toss.drop_height, toss.velocity, toss.spin)
            );
            let mut rng = ChaCha8Rng::seed_from_u64(4);
            rng.set_stream(i);
            let d: [f64; 6] = std::array::from_fn(|_| rng.random::<f64>());
            assert_eq!(hand.turn.unwrap(), hand_turn(3.0, d));
            let paper = keyed_styled(ThrowStyle::Toss, Some(MAX_KAPPA_TEST), 4, &r, i);
            let s = paper.start(&scene);
            let z = s.rotation * Vector3::z();
            assert!(z.z > 1.0 - 1e-4, "throw {i}: {z}");
            assert!(s.angular_velocity.normalize().z > 1.0 - 1e-4, "throw {i}");
        }
        let n = 20_000u64;
        let (mut c, mut c2) = (0.0, 0.0);
        for i in 0..n {
            let s = keyed_styled(ThrowStyle::Toss, Some(0.0), 5, &r, i).start(&scene);
            let cos = (s.rotation * Vector3::z()).dot(&s.angular_velocity.normalize());
            c += cos;
            c2 += cos * cos;
        }
        let nf = n as f64;
        assert!(
            (c / nf).abs() < 4.0 * (1.0f64 / 3.0).sqrt() / nf.sqrt(),
            "{}",
            c / nf
        );
        let se2 = (1.0f64 / 5.0 - 1.0 / 9.0).sqrt() / nf.sqrt();
        assert!((c2 / nf - 1.0 / 3.0).abs() < 4.0 * se2, "{}", c2 / nf);
    }

    /// The largest κ `ThrowSpec` takes (`run::spec::MAX_KAPPA`, a layer above).
    const MAX_KAPPA_TEST: f64 = 1e6;

    #[test]
    fn a_flip_spins_the_die_about_a_diameter_at_a_uniform_phase() {
        // Every flip's spin axis is horizontal and square to the die's z axis (a coin's
        // diameter) exactly; the phase is uniform, so the z axis's cosine to the vertical has
        // mean 0 and mean square 1/2 (standard errors √(1/2)/√n and √(1/8)/√n: 4 of them, 20,000
        // throws); the toss's magnitudes are the toss's, throw for throw.
        let r = ThrowRanges::default();
        let scene = Scene::paper_shape(
            crate::model::shape::named("coin:24,2", None).unwrap(),
            Mode::ThreeD,
        );
        let n = 20_000u64;
        let (mut c, mut c2) = (0.0, 0.0);
        for i in 0..n {
            let t = keyed_styled(ThrowStyle::Flip, None, 6, &r, i);
            let toss = keyed_styled(ThrowStyle::Toss, None, 6, &r, i);
            assert_eq!((t.drop_height, t.spin), (toss.drop_height, toss.spin));
            let s = t.start(&scene);
            let axis = s.angular_velocity / t.spin;
            let z = s.rotation * Vector3::z();
            assert!(axis.y.abs() < 1e-12 && (axis.norm() - 1.0).abs() < 1e-12);
            assert!(z.dot(&axis).abs() < 1e-12, "throw {i}: {z} {axis}");
            c += z.y;
            c2 += z.y * z.y;
        }
        let nf = n as f64;
        assert!(
            (c / nf).abs() < 4.0 * 0.5f64.sqrt() / nf.sqrt(),
            "{}",
            c / nf
        );
        assert!(
            (c2 / nf - 0.5).abs() < 4.0 * 0.125f64.sqrt() / nf.sqrt(),
            "{}",
            c2 / nf
        );
    }
}
