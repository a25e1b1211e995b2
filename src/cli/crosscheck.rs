//! `dicephys crosscheck`: the very same throws on several engines, side by side
//! (`dicephys::studies::crosscheck`).

use super::args::Json;
use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use super::error::{Error, Result};
use super::study;
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::run::spec::RunSpec;
use dicephys::studies::outputs::Place;
use dicephys::studies::{crosscheck, StudyConfig};
use std::path::{Path, PathBuf};

/// `dicephys crosscheck`'s arguments.
#[derive(Args, Debug)]
pub struct CrosscheckArgs {
    /// Engines to compare (comma-separated); the first is the baseline.
    #[arg(long, value_delimiter = ',', default_value = super::args::DEFAULT_ENGINES, value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub throw: ThrowArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Keep each engine's rolls here as they are made (a directory per engine, in chunks of
    /// 1,000 rolls): the same command run again continues where it stopped.
    #[arg(long, value_name = "DIR")]
    pub checkpoint: Option<PathBuf>,
    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
}

impl CrosscheckArgs {
    /// The study's configuration, checked.
    pub fn config(&self) -> Result<crosscheck::Config> {
        if self.engines.len() < 2 {
            return Err(Error::Usage(
                "--engines: name at least two engines to compare".into(),
            ));
        }
        let scene = self
            .scene
            .scene_or(crosscheck::default_preset(self.run.faithful))?;
        let style = dicephys::model::throws::ThrowStyle::default_for(&scene);
        let cfg = crosscheck::Config {
            engines: self.engines.clone(),
            spec: RunSpec {
                engine: self.engines[0],
                roll: self.run.roll(&scene)?,
                scene,
                throws: self.throw.spec_or(style)?,
                rolls: self.run.rolls(),
                shard: None,
            },
            allow_restitution_above_one: self.scene.allow_restitution_above_one,
            precision: self.run.precision,
        };
        cfg.validate()?;
        Ok(cfg)
    }
}

/// Runs `dicephys crosscheck`.
pub fn run(a: &CrosscheckArgs) -> Result<()> {
    let cfg = a.config()?;
    // A loaded die that bounces is where the engines part most.
    if let Some(n) = cfg.spec.loaded_die_note(&cfg.engines).filter(|_| !*a.json) {
        eprintln!("dicephys: note: {n}");
    }
    let cfg = StudyConfig::Crosscheck(cfg);
    let place = Place {
        checkpoint: a.checkpoint.clone(),
        ..study::local(Path::new(""), &cfg, *a.run.threads, *a.json)?
    };
    study::run(&cfg, &place)
}
