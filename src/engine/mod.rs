//! The physics engines behind one interface. Everything else (throws, settling, outcomes,
//! batches, reports) is shared code that sees only this trait.

use crate::scene::Scene;
use nalgebra::{UnitQuaternion, Vector3};
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

pub mod bullet;

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
    /// Moves the die to `now` mid-roll (after a stretch of free flight integrated outside).
    fn set_state(&mut self, now: &BodyState) -> Result<(), String>;
    /// True if, out of contact, the engine moves the die exactly as `flight::Flight` does
    /// (gravity, symplectic Euler, constant angular velocity).
    fn ballistic_flight(&self) -> bool;
    /// Advances the world by one fixed time step.
    fn step(&mut self) -> Result<(), String>;
    fn state(&self) -> BodyState;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EngineKind {
    Bullet,
}

impl EngineKind {
    pub fn name(self) -> &'static str {
        match self {
            EngineKind::Bullet => "bullet",
        }
    }

    /// The engine and its version, for provenance.
    pub fn version(self) -> String {
        match self {
            EngineKind::Bullet => format!("Bullet {} (double precision)", bullet::version()),
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
        match s {
            "bullet" => Ok(EngineKind::Bullet),
            _ => Err(format!("unknown engine '{s}' (known: bullet)")),
        }
    }
}

/// A fresh world for the scene.
pub fn new_engine(kind: EngineKind, scene: &Scene) -> Result<Box<dyn Engine>, String> {
    match kind {
        EngineKind::Bullet => Ok(Box::new(bullet::Bullet::new(scene)?)),
    }
}
