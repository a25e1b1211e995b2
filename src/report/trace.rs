//! One throw's trajectory as CSV (`trace`): step, time, position, orientation, velocities,
//! energies, and the line that says how the throw ended.

use crate::model::die::DieShape;
use crate::model::state::BodyState;
use crate::model::throws::Throw;
use crate::sim::roll::{Fate, RollRecord};

/// The CSV's header.
pub const HEADER: &str =
    "step,time_s,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,kinetic_j,potential_j,total_j,sleeping";

/// The CSV row of the state after `step` steps of `dt`.
pub fn row(die: &DieShape, dt: f64, step: u64, s: &BodyState) -> String {
    let q = s.rotation.quaternion();
    let (k, p) = (die.kinetic(s), die.potential(s));
    format!(
        "{},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9e},{:.9e},{:.9e},{}",
        step,
        step as f64 * dt,
        s.position.x,
        s.position.y,
        s.position.z,
        q.w,
        q.i,
        q.j,
        q.k,
        s.linear_velocity.x,
        s.linear_velocity.y,
        s.linear_velocity.z,
        s.angular_velocity.x,
        s.angular_velocity.y,
        s.angular_velocity.z,
        k,
        p,
        k + p,
        s.sleeping as u8
    )
}

/// How throw `index` ended, in one line; a die of any shape's face named by `labels`.
pub fn ending(index: u64, throw: &Throw, record: &RollRecord, labels: &[&str]) -> String {
    let fate = match record.fate {
        Fate::Settled(crate::model::block::Outcome::Face) => format!(
            "settled, showing {}",
            record
                .up
                .and_then(|k| labels.get(usize::from(k)))
                .unwrap_or(&"?")
        ),
        Fate::Settled(o) => format!("settled, {} vertical", o.name()),
        Fate::Unconverged(crate::model::block::Outcome::Face) => format!(
            "unconverged (showing {} at the cap)",
            record
                .up
                .and_then(|k| labels.get(usize::from(k)))
                .unwrap_or(&"?")
        ),
        Fate::Unconverged(o) => format!("unconverged ({} vertical at the cap)", o.name()),
        Fate::Failed(f) => format!("failed: {}", f.name()),
    };
    format!(
        "throw {index}: drop {:.4} m, v {:.4} m/s, spin {:.3} rad/s: {fate} after {} steps",
        throw.drop_height, throw.velocity, throw.spin, record.steps
    )
}

/// When the step cap ended the trace (the die not at rest after `cap` steps), one line that
/// says so: the cap, whose it was (`asked`: `--max-steps`, else the die's default) and how to
/// move it. `None` when the roll ended otherwise.
pub fn capped(record: &RollRecord, cap: u64, asked: bool) -> Option<String> {
    if !matches!(record.fate, Fate::Unconverged(_)) {
        return None;
    }
    let whose = if asked {
        "as asked".to_string()
    } else if cap == crate::sim::roll::SHAPE_MAX_STEPS {
        "a die of any shape's default, as `roll`'s; --max-steps sets another".to_string()
    } else {
        "DicePhys's default; --max-steps sets another".to_string()
    };
    Some(format!(
        "the step cap ended the trace: the die was not at rest after {cap} steps ({whose})"
    ))
}
