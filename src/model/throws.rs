//! Throws: the initial conditions of each roll, drawn from the paper's ranges
//! (its table of initial conditions) by one of two sources.
//!
//! - `keyed`: every throw is a pure function of (seed, throw index): its numbers come from a
//!   ChaCha8 stream chosen by the index, so any thread count, order, shard or resumed run
//!   gives the same throws.
//! - `dicephys`: the exact sequence DicePhys draws from glibc's `rand()` after `srand(seed)`,
//!   drawn up front, so that dicephys can be compared with DicePhys throw for throw.

use crate::model::glibc::GlibcRand;
use crate::model::scene::Scene;
use crate::model::state::BodyState;
use nalgebra::{UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

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
        let bad = |m: String| Err(crate::Error::Invalid(m));
        if self.spin.lo < 0.0 {
            return bad(format!("--spin {}: must be >= 0 rad/s", self.spin));
        }
        if self.drop_height.lo < 0.0 {
            return bad(format!(
                "--drop-height {}: must be >= 0 m",
                self.drop_height
            ));
        }
        for (name, r, max) in [
            ("--velocity", self.velocity, 100.0),
            ("--spin", self.spin, 10_000.0),
            ("--drop-height", self.drop_height, 100.0),
        ] {
            if r.lo.abs() > max || r.hi.abs() > max {
                return bad(format!(
                    "{name} {r}: magnitudes above {max} are not accepted"
                ));
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

/// One throw's drawn numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Throw {
    /// The throw's index in the run, from 0.
    pub index: u64,
    /// Height added to the longest side for the centre's start, m.
    pub drop_height: f64,
    /// Linear velocity along x, m/s.
    pub velocity: f64,
    /// The spin's z component as the engine receives it (rad/s).
    pub spin: f64,
}

impl Throw {
    /// The die's starting state: identity orientation (length along z), centre at
    /// (0, longest side + drop height, 0), velocity (v, 0, 0), spin (0, 0, ω).
    pub fn start(&self, scene: &Scene) -> BodyState {
        BodyState {
            position: Vector3::new(0.0, scene.drop_base() + self.drop_height, 0.0),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::new(self.velocity, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, 0.0, self.spin),
            sleeping: false,
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
    /// A throw source that can give throws `0..n`.
    pub fn new(kind: ThrowKind, seed: u64, ranges: ThrowRanges, n: u64) -> Throws {
        match kind {
            ThrowKind::Keyed => Throws::Keyed { seed, ranges },
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
            Throws::Keyed { seed, ranges } => keyed(*seed, ranges, index),
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

/// Throw `index` of the keyed source: ChaCha8 seeded by `seed`, on stream `index`.
pub fn keyed(seed: u64, ranges: &ThrowRanges, index: u64) -> Throw {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let drop_height = ranges.drop_height.draw(rng.random::<f64>());
    let velocity = ranges.velocity.draw(rng.random::<f64>());
    let spin = ranges.spin.draw(rng.random::<f64>());
    Throw {
        index,
        drop_height,
        velocity,
        spin,
    }
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
}
