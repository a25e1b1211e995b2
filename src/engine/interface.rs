//! The one interface every engine implements: reset a die to a state, step, read the state
//! back (`super::new_engine` makes one by kind).

use crate::error::{Error, Result};
use crate::model::state::BodyState;

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
