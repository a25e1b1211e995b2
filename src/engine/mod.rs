//! The physics engines behind one interface. Everything else (throws, settling, outcomes,
//! batches, reports) is shared code that sees only this trait.

use crate::error::Result;
use crate::model::scene::{Mode, Scene};
use serde::{Deserialize, Serialize};

pub mod bullet;
mod interface;
pub mod moreau;
pub mod rapier2d;
pub mod rapier3d;
mod rapier_shared;

pub use interface::Engine;

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

    /// Whether the engine takes rolling resistance in this mode: Bullet's rolling and
    /// spinning friction, Rapier's 3D body's couple after each step
    /// (`Rapier3d::resist_rolling`); not Rapier's 2D body, not the arbiter.
    pub fn resists_rolling(self, mode: crate::model::scene::Mode) -> bool {
        match self {
            EngineKind::Bullet | EngineKind::RapierLocked => true,
            EngineKind::Rapier => mode == crate::model::scene::Mode::ThreeD,
            EngineKind::Moreau => false,
        }
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
