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
    /// What fair means: uniform (each face 1/6; in 2D each side 1/4) or solid-angle (the
    /// quasi-static theory: each face the solid angle the face opposite subtends from the
    /// centre of mass, what the die would show released at rest and rolling without a bounce;
    /// 3D).
    #[arg(long, default_value = "uniform")]
    pub null: Null,
    /// Also write fairness.json (the --json document) and the die map (die_map.svg, .png:
    /// the six faces as a net, each with its probability and departure) into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<std::path::PathBuf>,
}

/// Runs `dicephys fair`.
pub fn run(a: &FairArgs) -> Result<()> {
    let spec = a.roll.spec_or(ThrowStyle::Tumble)?;
    // The null is checked before anything rolls.
    if a.null == Null::SolidAngle && spec.scene.mode == dicephys::model::scene::Mode::TwoD {
        return Err(Error::Usage(
            "--null solid-angle: the solid angle is the 3D theory; in 2D give uniform".into(),
        ));
    }
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::Usage(format!("--out {}: cannot create it ({e})", dir.display()))
        })?;
        let identity =
            serde_json::json!({ "spec": spec, "null": a.null, "layout": a.roll.layout(&spec) });
        dicephys::studies::fair::claim(dir, &identity)?;
    }
    // --precision here is every face's probability's.
    let (summary, done) = rolled(
        &a.roll,
        &spec,
        "fair",
        dicephys::report::summary::Target::Faces,
    )?;
    let fair = assess(&summary, a.null)?;
    let doc = serde_json::json!({ "fairness": fair, "summary": summary });
    let json = dicephys::run::seal::to_string(&doc, true)?;
    if let (Some(dir), false) = (&a.out, summary.partial) {
        dicephys::studies::fair::write(dir, &json, &fair, &summary)?;
        if !a.roll.json {
            eprintln!(
                "wrote {}/fairness.json and die_map.svg, .png",
                dir.display()
            );
        }
    }
    if a.roll.json {
        outln!("{}", json);
    } else {
        out!("{}", fair.text(&summary));
    }
    done
}
