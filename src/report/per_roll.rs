//! The per-roll CSV (`roll --per-roll`): one row per throw, its initial conditions and how it
//! ended, written with the `csv` crate as the records arrive.

use crate::error::{Error, Result};
use crate::model::faces::Layout;
use crate::model::faces::Outcome;
use crate::sim::roll::{Fate, RollRecord};
use serde::Serialize;
use std::io::Write;

/// One row, in column order.
#[derive(Serialize)]
struct Row<'a> {
    index: u64,
    #[serde(serialize_with = "shortest")]
    drop_height_m: f64,
    #[serde(serialize_with = "shortest")]
    velocity_m_s: f64,
    #[serde(serialize_with = "shortest")]
    spin_rad_s: f64,
    /// `settled`, `unconverged`, or the failure's name.
    status: &'a str,
    /// The side vertical (at rest, or at the step cap); empty for a failed roll.
    outcome: &'a str,
    steps: u64,
    #[serde(serialize_with = "shortest")]
    sim_time_s: f64,
    /// The energy-gain flag, 0 or 1.
    energy_gain: u8,
    /// Steps at whose end the die's centre was below the floor's top face.
    dip_steps: u64,
    /// The longest run of such steps.
    longest_dip_steps: u64,
    /// The deepest any point of the die went below that face, m (`roll::Dip`).
    #[serde(serialize_with = "shortest")]
    penetration_m: f64,
    /// The number on the face up (under the run's layout); empty unless settled on a side.
    face: String,
}

/// A float as Rust writes it (`{:?}`: the shortest text that reads back to the same double,
/// with an exponent below 1e-5 and above 1e16), so rows are the same bytes as before the
/// `csv` crate wrote them (it would write 3.86e-5 as 0.0000386).
fn shortest<S: serde::Serializer>(v: &f64, s: S) -> std::result::Result<S::Ok, S::Error> {
    s.collect_str(&format_args!("{v:?}"))
}

/// The columns, as the header names them.
pub const COLUMNS: [&str; 13] = [
    "index",
    "drop_height_m",
    "velocity_m_s",
    "spin_rad_s",
    "status",
    "outcome",
    "steps",
    "sim_time_s",
    "energy_gain",
    "dip_steps",
    "longest_dip_steps",
    "penetration_m",
    "face",
];

/// A per-roll CSV being written.
pub struct PerRoll<W: Write> {
    csv: csv::Writer<W>,
    dt: f64,
    /// What each outcome shows, by its index (`Form::face_labels`).
    labels: Vec<String>,
    /// The cuboid's outcome column is its side (`Form::counts_sides`); a die of any shape's
    /// is "face".
    sides: bool,
}

fn failed(e: csv::Error) -> Error {
    Error::failed(format!("per-roll CSV: {e}"))
}

impl<W: Write> PerRoll<W> {
    /// Starts the CSV on `out` with its header; `dt` turns steps into simulated time, and
    /// `layout` numbers the faces.
    pub fn new(out: W, dt: f64, layout: Layout) -> Result<PerRoll<W>> {
        let mut csv = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(out);
        csv.write_record(COLUMNS).map_err(failed)?;
        Ok(PerRoll {
            csv,
            dt,
            labels: layout.numbers().iter().map(u8::to_string).collect(),
            sides: true,
        })
    }

    /// The same CSV for a die of any shape: its `face` column the label each roll shows.
    pub fn for_scene(
        out: W,
        scene: &crate::model::scene::Scene,
        layout: Layout,
    ) -> Result<PerRoll<W>> {
        let mut p = PerRoll::new(out, scene.dt, layout)?;
        p.labels = scene.die.face_labels(layout);
        p.sides = scene.die.counts_sides();
        Ok(p)
    }

    /// Writes one row per record, in order.
    pub fn write(&mut self, records: &[RollRecord]) -> Result<()> {
        for r in records {
            // A cuboid's outcome by its side; a die of any shape's as "face" (which one: the
            // face column).
            let side = |o: Outcome| match o {
                Outcome::Face(_) if !self.sides => "face",
                _ => o.side().name(),
            };
            let (status, outcome) = match r.fate {
                Fate::Settled(o) => ("settled", side(o)),
                Fate::Unconverged(o) => ("unconverged", side(o)),
                Fate::Failed(f) => (f.name(), ""),
            };
            // The face of a roll at rest (at the step cap it is the record's only).
            let up = match r.fate {
                Fate::Settled(o) => o.face(),
                _ => None,
            };
            let t = &r.throw;
            self.csv
                .serialize(Row {
                    index: t.index,
                    drop_height_m: t.drop_height,
                    velocity_m_s: t.velocity,
                    spin_rad_s: t.spin,
                    status,
                    outcome,
                    steps: r.steps,
                    sim_time_s: r.sim_time(self.dt),
                    energy_gain: r.energy_gain as u8,
                    dip_steps: r.dip.steps,
                    longest_dip_steps: r.dip.longest,
                    penetration_m: r.dip.penetration,
                    face: up
                        .and_then(|d| self.labels.get(usize::from(d)).cloned())
                        .unwrap_or_default(),
                })
                .map_err(failed)?;
        }
        Ok(())
    }

    /// Flushes and hands back the writer.
    pub fn finish(self) -> Result<W> {
        self.csv
            .into_inner()
            .map_err(|e| Error::failed(format!("per-roll CSV: {}", e.error())))
    }
}
