//! `dicephys fair`: a die rolled as `roll` rolls it (every flag of `roll`, thrown in a tumble
//! unless `--throw` says otherwise: the paper's throw spins about one axis and favours no face
//! less than it favours the ends), then each face set against a fair die's.

use super::error::{Error, Result};
use super::roll::RollArgs;
use super::term::{out, outln};
use clap::Args;
use dicephys::model::throws::ThrowStyle;
use dicephys::studies::fair::Null;

/// The flags that say how a die is rolled: refused beside `--counts`, which rolls nothing
/// (the die's own flags stay: the quasi-static null reads them).
const SIMULATION: [&str; 31] = [
    "engine",
    "dt",
    "friction",
    "restitution",
    "allow_restitution_above_one",
    "preset",
    "floor",
    "floor_thickness",
    "linear_damping",
    "angular_damping",
    "rolling_resistance",
    "bounce_threshold",
    "contact_time",
    "static_ratio",
    "no_sleep",
    "seed",
    "source",
    "velocity",
    "spin",
    "drop_height",
    "style",
    "kappa",
    "rolls",
    "threads",
    "max_steps",
    "settle",
    "margin",
    "audit",
    "flight",
    "faithful",
    "per_roll",
];

/// `dicephys fair`'s arguments.
#[derive(Args, Debug)]
#[command(mut_arg("precision", |a| a.hide(true)))]
pub struct FairArgs {
    #[command(flatten)]
    pub roll: RollArgs,
    /// Roll until every face's probability is known within ±PP percentage points at 2σ (0.5:
    /// each face to ±0.005), tested every 1,000 rolls, so that the same seed gives the same
    /// rolls on any thread count; --rolls is then the most it may take [default: 10,000,000].
    /// (`--precision`, a relative error of the ratio in `roll`, meant this here before.)
    #[arg(long, value_name = "PP", value_parser = super::args::parse_points, conflicts_with = "precision")]
    pub within: Option<f64>,
    /// What fair means: uniform (each facet the die rests on 1/N, a label its facets' share;
    /// in 2D each side 1/4; noted where the die's faces are not alike, as on a prism or a
    /// coin), quasi-static (what the die would show released at rest and rolling down
    /// without a bounce: for a cuboid each face the solid angle the face opposite subtends
    /// from the centre of mass, so also called solid-angle; for any other die the exact
    /// basins of its rolling; 3D), or a target LABEL=P,… (a design's: 6=1/4,1=3/20,…,
    /// summing to 1, every label of the die) [default: uniform; a resumed run's own].
    #[arg(long, value_parser = super::args::parse_null, conflicts_with = "resume")]
    pub null: Option<Null>,
    /// Also write fairness.json (the --json document) and the die map (die_map.svg, .png:
    /// the six faces as a net, each with its probability and departure) into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<std::path::PathBuf>,
    /// How a feature of the die biases it: the die rolled at N values of NAME from LO to HI
    /// (mm; NAME com_x, com_y, com_z, pip_depth, edge_radius, thickness (a coin), length (a
    /// block or a prism), breadth or width (a block)), the same throws at each,
    /// each judged; with --out, the figure bias.svg, .png (each face's probability against
    /// the value, the null beside it) and bias.json.
    #[arg(long, value_name = "NAME=LO:HI:N", conflicts_with_all = ["checkpoint", "resume", "precision", "within", "per_roll", "shard"])]
    pub vary: Option<String>,
    /// Judge counts you measured instead of rolling: LABEL=N for each face (1=170,2=160,…;
    /// heads=48,tails=51,edge=1), against --null (uniform: 1/N over the faces given;
    /// quasi-static: the die --block, --shape or --die describe). No simulation: each face's
    /// p ± σ, the χ², and the throws that would see the bias; with --out, fairness.csv,
    /// fairness.json and the faces figure.
    #[arg(long, value_name = "LABEL=N,...", conflicts_with_all = ["vary", "checkpoint", "resume", "precision", "within", "per_roll", "shard"], conflicts_with_all = SIMULATION)]
    pub counts: Option<String>,
}

/// Runs `dicephys fair`.
pub fn run(mut a: FairArgs) -> Result<()> {
    // One meaning for --precision (a relative error of the ratio): fair's own target, every
    // face's probability in percentage points, is --within; the old spelling still works for
    // this version, with a word.
    if a.roll.run.precision.is_some() {
        eprintln!(
            "dicephys: warning: fair --precision is now --within (the same number: percentage \
             points of every face's probability at 2σ)"
        );
    }
    a.roll.run.precision = a.within.or(a.roll.run.precision);
    let a = &a;
    let spec = a.roll.spec_or(ThrowStyle::Tumble)?;
    if let Some(c) = &a.counts {
        return counted(a, &spec, c, &a.null.clone().unwrap_or_default());
    }
    let asked = a.null.clone().unwrap_or_default();
    // The null is checked before anything rolls or is written.
    if asked == Null::QuasiStatic && spec.scene.mode == dicephys::model::scene::Mode::TwoD {
        return Err(Error::Usage(
            "--null quasi-static (solid-angle): the quasi-static theory is 3D; in 2D give uniform"
                .into(),
        ));
    }
    dicephys::studies::fair::check_null(&spec, &asked)?;
    if let Some(v) = &a.vary {
        return vary(a, spec, v, asked);
    }
    // A checkpointed run keeps its null beside its specification, so that --resume judges it
    // as it was asked (the Ctrl-C message gives that command).
    let null = match &a.roll.resume {
        Some(dir) => dicephys::studies::roll::kept_null(dir)
            .map_err(|e| Error::Usage(format!("--resume {}: {e}", dir.display())))?,
        None => asked,
    };
    super::roll::study(&a.roll, spec, Some(null), a.out.as_deref())
}

/// `--out DIR` made, claimed and held for this `fair` run (another run's directory is refused,
/// and so is this one's while another process runs it): held while the returned file lives.
fn claim_out(
    dir: &std::path::Path,
    identity: &serde_json::Value,
) -> Result<dicephys::run::lock::Held> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::Usage(format!("--out {}: cannot create it ({e})", dir.display())))?;
    Ok(dicephys::studies::fair::claim(dir, identity)?)
}

/// `fair --counts`: measured counts judged without a simulation.
fn counted(
    a: &FairArgs,
    spec: &dicephys::run::spec::RunSpec,
    text: &str,
    null: &Null,
) -> Result<()> {
    use dicephys::studies::fair::{assess_counts, parse_counts, write_counted};
    let counts = parse_counts(text)?;
    let fair = assess_counts(&counts, null, &spec.scene, a.roll.layout(spec))?;
    let doc = serde_json::json!({ "fairness": fair });
    let json = dicephys::run::seal::to_string(&doc, true)?;
    if let Some(dir) = &a.out {
        let _held = claim_out(
            dir,
            &serde_json::json!({ "counts": counts, "null": (null.spec()) }),
        )?;
        write_counted(dir, &json, &fair)?;
        dicephys::report::html::write_text_report(
            dir,
            "Is this die fair?",
            &fair.counted_text(),
            &["faces"],
        )?;
        if !*a.roll.json {
            eprintln!(
                "wrote {}/fairness.json, fairness.csv, report.md, report.html and faces.svg, .png",
                dir.display()
            );
        }
    }
    if *a.roll.json {
        outln!("{}", json);
    } else {
        out!("Is this die fair? {}", fair.counted_text());
    }
    Ok(())
}

/// `fair --vary`: the die at each value of one feature, judged, as a table (or JSON) and,
/// with `--out`, the bias figure.
fn vary(a: &FairArgs, spec: dicephys::run::spec::RunSpec, v: &str, null: Null) -> Result<()> {
    let study = dicephys::studies::bias::BiasStudy {
        spec,
        null,
        vary: v.to_string(),
    };
    // Every value checked before the directory is made: a refused one writes nothing.
    if a.out.is_some() {
        dicephys::studies::kind::Kind::validate(&study)?;
    }
    let threads = a.roll.run.threads()?;
    let place = super::study::here(a.out.as_deref(), None, threads, *a.roll.json)?;
    super::study::run(&dicephys::studies::StudyConfig::Bias(study), &place)
}
