//! The library's errors. Which exit code each becomes is the command line's business.

use std::path::{Path, PathBuf};

/// What can go wrong in the library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A value refused before anything runs: out of range, malformed, or inconsistent.
    #[error("{0}")]
    Invalid(String),
    /// A value of a configuration refused before anything runs, named by its field as the
    /// library spells it (`max_steps`, `rolls`): "max_steps 0: need at least one step". The
    /// field, and any field `why` names, are typed ([`Text`]), so that a caller names each as
    /// its user knows it (the command line by its flag, Python by its argument).
    #[error("{}", field_line(field.name(), value, &why.to_string()))]
    Field {
        /// The field, e.g. `max_steps`.
        field: Field,
        /// Its value as given (empty if the field as a whole is wrong, e.g. an empty list).
        value: String,
        /// What is wrong with it, and what would do.
        why: Text,
    },
    /// Inputs that do not belong together: a checkpoint of another run, shards of two runs.
    #[error("{0}")]
    Mismatch(String),
    /// Reading or writing a file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// An engine could not be built, or failed outside a roll.
    #[error("{0}")]
    Engine(String),
    /// A stop was requested (Ctrl-C, SIGTERM) before the work was done; what was done is kept.
    #[error("stopped before the end")]
    Stopped,
    /// Anything else that stops a run: encoding output, drawing a figure, rolls that did not
    /// settle (its text may name the field to change).
    #[error("{0}")]
    Failed(Text),
}

/// A message that may name fields of the configurations: its words, and each field it names as
/// a [`Field`], so that whoever shows it names that field as its user knows it (the command
/// line by its flag, Python by its argument) without reading the text again. Shown as it is,
/// a field is its library name in backquotes: "raise `max_steps`". Built with [`text!`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Text(Vec<Part>);

/// A part of a [`Text`]: words, or a field.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Part {
    /// Words, as written.
    Words(String),
    /// A field, named by whoever shows the text.
    Field(Field),
}

impl From<&str> for Part {
    fn from(s: &str) -> Part {
        Part::Words(s.to_string())
    }
}

impl From<String> for Part {
    fn from(s: String) -> Part {
        Part::Words(s)
    }
}

impl From<Field> for Part {
    fn from(f: Field) -> Part {
        Part::Field(f)
    }
}

impl Text {
    /// The parts in order.
    pub fn new(parts: Vec<Part>) -> Text {
        Text(parts)
    }

    /// The text with each field named by `name`.
    pub fn named(&self, name: &dyn Fn(Field) -> String) -> String {
        self.0
            .iter()
            .map(|p| match p {
                Part::Words(w) => w.clone(),
                Part::Field(f) => name(*f),
            })
            .collect()
    }

    /// Words put before the text.
    pub fn after(self, words: &str) -> Text {
        let mut parts = vec![Part::from(words)];
        parts.extend(self.0);
        Text(parts)
    }
}

impl std::fmt::Display for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.named(&|field| format!("`{}`", field.name())))
    }
}

impl From<&str> for Text {
    fn from(s: &str) -> Text {
        Text(vec![s.into()])
    }
}

impl From<String> for Text {
    fn from(s: String) -> Text {
        Text(vec![s.into()])
    }
}

/// A [`Text`] of words and fields: `text!["raise ", Field::MaxSteps, " or use a finer ",
/// Field::Dt]`.
#[macro_export]
macro_rules! text {
    ($($part:expr),* $(,)?) => {
        $crate::error::Text::new(vec![$($crate::error::Part::from($part)),*])
    };
}

/// A value of a configuration that a check can refuse, as the library spells it
/// (`max_steps`, `pips.spacing`): a caller names each as its user knows it (the command line
/// by its flag, Python by its argument), in one table each.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    strum::IntoStaticStr,
    strum::EnumString,
    strum::EnumIter,
    strum::VariantNames,
)]
#[strum(serialize_all = "snake_case")]
pub enum Field {
    /// `account`.
    Account,
    /// `allow_restitution_above_one`.
    AllowRestitutionAboveOne,
    /// `angular_damping`.
    AngularDamping,
    /// `bin`.
    Bin,
    /// `block`.
    Block,
    /// `blocks`.
    Blocks,
    /// `bootstrap`.
    Bootstrap,
    /// `budget_s`.
    BudgetS,
    /// `check_rolls`.
    CheckRolls,
    /// `com`.
    Com,
    /// `contact`.
    Contact,
    /// `counts`.
    Counts,
    /// `data`.
    Data,
    /// `density`.
    Density,
    /// `dicephys`: DicePhys 2.81's binary, run beside `bench`.
    Dicephys,
    /// `dice_rolls`.
    DiceRolls,
    /// `die`.
    Die,
    /// `dir`.
    Dir,
    /// `draws`.
    Draws,
    /// `drop_height`.
    DropHeight,
    /// `dt`.
    Dt,
    /// `dts`.
    Dts,
    /// `edge_radius`.
    EdgeRadius,
    /// `engines`.
    Engines,
    /// `every`: `trace`'s rows, every Nth step's.
    Every,
    /// `faces`.
    Faces,
    /// `flight_dts`.
    FlightDts,
    /// `flight_time`.
    FlightTime,
    /// `floor`.
    Floor,
    /// `floor_thickness`.
    FloorThickness,
    /// `free`.
    Free,
    /// `friction`.
    Friction,
    /// `frictions`.
    Frictions,
    /// `index`: the throws `trace` follows.
    Index,
    /// `inertia`.
    Inertia,
    #[strum(serialize = "insert.centre")]
    /// `insert.centre`.
    InsertCentre,
    #[strum(serialize = "insert.density")]
    /// `insert.density`.
    InsertDensity,
    #[strum(serialize = "insert.size")]
    /// `insert.size`.
    InsertSize,
    /// `kappa`.
    Kappa,
    /// `kind`.
    Kind,
    /// `ladder`.
    Ladder,
    /// `layout`.
    Layout,
    /// `linear_damping`.
    LinearDamping,
    /// `margin`.
    Margin,
    /// `max_steps`.
    MaxSteps,
    /// `modes`.
    Modes,
    /// `null`.
    Null,
    /// `out`.
    Out,
    /// `partition`.
    Partition,
    #[strum(serialize = "pips.depth")]
    /// `pips.depth`.
    PipsDepth,
    #[strum(serialize = "pips.diameter")]
    /// `pips.diameter`.
    PipsDiameter,
    #[strum(serialize = "pips.fill_density")]
    /// `pips.fill_density`.
    PipsFillDensity,
    #[strum(serialize = "pips.spacing")]
    /// `pips.spacing`.
    PipsSpacing,
    /// `plan_only`.
    PlanOnly,
    /// `point_rolls`.
    PointRolls,
    /// `points`.
    Points,
    /// `precision`.
    Precision,
    /// `preroll_chunks`.
    PrerollChunks,
    /// `profile_points`.
    ProfilePoints,
    /// `range`.
    Range,
    /// `rapier_dts`.
    RapierDts,
    /// `recover`.
    Recover,
    /// `rolling_resistance`.
    RollingResistance,
    /// `bounce_threshold`.
    BounceThreshold,
    /// `contact_time`.
    ContactTime,
    /// `static_ratio`.
    StaticRatio,
    /// `reference_budget_s`.
    ReferenceBudgetS,
    /// `reference_dt`.
    ReferenceDt,
    /// `refine`.
    Refine,
    /// `repeat`: `bench`'s rounds, each measurement's fastest kept.
    Repeat,
    /// `repeats`.
    Repeats,
    /// `resolve`.
    Resolve,
    /// `restitution`.
    Restitution,
    /// `restitutions`.
    Restitutions,
    /// `rolls`.
    Rolls,
    /// `scale`.
    Scale,
    /// `seed`.
    Seed,
    /// `settle`.
    Settle,
    /// `shape`.
    Shape,
    #[strum(serialize = "shell.infill")]
    /// `shell.infill`.
    ShellInfill,
    #[strum(serialize = "shell.wall")]
    /// `shell.wall`.
    ShellWall,
    /// `shared`.
    Shared,
    /// `size`.
    Size,
    /// `spin`.
    Spin,
    /// `starts`.
    Starts,
    /// `style`.
    Style,
    /// `target`.
    Target,
    /// `tasks`.
    Tasks,
    /// `threads`.
    Threads,
    /// `time`.
    Time,
    /// `trend`.
    Trend,
    /// `trend_rolls`.
    TrendRolls,
    /// `vary`.
    Vary,
    /// `velocity`.
    Velocity,
}

impl Field {
    /// The field's name as the library spells it.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// A value as a message shows it: a number of many digits (1e300 prints as 301 of them) in
/// scientific notation, one that a unit's conversion left with a tail of rounding
/// (7.998999999999999) to 12 significant digits (7.999), each of a list's numbers alike,
/// anything else as it is.
fn shown_value(v: String) -> String {
    let one = |p: &str| match p.parse::<f64>() {
        Ok(x) if x.is_finite() && p.len() > 14 => {
            let short: f64 = format!("{x:.11e}").parse().unwrap_or(x);
            let plain = format!("{short}");
            if plain.len() > 20 {
                format!("{short:e}")
            } else {
                plain
            }
        }
        _ => p.to_string(),
    };
    v.split(',').map(one).collect::<Vec<_>>().join(",")
}

/// "field value: why", or "field: why" without a value.
fn field_line(field: &str, value: &str, why: &str) -> String {
    if value.is_empty() {
        format!("{field}: {why}")
    } else {
        format!("{field} {value}: {why}")
    }
}

impl Error {
    /// A value of `field` refused: see [`Error::Field`].
    pub fn field(field: Field, value: impl ToString, why: impl Into<Text>) -> Error {
        Error::Field {
            field,
            value: shown_value(value.to_string()),
            why: why.into(),
        }
    }

    /// A run stopped by `why`: see [`Error::Failed`].
    pub fn failed(why: impl Into<Text>) -> Error {
        Error::Failed(why.into())
    }

    /// The error's line with each field it names named by `name` (the command line's flags,
    /// Python's arguments); any other error as it shows itself.
    pub fn named(&self, name: &dyn Fn(Field) -> String) -> String {
        match self {
            Error::Field { field, value, why } => {
                field_line(&name(*field), value, &why.named(name))
            }
            Error::Failed(why) => why.named(name),
            e => e.to_string(),
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Error {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// True for errors in what was asked (bad values, mismatched inputs), not in running it.
    pub fn is_input(&self) -> bool {
        matches!(
            self,
            Error::Invalid(_) | Error::Field { .. } | Error::Mismatch(_)
        )
    }
}

/// The library's result type.
pub type Result<T> = std::result::Result<T, Error>;

/// Parses one of an enum's names (`strum`), or says which names there are:
/// "unknown floor 'x' (known: box, plane)".
pub fn parse_name<T>(what: &str, s: &str) -> Result<T>
where
    T: std::str::FromStr + strum::VariantNames,
{
    s.parse().map_err(|_| {
        Error::Invalid(format!(
            "unknown {what} '{s}' (known: {})",
            T::VARIANTS.join(", ")
        ))
    })
}
