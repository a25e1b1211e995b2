//! The frame: how an engine's body is turned from the die's axes.

use nalgebra::UnitQuaternion;

/// How an engine's body is turned from the die's axes: by the die's principal frame when that
/// is not the body axes, else not at all. Every engine and the free flight turn orientations
/// through this one pair, so that the die's state is the same number wherever it is read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyTurn(pub(super) Option<UnitQuaternion<f64>>);

impl BodyTurn {
    /// True if the body is turned off the die's axes.
    pub fn turned(&self) -> bool {
        self.0.is_some()
    }

    /// The body's orientation from the die's.
    #[inline]
    pub fn to_body(&self, die: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        match &self.0 {
            Some(p) => die * p,
            None => *die,
        }
    }

    /// The die's orientation from the body's.
    #[inline]
    pub fn to_die(&self, body: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        match &self.0 {
            Some(p) => body * p.inverse(),
            None => *body,
        }
    }
}
