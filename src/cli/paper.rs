//! `dicephys paper`: the main job. Reproduces the paper end to end and writes a report.

use super::args::parse_engine;
use super::args::{MaxSteps, Seed};
use super::error::Result;
use super::study;
use super::study::StudyPlace;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::studies::calibrated::CalibratedStudy;
use dicephys::studies::fit::Stage;
use dicephys::studies::paper::PaperConfig;
use dicephys::studies::StudyConfig;

/// `dicephys paper`'s arguments.
#[derive(Args, Debug)]
pub struct PaperArgs {
    /// Rolls per simulated cell (block × engine × 2D/3D); 100000 is the paper's own scale.
    #[arg(long, default_value_t = dicephys::run::request::DEFAULT_ROLLS)]
    pub rolls: u64,
    /// The keyed throws' seed.
    #[command(flatten)]
    pub seed: Seed,
    /// Engines to simulate with (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = super::args::DEFAULT_ENGINES, value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Fixed time step, s or 1/N.
    #[arg(long, default_value_t = dicephys::run::request::SceneRequest::default().dt, value_parser = super::args::parse_step)]
    pub dt: f64,
    /// Threads, --out, --json.
    #[command(flatten)]
    pub place: StudyPlace,
    /// The step cap.
    #[command(flatten)]
    pub max_steps: MaxSteps,
    /// DicePhys exactly as the paper ran it (its rest rule, every flight step stepped) instead
    /// of the exact early stop and closed-form flight.
    #[arg(long)]
    pub faithful: bool,
    /// All 19 rows simulated with e, μ (per surface) and the throw's κ fitted to the counts;
    /// every row predicted by a fit without it, beside the theory; the models compared; the
    /// method checked (calibrated.md, calibrated.json and figures in --out). --dt is the fit's
    /// step; --rolls and --engines are not used.
    #[arg(long)]
    pub calibrated: bool,
    /// With --calibrated: parameter points each block is simulated at, per pass.
    #[arg(long, default_value_t = dicephys::calibration::design::DesignSpec::default().points)]
    pub points: usize,
    /// With --calibrated: rolls at each point.
    #[arg(long, default_value_t = dicephys::calibration::design::DesignSpec::default().rolls)]
    pub point_rolls: u64,
    /// With --calibrated: the method check's reference step, s or 1/N.
    #[arg(long, default_value = "1/5000", value_parser = super::args::parse_step)]
    pub reference_dt: f64,
    /// With --calibrated: throws per block in the method check.
    #[arg(long, default_value_t = dicephys::studies::calibrated::DEFAULT_CHECK_ROLLS)]
    pub check_rolls: u64,
    /// With --calibrated: data sets of the parametric bootstrap (the main fit's data simulated
    /// from its values and fitted again), which measures the goodness of fit's p-value, the
    /// region's coverage and the likelihood ratio's scale (0: none, χ²'s own).
    #[arg(long, default_value_t = dicephys::calibration::estimate::Search::default().bootstrap)]
    pub bootstrap: usize,
    /// With --calibrated: starting points of each fit's search for its maximum (the centre and
    /// a Halton sequence; the report says where each ended).
    #[arg(long, default_value_t = dicephys::calibration::estimate::Search::default().starts)]
    pub starts: usize,
    /// With --calibrated: grid points of each parameter's profile likelihood across its box.
    #[arg(long, default_value_t = dicephys::calibration::estimate::Search::default().profile_points)]
    pub profile_points: usize,
}

/// Runs `dicephys paper --calibrated`.
fn calibrated(a: &PaperArgs) -> Result<()> {
    // Its cells beside paper's own, apart.
    let cfg = StudyConfig::Calibrated(CalibratedStudy {
        config: a.calibrated_config(),
        stage: Stage::Whole,
    });
    cfg.validate()?;
    study::run(&cfg, &a.place.local("paper", &cfg)?)
}

impl PaperArgs {
    /// `paper --calibrated`'s configuration.
    pub fn calibrated_config(&self) -> dicephys::studies::calibrated::CalibratedConfig {
        use dicephys::calibration::design::DesignSpec;
        use dicephys::calibration::estimate::Search;
        use dicephys::calibration::params::Method;
        let a = self;
        dicephys::studies::calibrated::CalibratedConfig {
            method: Method {
                dice: Vec::new(),
                engine: EngineKind::Bullet,
                dt: a.dt,
                max_steps: *a.max_steps,
                die: Default::default(),
            },
            design: DesignSpec {
                points: a.points,
                rolls: a.point_rolls,
                ..DesignSpec::default()
            },
            // Every flag honoured (reliability round 5, class F: --starts and
            // --profile-points used to be parsed and left at their defaults).
            search: Search {
                seed: *a.seed,
                bootstrap: a.bootstrap,
                starts: a.starts,
                profile_points: a.profile_points,
                ..Search::default()
            },
            seed: *a.seed,
            check_rolls: a.check_rolls,
            reference_dt: a.reference_dt,
        }
    }

    /// The study's configuration.
    pub fn config(&self) -> PaperConfig {
        let mut engines = self.engines.clone();
        engines.dedup();
        PaperConfig {
            rolls: self.rolls,
            seed: *self.seed,
            engines,
            dt: self.dt,
            max_steps: *self.max_steps,
            faithful: self.faithful,
        }
    }
}

/// Runs `dicephys paper`.
pub fn run(a: &PaperArgs) -> Result<()> {
    if a.calibrated {
        return calibrated(a);
    }
    let cfg = StudyConfig::Paper(a.config());
    cfg.validate()?;
    study::run(&cfg, &a.place.local("paper", &cfg)?)
}
