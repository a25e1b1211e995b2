//! The scene a throw happens in: the block, the surface, the time step, 2D or 3D, and the
//! engine settings. Defaults are DicePhys's, as the paper ran it (DESIGN.md).

use crate::error::{Error, Result};
use crate::model::block::Block;
use serde::{Deserialize, Serialize};

/// Gravity, m/s², along −y.
pub const GRAVITY: f64 = 9.81;

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

/// Bullet solver settings, by name.
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
pub enum Preset {
    /// Bullet 2.81's behaviour on Debian's 3.24, as the paper ran it.
    Dicephys281,
    /// Debian 3.24's stock defaults.
    Bullet3,
}

impl Preset {
    /// The preset's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// The floor: DicePhys's static 10000 x 100 x 10000 m box, or a static plane.
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
pub enum Floor {
    /// DicePhys's static box, top face at y = 0.
    Box,
    /// A static plane at y = 0.
    Plane,
}

impl Floor {
    /// "box" or "plane".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Everything a throw happens in.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// The die's sides.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// kg/m³. The paper does not give it; outcomes should not depend on it.
    pub density: f64,
    /// The die's friction; Bullet multiplies it by the floor's (1), so the contact's μ.
    pub friction: f64,
    /// The die's restitution; multiplied by the floor's (1), so the contact's e.
    pub restitution: f64,
    /// The floor's friction (DicePhys: 1).
    pub floor_friction: f64,
    /// The floor's restitution (DicePhys: 1).
    pub floor_restitution: f64,
    /// Fixed time step, s.
    pub dt: f64,
    /// Bullet's solver settings.
    pub preset: Preset,
    /// Box or plane.
    pub floor: Floor,
    /// The box floor's thickness, m: DicePhys's is 100 m (`DICEPHYS_FLOOR_THICKNESS`), which
    /// nothing gets through; a table top (2 cm) lets a die at a coarse step pass through it.
    pub floor_thickness: f64,
    /// m/s², along −y.
    pub gravity: f64,
}

/// DicePhys's floor box is 100 m thick, its top face at y = 0.
pub const DICEPHYS_FLOOR_THICKNESS: f64 = 100.0;

impl Scene {
    /// Checks every value before anything runs. A restitution above 1 is not physics; it is
    /// accepted (up to 10) only for engine-stability studies that ask for it.
    pub fn validate(&self, allow_restitution_above_one: bool) -> Result<()> {
        let bad = |m: String| Err(Error::Invalid(m));
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= 0.1) {
            return bad(format!("--dt {}: must be in (0, 0.1] s", self.dt));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return bad(format!(
                "--friction {}: must be finite and >= 0",
                self.friction
            ));
        }
        let e_max = if allow_restitution_above_one {
            10.0
        } else {
            1.0
        };
        if !(self.restitution.is_finite() && self.restitution >= 0.0 && self.restitution <= e_max) {
            return bad(format!(
                "--restitution {}: must be in [0, 1] (above 1 only with --allow-restitution-above-one)",
                self.restitution
            ));
        }
        if !(self.floor_thickness.is_finite()
            && (0.001..=DICEPHYS_FLOOR_THICKNESS).contains(&self.floor_thickness))
        {
            return bad(format!(
                "--floor-thickness {}: must be in [0.001, 100] m",
                self.floor_thickness
            ));
        }
        if !(self.density.is_finite() && self.density > 0.0 && self.density <= 1e5) {
            return bad(format!(
                "--density {}: must be in (0, 100000] kg/m³",
                self.density
            ));
        }
        Ok(())
    }

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
