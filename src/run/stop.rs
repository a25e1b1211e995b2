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
