//! The physics engines behind one interface. Everything else (throws, settling, outcomes,
//! batches, reports) is shared code that sees only this trait.

use crate::error::{Error, Result};
use crate::model::scene::{Mode, Scene};
use crate::model::state::BodyState;
use serde::{Deserialize, Serialize};

pub mod bullet;
pub mod moreau;
pub mod rapier2d;
pub mod rapier3d;
mod rapier_shared;

/// One world with one die in it, reused throw after throw.
pub trait Engine: Send {
    /// Puts the die in its starting state, with nothing left over from an earlier throw.
    fn reset(&mut self, start: &BodyState) -> Result<()>;
    /// Moves the die to `now` mid-roll, at the end of a stretch of free flight integrated
    /// outside (`flight::Flight`), leaving the body as the engine's own steps would have.
    /// Only engines with `ballistic_flight` are handed a flight.
    fn set_state(&mut self, _now: &BodyState) -> Result<()> {
        Err(Error::Engine(
            "this engine's free flight is not integrated outside it".into(),
        ))
    }
    /// True if, out of contact, the engine moves the die exactly as `flight::Flight` does
    /// (gravity, symplectic Euler, constant angular velocity): Bullet without its gyroscopic
    /// term. Not Rapier, which keeps the gyroscopic term and integrates rotation to first order:
    /// it flies its own flight instead (`own_flight`).
    fn ballistic_flight(&self) -> bool {
        false
    }
    /// True if the engine keeps no contact point between the die and the floor now, so that
    /// its next step from a state clear of the floor is free flight (`flight::Flight`).
    fn contact_free(&self) -> bool {
        false
    }
    /// True if the engine flies the die itself, in Rust, bit for bit as its own steps would
    /// (`own_flight_start`, `own_flight_step`; Rapier), rather than as `flight::Flight`.
    fn own_flight(&self) -> bool {
        false
    }
    /// Starts a flight from `s`, the state after the engine's last step, if the engine's
    /// next step from it would be pure flight (`own_flight`). A started flight ends with
    /// `set_state` (when a step was flown) or with the engine's next `step`.
    fn own_flight_start(&mut self, _s: &BodyState) -> bool {
        false
    }
    /// One step of the started flight from `s`, exactly as the engine would take it, or
    /// `None` if the engine must take it (a contact could form, the die could fall asleep).
    fn own_flight_step(&mut self, _s: &BodyState) -> Option<BodyState> {
        None
    }
    /// The engine's own body state, when its body's frame is turned off the die's axes (a
    /// made die's principal frame, `model::mass`): what `flight::Flight` flies, bit for bit as
    /// the engine would. Otherwise, and by default, `state`.
    fn body_state(&self) -> BodyState {
        self.state()
    }
    /// `set_state` from the engine's own body state (`body_state`).
    fn set_body_state(&mut self, now: &BodyState) -> Result<()> {
        self.set_state(now)
    }
    /// Advances the world by one fixed time step.
    fn step(&mut self) -> Result<()>;
    /// The die's state now, as the engine last left it.
    fn state(&self) -> BodyState;
}

/// Which engine rolls the die.
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
#[serde(rename_all = "kebab-case")]
#[strum(serialize_all = "kebab-case")]
pub enum EngineKind {
    /// Bullet 3 (Debian's, double precision) through the C++ shim.
    Bullet,
    /// Rapier: 3D with `rapier3d-f64`; 2D with `rapier2d-f64`, a true 2D body.
    Rapier,
    /// Rapier, 2D as DicePhys ran it: a 3D body with locked axes (3D: as `Rapier`). A check
    /// of the 2D engine against the locked 3D body.
    RapierLocked,
    /// The arbiter (`moreau`): a polyhedral die on a flat floor, Moreau–Jean time stepping
    /// with Newton's restitution and Coulomb's friction at every touching corner, solved to
    /// convergence. 3D only; meant for fine steps (`--dt 1e-4`).
    Moreau,
}

/// Every engine.
pub const ENGINES: [EngineKind; 4] = [
    EngineKind::Bullet,
    EngineKind::Rapier,
    EngineKind::RapierLocked,
    EngineKind::Moreau,
];

impl EngineKind {
    /// The engine's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// The engine and its version, for provenance.
    pub fn version(self) -> String {
        match self {
            EngineKind::Bullet => format!("Bullet {} (double precision)", bullet::version()),
            // The version is the rapier3d-f64 crate's own (its VERSION const, the crate's
            // CARGO_PKG_VERSION); a test checks that rapier2d-f64 is the same release. The
            // 3D crate is patched (vendor/rapier3d-f64/PATCH.md: its Coulomb model's bounce and
            // its friction against the slip).
            EngineKind::Rapier => format!(
                "Rapier {} (f64, Coulomb friction patched; 2D: rapier2d, a 2D body)",
                rapier3d::version()
            ),
            EngineKind::RapierLocked => format!(
                "Rapier {} (f64, Coulomb friction patched; 2D: rapier3d, a locked 3D body)",
                rapier3d::version()
            ),
            EngineKind::Moreau => format!("Moreau–Jean (dicephys {})", env!("CARGO_PKG_VERSION")),
        }
    }
}

/// A fresh world for the scene.
pub fn new_engine(kind: EngineKind, scene: &Scene) -> Result<Box<dyn Engine>> {
    match kind {
        EngineKind::Bullet => Ok(Box::new(bullet::Bullet::new(scene)?)),
        EngineKind::Rapier if scene.mode == Mode::TwoD => {
            Ok(Box::new(rapier2d::Rapier2d::new(scene)?))
        }
        EngineKind::Rapier | EngineKind::RapierLocked => {
            Ok(Box::new(rapier3d::Rapier3d::new(scene)?))
        }
        EngineKind::Moreau => Ok(Box::new(moreau::Moreau::new(scene)?)),
    }
}
