//! When a roll is over: DicePhys's at-rest rule (its outcome test, `classify`, is the die's).

use crate::model::state::BodyState;
use nalgebra::Vector3;

/// DicePhys's at-rest rule: over the last `window` steps, the vector sums of the linear and
/// of the angular velocity are both shorter than `tolerance` (sums of vectors, not of
/// lengths, so a die rocking back and forth also counts as at rest).
#[derive(Clone, Debug)]
pub struct RestDetector {
    tolerance: f64,
    linear: [Vector3<f64>; REST_WINDOW],
    angular: [Vector3<f64>; REST_WINDOW],
    seen: usize,
}

/// Steps the at-rest rule sums over (DicePhys: 10).
pub const REST_WINDOW: usize = 10;
/// DicePhys's bound on both velocity sums, m/s and rad/s.
pub const REST_TOLERANCE: f64 = 1e-4;

impl Default for RestDetector {
    fn default() -> Self {
        RestDetector::new(REST_TOLERANCE)
    }
}

impl RestDetector {
    /// A detector with `tolerance` as the bound on both sums, nothing seen yet.
    pub fn new(tolerance: f64) -> RestDetector {
        RestDetector {
            tolerance,
            linear: [Vector3::zeros(); REST_WINDOW],
            angular: [Vector3::zeros(); REST_WINDOW],
            seen: 0,
        }
    }

    /// Forgets the steps seen, to start over.
    pub fn clear(&mut self) {
        self.seen = 0;
    }

    /// Records one step's state without asking whether the die is at rest: for a step at
    /// which the rule is known not to fire (`flight::Flight::jump`). The window then holds
    /// the same velocities in the same slots as if `push` had been called, so the next
    /// `push` sums them in the same order.
    pub fn record(&mut self, s: &BodyState) {
        let slot = self.seen % REST_WINDOW;
        self.linear[slot] = s.linear_velocity;
        self.angular[slot] = s.angular_velocity;
        self.seen += 1;
    }

    /// Counts `n` steps as seen without recording them: for steps that `record` calls for
    /// the window's last ten states will overwrite (`flight::Flight::jump`).
    pub fn skip(&mut self, n: u64) {
        self.seen += n as usize;
    }

    /// Records one step's state; true once the die is at rest. Inlined into the step loop
    /// (`roll_or_abandon`) wherever the compiler's partitioning puts it: called on every
    /// step, out of line it cost 2 M instructions in the paper's plain roll (issue 72).
    #[inline(always)]
    pub fn push(&mut self, s: &BodyState) -> bool {
        self.record(s);
        if self.seen < REST_WINDOW {
            return false;
        }
        let v: Vector3<f64> = self.linear.iter().sum();
        if v.norm() >= self.tolerance {
            return false;
        }
        let w: Vector3<f64> = self.angular.iter().sum();
        w.norm() < self.tolerance
    }
}

/// DicePhys's outcome test lives with the die (`model::die`): the rest rule here says when a
/// roll is over, the die how it came out.
pub use crate::model::die::{classify, VERTICAL_TOLERANCE};
