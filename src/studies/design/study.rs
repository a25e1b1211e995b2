//! `design` as a study: a feature's value (`--free NAME`, [`DesignConfig`]) or a mesh's facets
//! (`--free facets`, [`MeshConfig`]), checked, rolled, rendered and written the one way, for
//! the command line (through [`crate::studies::StudyConfig::run`]) and Python alike.

use super::mesh::{self, MeshConfig};
use super::DesignConfig;
use crate::error::{Error, Result};
use crate::report::progress::Unit;
use crate::run::runner::Runner;
use crate::studies::kind::Kind;
use crate::studies::place::{Done, Hooks, Place};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What `design` is asked to make.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DesignStudy {
    /// One feature's value, scanned (`--free NAME`).
    Feature(DesignConfig),
    /// A mesh's facets moved, round by round (`--free facets`).
    Facets(MeshConfig),
}

impl DesignStudy {
    /// Every value checked before anything rolls or is written.
    pub fn check(&self) -> Result<()> {
        match self {
            DesignStudy::Feature(c) => super::check(c).map(drop),
            DesignStudy::Facets(c) => mesh::check(c),
        }
    }

    /// The throws it rolls in all: two scans and the check, or the rounds, the start and two
    /// checks.
    pub fn rolls(&self) -> u64 {
        match self {
            DesignStudy::Feature(c) => c.spec.rolls * 2 * c.points as u64 + c.check_rolls,
            DesignStudy::Facets(c) => c.spec.rolls * (c.rounds as u64 + 1) + 2 * c.check_rolls,
        }
    }

    /// What makes two designs one, for `--out`'s directory: its configuration (as `design`
    /// has always claimed it).
    pub fn identity(&self) -> serde_json::Value {
        match self {
            DesignStudy::Feature(c) => serde_json::to_value(c),
            DesignStudy::Facets(c) => serde_json::to_value(c),
        }
        .unwrap_or_default()
    }

    /// Claims `dir` for this design (`run::owner`; refused if another command or another run
    /// owns it, or a cluster's run) and holds it while the returned file lives: for a caller
    /// that runs it without [`Kind::run`] (Python).
    pub fn claim(&self, dir: &Path) -> Result<crate::run::lock::Held> {
        use crate::studies::place::{claim, Claimant};
        claim(dir, "design", &self.identity(), Claimant::Here)?;
        crate::run::owner::hold(dir)
    }

    /// Makes it with `runner`: its JSON document and its text, and its files written into
    /// `out` if given (`design.json`, the report, the figure; a mesh's design.obj and die file).
    /// `None` if a stop request ended it (a design does not resume).
    pub fn make(&self, runner: &Runner, out: Option<&Path>) -> Result<Option<(String, String)>> {
        match self {
            DesignStudy::Feature(c) => {
                let Some(d) = super::run(c, runner)? else {
                    return Ok(None);
                };
                let json = crate::run::seal::to_string(&d, true)?;
                if let Some(dir) = out {
                    super::write(dir, &json, &d)?;
                }
                Ok(Some((json, d.text())))
            }
            DesignStudy::Facets(c) => {
                let Some(d) = mesh::run(c, runner)? else {
                    return Ok(None);
                };
                let json = crate::run::seal::to_string(&d, true)?;
                if let Some(dir) = out {
                    mesh::write(dir, &json, &d)?;
                }
                Ok(Some((json, d.text())))
            }
        }
    }
}

impl Kind for DesignStudy {
    fn name(&self) -> &'static str {
        "design"
    }

    fn validate(&self) -> Result<()> {
        self.check()
    }

    fn unit(&self) -> Unit {
        Unit::Rolls { per_cell: 0 }
    }

    /// `--out`'s directory, if one is named.
    fn owns<'a>(&self, place: &'a Place) -> Option<&'a Path> {
        (!place.out.as_os_str().is_empty()).then_some(place.out.as_path())
    }

    fn check_splittable(&self) -> Result<()> {
        Err(Error::Invalid(
            "a design decides each scan from the one before, on one machine".into(),
        ))
    }

    fn run(&self, place: &Place, hooks: &Hooks) -> Result<Done> {
        let total = self.rolls() as f64;
        let progress = |n: u64| (hooks.progress)(n as f64, total);
        let runner = Runner::new(place.threads, hooks.stop.clone()).with_progress(&progress);
        let out = self.owns(place);
        let Some((json, text)) = self.make(&runner, out)? else {
            return Ok(Done {
                interrupted: Some(crate::run::stop::interrupted(
                    &crate::run::stop::Kept::Nothing(Some("a design does not resume")),
                )),
                ..Done::default()
            });
        };
        let mesh = match self {
            DesignStudy::Feature(_) => "",
            DesignStudy::Facets(_) => ", the die design.obj and its die file design.toml",
        };
        Ok(Done {
            note: out.filter(|_| !place.json).map(|dir| {
                format!(
                    "wrote {}/design.json, report.md, report.html and design.svg, .png{mesh}",
                    dir.display()
                )
                .into()
            }),
            stdout: match place.json {
                true => format!("{json}\n"),
                false => text,
            },
            ..Done::default()
        })
    }
}
