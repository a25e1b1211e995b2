//! `trace` as a study: one throw's trajectory as CSV rows, printed as they are made
//! ([`super::place::Hooks::print`]), or a page that plays one or several throws in 3D
//! (`report::view`); each throw's ending line on the log. The rows and the page are
//! `report::trace`'s; this is how a front end runs them, stopped by its stop request mid-roll.

use super::kind::Kind;
use super::place::{Done, Hooks, Place};
use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::scene::Scene;
use crate::report::progress::Unit;
use crate::report::trace::{self, Ended, Stepping};
use crate::run::spec::ThrowSpec;
use crate::run::stop::Kept;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The bytes of rows printed at once.
const BLOCK: usize = 8 << 10;

/// Throws `first` to `last` of `throws` traced on `engine`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TraceStudy {
    /// The engine.
    pub engine: EngineKind,
    /// The scene and its die.
    pub scene: Scene,
    /// The throws.
    pub throws: ThrowSpec,
    /// The first throw traced.
    pub first: u64,
    /// The last (the CSV's: `first`).
    pub last: u64,
    /// Every `every`th step's row in the CSV (and the last's).
    pub every: u64,
    /// The step cap asked, and free flight in closed form or stepped.
    pub max_steps: Option<u64>,
    /// Free flight flown in closed form (as `roll` flies it), else stepped.
    pub fast_flight: bool,
    /// The page written here, in place of the CSV.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub html: Option<PathBuf>,
}

impl TraceStudy {
    /// The CSV's rows of throw `first`, its header first, each passed to `line`; its ending
    /// line and the cap's note, or the step a stop request (`abandon`) ended it at.
    pub fn csv(
        &self,
        mut line: impl FnMut(&str),
        abandon: &dyn Fn() -> bool,
    ) -> Result<std::result::Result<(String, Option<String>), u64>> {
        let index = self.first;
        let throw = self.throws.source(index + 1).get(index);
        let settle = trace::config(&self.scene, self.max_steps, self.fast_flight, false);
        line(trace::HEADER);
        let ended = trace::rows(
            self.engine,
            &self.scene,
            &throw,
            &settle,
            self.every,
            line,
            abandon,
        )?;
        let record = match ended {
            Ended::Rolled(r) => r,
            Ended::Stopped { step } => return Ok(Err(step)),
        };
        let labels = self
            .scene
            .die
            .as_shape()
            .map(|s| s.labels())
            .unwrap_or_default();
        Ok(Ok((
            trace::ending(index, &throw, &record, &labels),
            trace::capped(&record, settle.max_steps, self.max_steps.is_some()),
        )))
    }

    /// The page that plays throws `first` to `last`, each throw's ending line and the cap's
    /// note passed to `say`; `None` if a stop request (`abandon`) ended it.
    pub fn page(
        &self,
        say: impl FnMut(&str, Option<&str>),
        abandon: &dyn Fn() -> bool,
    ) -> Result<Option<String>> {
        trace::page(
            self.engine,
            &self.scene,
            &self.throws.source(self.last + 1),
            self.first..=self.last,
            Stepping {
                max_steps: self.max_steps,
                fast_flight: self.fast_flight,
            },
            say,
            abandon,
        )
    }
}

impl Kind for TraceStudy {
    fn name(&self) -> &'static str {
        "trace"
    }

    fn validate(&self) -> Result<()> {
        if self.max_steps == Some(0) {
            return Err(Error::field(Field::MaxSteps, 0, "need at least one step"));
        }
        if self.every == 0 {
            return Err(Error::field(Field::Every, 0, "need at least one step"));
        }
        if self.last < self.first || self.last - self.first >= trace::MAX_ON_A_PAGE {
            return Err(Error::field(
                Field::Index,
                format!("{}..{}", self.first, self.last),
                format!("at most {} throws, in order", trace::MAX_ON_A_PAGE),
            ));
        }
        if self.html.is_none() && self.first != self.last {
            return Err(Error::field(
                Field::Index,
                format!("{}..{}", self.first, self.last),
                "the CSV is one throw's; several are for --html",
            ));
        }
        Ok(())
    }

    /// Its rows, printed as they are made, are its progress.
    fn unit(&self) -> Unit {
        Unit::Rows
    }

    fn owns<'a>(&self, _: &'a Place) -> Option<&'a std::path::Path> {
        None
    }

    fn check_splittable(&self) -> Result<()> {
        Err(Error::Invalid("trace follows one throw at a time".into()))
    }

    fn run(&self, _: &Place, hooks: &Hooks) -> Result<Done> {
        let abandon = || hooks.stop.requested();
        let say = |ending: &str, note: Option<&str>| {
            (hooks.log)(ending);
            if let Some(n) = note {
                (hooks.log)(&format!("dicephys: {n}"));
            }
        };
        let stopped = |kept: &Kept| Done {
            interrupted: Some(crate::run::stop::interrupted(kept)),
            ..Done::default()
        };
        let Some(path) = &self.html else {
            // The rows go out in blocks of about 8 KiB (as a buffered writer would write
            // them), the last block whatever ended the roll: the rows up to a stop are written.
            let mut block = String::new();
            let ended = self.csv(
                |l| {
                    if block.len() + l.len() >= BLOCK && !block.is_empty() {
                        (hooks.print)(&block);
                        block.clear();
                    }
                    if !block.is_empty() {
                        block.push('\n');
                    }
                    block.push_str(l);
                },
                &abandon,
            );
            if !block.is_empty() {
                (hooks.print)(&block);
            }
            return Ok(match ended? {
                Ok((ending, note)) => {
                    say(&ending, note.as_deref());
                    Done::default()
                }
                Err(step) => stopped(&Kept::Steps(step)),
            });
        };
        // Checked before any roll: a page that cannot be written is refused at once.
        let out = crate::run::io::Output::check(path)?;
        Ok(match self.page(say, &abandon)? {
            Some(page) => {
                out.write(page.as_bytes())?;
                Done::default()
            }
            None => stopped(&Kept::Nothing(None)),
        })
    }
}
