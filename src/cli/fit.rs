//! `dicephys fit` (calibrate e, μ and the throw to measured counts, or check that a fit
//! recovers known values) and `dicephys predict` (a block the fit did not see).

use super::args::{parse_engine, parse_step};
use super::args::{Json, MaxSteps, Seed, Threads};
use super::error::{Error, Result};
use super::study::StudyPlace;
use clap::Args;
use dicephys::calibration::data;
use dicephys::calibration::params::{FixedThrow, Kind};
use dicephys::calibration::predict::PredictConfig;
use dicephys::calibration::request::FitRequest;
use dicephys::calibration::{FitConfig, FitResult};
use dicephys::engine::EngineKind;
use dicephys::model::block::Block;
use dicephys::model::scene::Mode;
use dicephys::model::throws::Range;
use dicephys::studies::fit::{
    BlocksConfig, BlocksStudy, FitStudy, PredictStudy, RecoverStudy, Stage,
};
use dicephys::studies::StudyConfig;
use std::path::PathBuf;

/// `dicephys fit`'s arguments.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// The measured counts: a CSV with the columns label, surface, length_mm, breadth_mm,
    /// width_mm, mode (2d or 3d), length_vertical, breadth_vertical, width_vertical and
    /// optionally thrower (docs/guide.md, "Calibrating"); or label, surface, die (a shape name
    /// or a die file beside the CSV) and face_<label> counts, several dice in one fit; or
    /// "paper", the paper's 19 rows.
    #[arg(long, value_name = "COUNTS.csv")]
    pub data: PathBuf,
    /// The free parameters (comma-separated): e (restitution), mu (friction), kappa (the
    /// throw's concentration, --throw hand), spin, height and speed (factors on the throw's
    /// spin, launch height and launch speed); for a die, com_x, com_y, com_z (its centre of
    /// mass, mm), pip_depth (mm) and infill (a printed die's infill fraction, in its --shell
    /// wall or a 1 mm one).
    #[arg(long, value_delimiter = ',', default_value = "e,mu", value_parser = parse_kind)]
    pub free: Vec<Kind>,
    /// Surface parameters shared by every surface instead of one per surface (e, mu).
    #[arg(long, value_delimiter = ',', value_parser = parse_kind)]
    pub shared: Vec<Kind>,
    /// A free parameter's range, NAME=LO:HI (repeat for several). Defaults: e=0.05:0.8,
    /// mu=0.1:1, kappa=0:10000, spin=0.25:3, height=0.1:2, speed=0.25:10, com_x|y|z=-2:2,
    /// pip_depth=0.2:1.5, infill=0:1.
    #[arg(long = "range", value_name = "NAME=LO:HI")]
    pub ranges: Vec<String>,
    /// e where it is not free.
    #[arg(long, default_value_t = FitRequest::default().restitution, allow_hyphen_values = true)]
    pub restitution: f64,
    /// μ where it is not free.
    #[arg(long, default_value_t = FitRequest::default().friction, allow_hyphen_values = true)]
    pub friction: f64,
    /// Where kappa is not free: a hand's throw with this concentration κ, as `roll --kappa`
    /// [default: the paper's throw].
    #[arg(long, value_name = "KAPPA", allow_hyphen_values = true)]
    pub kappa: Option<String>,
    /// The throw where kappa is not free, by its style: paper, tumble, toss (a hand's toss:
    /// the tumble's directions, its spin, height and speed drawn with scales, which the spin,
    /// height and speed parameters multiply; `roll --throw toss`; with --free kappa, in a
    /// hand's directions, `roll --throw toss --kappa K`), flip (a spin about a diameter, the toss's magnitudes;
    /// `roll --throw flip`) or rest (released at rest touching the table, `roll --throw rest`;
    /// no spin, height or speed) [default: the paper's throw for blocks, a tumble for a die of
    /// any shape]. A hand's throw is `--kappa K`.
    #[arg(long, value_name = "STYLE", value_parser = ["paper", "tumble", "toss", "flip", "rest"])]
    pub throw: Option<String>,
    /// The spin scale where spin is not free.
    #[arg(long, default_value_t = FitRequest::default().spin_scale, allow_hyphen_values = true)]
    pub spin_scale: f64,
    /// The die thrown, as `roll` takes it (a centre of mass that is not free, pips, rounded
    /// edges, a die file); one die for every row, 3D only.
    #[command(flatten)]
    pub made: super::args::DieArgs,
    /// Which number is on which face, for counts of faces: right (western dice) or left
    /// [default: the --die file's layout or face map, else right].
    #[arg(long, value_parser = super::args::parse_layout)]
    pub layout: Option<dicephys::model::faces::Layout>,
    /// The engine.
    #[arg(long, default_value_t = FitRequest::default().engine, value_parser = parse_engine)]
    pub engine: EngineKind,
    /// The time step, s or 1/N.
    #[arg(long, default_value_t = FitRequest::default().dt, value_parser = parse_step)]
    pub dt: f64,
    /// The step cap.
    #[command(flatten)]
    pub max_steps: MaxSteps,
    /// Parameter points each block is simulated at.
    #[arg(long, default_value_t = FitRequest::default().points)]
    pub points: usize,
    /// Rolls at each parameter point (as `paper --calibrated --point-rolls`).
    #[arg(long = "point-rolls", alias = "rolls", default_value_t = FitRequest::default().point_rolls)]
    pub rolls: u64,
    /// The surrogate's polynomial degree (raised while it lacks fit, up to --max-degree)
    /// [default: 3; 2 for a die of more than six faces].
    #[arg(long)]
    pub degree: Option<usize>,
    /// The highest surrogate degree tried [default: 4; 2 for a die of more than six faces].
    #[arg(long)]
    pub max_degree: Option<usize>,
    /// One pass only: no second pass over the box narrowed to the first pass's region.
    #[arg(long)]
    pub no_refine: bool,
    /// The same throws at every design point (common random numbers) rather than independent
    /// ones, to compare the two (docs/results/calibration.md).
    #[arg(long)]
    pub common_throws: bool,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Threads, --out, --json.
    #[command(flatten)]
    pub place: StudyPlace,
    /// Instead of fitting the file's counts: simulate counts of its rows (same blocks and
    /// numbers of throws) at these values, NAME=V,… for every free parameter, fit them back,
    /// --repeats times, and report how often the 2σ region holds the truth.
    #[arg(long, value_name = "NAME=V,...")]
    pub recover: Option<String>,
    /// With --recover: repetitions (each its own data and simulations).
    #[arg(long, default_value_t = dicephys::calibration::recovery::DEFAULT_REPEATS)]
    pub repeats: usize,
}

/// `dicephys predict`'s arguments.
#[derive(Args, Debug)]
pub struct PredictArgs {
    /// The fit to predict from (a fit's fit.json).
    #[arg(long, value_name = "FIT.json")]
    pub fit: PathBuf,
    /// The block, LENGTHxBREADTHxWIDTH in mm (a fit of a die of any shape predicts that die:
    /// leave it out).
    #[arg(long, conflicts_with = "blocks")]
    pub block: Option<Block>,
    /// Many blocks at once: a CSV with the columns label, block, mode and optionally surface,
    /// thrower and the three counts (length_vertical, breadth_vertical, width_vertical), or a
    /// counts file; writes the table, its figure and, where counted, each row's z and the χ²
    /// of the whole into --out.
    /// (`--blocks`, its name until this version, still reads: elsewhere `--blocks` is a list.)
    #[arg(long = "blocks-file", alias = "blocks", value_name = "BLOCKS.csv", conflicts_with_all = ["two_d", "surface", "thrower"])]
    pub blocks: Option<PathBuf>,
    /// With --blocks-file: the output directory [default: predict-out].
    #[arg(long, value_name = "OUT", requires = "blocks")]
    pub out: Option<PathBuf>,
    /// Simulate it in 2D (DicePhys's plane-locked block).
    #[arg(long = "2d")]
    pub two_d: bool,
    /// The surface whose fitted e and μ to use (when the fit has one per surface).
    #[arg(long)]
    pub surface: Option<String>,
    /// The thrower whose fitted throw to use (when the fit has several).
    #[arg(long)]
    pub thrower: Option<String>,
    /// Another surface, by its restitution e and friction μ (E,MU), where the fit held e and
    /// μ fixed: a die whose weight a fit found on one surface, predicted on another.
    #[arg(long, value_name = "E,MU", conflicts_with_all = ["surface", "blocks"], value_parser = parse_contact)]
    pub contact: Option<[f64; 2]>,
    /// Another die than the fit's, thrown by the same hand on the same table: --shape NAME or
    /// --die FILE (a mesh or a die file, as `roll` takes it), or --block from a fit of a die of
    /// any shape; the fit's surface and throw, the die's own geometry and mass.
    #[command(flatten)]
    pub other: super::args::DieArgs,
    /// Counts of the die predicted (`fit --data`'s format: a block's sides, a cube's faces or a
    /// die of any shape's face_<label> columns): the prediction is scored against each row
    /// (log predictive density, Σz² and coverage, sharpness) beside the uncalibrated default
    /// scene and the quasi-static theory.
    #[arg(long, value_name = "COUNTS.csv", conflicts_with = "blocks")]
    pub counts: Option<PathBuf>,
    /// The fit's discrepancy (how far it missed rows it did not see): applied where it
    /// improved the fit's held-out log score (auto), always (on) or never (off).
    #[arg(long, value_name = "auto|on|off", default_value = "auto")]
    pub discrepancy: dicephys::calibration::discrepancy::Use,
    /// Posterior draws to simulate the block at.
    #[arg(long, default_value_t = dicephys::calibration::predict::DEFAULT_DRAWS)]
    pub draws: usize,
    /// Rolls at each draw.
    #[arg(long, default_value_t = dicephys::calibration::predict::DEFAULT_ROLLS)]
    pub rolls: u64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Worker threads.
    #[command(flatten)]
    pub threads: Threads,
    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
}

/// `E,MU`: two numbers.
fn parse_contact(s: &str) -> std::result::Result<[f64; 2], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts[..] {
        [e, mu] => match (e.parse::<f64>(), mu.parse::<f64>()) {
            (Ok(e), Ok(mu)) => Ok([e, mu]),
            _ => Err(format!("'{s}': E and MU must be numbers")),
        },
        _ => Err(format!("'{s}' is not E,MU (e.g. 0.2,0.6)")),
    }
}

/// A parameter's name as clap reads it.
pub fn parse_kind(s: &str) -> std::result::Result<Kind, dicephys::Error> {
    dicephys::error::parse_name("parameter", s)
}

/// `NAME=V` pairs, comma-separated, each name a parameter kind given once.
fn pairs<T>(
    flag: &str,
    items: &[&str],
    value: impl Fn(&str) -> std::result::Result<T, String>,
) -> Result<Vec<(Kind, T)>> {
    let out: Vec<(Kind, T)> = items
        .iter()
        .map(|item| {
            let (k, v) = item
                .split_once('=')
                .ok_or_else(|| Error::Usage(format!("{flag} {item}: write NAME=VALUE")))?;
            let kind =
                parse_kind(k.trim()).map_err(|e| Error::Usage(format!("{flag} {item}: {e}")))?;
            let v = value(v.trim()).map_err(|e| Error::Usage(format!("{flag} {item}: {e}")))?;
            Ok((kind, v))
        })
        .collect::<Result<_>>()?;
    once(flag, out.iter().map(|p| p.0))?;
    Ok(out)
}

/// Refuses a parameter named twice in one flag (which of the two was meant?).
fn once(flag: &str, kinds: impl Iterator<Item = Kind>) -> Result<()> {
    let mut seen = Vec::new();
    for k in kinds {
        if seen.contains(&k) {
            return Err(Error::Usage(format!(
                "{flag}: {k} is given twice; give each parameter once"
            )));
        }
        seen.push(k);
    }
    Ok(())
}

impl FitArgs {
    /// The fit asked, as the library's request: the counts read (`--data`), the names parsed.
    fn request(&self) -> Result<FitRequest> {
        let rows = if self.data.as_os_str() == "paper" && !self.data.exists() {
            data::paper_rows()?
        } else {
            data::read(&self.data, super::term::stop()).map_err(|e| match e {
                dicephys::Error::Stopped => Error::Interrupted(nothing_read()),
                e => Error::Usage(format!("--data {e}")),
            })?
        };
        let given: Vec<&str> = self.ranges.iter().map(String::as_str).collect();
        let ranges = pairs("--range", &given, |v| {
            v.parse::<Range>().map_err(|e| e.to_string())
        })?;
        // `--kappa paper`, the paper's throw, was the spelling before --kappa meant only a
        // hand's κ; it is still read.
        let style = match self.throw.as_deref() {
            Some("paper") => Some(FixedThrow::Paper),
            Some("tumble") => Some(FixedThrow::Tumble),
            Some("toss") => Some(FixedThrow::Toss),
            Some("flip") => Some(FixedThrow::Flip),
            Some(_) => Some(FixedThrow::Rest),
            None => None,
        };
        let throw = match self.kappa.as_deref() {
            None => style,

            Some(k) if style.is_some() => {
                return Err(Error::Usage(format!(
                    "--kappa {k} with --throw: a hand's throw has its own style; give one of them \
                     (--throw toss --free kappa fits a toss in a hand's directions)"
                )))
            }
            Some("paper") => Some(FixedThrow::Paper),
            Some("tumble") => Some(FixedThrow::Tumble),
            Some(k) => Some(FixedThrow::Hand(k.parse().map_err(|_| {
                Error::Usage(format!(
                    "--kappa {k}: a hand's concentration, a number >= 0"
                ))
            })?)),
        };
        Ok(FitRequest {
            rows,
            free: self.free.clone(),
            shared: self.shared.clone(),
            ranges,
            restitution: self.restitution,
            friction: self.friction,
            throw,
            spin_scale: self.spin_scale,
            die: self.made.request(None, self.layout),
            engine: self.engine,
            dt: self.dt,
            max_steps: *self.max_steps,
            points: self.points,
            point_rolls: self.rolls,
            degree: self.degree,
            max_degree: self.max_degree,
            refine: !self.no_refine,
            common_throws: self.common_throws,
            seed: *self.seed,
        })
    }

    /// The fit's configuration, checked by the library.
    pub fn config(&self) -> Result<FitConfig> {
        Ok(self.request()?.config()?)
    }
}

/// Runs `dicephys fit`.
pub fn run(a: &FitArgs) -> Result<()> {
    let config = a.config()?;
    let cfg = match &a.recover {
        Some(truth) => StudyConfig::Recover(RecoverStudy {
            truth: truth_values(&config, truth)?,
            config,
            repeats: a.repeats,
        }),
        None => StudyConfig::Fit(FitStudy {
            config,
            stage: Stage::Whole,
        }),
    };
    super::study::run(&cfg, &a.place.local("fit", &cfg)?)
}

/// `--recover NAME=V,…`: a value for every free parameter, in the model's order.
fn truth_values(cfg: &FitConfig, truth: &str) -> Result<Vec<f64>> {
    let given: Vec<&str> = truth.split(',').collect();
    let values = pairs("--recover", &given, |v| {
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("'{v}' is not a finite number"))
    })?;
    if let Some((k, _)) = values.iter().find(|(k, _)| !cfg.model.free.contains(k)) {
        return Err(Error::Usage(format!(
            "--recover {k}=…: {k} is not among --free"
        )));
    }
    cfg.model
        .free
        .iter()
        .map(|k| {
            values
                .iter()
                .find(|(kind, _)| kind == k)
                .map(|v| v.1)
                .ok_or_else(|| {
                    Error::Usage(format!(
                        "--recover: give a value for the free parameter {k}"
                    ))
                })
        })
        .collect()
}

/// Runs `dicephys predict`.
pub fn predict(a: &PredictArgs) -> Result<()> {
    let mut fit: FitResult =
        dicephys::calibration::read_fit(&a.fit, super::term::stop()).map_err(|e| match e {
            dicephys::Error::Stopped => Error::Interrupted(nothing_read()),
            e => Error::Usage(format!("--fit {e}")),
        })?;
    if let Some(d) = fit.discrepancy.as_mut() {
        d.set_use(a.discrepancy);
    }
    if let Some(file) = &a.blocks {
        return predict_blocks(a, fit, file);
    }
    let other = other_die(a, &fit)?;
    let block = match (
        a.block,
        dicephys::calibration::predict::own_block(&fit),
        &other,
    ) {
        (Some(b), _, _) | (None, Some(b), _) => b,
        (None, None, Some(o)) if o.shape.is_some() => o.block(Block::from_mm(16.0, 16.0, 16.0)?),
        (None, None, _) => {
            return Err(Error::Usage(
                "give --block (the block to predict) or --blocks-file (a file of them)".into(),
            ))
        }
    };
    let block = other.as_ref().map_or(block, |o| o.block(block));
    let counts = match &a.counts {
        Some(path) => counts_of(
            path,
            other
                .as_ref()
                .map_or(fit.config.method.die.shape.as_deref(), |o| {
                    o.shape.as_deref()
                }),
        )?,
        None => Vec::new(),
    };
    let cfg = PredictConfig {
        other: other.map(Box::new),
        counts,
        block,
        mode: if a.two_d { Mode::TwoD } else { Mode::ThreeD },
        surface: a.surface.clone(),
        thrower: a.thrower.clone(),
        contact: a.contact,
        draws: a.draws,
        rolls: a.rolls,
        seed: *a.seed,
    };
    let cfg = StudyConfig::Predict(PredictStudy { fit, config: cfg });
    // It writes nothing: no directory of its own.
    let place = dicephys::studies::place::Place {
        out: ".".into(),
        checkpoint: None,
        threads: a.threads.checked()?,
        share: dicephys::run::runner::ChunkShare::All,
        json: *a.json,
        command_line: super::term::command_line(),
    };
    super::study::run(&cfg, &place)
}

/// The die `predict` throws in place of the fit's: --shape or --die (or another flag of the
/// die), or --block from a fit of a die of any shape; `None`: the fit's own.
fn other_die(a: &PredictArgs, fit: &FitResult) -> Result<Option<dicephys::model::die::Die>> {
    let d = &a.other;
    let described = d.shape.is_some()
        || d.die.is_some()
        || d.com.is_some()
        || d.pips.is_some()
        || d.edge_radius.is_some()
        || d.shell.is_some()
        || d.density.is_some();
    let block_of_shape_fit = a.block.is_some() && fit.config.method.die.shape.is_some();
    if !described && !block_of_shape_fit {
        return Ok(None);
    }
    d.request(a.block, None)
        .resolve_resting()
        .map(Some)
        .map_err(|e| d.named(e))
}

/// `--counts`: the rows of a counts file, read against the die of any shape predicted.
fn counts_of(
    path: &std::path::Path,
    shape: Option<&dicephys::model::shape::Shape>,
) -> Result<Vec<data::DataRow>> {
    let rows = data::read(path, super::term::stop()).map_err(|e| match e {
        dicephys::Error::Stopped => Error::Interrupted(nothing_read()),
        e => Error::Usage(format!("--counts {e}")),
    })?;
    match shape {
        Some(s) => data::on_shape(&rows, s).map_err(|e| Error::Usage(format!("--counts {e}"))),
        None => Ok(rows),
    }
}

/// Runs `dicephys predict --blocks-file`.
fn predict_blocks(a: &PredictArgs, fit: FitResult, file: &std::path::Path) -> Result<()> {
    use dicephys::calibration::heldout;
    let bytes = dicephys::run::io::read_capped(file, data::MAX_DATA_BYTES, super::term::stop())
        .map_err(|e| match e {
            dicephys::Error::Stopped => Error::Interrupted(nothing_read()),
            e => Error::Usage(format!("--blocks-file {e}")),
        })?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::Usage(format!("--blocks-file {}: not UTF-8", file.display())))?;
    let usage = |e: dicephys::Error| Error::Usage(format!("--blocks-file {e}"));
    // A counts file whose rows name their dice (a `die` column) predicts each of them.
    let names_dice = text
        .lines()
        .find(|l| !l.starts_with('#'))
        .is_some_and(|h| h.split(',').any(|c| c.trim() == "die"));
    let (rows, dice) = if names_dice {
        let rows = data::read(file, super::term::stop()).map_err(usage)?;
        let dice = dicephys::studies::fit::predict::die_configs(rows, a.draws, a.rolls, *a.seed)
            .map_err(usage)?;
        (Vec::new(), dice)
    } else {
        let rows = heldout::parse(text, &file.display().to_string()).map_err(usage)?;
        (rows, Vec::new())
    };
    let config = BlocksConfig {
        rows,
        dice,
        draws: a.draws,
        rolls: a.rolls,
        seed: *a.seed,
        fit: a.fit.display().to_string(),
    };
    let cfg = StudyConfig::PredictBlocks(BlocksStudy { fit, config });
    let out = a.out.clone().unwrap_or_else(|| "predict-out".into());
    let mut place = super::study::local(&out, &cfg, *a.threads, *a.json)?;
    place.checkpoint = None;
    super::study::run(&cfg, &place)
}

/// A stop while a command reads its input: nothing read, nothing written.
pub(super) fn nothing_read() -> String {
    dicephys::run::stop::interrupted(&dicephys::run::stop::Kept::NothingRead)
}
