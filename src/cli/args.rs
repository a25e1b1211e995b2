//! Command-line arguments shared by the commands that simulate. They only spell the library's
//! types; every check of a value is the library's (`Scene::validate`, `RunSpec::validate`).

use super::error::{Error, Result};
use clap::{Args, ValueEnum};
use dicephys::engine::EngineKind;
use dicephys::error::parse_name;
use dicephys::model::block::Block;
use dicephys::model::faces::Layout;
use dicephys::model::scene::{Floor, Preset, Scene};
use dicephys::model::throws::{Range, ThrowKind, ThrowRanges, ThrowStyle};
use dicephys::run::request::{DieRequest, EndRequest, RollRequest, SceneRequest, ThrowRequest};
use dicephys::run::spec::ThrowSpec;
use dicephys::sim::roll::{RollConfig, Rule, DEFAULT_MARGIN, DEFAULT_MAX_STEPS};

/// The seed of the keyed throws (`*seed` reads it).
#[derive(Args, Debug, Clone, Copy)]
pub struct Seed {
    /// Seed of the throws (each throw drawn from the seed and its own number, "keyed"): the
    /// same seed gives the same rolls on any thread count.
    #[arg(long, default_value_t = dicephys::model::throws::DEFAULT_SEED)]
    pub seed: u64,
}

/// Worker threads (`*threads` reads them as given; `Threads::checked` resolves 0).
#[derive(Args, Debug, Clone, Copy)]
pub struct Threads {
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// One JSON document on stdout in place of the text (`*json` reads it).
#[derive(Args, Debug, Clone, Copy)]
pub struct Json {
    /// Print the result as one JSON document on stdout (its keys: docs/json.md), in place of
    /// the text and the progress bar.
    #[arg(long)]
    pub json: bool,
}

/// The step cap, the library's [`DEFAULT_MAX_STEPS`] unless given (`*max_steps` reads it).
/// Not generic over its default: clap's derive keeps a `default_value_t`'s text in a static
/// that every instantiation of a generic shares, so `MaxSteps<2_000_000>` and
/// `MaxSteps<20_000>` both showed and used the first one built (20,000,000). The sweeps,
/// whose caps differ, declare their own (`cli::sweeps`).
#[derive(Args, Debug, Clone, Copy)]
pub struct MaxSteps {
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = DEFAULT_MAX_STEPS)]
    pub max_steps: u64,
}

impl std::ops::Deref for Seed {
    type Target = u64;
    fn deref(&self) -> &u64 {
        &self.seed
    }
}

impl std::ops::Deref for Threads {
    type Target = usize;
    fn deref(&self) -> &usize {
        &self.threads
    }
}

impl std::ops::Deref for Json {
    type Target = bool;
    fn deref(&self) -> &bool {
        &self.json
    }
}

impl std::ops::Deref for MaxSteps {
    type Target = u64;
    fn deref(&self) -> &u64 {
        &self.max_steps
    }
}

impl MaxSteps {
    /// The step cap asked, as the library's request: `None` when left at its default, so
    /// that the library chooses the die's (`EndRequest::cap`: a die of any shape's is
    /// smaller).
    pub fn asked(&self) -> Option<u64> {
        Some(self.max_steps).filter(|&m| m != DEFAULT_MAX_STEPS)
    }
}

impl Threads {
    /// The worker threads, checked (0: one per core).
    pub fn checked(&self) -> Result<usize> {
        threads(self.threads)
    }
}

/// The scene: the block, the surface, the time step.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// The block, LENGTHxBREADTHxWIDTH in mm (the paper's order), e.g. 140x24x20.
    #[arg(long)]
    pub block: Option<Block>,
    /// DicePhys's 2D mode: a 1 m deep box locked to the x-y plane.
    #[arg(long = "2d")]
    pub two_d: bool,
    /// Fixed time step, s, as a decimal or a fraction (the paper: 0.001, or 1/1000).
    #[arg(long, default_value_t = SceneRequest::default().dt, value_parser = parse_step)]
    pub dt: f64,
    /// The contact's friction coefficient μ (the die's; the floor's is 1).
    #[arg(long, default_value_t = SceneRequest::default().friction)]
    pub friction: f64,
    /// The contact's restitution e (the die's; the floor's is 1).
    #[arg(long, default_value_t = SceneRequest::default().restitution)]
    pub restitution: f64,
    /// Allow a restitution above 1 (an engine-stability study, not physics).
    #[arg(long)]
    pub allow_restitution_above_one: bool,
    /// The engines' contact settings: dicephys281 (Bullet 2.81 as the paper ran it), bullet3
    /// (Debian 3.24's defaults), split (dicephys281 with every penetration pushed out apart from
    /// the bounce, so that a bounce is exactly e: dicephys281's averages e + 0.1) or laws (each
    /// engine held to the impact, friction and flight closed forms a loaded or long die needs)
    /// [default: dicephys281; crosscheck: laws].
    #[arg(long, value_parser = parse_preset)]
    pub preset: Option<Preset>,
    /// The floor: box (DicePhys's 10 km static box) or plane.
    #[arg(long, default_value_t = SceneRequest::default().floor, value_parser = parse_floor)]
    pub floor: Floor,
    /// The box floor's thickness, m [default: 100, DicePhys's; the plane floor has none]. A
    /// table top (0.02) is thin enough for a die to pass through at a coarse step: a real
    /// tunnel, counted as failed.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub floor_thickness: Option<f64>,
    /// Linear damping, a rate in 1/s (velocity ∝ e^(−λt) out of contact; 0 to 30; DicePhys: 0).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub linear_damping: f64,
    /// Angular damping, a rate in 1/s (0 to 30; DicePhys: 0).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub angular_damping: f64,
    /// Rolling resistance, mm: the lever arm of the floor's push against a die rolling or
    /// turning in place, so that a cylinder rolling on its side or a coin spinning on its rim
    /// stops (0 to 1; hard surfaces about 0.01, felt more; DicePhys: 0). Bullet, and Rapier
    /// in 3D [default: 0.05 for a coin, else 0].
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub rolling_resistance: Option<f64>,
    /// Bounce threshold, m/s: an impact slower than this along the contact's normal does not
    /// bounce, a faster one bounces with --restitution (0 to 2; DicePhys: 0). Bullet only.
    #[arg(
        long,
        value_name = "M/S",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub bounce_threshold: f64,
    /// Contact time, ms: a soft table, each impact a spring and a dashpot whose flat landing
    /// lasts this long and leaves at --restitution times its speed (0: the rigid contact,
    /// DicePhys's; else at least two steps of --dt, up to 50; felt or cloth a few ms, a hard
    /// table about 0.1). Bullet only.
    #[arg(
        long,
        value_name = "MS",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub contact_time: f64,
    /// Static friction over sliding friction, μs/μk: a contact point that is not sliding (its
    /// slip under g·dt as a step begins) holds up to this times --friction; a sliding one drags
    /// with --friction (1 to 3; steel on steel about 1.3, wood on wood up to 2; DicePhys: 1, one
    /// friction). Bullet only.
    #[arg(
        long,
        value_name = "RATIO",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub static_ratio: f64,
    /// Never let the engine put the die to sleep (for slow, over-damped rolls, which it would
    /// freeze mid-fall).
    #[arg(long)]
    pub no_sleep: bool,
    /// The die as it is made: its centre of mass, pips, rounded edges, density.
    #[command(flatten)]
    pub made: DieArgs,
}

/// The die as it is made (3D only): what departs from the paper's uniform, sharp block.
#[derive(Args, Debug, Clone, Default)]
pub struct DieArgs {
    /// The die's density, kg/m³ [default: 800, or the --die file's].
    #[arg(long)]
    pub density: Option<f64>,
    /// The die's centre of mass, X,Y,Z in mm from its geometric centre along the body axes
    /// (x breadth, y width, z length): 0,0,-2 is a weight toward the −z face (6 on a western
    /// die). The inertia about the centre stays the solid's. 3D only.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_com)]
    pub com: Option<[f64; 3]>,
    /// Pips drilled in the standard pattern (one to six, as the faces' numbers), DIAMETER,DEPTH
    /// in mm, as spherical caps: they lighten the die (its mass, centre and inertia), not its
    /// surface. Paint, cylinders, spacing: in a --die file. 3D only.
    #[arg(long, value_name = "D,H", allow_hyphen_values = true, value_parser = parse_pips)]
    pub pips: Option<[f64; 2]>,
    /// Round the die's edges and corners with this radius, mm (0, the default: sharp). 3D only.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub edge_radius: Option<f64>,
    /// A 3D-printed die: a solid wall WALL mm thick under every face and a sparse infill of
    /// volume fraction INFILL (0 to 1) inside it, as a slicer prints it (e.g. 1,0.2): its
    /// mass, centre of mass and inertia are the wall's and the infill's. 3D only.
    #[arg(long, value_name = "WALL,INFILL", allow_hyphen_values = true, value_parser = parse_shell)]
    pub shell: Option<[f64; 2]>,
    /// A die file: a mesh (FILE.obj or FILE.stl, in mm: a die of any shape, rolled on its
    /// convex hull, its mass from the mesh as given), or TOML (lengths in mm): com,
    /// edge_radius, density, [pips] diameter, depth, shape (cap or cylinder), fill_density,
    /// spacing, [shell] wall, infill; or mesh, scale, reads (up or down) and labels for a mesh. Flags given beside
    /// it override its values.
    #[arg(long, value_name = "FILE")]
    pub die: Option<std::path::PathBuf>,
    /// A die of a named shape in place of --block: d4, d6, d8, d10 (pentagonal
    /// trapezohedron), d12, d20, coin:D,H (a cylinder D mm across, H thick: heads, tails or
    /// edge), prism:N,D,L (an N-sided prism D mm across its corners, L long). Thrown in a
    /// tumble. Without --block, --shape or --die: a 16 mm d6.
    #[arg(long, value_name = "NAME")]
    pub shape: Option<String>,
    /// A named shape's size, mm, instead of its standard one (see the guide: a d4's edge,
    /// the others' distance between opposite faces).
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub size: Option<f64>,
    /// A mesh's lengths times this (e.g. 25.4 for a mesh in inches; default 1: mm).
    #[arg(long, value_name = "FACTOR", allow_hyphen_values = true)]
    pub scale: Option<f64>,
}

impl DieArgs {
    /// The die asked, as the library's request: `block` (a fit's rows name their own: none)
    /// and the faces' `layout` beside these flags.
    pub fn request(&self, block: Option<Block>, layout: Option<Layout>) -> DieRequest {
        DieRequest {
            block,
            shape: self.shape.clone(),
            size: self.size,
            scale: self.scale,
            file: self.die.clone(),
            density: self.density,
            com: self.com,
            pips: self.pips,
            edge_radius: self.edge_radius,
            shell: self.shell,
            layout,
        }
    }

    /// A refused value a TOML die file gave (its flag not given beside it), named by the file
    /// and its key as the user wrote them, not by a flag they did not give (reliability round
    /// 5, class G): "--die d.toml: com 0,0,8: must lie inside the die".
    pub fn named(&self, e: dicephys::Error) -> Error {
        use dicephys::error::Field as F;
        let (Some(path), dicephys::Error::Field { field, value, why }) = (&self.die, &e) else {
            return e.into();
        };
        let (key, flagged) = match field {
            F::Com => ("com", self.com.is_some()),
            F::Density => ("density", self.density.is_some()),
            F::EdgeRadius => ("edge_radius", self.edge_radius.is_some()),
            F::PipsDiameter => ("pips.diameter", self.pips.is_some()),
            F::PipsDepth => ("pips.depth", self.pips.is_some()),
            F::PipsSpacing => ("pips.spacing", false),
            F::PipsFillDensity => ("pips.fill_density", false),
            F::Inertia => ("inertia", false),
            F::InsertCentre => ("insert.centre", false),
            F::InsertDensity => ("insert.density", false),
            F::InsertSize => ("insert.size", false),
            F::ShellWall => ("shell.wall", self.shell.is_some()),
            F::ShellInfill => ("shell.infill", self.shell.is_some()),
            _ => return e.into(),
        };
        if flagged || dicephys::model::mass::is_mesh(path) {
            return e.into();
        }
        let value = if value.is_empty() {
            String::new()
        } else {
            format!(" {value}")
        };
        Error::Usage(format!(
            "--die {}: {key}{value}: {}",
            path.display(),
            super::error::flags_in(why)
        ))
    }
}

/// Two or three numbers separated by commas.
fn numbers<const N: usize>(what: &str, s: &str) -> std::result::Result<[f64; N], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let mut out = [0.0; N];
    if parts.len() != N {
        return Err(format!("'{s}' is not {what}"));
    }
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p
            .parse::<f64>()
            .map_err(|_| format!("'{s}': '{p}' is not a number of mm"))?;
    }
    Ok(out)
}

fn parse_com(s: &str) -> std::result::Result<[f64; 3], String> {
    numbers("X,Y,Z in mm (e.g. 0,0,-2)", s)
}

fn parse_pips(s: &str) -> std::result::Result<[f64; 2], String> {
    numbers("DIAMETER,DEPTH in mm (e.g. 3,1)", s)
}

fn parse_shell(s: &str) -> std::result::Result<[f64; 2], String> {
    numbers(
        "WALL,INFILL: the wall in mm, the infill a fraction (e.g. 1,0.2)",
        s,
    )
    .map_err(|e| e.replace("a number of mm", "a number"))
}

/// Where the throws come from.
#[derive(Args, Debug, Clone)]
pub struct ThrowArgs {
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Where the throws' numbers come from: keyed (each throw from (seed, index)) or dicephys
    /// (DicePhys's glibc rand() sequence, the paper's throw only).
    #[arg(long = "source", alias = "throws", default_value_t = ThrowRequest::default().source, value_parser = parse_throw_kind)]
    pub source: ThrowKind,
    /// Launch velocity, m/s: LO:HI, or one number (the paper's throw: along x; a tumble or a
    /// hand's throw: its speed, in a random horizontal direction).
    #[arg(long, default_value_t = ThrowRanges::default().velocity, allow_hyphen_values = true)]
    pub velocity: Range,
    /// Spin, rad/s: LO:HI, or one number (the paper's throw: about the length axis; a tumble
    /// or a hand's throw: its magnitude, about an axis drawn at random).
    #[arg(long, default_value_t = ThrowRanges::default().spin, allow_hyphen_values = true)]
    pub spin: Range,
    /// Drop height added to the longest side, m: LO:HI, or one number.
    #[arg(long, default_value_t = ThrowRanges::default().drop_height, allow_hyphen_values = true)]
    pub drop_height: Range,
    /// How the die is thrown: paper (length along z, spin about it, velocity along x), tumble
    /// (random orientation, spin axis uniform on the sphere, velocity in a random horizontal
    /// direction; the ranges give the magnitudes), hand (between the two, by --kappa), rest
    /// (released at rest in a random orientation, its lowest corner touching the floor; no
    /// range is used) or toss (a tumble whose magnitudes have scales, not ranges: the spin an
    /// isotropic Gaussian of RMS the spin range's middle, the height above touching and the
    /// speed half-normal, of mean the drop height's middle and RMS the velocity's larger end;
    /// every range 0 is the rest; with --kappa, in a hand's directions) or flip (a spin about
    /// one of the die's diameters, square to its z axis, which starts upright; the toss's
    /// magnitudes). [default: paper; `fair`: tumble]
    #[arg(long = "throw", value_parser = parse_throw_style)]
    pub style: Option<ThrowStyle>,
    /// A hand's throw, with this concentration κ >= 0: the paper's throw turned by random
    /// angles whose mean cosine is coth κ − 1/κ (0: the tumble's spread; large: the paper's
    /// throw). Implies --throw hand; with --throw toss, the toss's directions a hand's.
    #[arg(long, value_name = "KAPPA", allow_hyphen_values = true)]
    pub kappa: Option<f64>,
}

/// What ends a roll, on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SettleArg {
    /// The exact early stop: energy below the barrier out of the current face.
    Certificate,
    /// At rest by DicePhys's rule.
    Dicephys,
}

/// How free flight is stepped, on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FlightArg {
    /// Integrated outside the engine: in closed form where its flight is ballistic (Bullet),
    /// or as the engine itself steps it (Rapier).
    Fast,
    /// Every step by the engine.
    Stepped,
}

/// How many rolls, how.
#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// Number of rolls [default: 10,000]; with --precision (fair: --within), the most it may take [default:
    /// 10,000,000].
    #[arg(long)]
    pub rolls: Option<u64>,
    /// Roll until the ratio breadth/width is known to this precision: its relative 2σ error
    /// (per cent, e.g. 2 or 2%) at most this, tested every 1,000 rolls, so that the same seed
    /// gives the same rolls on any thread count. The summary says how many rolls it took.
    #[arg(long, value_name = "PERCENT", value_parser = parse_percent)]
    pub precision: Option<f64>,
    /// Worker threads.
    #[command(flatten)]
    pub threads: Threads,
    /// The step cap.
    #[command(flatten)]
    pub max_steps: MaxSteps,
    /// What ends a roll: certificate (the exact early stop: energy below the barrier out of
    /// the current face) or dicephys (at rest by DicePhys's rule). Default: certificate at
    /// dt <= 1/250 s, where it is audited exact; dicephys at coarser steps.
    #[arg(long, value_enum)]
    pub settle: Option<SettleArg>,
    /// The certificate's reserve, a fraction of the barrier in [0, 1).
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
    /// Settle by DicePhys's rule but record when the certificate would have stopped each roll
    /// and whether it named the same outcome.
    #[arg(long)]
    pub audit: bool,
    /// Free flight: fast (integrated outside the engine: in closed form where its flight is
    /// ballistic, Bullet; as the engine steps it, Rapier; the default) or stepped (every step
    /// by the engine).
    #[arg(long, value_enum, default_value = "fast")]
    pub flight: FlightArg,
    /// DicePhys exactly as the paper ran it: --settle dicephys --flight stepped (with the
    /// defaults --floor box --preset dicephys281, crosscheck's included).
    #[arg(long, conflicts_with_all = ["settle", "flight"])]
    pub faithful: bool,
}

/// Percentage points of a probability, "0.5" or "0.5pp", as a probability in (0, 1).
pub fn parse_points(s: &str) -> std::result::Result<f64, String> {
    hundredths(s, "pp").map_err(|bad| match bad {
        Bad::Unread => format!("'{s}': give percentage points, e.g. 0.5 (each face to ±0.005)"),
        Bad::Range => format!("'{s}': must be in (0, 100) percentage points"),
    })
}

/// A precision in per cent, "1" or "1%", as a fraction in (0, 100 %).
pub fn parse_percent(s: &str) -> std::result::Result<f64, String> {
    hundredths(s, "%").map_err(|bad| match bad {
        Bad::Unread => format!("bad precision '{s}': give per cent, e.g. 1 or 1%"),
        Bad::Range => format!("precision '{s}': must be in (0, 100) %"),
    })
}

/// Why a number of hundredths was refused.
enum Bad {
    Unread,
    Range,
}

/// A number in (0, 100), its unit `suffix` optional, over 100.
fn hundredths(s: &str, suffix: &str) -> std::result::Result<f64, Bad> {
    let v: f64 = s
        .trim()
        .trim_end_matches(suffix)
        .trim()
        .parse()
        .map_err(|_| Bad::Unread)?;
    if v.is_finite() && v > 0.0 && v < 100.0 {
        Ok(v / 100.0)
    } else {
        Err(Bad::Range)
    }
}

/// `--dt` as clap reads it: a decimal or a fraction (the scene checks its range).
pub fn parse_step(s: &str) -> std::result::Result<f64, dicephys::Error> {
    dicephys::studies::sweep::parse_seconds(s)
}
/// `--preset` as clap reads it.
pub fn parse_preset(s: &str) -> std::result::Result<Preset, dicephys::Error> {
    parse_name("preset", s)
}
/// `--floor` as clap reads it.
pub fn parse_floor(s: &str) -> std::result::Result<Floor, dicephys::Error> {
    parse_name("floor", s)
}
/// `--source` as clap reads it.
pub fn parse_throw_kind(s: &str) -> std::result::Result<ThrowKind, dicephys::Error> {
    parse_name("throw source", s)
}
/// `--throw` as clap reads it.
pub fn parse_throw_style(s: &str) -> std::result::Result<ThrowStyle, dicephys::Error> {
    parse_name("throw style", s)
}
/// `--layout` as clap reads it: "unknown layout 'x' (known: right, left)".
pub fn parse_layout(
    s: &str,
) -> std::result::Result<dicephys::model::faces::Layout, dicephys::Error> {
    parse_name("layout", s)
}
/// `--null` as clap reads it.
pub fn parse_null(s: &str) -> std::result::Result<dicephys::studies::fair::Null, dicephys::Error> {
    s.parse().map_err(dicephys::Error::Invalid)
}
/// `--engines`'s default, spelt as clap takes it: the library's
/// `studies::paper::DEFAULT_ENGINES` (a test holds the two together).
pub const DEFAULT_ENGINES: &str = "bullet,rapier";

/// `--engine` as clap reads it.
pub fn parse_engine(s: &str) -> std::result::Result<EngineKind, dicephys::Error> {
    parse_name("engine", s)
}

impl SceneArgs {
    /// The scene asked, as the library's request.
    pub fn request(&self) -> SceneRequest {
        self.request_or(SceneRequest::default().preset)
    }

    /// The scene asked, with `preset` where none is given (a command whose own default differs:
    /// `crosscheck`'s, [`dicephys::studies::crosscheck::PRESET`]).
    pub fn request_or(&self, preset: Preset) -> SceneRequest {
        SceneRequest {
            die: self.made.request(self.block, None),
            two_d: self.two_d,
            dt: self.dt,
            friction: self.friction,
            restitution: self.restitution,
            allow_restitution_above_one: self.allow_restitution_above_one,
            preset: self.preset.unwrap_or(preset),
            floor: self.floor,
            floor_thickness: self.floor_thickness,
            linear_damping: self.linear_damping,
            angular_damping: self.angular_damping,
            rolling_resistance_mm: self.rolling_resistance,
            bounce_threshold: self.bounce_threshold,
            contact_time_ms: self.contact_time,
            static_ratio: self.static_ratio,
            sleep: !self.no_sleep,
        }
    }

    /// The scene, with every value checked before anything runs (a die file's value named by
    /// its key).
    pub fn scene(&self) -> Result<Scene> {
        self.scene_or(SceneRequest::default().preset)
    }

    /// The scene, checked, with `preset` where none is given.
    pub fn scene_or(&self, preset: Preset) -> Result<Scene> {
        self.request_or(preset)
            .scene()
            .map_err(|e| self.made.named(e))
    }
}

impl ThrowArgs {
    /// The throws asked, as the library's request.
    pub fn request(&self) -> ThrowRequest {
        ThrowRequest {
            source: self.source,
            seed: *self.seed,
            ranges: ThrowRanges {
                velocity: self.velocity,
                spin: self.spin,
                drop_height: self.drop_height,
            },
            style: self.style,
            kappa: self.kappa,
        }
    }

    /// The throws, checked, in the style `default` unless `--throw` (or `--kappa`) gives one.
    pub fn spec_or(&self, default: ThrowStyle) -> Result<ThrowSpec> {
        Ok(self.request().spec_or(default)?)
    }
}

impl RunArgs {
    /// How each roll ends, as the library's request: the step cap left at its default is the
    /// library's to choose (a die of any shape's is larger).
    pub fn end(&self) -> EndRequest {
        EndRequest {
            settle: self.settle.map(|s| match s {
                SettleArg::Certificate => Rule::Certificate,
                SettleArg::Dicephys => Rule::Dicephys,
            }),
            fast_flight: self.flight == FlightArg::Fast,
            faithful: self.faithful,
            audit: self.audit,
            max_steps: self.max_steps.asked(),
            margin: self.margin,
        }
    }

    /// The rolls asked, or the library's default (under --precision, its cap).
    pub fn rolls(&self) -> u64 {
        RollRequest {
            rolls: self.rolls,
            to_precision: self.precision.is_some(),
            ..RollRequest::default()
        }
        .rolls()
    }

    /// How each roll of `scene` is carried out and ended, checked.
    pub fn roll(&self, scene: &Scene) -> Result<RollConfig> {
        Ok(self.end().roll(scene)?)
    }

    /// The worker threads, checked (0: one per core).
    pub fn threads(&self) -> Result<usize> {
        self.threads.checked()
    }
}

/// Checks `--threads` (0: one per core) and resolves it (the library's check).
pub fn threads(asked: usize) -> Result<usize> {
    Ok(dicephys::run::batch::checked_threads(asked)?)
}
