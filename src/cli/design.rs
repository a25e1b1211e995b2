//! `dicephys design`: the value of one feature of a die that gives the probabilities a target
//! asks for, thrown as the scene throws it (`studies::design`).

use super::error::{Error, Result};
use super::roll::RollArgs;
use clap::Args;
use dicephys::model::throws::ThrowStyle;
use dicephys::studies::bias::Varied;
use dicephys::studies::design::mesh::{self, MeshConfig};
use dicephys::studies::design::named::Named;
use dicephys::studies::design::study::DesignStudy;
use dicephys::studies::design::{DesignConfig, DEFAULT_CHECK_ROLLS, DEFAULT_POINTS, DEFAULT_ROLLS};
use dicephys::studies::fair::Null;
use dicephys::studies::StudyConfig;
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
    /// --block, or a prism's, --shape prism:N,D,L), breadth or width (a block's), com_x,
    /// com_y, com_z (the centre of mass), pip_depth or edge_radius; mm. Or
    /// facets: a convex die's shape (--die FILE, --mesh or a named polyhedron), each facet's
    /// plane moved and tilted within --range of its start's, a mirror symmetry about x = 0
    /// kept.
    #[arg(long, value_name = "NAME")]
    pub free: String,
    /// Its range, mm, fixed before the search (a design at its end is reported as such):
    /// NAME=LO:HI (facets=-2:2: each facet's offset and its rim's tilts within 2 mm of the
    /// start's).
    #[arg(long, value_name = "NAME=LO:HI")]
    pub range: String,
    /// The probabilities wanted: LABEL=P,… summing to 1 (edge=1/3,heads=1/3,tails=1/3);
    /// rest=P gathers every label not named (6=1/4,rest=3/4). Or a named law over a die whose
    /// labels are its numbers, each once (a label 2|12 gathers two): 2d6 (the sum of two
    /// fair dice, 2 to 12) or binomial:N (heads in N fair tosses, 0 to N).
    #[arg(long, value_name = "LABEL=P,...|2d6|binomial:N", value_parser = parse_target)]
    pub target: TargetArg,
    /// Values each of the two scans rolls [default: 9].
    #[arg(long)]
    pub points: Option<usize>,
    /// Throws of the check: the design rolled at a fresh seed.
    #[arg(long, default_value_t = DEFAULT_CHECK_ROLLS)]
    pub check_rolls: u64,
    /// With --free facets: rounds of throws, each correcting the quasi-static design by
    /// what the throws show (--rolls throws a round [default: 20,000]) [default: 5].
    #[arg(long)]
    pub rounds: Option<usize>,
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
const FIT_SETS: [&str; 25] = [
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
    "bounce_threshold",
    "contact_time",
    "static_ratio",
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

/// What every design shares: the die and its scene (calibrated where `--fit` is given), its
/// numbering, the target over its labels.
struct Common {
    spec: dicephys::run::spec::RunSpec,
    layout: dicephys::model::faces::Layout,
    calibration: Option<dicephys::studies::design::calibrated::Calibration>,
    target: Vec<(String, f64)>,
    named_target: Option<Named>,
}

/// The design `a` asks for, every value checked (the fit read, the named target set over the
/// die's labels) before anything rolls or is written.
fn config_of(a: &DesignArgs) -> Result<DesignStudy> {
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
    if a.free.trim() == mesh::FACETS {
        if a.points.is_some() {
            return Err(Error::Usage(
                "--points: a design of the facets rolls rounds (--rounds), not scans".into(),
            ));
        }
        let range = range_of(&a.range, mesh::FACETS)?;
        let c = common(a, r.run.rolls.unwrap_or(mesh::DEFAULT_ROLLS))?;
        let cfg = MeshConfig {
            spec: c.spec,
            layout: c.layout,
            range,
            target: c.target,
            rounds: a.rounds.unwrap_or(mesh::DEFAULT_ROUNDS),
            check_rolls: a.check_rolls,
            named_target: c.named_target,
            calibration: c.calibration,
        };
        mesh::check(&cfg)?;
        return Ok(DesignStudy::Facets(cfg));
    }
    let what: Varied = dicephys::error::parse_name("feature", a.free.trim())?;
    if a.rounds.is_some() {
        return Err(Error::Usage(format!(
            "--rounds: only --free {} rolls rounds; a feature's design scans (--points)",
            mesh::FACETS
        )));
    }
    let range = range_of(&a.range, &what.to_string())?;
    let c = common(a, r.run.rolls.unwrap_or(DEFAULT_ROLLS))?;
    let cfg = DesignConfig {
        layout: c.layout,
        spec: c.spec,
        what,
        range,
        target: c.target,
        points: a.points.unwrap_or(DEFAULT_POINTS),
        check_rolls: a.check_rolls,
        named_target: c.named_target,
        calibration: c.calibration,
    };
    dicephys::studies::design::check(&cfg)?;
    Ok(DesignStudy::Feature(cfg))
}

/// The die, scene, calibration and target `a` gives, `rolls` throws a run.
fn common(a: &DesignArgs, rolls: u64) -> Result<Common> {
    let r = &a.roll;
    let mut spec = r.spec_or(ThrowStyle::Tumble)?;
    spec.rolls = rolls;
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
            let labels = spec.scene.labels(layout);
            let t = n
                .over(&labels)
                .map_err(|e| Error::Usage(format!("--target {e}")))?;
            (t, Some(n))
        }
    };
    Ok(Common {
        spec,
        layout,
        calibration,
        target,
        named_target,
    })
}

/// Runs `dicephys design`, as every study runs.
pub fn run(a: &DesignArgs) -> Result<()> {
    let cfg = config_of(a)?;
    // The directory is claimed once everything is checked: a refused design writes nothing.
    let place = super::study::here(a.out.as_deref(), None, a.roll.run.threads()?, *a.roll.json)?;
    super::study::run(&StudyConfig::Design(cfg), &place)
}

/// `--range NAME=LO:HI`, for the feature `--free` names.
fn range_of(s: &str, what: &str) -> Result<[f64; 2]> {
    let bad = |why: &str| Error::Usage(format!("--range '{s}': {why}"));
    let (name, span) = s
        .split_once('=')
        .ok_or_else(|| bad("write NAME=LO:HI, e.g. thickness=6:14"))?;
    if name.trim() != what {
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
