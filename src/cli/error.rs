//! How a command ends: its exit code and its one line on stderr.

use dicephys::error::Field;
use std::fmt;

/// The ways a command can end badly.
#[derive(Debug)]
pub enum Error {
    /// Bad input: exit code 2, one line naming what is wrong.
    Usage(String),
    /// A failure while running (I/O, an engine that cannot start): exit code 1.
    Run(String),
    /// Stopped by Ctrl-C or SIGTERM before the end, with what was done kept: exit code 130.
    Interrupted(String),
    /// Standard output was closed by its reader (`| head -1`): the command ends quietly.
    Closed,
}

impl Error {
    /// The process exit code.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Usage(_) => 2,
            Error::Run(_) => 1,
            Error::Interrupted(_) => 130,
            Error::Closed => 0,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Usage(m) | Error::Run(m) | Error::Interrupted(m) => f.write_str(m),
            Error::Closed => f.write_str("standard output closed"),
        }
    }
}

impl From<dicephys::Error> for Error {
    fn from(e: dicephys::Error) -> Error {
        if matches!(e, dicephys::Error::Stopped) {
            Error::Interrupted(dicephys::run::stop::interrupted(
                &dicephys::run::stop::Kept::Work,
            ))
        } else if e.is_input() {
            Error::Usage(named(&e))
        } else {
            // A failure may name what to change, as a field.
            Error::Run(named(&e))
        }
    }
}

/// The library's error with each field it names named by its flag.
pub fn named(e: &dicephys::Error) -> String {
    e.named(&|f| flag(f).to_string())
}

/// The flag that sets each field of the library's configurations: the one table from the
/// library's names to the command line's (a field only a die file sets is named as the file's
/// key). Every arm is checked against the commands' flags (`every_field_names_a_real_flag`).
pub fn flag(field: Field) -> &'static str {
    match field {
        Field::Account => "--account",
        Field::AllowRestitutionAboveOne => "--allow-restitution-above-one",
        Field::AngularDamping => "--angular-damping",
        Field::Bin => "--bin",
        Field::Block => "--block",
        Field::Blocks => "--blocks",
        Field::Bootstrap => "--bootstrap",
        Field::BudgetS => "--budget",
        Field::CheckRolls => "--check-rolls",
        Field::Com => "--com",
        Field::Contact => "--contact",
        Field::Counts => "--counts",
        Field::Data => "--data",
        Field::Density => "--density",
        Field::Dicephys => "--dicephys",
        Field::DiceRolls => "--dice-rolls",
        Field::Die => "--die",
        Field::Dir => "--dir",
        Field::Draws => "--draws",
        Field::DropHeight => "--drop-height",
        Field::Dt => "--dt",
        Field::Dts => "--dts",
        Field::EdgeRadius => "--edge-radius",
        Field::Engines => "--engines",
        Field::Every => "--every",
        Field::Faces => "--die's [faces]",
        Field::FlightDts => "--flight-dts",
        // Set by no command (validate's free flight lasts its default).
        Field::FlightTime => "flight_time",
        Field::Floor => "--floor",
        Field::FloorThickness => "--floor-thickness",
        Field::Free => "--free",
        Field::Friction => "--friction",
        Field::Frictions => "--frictions",
        Field::Index => "--index",
        Field::Inertia => "--die's inertia",
        Field::InsertCentre => "--die's insert.centre",
        Field::InsertDensity => "--die's insert.density",
        Field::InsertSize => "--die's insert.size",
        Field::Kappa => "--kappa",
        Field::Kind => "--source",
        Field::Ladder => "--ladder",
        Field::Layout => "--layout",
        Field::LinearDamping => "--linear-damping",
        Field::RollingResistance => "--rolling-resistance",
        Field::BounceThreshold => "--bounce-threshold",
        Field::ContactTime => "--contact-time",
        Field::StaticRatio => "--static-ratio",
        Field::Margin => "--margin",
        Field::MaxSteps => "--max-steps",
        Field::Modes => "--modes",
        Field::Null => "--null",
        Field::Out => "--out",
        Field::Partition => "--partition",
        Field::PipsDepth => "--pips depth",
        Field::PipsDiameter => "--pips diameter",
        Field::PipsFillDensity => "--die's pips.fill_density",
        Field::PipsSpacing => "--die's pips.spacing",
        Field::PlanOnly => "--plan",
        Field::PointRolls => "--point-rolls",
        Field::Points => "--points",
        Field::Precision => "--precision",
        Field::PrerollChunks => "--preroll",
        Field::ProfilePoints => "--profile-points",
        Field::Range => "--range",
        Field::RapierDts => "--rapier-dts",
        Field::Recover => "--recover",
        Field::ReferenceBudgetS => "--reference-budget",
        Field::ReferenceDt => "--reference-dt",
        Field::Refine => "--no-refine",
        Field::Repeat => "--repeat",
        Field::Repeats => "--repeats",
        Field::Resolve => "--resolve",
        Field::Restitution => "--restitution",
        Field::Restitutions => "--restitutions",
        Field::Rolls => "--rolls",
        Field::Scale => "--scale",
        Field::Seed => "--seed",
        Field::Settle => "--settle",
        Field::Shape => "--shape",
        Field::ShellInfill => "--shell infill",
        Field::ShellWall => "--shell wall",
        Field::Shared => "--shared",
        Field::Size => "--size",
        Field::Spin => "--spin",
        Field::Starts => "--starts",
        Field::Style => "--throw",
        Field::Tasks => "--tasks",
        Field::Threads => "--threads",
        Field::Time => "--time",
        Field::Trend => "--trend",
        Field::TrendRolls => "--trend-rolls",
        Field::Target => "--target",
        Field::Vary => "--vary",
        Field::Velocity => "--velocity",
    }
}

/// A library text with each field it names named by its flag.
pub fn flags_in(text: &dicephys::error::Text) -> String {
    text.named(&|f| flag(f).to_string())
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            Error::Closed
        } else {
            Error::Run(format!("standard output: {e}"))
        }
    }
}

/// A command's result.
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;
    use std::collections::HashSet;
    use strum::IntoEnumIterator;

    fn longs(c: &clap::Command, out: &mut HashSet<String>) {
        for a in c.get_arguments() {
            out.extend(a.get_long().map(String::from));
        }
        for s in c.get_subcommands() {
            longs(s, out);
        }
    }

    #[test]
    fn every_field_names_a_real_flag() {
        let mut all = HashSet::new();
        longs(&crate::cli::Cli::command(), &mut all);
        let missing: Vec<String> = Field::iter()
            .filter(|&f| f != Field::FlightTime)
            .filter(|&f| {
                let long = flag(f).trim_start_matches("--").split(['\'', ' ']).next();
                !all.contains(long.unwrap_or_default())
            })
            .map(|f| format!("{} ({})", f.name(), flag(f)))
            .collect();
        assert!(
            missing.is_empty(),
            "no command has these flags: {missing:?}"
        );
    }

    /// A default clap must spell as text (a list, shown comma-separated) is the library's.
    #[test]
    fn the_engines_spelt_as_defaults_are_the_librarys() {
        use clap::Parser;
        let parsed = |args: &[&str]| crate::cli::Cli::try_parse_from(args).unwrap().command;
        let want = dicephys::studies::paper::DEFAULT_ENGINES.to_vec();
        match parsed(&["dicephys", "paper"]) {
            crate::cli::Command::Paper(a) => assert_eq!(a.engines, want),
            _ => unreachable!(),
        }
        match parsed(&["dicephys", "validate"]) {
            crate::cli::Command::Validate(a) => {
                assert_eq!(
                    a.engines,
                    dicephys::studies::validate::Config::default().engines
                )
            }
            _ => unreachable!(),
        }
    }

    /// Every study's flags, none given, make the library's default configuration: the lists
    /// clap spells as text (blocks, steps, ladders, trend points) included.
    #[test]
    fn the_studies_defaults_spelt_in_clap_are_the_librarys() {
        use clap::Parser;
        use dicephys::studies::{calibrated, converge, stability, tradeoff, validate};
        let parsed = |args: &[&str]| crate::cli::Cli::try_parse_from(args).unwrap().command;
        match parsed(&["dicephys", "validate"]) {
            crate::cli::Command::Validate(a) => assert_eq!(a.config(), validate::Config::default()),
            _ => unreachable!(),
        }
        match parsed(&["dicephys", "converge"]) {
            crate::cli::Command::Converge(a) => assert_eq!(a.config(), converge::Config::default()),
            _ => unreachable!(),
        }
        match parsed(&["dicephys", "stability"]) {
            crate::cli::Command::Stability(a) => {
                assert_eq!(a.config(), stability::Config::default())
            }
            _ => unreachable!(),
        }
        match parsed(&["dicephys", "tradeoff"]) {
            crate::cli::Command::Tradeoff(a) => {
                assert_eq!(a.config().unwrap(), tradeoff::Config::default())
            }
            _ => unreachable!(),
        }
        match parsed(&["dicephys", "paper"]) {
            crate::cli::Command::Paper(a) => {
                assert_eq!(a.reference_dt, calibrated::DEFAULT_REFERENCE_DT)
            }
            _ => unreachable!(),
        }
    }

    #[test]
    fn the_ranges_spelt_in_fits_help_are_the_librarys() {
        use clap::CommandFactory;
        use dicephys::calibration::params::Kind;
        let cmd = crate::cli::Cli::command();
        let fit = cmd.find_subcommand("fit").unwrap();
        let arg = fit.get_arguments().find(|a| a.get_id() == "ranges");
        let help = arg.unwrap().get_help().unwrap().to_string();
        let spelt = help
            .split("Defaults: ")
            .nth(1)
            .unwrap()
            .trim_end_matches('.');
        let mut seen = 0;
        for item in spelt.split(", ") {
            let (names, range) = item.split_once('=').unwrap();
            let (lo, hi) = range.split_once(':').unwrap();
            let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
            let kinds: Vec<String> = match names {
                "com_x|y|z" => vec!["com_x".into(), "com_y".into(), "com_z".into()],
                one => vec![one.into()],
            };
            for k in kinds {
                let r = dicephys::error::parse_name::<Kind>("parameter", &k)
                    .unwrap()
                    .default_range();
                assert_eq!(
                    (r.lo, r.hi),
                    (lo, hi),
                    "--range's help spells {k} as {item}"
                );
                seen += 1;
            }
        }
        assert_eq!(seen, 11, "every kind's default range spelt: {spelt}");
    }

    #[test]
    fn a_message_names_fields_by_flag_and_leaves_other_words_alone() {
        use dicephys::error::Field;
        let why = dicephys::text![
            "give ",
            Field::MaxSteps,
            " or ",
            Field::Style,
            ", not a `roll` checkpoint"
        ];
        assert_eq!(
            flags_in(&why),
            "give --max-steps or --throw, not a `roll` checkpoint"
        );
        let e = dicephys::Error::field(
            Field::Recover,
            "e=2",
            dicephys::text!["outside (", Field::Range, " sets it)"],
        );
        assert_eq!(named(&e), "--recover e=2: outside (--range sets it)");
        assert_eq!(e.to_string(), "recover e=2: outside (`range` sets it)");
    }
}
