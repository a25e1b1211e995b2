//! A request to stop a run early (Ctrl-C, SIGTERM), passed to whatever runs rolls. It is
//! checked before every roll, so it is honoured within one roll's time however slow the
//! rolls; what was rolled is kept and reported as partial.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A shared stop flag: cheap to clone, set from a signal handler, read by the workers.
#[derive(Clone, Debug, Default)]
pub struct Stop(Arc<AtomicBool>);

impl Stop {
    /// The process's own flag, raised by its signal handler (the command line's Ctrl-C and
    /// SIGTERM): what a read deep in the library (a die file on a named pipe) honours.
    pub fn global() -> &'static Stop {
        static STOP: std::sync::OnceLock<Stop> = std::sync::OnceLock::new();
        STOP.get_or_init(Stop::new)
    }

    /// A flag not yet raised.
    pub fn new() -> Stop {
        Stop::default()
    }

    /// Raises the flag; returns whether it was already raised.
    pub fn request(&self) -> bool {
        self.0.swap(true, Ordering::SeqCst)
    }

    /// True once a stop was requested.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// What a long computation that rolls nothing (a fit's estimate) hears: the stop flag, and
/// where to say which stage it has reached.
#[derive(Clone, Copy)]
pub struct Watch<'a> {
    /// Checked between stages, and by the likelihood at every evaluation.
    pub stop: &'a Stop,
    /// A stage's line of progress ("fit: profiles of 5 parameters").
    pub say: &'a (dyn Fn(&str) + Sync),
}

impl<'a> Watch<'a> {
    /// Watching `stop`, saying nothing.
    pub fn quiet(stop: &'a Stop) -> Watch<'a> {
        Watch { stop, say: &|_| {} }
    }

    /// `Err(Stopped)` once a stop was requested.
    pub fn check(&self) -> crate::Result<()> {
        if self.stop.requested() {
            Err(crate::Error::Stopped)
        } else {
            Ok(())
        }
    }
}

/// What a command stopped before its end had kept, for [`interrupted`].
#[derive(Clone, Debug, PartialEq)]
pub enum Kept<'a> {
    /// Nothing was written; with why it cannot be continued, if that is so.
    Nothing(Option<&'a str>),
    /// Nothing was read yet (stopped while reading its input).
    NothingRead,
    /// What was rolled is kept in this directory: the same command continues.
    Dir(&'a std::path::Path),
    /// The finished work is kept where the command keeps it: the same command continues.
    Work,
    /// A trace's rows up to this step are written (a trace does not resume).
    Steps(u64),
    /// `done` of `of` rolls made, and the command that continues them, if one does.
    Rolls {
        /// Rolls made.
        done: u64,
        /// Rolls asked.
        of: u64,
        /// The command line that continues them.
        resume: Option<String>,
    },
}

/// What every command stopped before its end says (exit 130): the one writer of the word
/// "interrupted", with what was kept and how to go on.
pub fn interrupted(kept: &Kept) -> String {
    match kept {
        Kept::Nothing(None) => "interrupted; nothing written".into(),
        Kept::Nothing(Some(why)) => format!("interrupted; nothing written ({why})"),
        Kept::NothingRead => "interrupted; nothing read".into(),
        Kept::Dir(d) => format!(
            "interrupted; {} kept what was rolled: run the same command to continue",
            d.display()
        ),
        Kept::Work => {
            "interrupted; the finished work is kept: run the same command to continue".into()
        }
        Kept::Steps(step) => format!("interrupted at step {step}; the rows up to it are written"),
        Kept::Rolls {
            done,
            of,
            resume: Some(c),
        } => format!("interrupted after {done} of {of} rolls; continue with: {c}"),
        Kept::Rolls {
            done,
            of,
            resume: None,
        } => format!("interrupted after {done} of {of} rolls"),
    }
}
