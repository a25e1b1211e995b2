//! Exact integer counts over a set of rolls: the same whatever the thread count, order, shard
//! or resumed segment they were rolled in.

use crate::model::block::Side;
use crate::model::faces::Outcome;
use crate::sim::roll::{Failure, Fate, RollRecord};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Exact counts over a set of rolls.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    /// Settled rolls by the side standing vertical.
    pub counts: Counts,
    /// Rolls not at rest at the step cap.
    pub unconverged: u64,
    /// Failed rolls by why they failed.
    pub failed: BTreeMap<Failure, u64>,
    /// Rolls counted.
    pub rolls: u64,
    /// Steps simulated over all rolls.
    pub steps: u64,
    /// Steps the engines took (fewer where free flight was coasted).
    pub engine_steps: u64,
    /// Auditing the early stop: rolls the certificate fired on.
    pub certified: u64,
    /// Of those, rolls that ended on another face than it named (at rest, or at the step cap).
    pub certified_wrong: u64,
    /// Of those, rolls the full settle left "unknown" (DicePhys's rest rule stopping a rocking
    /// die at the turning point of a swing, still tilted: no face to disagree with).
    #[serde(default)]
    pub certified_unknown: u64,
    /// The steps at which the certificate fired, summed over those rolls.
    pub certified_steps: u64,
    /// Rolls in which the engine injected energy (`RollRecord::energy_gain`), whatever their
    /// fate.
    #[serde(default)]
    pub energy_gain: u64,
    /// Rolls whose die's centre went below the floor's top face at some step (`roll::Dip`),
    /// whatever their fate. A flag, like the energy gain.
    #[serde(default)]
    pub dipped: u64,
    /// The deepest any point of a die went below the floor's top face, over all rolls, in
    /// nanometres, rounded up (an integer, so that tallies merge exactly, by the maximum).
    #[serde(default)]
    pub deepest_dip_nm: u64,
    /// Settled rolls by the face they came to rest with: the cuboid's by the direction of its
    /// face up (`faces::DIRECTIONS`: +x, −x, +y, −y, +z, −z; six, once a roll settled on a
    /// side), a die of any shape's by its outcome, in the order of its faces (`Shape::faces`;
    /// up to the last that came up). They add up to the rolls settled on a side or a face
    /// (`counts`, their view by side), except in a tally that holds rolls from chunks written
    /// before faces were kept ([`Tally::faces_complete`]). Written as `faces`; a cuboid's
    /// `up`, as tallies wrote it before, is read into it.
    #[serde(flatten)]
    pub faces: FaceCounts,
}

/// A tally's counts by face (`Tally::faces`): a list, written as the tally's `faces` (absent
/// when empty).
#[derive(Clone, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(from = "FacesRead")]
pub struct FaceCounts(pub Vec<u64>);

impl std::ops::Deref for FaceCounts {
    type Target = Vec<u64>;
    fn deref(&self) -> &Vec<u64> {
        &self.0
    }
}

impl std::ops::DerefMut for FaceCounts {
    fn deref_mut(&mut self) -> &mut Vec<u64> {
        &mut self.0
    }
}

impl PartialEq<Vec<u64>> for FaceCounts {
    fn eq(&self, o: &Vec<u64>) -> bool {
        self.0 == *o
    }
}

impl Serialize for FaceCounts {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(None)?;
        if !self.0.is_empty() {
            m.serialize_entry("faces", &self.0)?;
        }
        m.end()
    }
}

/// What a tally's faces are read from: `faces`, or, from a tally written before the cuboid's
/// faces were counted there, its `up` (a die of any shape's tallies wrote `up` as zeros beside
/// their `faces`).
#[derive(Deserialize)]
struct FacesRead {
    #[serde(default)]
    faces: Vec<u64>,
    #[serde(default)]
    up: [u64; 6],
}

impl From<FacesRead> for FaceCounts {
    fn from(r: FacesRead) -> FaceCounts {
        FaceCounts(if r.faces.is_empty() && r.up.iter().any(|&n| n > 0) {
            r.up.to_vec()
        } else {
            r.faces
        })
    }
}

/// Settled rolls by the side standing vertical.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Breadth vertical.
    pub breadth: u64,
    /// Width vertical.
    pub width: u64,
    /// Length vertical (standing on its end).
    pub length: u64,
    /// No side vertical (at rest on an edge, or leaning).
    pub unknown: u64,
    /// A die of any shape at rest on one of its faces (which: `Tally::faces`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub face: u64,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl Counts {
    /// Counts one roll at rest on `o`: a cuboid's (`sides`) by the side standing vertical
    /// (`Outcome::side`), a die of any shape's as on a face.
    pub fn add(&mut self, o: Outcome, sides: bool) -> crate::Result<()> {
        let n = match (o, sides) {
            (Outcome::Unknown, _) => &mut self.unknown,
            (Outcome::Face(_), false) => &mut self.face,
            (Outcome::Face(_), true) => match o.side() {
                Side::Breadth => &mut self.breadth,
                Side::Width => &mut self.width,
                Side::Length => &mut self.length,
                Side::Unknown => &mut self.unknown,
            },
        };
        plus(n, 1)
    }
}

/// `*a += b`, or an error if the sum overflows: a tally is exact or refused, never wrapped.
fn plus(a: &mut u64, b: u64) -> crate::Result<()> {
    *a = a.checked_add(b).ok_or_else(|| {
        crate::Error::Mismatch(format!(
            "a count overflows: {a} + {b} is past 2^64 - 1 (a damaged or forged input?)"
        ))
    })?;
    Ok(())
}

impl Tally {
    /// Counts one roll of a die whose outcomes are `sides` (a cuboid's, also counted by the
    /// side standing vertical) or not (a die of any shape's); an error if a count would
    /// overflow.
    pub fn add(&mut self, r: &RollRecord, sides: bool) -> crate::Result<()> {
        plus(&mut self.rolls, 1)?;
        plus(&mut self.steps, r.steps)?;
        plus(&mut self.engine_steps, r.engine_steps)?;
        plus(&mut self.energy_gain, r.energy_gain as u64)?;
        plus(&mut self.dipped, r.dip.dipped() as u64)?;
        self.deepest_dip_nm = self.deepest_dip_nm.max(nanometres(r.dip.penetration));
        if let Some((step, o)) = r.certified {
            plus(&mut self.certified, 1)?;
            plus(&mut self.certified_steps, step)?;
            match r.fate {
                Fate::Settled(Outcome::Unknown) | Fate::Unconverged(Outcome::Unknown) => {
                    plus(&mut self.certified_unknown, 1)?
                }
                // Another face than it named.
                Fate::Settled(s) | Fate::Unconverged(s) => {
                    plus(&mut self.certified_wrong, (s != o) as u64)?
                }
                Fate::Failed(_) => {}
            }
        }
        if let Fate::Settled(Outcome::Face(d)) = r.fate {
            let d = usize::from(d);
            if sides && d >= 6 {
                // Only from a damaged or forged chunk: a cuboid has six faces.
                return Err(crate::Error::Mismatch(format!(
                    "a cuboid's roll on face {d} (it has six, 0 to 5)"
                )));
            }
            // A cuboid's six directions at once; a shape's faces up to this one.
            let len = if sides { 6 } else { d + 1 };
            if self.faces.len() < len {
                self.faces.resize(len, 0);
            }
            plus(&mut self.faces[d], 1)?;
        }
        match r.fate {
            Fate::Settled(o) => self.counts.add(o, sides),
            Fate::Unconverged(_) => plus(&mut self.unconverged, 1),
            Fate::Failed(f) => plus(self.failed.entry(f).or_insert(0), 1),
        }
    }

    /// Checks that the counts add up: every roll settled, unconverged or failed, and the
    /// audit's counts within the rolls. A tally read from a file must pass this.
    pub fn check(&self) -> crate::Result<()> {
        let c = &self.counts;
        let ended = [
            c.breadth,
            c.width,
            c.length,
            c.unknown,
            c.face,
            self.unconverged,
        ]
        .into_iter()
        .chain(self.failed.values().copied())
        .try_fold(0u64, u64::checked_add);
        let sides = c.breadth.saturating_add(c.width).saturating_add(c.length);
        let faced = self.faces.iter().try_fold(0u64, |a, &b| a.checked_add(b));
        // A die of any shape's faces add up to its rolls on a face; the cuboid's six
        // directions to at most its rolls on a side, each pair to at most its side's.
        let faces_fine = if c.face > 0 || sides == 0 {
            faced == Some(c.face)
        } else {
            self.faces.len() <= 6
                && faced.is_some_and(|n| n <= sides)
                && (0..3).all(|k| {
                    let side = [c.breadth, c.width, c.length][k];
                    let at = |d: usize| self.faces.get(d).copied().unwrap_or(0);
                    at(2 * k).saturating_add(at(2 * k + 1)) <= side
                })
        };
        let fine = ended == Some(self.rolls)
            && self.certified <= self.rolls
            && self
                .certified_wrong
                .checked_add(self.certified_unknown)
                .is_some_and(|n| n <= self.certified)
            && self.energy_gain <= self.rolls
            && self.dipped <= self.rolls
            && faces_fine;
        if fine {
            Ok(())
        } else {
            Err(crate::Error::Mismatch(format!(
                "a tally whose counts do not add up to its {} rolls",
                self.rolls
            )))
        }
    }

    /// Rolls that failed, for any reason.
    pub fn failed_total(&self) -> u64 {
        self.failed.values().fold(0, |a, &b| a.saturating_add(b))
    }

    /// Rolls that failed for this reason.
    pub fn failed_of(&self, f: Failure) -> u64 {
        self.failed.get(&f).copied().unwrap_or(0)
    }

    /// Adds another tally's counts (of other rolls) to this one; an error, and this tally
    /// left partly added, if a count would overflow.
    pub fn merge(&mut self, o: &Tally) -> crate::Result<()> {
        plus(&mut self.counts.breadth, o.counts.breadth)?;
        plus(&mut self.counts.width, o.counts.width)?;
        plus(&mut self.counts.length, o.counts.length)?;
        plus(&mut self.counts.unknown, o.counts.unknown)?;
        plus(&mut self.counts.face, o.counts.face)?;
        if self.faces.len() < o.faces.len() {
            self.faces.resize(o.faces.len(), 0);
        }
        for (a, b) in self.faces.iter_mut().zip(o.faces.iter()) {
            plus(a, *b)?;
        }
        plus(&mut self.unconverged, o.unconverged)?;
        for (k, v) in &o.failed {
            plus(self.failed.entry(*k).or_insert(0), *v)?;
        }
        plus(&mut self.rolls, o.rolls)?;
        plus(&mut self.steps, o.steps)?;
        plus(&mut self.engine_steps, o.engine_steps)?;
        plus(&mut self.certified, o.certified)?;
        plus(&mut self.certified_wrong, o.certified_wrong)?;
        plus(&mut self.certified_unknown, o.certified_unknown)?;
        plus(&mut self.certified_steps, o.certified_steps)?;
        plus(&mut self.energy_gain, o.energy_gain)?;
        plus(&mut self.dipped, o.dipped)?;
        self.deepest_dip_nm = self.deepest_dip_nm.max(o.deepest_dip_nm);
        Ok(())
    }

    /// True if every roll settled on a side has its face counted (none came from a chunk
    /// written before faces were kept).
    pub fn faces_complete(&self) -> bool {
        let c = &self.counts;
        let settled = [c.breadth, c.width, c.length, c.face]
            .into_iter()
            .fold(0u64, u64::saturating_add);
        self.faces.iter().fold(0u64, |a, &b| a.saturating_add(b)) == settled
    }

    /// The cuboid's settled rolls by the direction of the face up (`faces::DIRECTIONS`), six
    /// (zeros before any roll settled on a side).
    pub fn by_direction(&self) -> [u64; 6] {
        std::array::from_fn(|d| self.faces.get(d).copied().unwrap_or(0))
    }

    /// `deepest_dip_nm` in metres.
    pub fn deepest_dip_m(&self) -> f64 {
        self.deepest_dip_nm as f64 * 1e-9
    }

    /// The tally of these records, of a die whose outcomes are `sides` or not (`add`).
    pub fn of(records: &[RollRecord], sides: bool) -> crate::Result<Tally> {
        let mut t = Tally::default();
        for r in records {
            t.add(r, sides)?;
        }
        Ok(t)
    }
}

/// A depth in whole nanometres, rounded up (0 for none; a NaN never reaches here, as a
/// non-finite state fails the roll before its depth is recorded).
fn nanometres(m: f64) -> u64 {
    if m > 0.0 {
        (m * 1e9).ceil().min(u64::MAX as f64) as u64
    } else {
        0
    }
}

/// How two runs of the same throws agree, throw for throw. "Same outcome" means both rolls
/// settled, a cuboid's on the same side, a die of any shape's on the same face; a roll that
/// did not settle agrees with nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Agreement {
    /// Throws compared.
    pub rolls: u64,
    /// Throws both runs settled.
    pub both_settled: u64,
    /// Throws both runs settled on the same side (a die of any shape: the same face).
    pub same: u64,
}

impl Agreement {
    /// Compares records of the same throws, in the same order, of a die whose outcomes are
    /// `sides` (compared by the side standing vertical, as the paper counts) or not (by face).
    pub fn of(a: &[RollRecord], b: &[RollRecord], sides: bool) -> Agreement {
        let mut g = Agreement::default();
        for (x, y) in a.iter().zip(b) {
            g.rolls += 1;
            if let (Fate::Settled(p), Fate::Settled(q)) = (x.fate, y.fate) {
                g.both_settled += 1;
                g.same += if sides { p.side() == q.side() } else { p == q } as u64;
            }
        }
        g
    }

    /// Same outcome, as a fraction of all throws compared.
    pub fn of_rolls(&self) -> f64 {
        self.same as f64 / self.rolls.max(1) as f64
    }

    /// Same outcome, as a fraction of the throws both settled.
    pub fn of_settled(&self) -> f64 {
        self.same as f64 / self.both_settled.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_one_count_read_from_a_tally_written_either_way() {
        let counts = r#""counts": {"breadth": 3, "width": 4, "length": 0, "unknown": 1}"#;
        // A cuboid's tally as written before: its faces up under `up`.
        let old: Tally = serde_json::from_str(&format!(
            r#"{{{counts}, "unconverged": 0, "failed": {{}}, "rolls": 8, "steps": 80,
            "engine_steps": 80, "certified": 0, "certified_wrong": 0, "certified_steps": 0,
            "up": [1, 2, 3, 1, 0, 0]}}"#
        ))
        .unwrap();
        assert_eq!(old.faces, vec![1, 2, 3, 1, 0, 0]);
        assert!(old.check().is_ok() && old.faces_complete());
        // Written now: `faces`, no `up`; read back the same.
        let v = serde_json::to_value(&old).unwrap();
        assert!(v.get("up").is_none(), "{v}");
        assert_eq!(v["faces"], serde_json::json!([1, 2, 3, 1, 0, 0]));
        assert_eq!(serde_json::from_value::<Tally>(v).unwrap(), old);
        // A die of any shape's, as written before: zeros under `up` beside its faces.
        let shape: Tally = serde_json::from_str(
            r#"{"counts": {"breadth": 0, "width": 0, "length": 0, "unknown": 0, "face": 5},
            "unconverged": 0, "failed": {}, "rolls": 5, "steps": 50, "engine_steps": 50,
            "certified": 0, "certified_wrong": 0, "certified_steps": 0,
            "up": [0, 0, 0, 0, 0, 0], "faces": [0, 2, 0, 0, 0, 0, 0, 3]}"#,
        )
        .unwrap();
        assert_eq!(shape.faces, vec![0, 2, 0, 0, 0, 0, 0, 3]);
        assert!(shape.check().is_ok());
        // A cuboid's directions past its sides are refused.
        let mut forged = old.clone();
        forged.faces[2] = 9;
        assert!(forged.check().is_err());
    }

    #[test]
    fn a_cuboid_s_face_past_its_six_is_an_error_not_a_panic() {
        use crate::model::throws::{ThrowKind, ThrowRanges, ThrowStyle, Throws};
        let throws = Throws::styled(
            ThrowKind::Keyed,
            ThrowStyle::Paper,
            None,
            1,
            ThrowRanges::default(),
            0,
        );
        let r = RollRecord {
            throw: throws.get(0),
            fate: Fate::Settled(Outcome::Face(6)),
            steps: 10,
            engine_steps: 10,
            certified: None,
            energy_gain: false,
            dip: Default::default(),
        };
        assert!(Tally::of(&[r], true).is_err());
        // A die of any shape's seventh face is a face.
        let t = Tally::of(&[r], false).unwrap();
        assert_eq!(t.faces, vec![0, 0, 0, 0, 0, 0, 1]);
        assert_eq!(t.counts.face, 1);
    }

    #[test]
    fn a_sum_past_u64_max_is_an_error_not_a_wrap() {
        let mut t = Tally {
            steps: u64::MAX - 1,
            rolls: 1,
            ..Tally::default()
        };
        let big = Tally {
            steps: 2,
            rolls: 1,
            ..Tally::default()
        };
        assert!(t.merge(&big).is_err());
    }
}
