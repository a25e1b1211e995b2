//! How precise a run is and how many rolls a precision asks: the ratio's 2σ, each face's,
//! and where a run stopped reaching it.

use crate::run::tally::{Counts, Tally};
use serde::{Deserialize, Serialize};

/// The ratio N_b/N_w's relative 2σ error, 2·sqrt(1/N_b + 1/N_w): the paper's binomial error
/// of the ratio (`theory::stats::ratio`) over the ratio. `None` while either count is 0.
pub fn ratio_two_sigma(c: &Counts) -> Option<f64> {
    let r = crate::theory::stats::ratio(c.breadth, c.width);
    (c.breadth > 0 && c.width > 0).then(|| 2.0 * r.err / r.value)
}

/// The rolls that would bring the ratio's relative 2σ error to `precision`, at the
/// proportions measured in `tally`: 4 (1/p_b + 1/p_w) / precision². `None` while either
/// outcome is missing.
pub fn rolls_for_precision(tally: &Tally, precision: f64) -> Option<u64> {
    let (b, w, n) = (
        tally.counts.breadth as f64,
        tally.counts.width as f64,
        tally.rolls as f64,
    );
    (b > 0.0 && w > 0.0).then(|| (4.0 * (n / b + n / w) / (precision * precision)).ceil() as u64)
}

/// What a precision is asked of: the ratio breadth/width (`roll --precision`), or each face's
/// probability (`fair --precision`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// 2σ of the ratio, relative to it.
    #[default]
    Ratio,
    /// 2σ of every face's probability, absolute (a fraction of the throws).
    Faces,
}

impl Target {
    fn is_ratio(&self) -> bool {
        *self == Target::Ratio
    }

    /// 2σ of what is asked in `tally`; `None` while it is undefined.
    pub fn two_sigma(self, tally: &Tally) -> Option<f64> {
        match self {
            Target::Ratio => ratio_two_sigma(&tally.counts),
            Target::Faces => {
                let n: u64 = tally.faces.iter().sum();
                let worst = face_variance(tally)?;
                Some(2.0 * (worst / n as f64).sqrt())
            }
        }
    }

    /// The rolls that would bring it to `precision` at the proportions measured.
    pub fn rolls_for(self, tally: &Tally, precision: f64) -> Option<u64> {
        match self {
            Target::Ratio => rolls_for_precision(tally, precision),
            // 2σ = 2 √(p(1 − p)/n) ≤ P at the largest p(1 − p): n = 4 p(1 − p)/P², scaled from
            // the faces' rolls to all rolls (some may not settle on a face).
            Target::Faces => {
                let faced: u64 = tally.faces.iter().sum();
                let v = face_variance(tally)?;
                let n = 4.0 * v / (precision * precision) * tally.rolls as f64 / faced as f64;
                Some(n.ceil() as u64)
            }
        }
    }
}

/// The largest p(1 − p) over the faces a tally counts; `None` before any face.
fn face_variance(tally: &Tally) -> Option<f64> {
    let n: u64 = tally.faces.iter().sum();
    (n > 0).then(|| {
        tally
            .faces
            .iter()
            .map(|&c| {
                let p = c as f64 / n as f64;
                p * (1.0 - p)
            })
            .fold(0.0, f64::max)
    })
}

/// What a run rolled to a precision reached: asked, reached, and the rolls it took.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Reached {
    /// What the precision is of: the ratio (left out), or `faces`.
    #[serde(default, skip_serializing_if = "Target::is_ratio")]
    pub target: Target,
    /// The precision asked: 2σ of the ratio relative to it, per cent (faces: 2σ of every
    /// face's probability, percentage points).
    pub asked_percent: f64,
    /// 2σ of the ratio relative to it when the run stopped, per cent; null while breadth or
    /// width has not been seen.
    pub reached_percent: Option<f64>,
    /// True when the run stopped at the first chunk boundary where reached ≤ asked; false
    /// when it met its cap (`--rolls`) or a stop request first.
    pub resolved: bool,
    /// Rolls made (chunks of 1,000: the rule is tested only at chunk boundaries, so that the
    /// same seed and precision give the same rolls on any thread count).
    pub rolls: u64,
    /// When not resolved: the rolls that would resolve it at the measured proportions.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rolls_needed: Option<u64>,
}

impl Reached {
    /// One line for the human summary.
    pub fn line(&self) -> String {
        // The ratio's error is relative (per cent of it); a face's is of a probability
        // (percentage points).
        let (what, unseen, unit) = match self.target {
            Target::Ratio => ("the ratio", "breadth or width not yet seen", "%"),
            Target::Faces => ("every face's probability", "no face yet", "pp"),
        };
        let reached = self
            .reached_percent
            .map_or(format!("undefined ({unseen})"), |p| {
                format!("{p:.2} {unit}")
            });
        if self.resolved {
            format!(
                "precision: 2σ of {what} {reached} ≤ {} {unit} asked, after {} rolls (the \
                 first chunk of 1,000 where it held)",
                self.asked_percent, self.rolls
            )
        } else {
            format!(
                "precision NOT reached: 2σ of {what} {reached} > {} {unit} asked after {} \
                 rolls; about {} rolls would reach it (raise --rolls, the cap)",
                self.asked_percent,
                self.rolls,
                self.rolls_needed
                    .map_or("an unknown number of".into(), |n| n.to_string())
            )
        }
    }

    /// What `tallies` (one per engine, all rolled over the same throws) reached at `precision`:
    /// the worst of them.
    pub fn of(tallies: &[&Tally], precision: f64) -> Reached {
        let errs: Vec<Option<f64>> = tallies.iter().map(|t| ratio_two_sigma(&t.counts)).collect();
        let worst = errs.iter().try_fold(0.0f64, |m, e| e.map(|e| m.max(e)));
        let resolved = worst.is_some_and(|e| e <= precision);
        let needed = tallies
            .iter()
            .map(|t| rolls_for_precision(t, precision))
            .try_fold(0u64, |m, n| n.map(|n| m.max(n)));
        Reached {
            target: Target::Ratio,
            asked_percent: 100.0 * precision,
            reached_percent: worst.map(|e| 100.0 * e),
            resolved,
            rolls: tallies.first().map_or(0, |t| t.rolls),
            rolls_needed: (!resolved).then_some(needed).flatten(),
        }
    }

    /// What one run's `tally` reached at `precision` of `target`.
    pub fn of_target(tally: &Tally, target: Target, precision: f64) -> Reached {
        if target == Target::Ratio {
            return Reached::of(&[tally], precision);
        }
        let e = target.two_sigma(tally);
        let resolved = e.is_some_and(|e| e <= precision);
        Reached {
            target,
            asked_percent: 100.0 * precision,
            reached_percent: e.map(|e| 100.0 * e),
            resolved,
            rolls: tally.rolls,
            rolls_needed: (!resolved)
                .then(|| target.rolls_for(tally, precision))
                .flatten(),
        }
    }
}
