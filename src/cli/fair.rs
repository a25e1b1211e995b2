//! `dicephys fair`: a die rolled as `roll` rolls it (every flag of `roll`, thrown in a tumble
//! unless `--throw` says otherwise: the paper's throw spins about one axis and favours no face
//! less than it favours the ends), then each face set against a fair die's.

use super::error::{Error, Result};
use super::roll::{rolled, RollArgs};
use super::{out, outln};
use clap::Args;
use dicephys::model::throws::ThrowStyle;
use dicephys::studies::fair::{assess, Null};

/// `dicephys fair`'s arguments.
#[derive(Args, Debug)]
pub struct FairArgs {
    #[command(flatten)]
    pub roll: RollArgs,
    /// What fair means: uniform (each face 1/6; in 2D each side 1/4) or solid-angle (each
    /// face the solid angle it subtends from the centre: an ideal block of these sides
    /// released at rest; 3D).
    #[arg(long, default_value = "uniform")]
    pub null: Null,
}

/// Runs `dicephys fair`.
pub fn run(a: &FairArgs) -> Result<()> {
    if a.roll.run.precision.is_some() {
        return Err(Error::Usage(
            "fair: --precision rolls to the ratio breadth/width's precision, not the faces'; \
             give --rolls (the report says the rolls a bias would need)"
                .into(),
        ));
    }
    let spec = a.roll.spec_or(ThrowStyle::Tumble)?;
    // The null is checked before anything rolls.
    if a.null == Null::SolidAngle && spec.scene.mode == dicephys::model::scene::Mode::TwoD {
        return Err(Error::Usage(
            "--null solid-angle: the solid angle is the 3D theory; in 2D give uniform".into(),
        ));
    }
    let (summary, done) = rolled(&a.roll, &spec, "fair")?;
    let fair = assess(&summary, a.null)?;
    if a.roll.json {
        let doc = serde_json::json!({ "fairness": fair, "summary": summary });
        outln!("{}", dicephys::run::seal::to_string(&doc, true)?);
    } else {
        out!("{}", fair.text(&summary));
    }
    done
}
