//! Another die than the fit's, thrown by the same hand on the same table (issue 71.2): a
//! calibration carried from the die it was fitted on to a die it never saw. The surface's and
//! the thrower's parameters are the fit's (its posterior draws); the die's geometry, mass and
//! centre of mass are the new die's own, and a parameter of the fitted die itself (its centre
//! of mass, its pips' depth) is not carried: it belongs to that die. A printed die's infill is
//! carried: it is the printer's setting, not the die's shape (issue 72: calibrate on one print,
//! predict the next design printed alike).

use crate::calibration::params::{Fixed, FixedThrow, Method};
use crate::calibration::FitResult;
use crate::error::{Error, Field, Result};
use crate::model::die::Die;

/// The fit's method with `die` in place of the fit's (the engine, the step and the step cap
/// kept).
pub fn method(die: &Die, fit: &Method) -> Method {
    Method {
        die: die.clone(),
        ..fit.clone()
    }
}

/// Refuses a die the fit's throw cannot throw: a die of any shape has no long axis for the
/// paper's or a hand's throw (a fit of blocks) to spin it about.
pub fn check(die: &Die, fit: &FitResult) -> Result<()> {
    let hand = fit
        .config
        .model
        .is_free(crate::calibration::params::Kind::Kappa);
    let throw = fit.config.model.fixed.throw;
    if let (Some(s), true) = (
        &die.shape,
        hand || !matches!(
            throw,
            FixedThrow::Tumble | FixedThrow::Toss | FixedThrow::Rest | FixedThrow::Flip
        ),
    ) {
        return Err(Error::field(
            Field::Shape,
            &s.name,
            "the fit threw blocks with the paper's or a hand's throw, which spins a die \
             about its long axis, and this die has none: a fit of blocks predicts blocks",
        ));
    }
    Ok(())
}

/// The values `v` for another die: the fitted die's own parameters (its centre of mass, its
/// pips' depth) dropped, the new die's taken as it is described; a fitted infill kept (the
/// printer's, in the new die's own shell or a 1 mm one).
pub fn without_die_params(v: Fixed) -> Fixed {
    Fixed {
        com: [None; 3],
        pip_depth: None,
        ..v
    }
}
