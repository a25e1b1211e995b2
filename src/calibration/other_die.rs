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
use crate::model::block::Block;
use crate::model::mass::Features;
use crate::model::shape::Shape;
use crate::run::request::DieRequest;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// The die a prediction throws in place of the fit's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OtherDie {
    /// A die of any shape (a named one or a mesh), resting on the facets it rests on at its
    /// own centre of mass; `None`: a block (the prediction's `block`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Arc<Shape>>,
    /// Its centre of mass, pips, rounding, insert, inertia and numbering.
    #[serde(default)]
    pub features: Features,
    /// Its density, kg/m³, where it is not the paper's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
}

impl OtherDie {
    /// The die `req` describes (as `roll` and `fit` read it), its outcomes the facets it rests
    /// on at its own centre of mass.
    pub fn resolve(req: &DieRequest) -> Result<OtherDie> {
        let d = req.resolve_resting()?;
        Ok(OtherDie {
            shape: d.shape.map(Arc::new),
            features: d.features,
            density: d.density,
        })
    }

    /// The block a prediction of it simulates: a shape's bounding box, else `block`.
    pub fn block(&self, block: Block) -> Block {
        match &self.shape {
            Some(s) => {
                let [x, y, z] = s.bounding_box();
                Block {
                    breadth: x,
                    width: y,
                    length: z,
                }
            }
            None => block,
        }
    }

    /// What it is, in a few words.
    pub fn name(&self, block: Block) -> String {
        self.shape
            .as_ref()
            .map_or_else(|| format!("the block {block}"), |s| s.name.clone())
    }

    /// The fit's method with this die in place of the fit's (the engine, the step and the
    /// step cap kept).
    pub fn method(&self, fit: &Method) -> Method {
        Method {
            shape: self.shape.clone(),
            die: self.features,
            density: self.density,
            ..fit.clone()
        }
    }

    /// Refuses a die the fit's throw cannot throw: a die of any shape has no long axis for the
    /// paper's or a hand's throw (a fit of blocks) to spin it about.
    pub fn check(&self, fit: &FitResult) -> Result<()> {
        let hand = fit
            .config
            .model
            .is_free(crate::calibration::params::Kind::Kappa);
        let throw = fit.config.model.fixed.throw;
        if let (Some(s), true) = (
            &self.shape,
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
