//! The die: a cuboid block with the paper's names for its sides.
//!
//! The paper calls the long axis (the spin axis) the **length**, and the two sides of the
//! cross-section the **breadth** and the **width**, breadth ≥ width. Its ratio R = width/breadth
//! is at most 1. "Breadth vertical" is the outcome where the breadth side stands upright, so the
//! block lies on a (length × width) face.
//!
//! Engine axes, one place for all engines (as DicePhys): body x = breadth, body y = width,
//! body z = length. The world's y axis is up.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Largest side accepted, in metres.
pub const MAX_SIDE_M: f64 = 10.0;
/// Smallest side accepted, in metres (a micrometre: below it no engine's contact tolerances
/// mean anything).
pub const MIN_SIDE_M: f64 = 1e-6;
/// Largest ratio between two sides accepted.
pub const MAX_SIDE_RATIO: f64 = 1000.0;

/// A cuboid block, sides in metres, with `breadth >= width`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Block {
    /// The long axis, the spin axis (body z).
    pub length: f64,
    /// The larger side of the cross-section (body x).
    pub breadth: f64,
    /// The smaller side of the cross-section (body y).
    pub width: f64,
}

impl Block {
    /// A block from its sides in millimetres, in the paper's order (length, breadth, width).
    /// If the second side is smaller than the third the two are swapped, so that `breadth` is
    /// always the larger side of the cross-section, as the paper names them.
    pub fn from_mm(length: f64, breadth: f64, width: f64) -> crate::Result<Block> {
        let bad = |m: String| Err(crate::Error::Invalid(m));
        for (name, v) in [("length", length), ("breadth", breadth), ("width", width)] {
            if !v.is_finite() || v <= 0.0 {
                return bad(format!(
                    "block {name} must be a positive finite number of mm, got {v}"
                ));
            }
            if v / 1000.0 < MIN_SIDE_M {
                return bad(format!(
                    "block {name} {v} mm is under the {} mm limit",
                    MIN_SIDE_M * 1000.0
                ));
            }
            if v / 1000.0 > MAX_SIDE_M {
                return bad(format!(
                    "block {name} {v} mm is over the {} m limit",
                    MAX_SIDE_M
                ));
            }
        }
        let (breadth, width) = if breadth >= width {
            (breadth, width)
        } else {
            (width, breadth)
        };
        let sides = [length, breadth, width];
        let max = sides.iter().cloned().fold(f64::MIN, f64::max);
        let min = sides.iter().cloned().fold(f64::MAX, f64::min);
        if max / min > MAX_SIDE_RATIO {
            return bad(format!(
                "block sides {length}x{breadth}x{width} mm have a ratio over {MAX_SIDE_RATIO}"
            ));
        }
        // Division by 1000 is correctly rounded, so "24" mm gives the same double as "0.024" m
        // typed into DicePhys: throw-for-throw comparisons depend on it.
        Ok(Block {
            length: length / 1000.0,
            breadth: breadth / 1000.0,
            width: width / 1000.0,
        })
    }

    /// R = width / breadth, in (0, 1].
    pub fn r(&self) -> f64 {
        self.width / self.breadth
    }

    /// The sides in mm, (length, breadth, width).
    pub fn mm(&self) -> [f64; 3] {
        [
            self.length * 1000.0,
            self.breadth * 1000.0,
            self.width * 1000.0,
        ]
    }

    /// The side lengths along the body's x, y, z axes (breadth, width, length), in metres.
    pub fn body_sides(&self) -> [f64; 3] {
        [self.breadth, self.width, self.length]
    }
}

impl std::str::FromStr for Block {
    type Err = crate::Error;
    /// Parses `LENGTHxBREADTHxWIDTH` in millimetres, e.g. `140x24x20`.
    fn from_str(s: &str) -> crate::Result<Block> {
        let bad = |m: String| crate::Error::Invalid(m);
        let parts: Vec<&str> = s.split(['x', 'X', '×']).map(str::trim).collect();
        if parts.len() != 3 {
            return Err(bad(format!(
                "block '{s}' is not LENGTHxBREADTHxWIDTH in mm (e.g. 140x24x20)"
            )));
        }
        let mut v = [0.0; 3];
        for (i, p) in parts.iter().enumerate() {
            v[i] = p
                .parse::<f64>()
                .map_err(|_| bad(format!("block '{s}': '{p}' is not a number of mm")))?;
        }
        Block::from_mm(v[0], v[1], v[2]).map_err(|e| bad(format!("block '{s}': {e}")))
    }
}

impl fmt::Display for Block {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [l, b, w] = self.mm();
        write!(f, "{}x{}x{}", fmt_mm(l), fmt_mm(b), fmt_mm(w))
    }
}

fn fmt_mm(v: f64) -> String {
    let r = (v * 1e6).round() / 1e6;
    format!("{r}")
}

/// The side of the block that stands vertical when it comes to rest: the paper's view of a
/// cuboid's outcome (`faces::Outcome::side`), not an outcome of its own.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    PartialOrd,
    Ord,
    strum::Display,
    strum::IntoStaticStr,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Side {
    /// The breadth stands upright: the block lies on a length × width face.
    Breadth,
    /// The width stands upright: the block lies on a length × breadth face (the likelier one).
    Width,
    /// The length stands upright: the block stands on its end.
    Length,
    /// No body axis is vertical within the tolerance (resting on an edge, or leaning).
    Unknown,
}

impl Side {
    /// Every side: breadth, width, length, unknown.
    pub const ALL: [Side; 4] = [Side::Breadth, Side::Width, Side::Length, Side::Unknown];

    /// The side's name in reports: "breadth", "width", "length" or "unknown".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// 3D: a free body. 2D: DicePhys's mode, a 1 m deep box locked to the x-y plane, spinning
/// about z only, so the block's length plays no part.
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
pub enum Mode {
    /// DicePhys's 2D mode.
    #[serde(rename = "2d")]
    #[strum(serialize = "2d")]
    TwoD,
    /// A free body.
    #[serde(rename = "3d")]
    #[strum(serialize = "3d")]
    ThreeD,
}

impl Mode {
    /// "2d" or "3d".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_papers_order() {
        let b: Block = "140x24x20".parse().unwrap();
        assert_eq!(b.length, 0.14);
        assert_eq!(b.breadth, 0.024);
        assert_eq!(b.width, 0.02);
        assert_eq!(b.to_string(), "140x24x20");
    }

    #[test]
    fn names_breadth_as_the_larger_side() {
        let b: Block = "140x20x24".parse().unwrap();
        assert_eq!(b.breadth, 0.024);
        assert_eq!(b.width, 0.02);
        assert!(b.r() < 1.0);
    }

    #[test]
    fn refuses_bad_blocks() {
        for s in [
            "0x24x20",
            "abc",
            "140x-1x20",
            "NaNx24x20",
            "140x24",
            "140x24x20x3",
            "inf x1x1",
            "20000x24x20",
            "1000x0.5x100",
        ] {
            assert!(s.parse::<Block>().is_err(), "{s} accepted");
        }
    }

    #[test]
    fn mm_to_m_matches_decimal_metres() {
        let b: Block = "140x22x13".parse().unwrap();
        assert_eq!(b.breadth, "0.022".parse::<f64>().unwrap());
        assert_eq!(b.width, "0.013".parse::<f64>().unwrap());
    }
}
