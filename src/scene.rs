//! The scene a throw happens in: the block, the surface, the time step, 2D or 3D, and the
//! engine settings. Defaults are DicePhys's, as the paper ran it (DESIGN.md).

use crate::block::Block;
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

pub const GRAVITY: f64 = 9.81;

/// 3D: a free body. 2D: DicePhys's mode, a 1 m deep box locked to the x-y plane, spinning
/// about z only, so the block's length plays no part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Mode {
    #[serde(rename = "2d")]
    TwoD,
    #[serde(rename = "3d")]
    ThreeD,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::TwoD => "2d",
            Mode::ThreeD => "3d",
        }
    }
}

/// Bullet solver settings, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Hash)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// Bullet 2.81's behaviour on Debian's 3.24, as the paper ran it.
    Dicephys281,
    /// Debian 3.24's stock defaults.
    Bullet3,
}

impl Preset {
    pub fn name(self) -> &'static str {
        match self {
            Preset::Dicephys281 => "dicephys281",
            Preset::Bullet3 => "bullet3",
        }
    }
}

impl FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "dicephys281" => Ok(Preset::Dicephys281),
            "bullet3" => Ok(Preset::Bullet3),
            _ => Err(format!(
                "unknown preset '{s}' (known: dicephys281, bullet3)"
            )),
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The floor: DicePhys's static 10000 x 100 x 10000 m box, or a static plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Floor {
    Box,
    Plane,
}

impl FromStr for Floor {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "box" => Ok(Floor::Box),
            "plane" => Ok(Floor::Plane),
            _ => Err(format!("unknown floor '{s}' (known: box, plane)")),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scene {
    pub block: Block,
    pub mode: Mode,
    /// kg/m³. The paper does not give it; outcomes should not depend on it.
    pub density: f64,
    /// The die's friction; Bullet multiplies it by the floor's (1), so the contact's μ.
    pub friction: f64,
    /// The die's restitution; multiplied by the floor's (1), so the contact's e.
    pub restitution: f64,
    pub floor_friction: f64,
    pub floor_restitution: f64,
    /// Fixed time step, s.
    pub dt: f64,
    pub preset: Preset,
    pub floor: Floor,
    /// The box floor's thickness, m: DicePhys's is 100 m (`DICEPHYS_FLOOR_THICKNESS`), which
    /// nothing gets through; a table top (2 cm) lets a die at a coarse step pass through it.
    pub floor_thickness: f64,
    pub gravity: f64,
}

/// DicePhys's floor box is 100 m thick, its top face at y = 0.
pub const DICEPHYS_FLOOR_THICKNESS: f64 = 100.0;

impl Scene {
    /// The paper's MDF scene (μ = 0.29, e = 0.5, dt = 1 ms) for a block.
    pub fn paper(block: Block, mode: Mode) -> Scene {
        Scene {
            block,
            mode,
            density: 800.0,
            friction: 0.29,
            restitution: 0.5,
            floor_friction: 1.0,
            floor_restitution: 1.0,
            dt: 0.001,
            preset: Preset::Dicephys281,
            floor: Floor::Box,
            floor_thickness: DICEPHYS_FLOOR_THICKNESS,
            gravity: GRAVITY,
        }
    }

    /// Full sides along the body's x, y, z axes (breadth, width, length); in 2D the depth
    /// along z is 1 m, as DicePhys's 2D die.
    pub fn body_sides(&self) -> [f64; 3] {
        let b = &self.block;
        match self.mode {
            Mode::ThreeD => [b.breadth, b.width, b.length],
            Mode::TwoD => [b.breadth, b.width, 1.0],
        }
    }

    /// The die's mass, multiplied in DicePhys's order so that the numbers agree to the bit.
    pub fn mass(&self) -> f64 {
        let b = &self.block;
        match self.mode {
            Mode::ThreeD => b.breadth * b.width * b.length * self.density,
            Mode::TwoD => b.breadth * b.width * self.density,
        }
    }

    /// Height of the floor's bottom face: the die is through the floor once wholly below it
    /// (−∞ for the plane, which is a half-space).
    pub fn floor_bottom(&self) -> f64 {
        match self.floor {
            Floor::Box => -self.floor_thickness,
            Floor::Plane => f64::NEG_INFINITY,
        }
    }

    /// The drop height is added to this: the longest side (in 2D, of breadth and width).
    pub fn drop_base(&self) -> f64 {
        let b = &self.block;
        match self.mode {
            Mode::ThreeD => b.width.max(b.breadth).max(b.length),
            Mode::TwoD => b.width.max(b.breadth),
        }
    }
}
