//! The physics engines behind one interface. Everything else (throws, settling, outcomes,
//! batches, reports) is shared code that sees only this trait.

use crate::scene::{Mode, Scene};
use nalgebra::{UnitQuaternion, Vector3};
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

pub mod bullet;
pub mod rapier2d;
pub mod rapier3d;

/// The die's state in world coordinates (y up, floor top at y = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    pub position: Vector3<f64>,
    pub rotation: UnitQuaternion<f64>,
    pub linear_velocity: Vector3<f64>,
    pub angular_velocity: Vector3<f64>,
    /// The engine has put the body to sleep (deactivated it).
    pub sleeping: bool,
}

impl BodyState {
    /// At rest at the origin, unrotated: the state of a world with no die in it yet.
    pub fn at_origin() -> BodyState {
        BodyState {
            position: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            sleeping: false,
        }
    }

    pub fn is_finite(&self) -> bool {
        let q = self.rotation.quaternion();
        self.position.iter().all(|v| v.is_finite())
            && [q.i, q.j, q.k, q.w].iter().all(|v| v.is_finite())
            && self.linear_velocity.iter().all(|v| v.is_finite())
            && self.angular_velocity.iter().all(|v| v.is_finite())
    }
}

/// One world with one die in it, reused throw after throw.
pub trait Engine: Send {
    /// Puts the die in its starting state, with nothing left over from an earlier throw.
    fn reset(&mut self, start: &BodyState) -> Result<(), String>;
    /// Moves the die to `now` mid-roll, at the end of a stretch of free flight integrated
    /// outside (`flight::Flight`), leaving the body as the engine's own steps would have.
    /// Only engines with `ballistic_flight` are handed a flight.
    fn set_state(&mut self, _now: &BodyState) -> Result<(), String> {
        Err("this engine's free flight is not integrated outside it".into())
    }
    /// True if, out of contact, the engine moves the die exactly as `flight::Flight` does
    /// (gravity, symplectic Euler, constant angular velocity): Bullet without its gyroscopic
    /// term. Not Rapier, which keeps the gyroscopic term and integrates rotation to first order.
    fn ballistic_flight(&self) -> bool {
        false
    }
    /// True if the engine keeps no contact point between the die and the floor now, so that
    /// its next step from a state clear of the floor is free flight (`flight::Flight`).
    fn contact_free(&self) -> bool {
        false
    }
    /// Advances the world by one fixed time step.
    fn step(&mut self) -> Result<(), String>;
    fn state(&self) -> BodyState;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EngineKind {
    Bullet,
    /// Rapier: 3D with `rapier3d-f64`; 2D with `rapier2d-f64`, a true 2D body.
    Rapier,
    /// Rapier, 2D as DicePhys ran it: a 3D body with locked axes (3D: as `Rapier`). A check
    /// of the 2D engine against the locked 3D body.
    #[serde(rename = "rapier-locked")]
    RapierLocked,
}

/// Every engine, in the order `FromStr`'s error lists them.
pub const ENGINES: [EngineKind; 3] = [
    EngineKind::Bullet,
    EngineKind::Rapier,
    EngineKind::RapierLocked,
];

impl EngineKind {
    pub fn name(self) -> &'static str {
        match self {
            EngineKind::Bullet => "bullet",
            EngineKind::Rapier => "rapier",
            EngineKind::RapierLocked => "rapier-locked",
        }
    }

    /// The engine and its version, for provenance.
    pub fn version(self) -> String {
        match self {
            EngineKind::Bullet => format!("Bullet {} (double precision)", bullet::version()),
            // The version is the rapier3d-f64 crate's own (its VERSION const, the crate's
            // CARGO_PKG_VERSION); a test checks that rapier2d-f64 is the same release.
            EngineKind::Rapier => format!(
                "Rapier {} (f64; 2D: rapier2d, a 2D body)",
                rapier3d::version()
            ),
            EngineKind::RapierLocked => format!(
                "Rapier {} (f64; 2D: rapier3d, a locked 3D body)",
                rapier3d::version()
            ),
        }
    }
}

impl fmt::Display for EngineKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for EngineKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        ENGINES.into_iter().find(|e| e.name() == s).ok_or_else(|| {
            let known: Vec<&str> = ENGINES.iter().map(|e| e.name()).collect();
            format!("unknown engine '{s}' (known: {})", known.join(", "))
        })
    }
}

/// A fresh world for the scene.
pub fn new_engine(kind: EngineKind, scene: &Scene) -> Result<Box<dyn Engine>, String> {
    match kind {
        EngineKind::Bullet => Ok(Box::new(bullet::Bullet::new(scene)?)),
        EngineKind::Rapier if scene.mode == Mode::TwoD => {
            Ok(Box::new(rapier2d::Rapier2d::new(scene)?))
        }
        EngineKind::Rapier | EngineKind::RapierLocked => {
            Ok(Box::new(rapier3d::Rapier3d::new(scene)?))
        }
    }
}
