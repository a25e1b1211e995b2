//! `dicephys design`: the value of one feature of a die that gives the probabilities a target
//! asks for, thrown as the scene throws it (`studies::design`).

use super::error::{Error, Result};
use super::roll::RollArgs;
use super::term::{out, outln};
use clap::Args;
use dicephys::model::throws::ThrowStyle;
use dicephys::studies::design::{Design, DesignConfig};
use dicephys::studies::fair::{Null, Varied};

/// Throws a scan rolls at each value unless --rolls says.
const DEFAULT_ROLLS: u64 = 2_000;

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
    /// rest=P gathers every label not named (6=1/4,rest=3/4).
    #[arg(long, value_name = "LABEL=P,...", value_parser = super::args::parse_null)]
    pub target: Null,
    /// Values each of the two scans rolls.
    #[arg(long, default_value_t = 9)]
    pub points: usize,
    /// Throws of the check: the design rolled at a fresh seed.
    #[arg(long, default_value_t = 20_000)]
    pub check_rolls: u64,
}

/// Runs `dicephys design`.
pub fn run(a: &DesignArgs) -> Result<()> {
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
    let Null::Target(target) = a.target.clone() else {
        return Err(Error::Usage(
            "--target: give each label's probability, LABEL=P,… (heads=1/3,tails=1/3,edge=1/3)"
                .into(),
        ));
    };
    let mut spec = r.spec_or(ThrowStyle::Tumble)?;
    spec.rolls = r.run.rolls.unwrap_or(DEFAULT_ROLLS);
    let cfg = DesignConfig {
        layout: r.layout(&spec),
        spec,
        what,
        range,
        target,
        points: a.points,
        check_rolls: a.check_rolls,
    };
    dicephys::studies::design::check(&cfg)?;
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
    if *r.json {
        outln!("{}", dicephys::run::seal::to_string(&design, true)?);
    } else {
        out!("{}", text(&design));
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

/// The design for the terminal.
fn text(d: &Design) -> String {
    use std::fmt::Write;
    let c = &d.config;
    let mut s = String::new();
    let die = match &c.spec.scene.shape {
        Some(shape) => shape.name.clone(),
        None => format!("{} mm", c.spec.scene.block),
    };
    let _ = writeln!(
        s,
        "design: {} of {die} ({}, {}), range {}–{} mm; two scans of {} values × {} throws, the \
         check {} throws at a fresh seed",
        c.what,
        c.spec.engine.name(),
        c.spec.throws.style,
        c.range[0],
        c.range[1],
        c.points,
        c.spec.rolls,
        c.check_rolls
    );
    let _ = writeln!(
        s,
        "\n  {} = {:.3} mm   (95 %: {:.3} to {:.3}; the designs the target allows within the \
         simulation's error)\n",
        c.what, d.value, d.interval[0], d.interval[1]
    );
    let _ = writeln!(
        s,
        "  {:<10} {:>8} {:>8} {:>17} {:>8} {:>7} {:>13}",
        "outcome", "target", "curve", "check", "design ±", "z", "quasi-static"
    );
    for (k, o) in d.outcomes.iter().enumerate() {
        let ch = &d.check;
        let _ = writeln!(
            s,
            "  {:<10} {:>8.4} {:>8.4} {:>8.4} ± {:.4} {:>8.4} {:>+7.2} {:>13}",
            o,
            c.target[k].1,
            d.curve[k],
            ch.p[k],
            ch.err[k],
            ch.design_err[k],
            ch.z[k],
            d.quasi_static
                .as_ref()
                .map_or("–".into(), |q| format!("{:.4}", q[k]))
        );
    }
    let _ = writeln!(s, "\n{}", d.verdict);
    s
}
