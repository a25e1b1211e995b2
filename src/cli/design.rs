//! `dicephys design`: the value of one feature of a die that gives the probabilities a target
//! asks for, thrown as the scene throws it (`studies::design`).

use super::error::{Error, Result};
use super::roll::RollArgs;
use super::term::{out, outln};
use clap::Args;
use dicephys::model::throws::ThrowStyle;
use dicephys::studies::design::named::Named;
use dicephys::studies::design::{DesignConfig, DEFAULT_CHECK_ROLLS, DEFAULT_POINTS, DEFAULT_ROLLS};
use dicephys::studies::fair::{Null, Varied};
use std::path::PathBuf;

/// `--target`: each label's probability, or a named law.
#[derive(Clone, Debug)]
pub enum TargetArg {
    /// `LABEL=P,…` (or a null's name, refused: a design needs probabilities).
    Labels(Null),
    /// `2d6`, `binomial:N`.
    Named(Named),
}

/// `--target` as clap reads it.
fn parse_target(s: &str) -> std::result::Result<TargetArg, dicephys::Error> {
    match Named::parse(s).map_err(dicephys::Error::Invalid)? {
        Some(n) => Ok(TargetArg::Named(n)),
        None => super::args::parse_null(s).map(TargetArg::Labels),
    }
}

/// `dicephys design`'s arguments.
#[derive(Args, Debug)]
pub struct DesignArgs {
    /// The die, its scene and its throw, as `roll` takes them (thrown in a tumble unless
    /// --throw says otherwise); --rolls is the throws at each value a scan rolls [default:
    /// 2,000].
    #[command(flatten)]
    pub roll: RollArgs,
    /// The feature to design: thickness (a coin's, --shape coin:D,H), length (a block's,
    /// --block), com_x, com_y, com_z (the centre of mass), pip_depth or edge_radius; mm.
    #[arg(long, value_name = "NAME")]
    pub free: String,
    /// Its range, mm, fixed before the search (a design at its end is reported as such):
    /// NAME=LO:HI.
    #[arg(long, value_name = "NAME=LO:HI")]
    pub range: String,
    /// The probabilities wanted: LABEL=P,… summing to 1 (edge=1/3,heads=1/3,tails=1/3);
    /// rest=P gathers every label not named (6=1/4,rest=3/4). Or a named law over a die whose
    /// labels are its numbers, each once (a label 2|12 gathers two): 2d6 (the sum of two
    /// fair dice, 2 to 12) or binomial:N (heads in N fair tosses, 0 to N).
    #[arg(long, value_name = "LABEL=P,...|2d6|binomial:N", value_parser = parse_target)]
    pub target: TargetArg,
    /// Values each of the two scans rolls.
    #[arg(long, default_value_t = DEFAULT_POINTS)]
    pub points: usize,
    /// Throws of the check: the design rolled at a fresh seed.
    #[arg(long, default_value_t = DEFAULT_CHECK_ROLLS)]
    pub check_rolls: u64,
    /// Design under a fit's calibration (its fit.json): the fit's e, μ, rolling resistance
    /// and throw at its maximum, on its engine and step, with this die in place of the fit's
    /// (as `predict --die`); the scene and throw flags are the fit's, not given.
    #[arg(long, value_name = "FIT.json", conflicts_with_all = FIT_SETS)]
    pub fit: Option<PathBuf>,
    /// With --fit: the surface whose fitted e and μ to use (when the fit has one per surface).
    #[arg(long, requires = "fit")]
    pub surface: Option<String>,
    /// With --fit: the thrower whose fitted throw to use (when the fit has several).
    #[arg(long, requires = "fit")]
    pub thrower: Option<String>,
    /// Also write design.json (the --json document), report.md, report.html and the figure
    /// design.svg, .png (per outcome: the target, the design thrown ± 2σ, the design at rest)
    /// into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// What a fit's calibration sets: refused beside --fit.
const FIT_SETS: [&str; 22] = [
    "engine",
    "two_d",
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
    "no_sleep",
    "source",
    "velocity",
    "spin",
    "drop_height",
    "style",
    "kappa",
    "max_steps",
    "settle",
    "faithful",
];

/// The design `a` asks for, every value checked (the fit read, the named target set over the
/// die's labels) before anything rolls or is written.
fn config_of(a: &DesignArgs) -> Result<DesignConfig> {
    let r = &a.roll;
    for (given, flag) in [
        (r.checkpoint.is_some(), "--checkpoint"),
        (r.resume.is_some(), "--resume"),
        (r.per_roll.is_some(), "--per-roll"),
        (r.run.precision.is_some(), "--precision"),
    ] {
        if given {
            return Err(Error::Usage(format!(
                "{flag}: a design rolls scans and a check of its own; leave it out"
            )));
        }
    }
    let what: Varied = dicephys::error::parse_name("feature", a.free.trim())?;
    let range = range_of(&a.range, what)?;
    let mut spec = r.spec_or(ThrowStyle::Tumble)?;
    spec.rolls = r.run.rolls.unwrap_or(DEFAULT_ROLLS);
    let layout = r.layout(&spec);
    let calibration = match &a.fit {
        Some(path) => {
            let fit =
                dicephys::calibration::read_fit(path, super::term::stop()).map_err(
                    |e| match e {
                        dicephys::Error::Stopped => {
                            Error::Interrupted(dicephys::run::stop::interrupted(
                                &dicephys::run::stop::Kept::Nothing(Some("nothing was rolled")),
                            ))
                        }
                        e => Error::Usage(format!("--fit {e}")),
                    },
                )?;
            let name = path.display().to_string();
            let (calibrated, c) = dicephys::studies::design::calibrated::calibrated(
                &fit, &name, &spec, &a.surface, &a.thrower,
            )
            .map_err(|e| Error::Usage(format!("--fit {name}: {e}")))?;
            spec = calibrated;
            Some(c)
        }
        None => None,
    };
    let (target, named_target) = match a.target.clone() {
        TargetArg::Labels(Null::Target(t)) => (t, None),
        TargetArg::Labels(_) => {
            return Err(Error::Usage(
                "--target: give each label's probability, LABEL=P,… (heads=1/3,tails=1/3,\
                 edge=1/3), or a named law, 2d6 or binomial:N"
                    .into(),
            ))
        }
        TargetArg::Named(n) => {
            let labels = dicephys::studies::fair::die_labels(&spec.scene, layout);
            let t = n
                .over(&labels)
                .map_err(|e| Error::Usage(format!("--target {e}")))?;
            (t, Some(n))
        }
    };
    let cfg = DesignConfig {
        layout,
        spec,
        what,
        range,
        target,
        points: a.points,
        check_rolls: a.check_rolls,
        named_target,
        calibration,
    };
    dicephys::studies::design::check(&cfg)?;
    Ok(cfg)
}

/// Runs `dicephys design`.
pub fn run(a: &DesignArgs) -> Result<()> {
    let r = &a.roll;
    let cfg = config_of(a)?;
    // The directory is claimed once everything is checked: a refused design writes nothing.
    let _held = match &a.out {
        Some(dir) => {
            std::fs::create_dir_all(dir).map_err(|e| {
                Error::Usage(format!("--out {}: cannot create it ({e})", dir.display()))
            })?;
            Some(dicephys::studies::design::claim(dir, &cfg)?)
        }
        None => None,
    };
    let threads = r.run.threads()?;
    let total = (cfg.spec.rolls * 2 * cfg.points as u64 + cfg.check_rolls) as f64;
    let bar = dicephys::report::progress::Progress::new(
        "design",
        dicephys::report::progress::Unit::Rolls { per_cell: 0 },
        true,
        *r.json,
        super::study::every(),
    );
    let progress = |n: u64| bar.set(n as f64, total);
    let runner = dicephys::run::runner::Runner::new(threads, super::term::stop().clone());
    let runner = runner.with_progress(&progress);
    let design = dicephys::studies::design::run(&cfg, &runner);
    bar.finish();
    let Some(design) = design? else {
        return Err(Error::Interrupted(dicephys::run::stop::interrupted(
            &dicephys::run::stop::Kept::Nothing(Some("a design does not resume")),
        )));
    };
    let json = dicephys::run::seal::to_string(&design, true)?;
    if let Some(dir) = &a.out {
        dicephys::studies::design::write(dir, &json, &design)?;
    }
    if *r.json {
        outln!("{}", json);
    } else {
        out!("{}", design.text());
    }
    if let (Some(dir), false) = (&a.out, *r.json) {
        eprintln!(
            "wrote {}/design.json, report.md, report.html and design.svg, .png",
            dir.display()
        );
    }
    Ok(())
}

/// `--range NAME=LO:HI`, for the feature `--free` names.
fn range_of(s: &str, what: Varied) -> Result<[f64; 2]> {
    let bad = |why: &str| Error::Usage(format!("--range '{s}': {why}"));
    let (name, span) = s
        .split_once('=')
        .ok_or_else(|| bad("write NAME=LO:HI, e.g. thickness=6:14"))?;
    if name.trim() != what.to_string() {
        return Err(bad(&format!("the range is --free's, {what}")));
    }
    let (lo, hi) = span
        .split_once(':')
        .ok_or_else(|| bad("write NAME=LO:HI, e.g. thickness=6:14"))?;
    match (lo.trim().parse::<f64>(), hi.trim().parse::<f64>()) {
        (Ok(lo), Ok(hi)) if lo.is_finite() && hi.is_finite() && lo < hi => Ok([lo, hi]),
        _ => Err(bad("LO and HI must be numbers of mm, LO < HI")),
    }
}
