//! Progress on stderr while a long command runs: a bar on a terminal; elsewhere (a log file, a
//! cluster job's output) a line now and then, so that no command is silent for minutes:
//! "dicephys converge: 50 % (12 of 24 cells done), ETA 3 min 20 s".

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// What a study's progress counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Rolls, `per_cell` to a cell.
    Rolls {
        /// Rolls in a cell.
        per_cell: u64,
    },
    /// The study's cells (or rows).
    Cells,
    /// Estimated CPU seconds of a study rolled to a precision.
    Cpu,
    /// Nothing counted: the study prints its rows as it makes them (`bench`), which are its
    /// progress; no bar, no progress lines.
    Rows,
}

/// A command's progress: `set` it as work is done.
pub struct Progress {
    command: &'static str,
    unit: Unit,
    bar: ProgressBar,
    /// Without a terminal: when the command started and when it last printed a line.
    lines: Option<(Instant, Mutex<Instant>)>,
    every: Duration,
}

impl Progress {
    /// Progress of `command` in `unit`: a bar on a terminal unless `quiet` (`--json`) or
    /// `bar` is false; a line at most `every` when stderr is not a terminal.
    pub fn new(
        command: &'static str,
        unit: Unit,
        bar: bool,
        quiet: bool,
        every: Duration,
    ) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let b = if terminal && bar && !quiet && unit != Unit::Rows {
            let b = ProgressBar::with_draw_target(Some(1), ProgressDrawTarget::stderr());
            let template = match unit {
                Unit::Rolls { .. } => "{elapsed_precise} [{wide_bar}] {pos}/{len} rolls, ETA {eta}",
                Unit::Cells => "{elapsed_precise} [{wide_bar}] {pos}/{len} cells, ETA {eta}",
                Unit::Cpu | Unit::Rows => {
                    "{elapsed_precise} [{wide_bar}] {percent}% of the planned CPU, ETA {eta}"
                }
            };
            b.set_style(
                ProgressStyle::with_template(template)
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b
        } else {
            ProgressBar::hidden()
        };
        let now = Instant::now();
        Progress {
            command,
            unit,
            bar: b,
            lines: (!terminal && unit != Unit::Rows).then(|| (now, Mutex::new(now))),
            every,
        }
    }

    /// `done` of `total` so far.
    pub fn set(&self, done: f64, total: f64) {
        // Whole rolls and cells as they are; CPU seconds in thousandths, so the bar moves.
        let scale = if self.unit == Unit::Cpu { 1000.0 } else { 1.0 };
        self.bar.set_length((scale * total) as u64);
        self.bar.set_position((scale * done.min(total)) as u64);
        let Some((start, last)) = &self.lines else {
            return;
        };
        let Ok(mut last) = last.lock() else { return };
        if last.elapsed() < self.every || total.is_nan() || total <= 0.0 {
            return;
        }
        *last = Instant::now();
        let f = (done / total).clamp(0.0, 1.0);
        let what = match self.unit {
            Unit::Rolls { per_cell } if per_cell > 0 && total > per_cell as f64 => format!(
                "{} of {} cells done",
                (done / per_cell as f64).floor(),
                (total / per_cell as f64).round()
            ),
            Unit::Rolls { .. } => format!("{done:.0} of {total:.0} rolls"),
            Unit::Cells => format!("{done:.0} of {total:.0} cells done"),
            Unit::Cpu | Unit::Rows => "of the planned CPU".to_string(),
        };
        let eta = if f > 0.0 {
            let left = start.elapsed().as_secs_f64() * (1.0 - f) / f;
            format!("ETA {}", duration(left))
        } else {
            "ETA unknown".to_string()
        };
        eprintln!(
            "dicephys {}: {:.0} % ({what}), {eta}",
            self.command,
            100.0 * f
        );
    }

    /// Runs `f` with the bar out of the way (for a log line).
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Seconds as people say them: 45 s, 3 min 20 s, 2 h 5 min.
fn duration(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {} s", s / 60, s % 60),
        _ => format!("{} h {} min", s / 3600, s % 3600 / 60),
    }
}
