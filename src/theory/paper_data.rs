//! The paper's measured data: all 19 rows of its table "sidewaystable" ("Full Experimental
//! Data"), compiled into the binary from `data/paper_table.csv`, and checked as they load.
//!
//! Every number is kept as printed, with its number of decimals ([`PrintedNumber`]), so that
//! the loader can recompute it and say whether the printed digits follow:
//!
//! * throws = length + breadth + width vertical counts, exactly;
//! * the ratio N(breadth vertical)/N(width vertical) and its binomial error (see
//!   [`crate::theory::stats::ratio`]) from the counts;
//! * R = width/breadth and its error from the dimensions and their printed ±;
//! * the predicted ratio of (MasterEqu) and its error, propagated from the same ±
//!   ([`crate::theory::propagation`]).
//!
//! **Rule.** A printed *value* must be the recomputed value rounded to nearest at the printed
//! number of decimals: |recomputed − printed| ≤ ½ unit of the last printed digit (+ 1e-9 unit for
//! floating point). A printed *error* may be rounded to nearest (same test) or rounded up (the
//! conservative convention for uncertainties): printed − 1 unit < recomputed < printed. An error
//! rounded down past nearest, or any other miss, is a discrepancy. Errors that pass only because
//! they were rounded up are listed apart in [`PaperTable::rounded_up`], so nothing passes silently.
//! Nothing is corrected or dropped: the rows are returned as printed, beside the findings.

use serde::Serialize;
use std::fmt;

use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::theory::propagation::{self, Propagated};
use crate::theory::stats;

/// The table as shipped in `data/paper_table.csv`.
pub const PAPER_TABLE_CSV: &str = include_str!("../../data/paper_table.csv");

/// The CSV's columns, in order.
pub const COLUMNS: [&str; 22] = [
    "row",
    "length_mm",
    "length_err_mm",
    "breadth_mm",
    "breadth_err_mm",
    "width_mm",
    "width_err_mm",
    "r",
    "r_err",
    "predicted_ratio",
    "predicted_ratio_err",
    "block",
    "surface",
    "set",
    "extra_length",
    "throws",
    "length_vertical",
    "breadth_vertical",
    "width_vertical",
    "ratio",
    "ratio_err",
    "simulated",
];

/// A number as printed in the paper: its value and its number of decimals.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PrintedNumber {
    /// The value.
    pub value: f64,
    /// Digits printed after the decimal point.
    pub decimals: u32,
}

impl PrintedNumber {
    /// Parses a plain decimal such as `0.070`, `782` or `-1.5`; keeps the decimals written.
    pub fn parse(s: &str) -> Option<PrintedNumber> {
        let s = s.trim();
        let digits = s.strip_prefix('-').unwrap_or(s);
        let (int, frac) = digits.split_once('.').unwrap_or((digits, ""));
        let all_digits = |p: &str| p.chars().all(|c| c.is_ascii_digit());
        if int.is_empty()
            || !all_digits(int)
            || !all_digits(frac)
            || (digits.contains('.') && frac.is_empty())
        {
            return None;
        }
        let value = s.parse::<f64>().ok()?;
        Some(PrintedNumber {
            value,
            decimals: u32::try_from(frac.len()).ok()?,
        })
    }

    /// One unit of the last printed digit, 10^−decimals.
    pub fn unit(&self) -> f64 {
        10f64.powi(-(self.decimals.min(300) as i32))
    }
}

impl fmt::Display for PrintedNumber {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.*}", self.decimals as usize, self.value)
    }
}

/// The block's material.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::EnumString, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
pub enum Material {
    /// Pine.
    Pine,
    /// 3D printed polylactide.
    Printed,
}

/// The surface the block was thrown onto.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::EnumString, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
pub enum Surface {
    /// Carpet (pine blocks).
    Carpet,
    /// A thin towel (pine blocks).
    #[strum(serialize = "Thin Towel")]
    ThinTowel,
    /// A towel on a rug (pine blocks).
    #[strum(serialize = "Towel+Rug")]
    TowelRug,
    /// Medium-density fibreboard (printed blocks; the surface the paper simulated).
    #[strum(serialize = "MDF")]
    Mdf,
    /// Tough carpet (printed blocks).
    #[strum(serialize = "Tough Carpet")]
    ToughCarpet,
}

/// The paper's three data sets, by colour in its table and figure (MasterGraph2).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Serialize,
    PartialOrd,
    Ord,
    strum::EnumString,
    strum::IntoStaticStr,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Set {
    /// RawSienna: pine blocks on carpet and towelling.
    Pine,
    /// Red: printed blocks on MDF.
    Mdf,
    /// Green: printed blocks on tough carpet.
    Carpet,
}

impl Material {
    /// The name the paper prints.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

impl Surface {
    /// The name the paper prints.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

impl Set {
    /// Every set, in the paper's order.
    pub const ALL: [Set; 3] = [Set::Pine, Set::Mdf, Set::Carpet];

    /// The set's name in the CSV: "pine", "mdf" or "carpet".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// One row of the paper's table, as printed (ditto marks resolved).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PaperRow {
    /// 1-based, in the paper's order.
    pub row: usize,
    /// Printed length, mm.
    pub length_mm: PrintedNumber,
    /// Printed ± on the length, mm.
    pub length_err_mm: PrintedNumber,
    /// Printed breadth, mm.
    pub breadth_mm: PrintedNumber,
    /// Printed ± on the breadth, mm.
    pub breadth_err_mm: PrintedNumber,
    /// Printed width, mm.
    pub width_mm: PrintedNumber,
    /// Printed ± on the width, mm.
    pub width_err_mm: PrintedNumber,
    /// Printed R = width/breadth.
    pub r: PrintedNumber,
    /// Printed error on R.
    pub r_err: PrintedNumber,
    /// Printed prediction of (MasterEqu).
    pub predicted_ratio: PrintedNumber,
    /// Printed error on the prediction.
    pub predicted_ratio_err: PrintedNumber,
    /// The block's material.
    pub block: Material,
    /// The surface it was thrown onto.
    pub surface: Surface,
    /// The data set (the row's colour).
    pub set: Set,
    /// An uncoloured row: the same cross-section as the set's row above, another length.
    pub extra_length: bool,
    /// Throws counted.
    pub throws: u64,
    /// Throws that ended length vertical (a blank in the paper is 0).
    pub length_vertical: u64,
    /// Throws that ended breadth vertical.
    pub breadth_vertical: u64,
    /// Throws that ended width vertical.
    pub width_vertical: u64,
    /// Printed measured ratio N(breadth vertical)/N(width vertical).
    pub ratio: PrintedNumber,
    /// Printed binomial error on the measured ratio.
    pub ratio_err: PrintedNumber,
    /// One of the five rows the paper simulated (red, printed on MDF, length 140).
    pub simulated: bool,
}

impl PaperRow {
    /// The block, from the printed dimensions.
    pub fn block_dims(&self) -> Result<Block> {
        Block::from_mm(
            self.length_mm.value,
            self.breadth_mm.value,
            self.width_mm.value,
        )
        .map_err(|e| Error::Invalid(format!("paper table row {}: {e}", self.row)))
    }

    /// A short name for messages, e.g. `140x24x20 MDF`.
    pub fn label(&self) -> String {
        let dims = format!("{}x{}x{}", self.length_mm, self.breadth_mm, self.width_mm);
        let dims = match self.block_dims() {
            Ok(b) => b.to_string(),
            Err(_) => dims,
        };
        format!("{dims} {}", self.surface.name())
    }

    /// The measured ratio with its binomial error, from the counts.
    pub fn measured_ratio(&self) -> stats::Ratio {
        stats::ratio(self.breadth_vertical, self.width_vertical)
    }

    /// R and the (MasterEqu) ratio with errors propagated from the printed dimensions and ±.
    pub fn theory(&self) -> Propagated {
        propagation::propagate(
            self.breadth_mm.value,
            self.breadth_err_mm.value,
            self.width_mm.value,
            self.width_err_mm.value,
        )
    }
}

/// A printed number and what the row's own data give for it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Discrepancy {
    /// The row, 1-based, in the paper's order.
    pub row: usize,
    /// e.g. `140x24x20 MDF`.
    pub label: String,
    /// The CSV column: `throws`, `ratio`, `ratio_err`, `r`, `r_err`, `predicted_ratio`,
    /// `predicted_ratio_err`.
    pub field: &'static str,
    /// The number as printed.
    pub printed: PrintedNumber,
    /// What the row's own data give for it.
    pub recomputed: f64,
}

impl Discrepancy {
    /// One line, e.g. `row 7 (140x24x20 MDF): printed ratio 0.54, counts give 0.565`.
    pub fn describe(&self) -> String {
        let source = match self.field {
            "throws" => "counts sum to",
            "ratio" | "ratio_err" => "counts give",
            _ => "dimensions give",
        };
        let name = self.field.replace('_', " ");
        let shown = if self.field == "throws" {
            format!("{}", self.recomputed)
        } else {
            format!("{:.*}", self.printed.decimals as usize + 1, self.recomputed)
        };
        format!(
            "row {} ({}): printed {name} {}, {source} {shown}",
            self.row, self.label, self.printed
        )
    }
}

/// The loaded table and what the check found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PaperTable {
    /// Every row, in the paper's order, as printed.
    pub rows: Vec<PaperRow>,
    /// Printed numbers the row's own data do not give (see the module's rule).
    pub discrepancies: Vec<Discrepancy>,
    /// Printed errors that are the recomputed error rounded up, not to nearest: accepted, noted.
    pub rounded_up: Vec<Discrepancy>,
}

impl PaperTable {
    /// The rows of one set.
    pub fn set(&self, set: Set) -> impl Iterator<Item = &PaperRow> {
        self.rows.iter().filter(move |r| r.set == set)
    }
}

/// The table shipped in the binary, parsed and checked.
pub fn load() -> Result<PaperTable> {
    parse(PAPER_TABLE_CSV)
}

/// One CSV record as read, before its printed numbers and names are checked.
#[derive(serde::Deserialize)]
struct Record {
    row: usize,
    length_mm: String,
    length_err_mm: String,
    breadth_mm: String,
    breadth_err_mm: String,
    width_mm: String,
    width_err_mm: String,
    r: String,
    r_err: String,
    predicted_ratio: String,
    predicted_ratio_err: String,
    block: String,
    surface: String,
    set: String,
    extra_length: bool,
    throws: u64,
    length_vertical: u64,
    breadth_vertical: u64,
    width_vertical: u64,
    ratio: String,
    ratio_err: String,
    simulated: bool,
}

/// Parses a table in the format of `data/paper_table.csv` (lines starting with `#` are
/// comments; the header must list [`COLUMNS`]) and checks it. A malformed file is an
/// `Error::Invalid` naming the line; numbers that disagree are findings, not errors.
pub fn parse(text: &str) -> Result<PaperTable> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let bad = |line: u64, what: String| Error::Invalid(format!("paper table line {line}: {what}"));
    let header = reader
        .headers()
        .map_err(|e| Error::Invalid(format!("paper table: no header ({e})")))?
        .clone();
    if header.is_empty() {
        return Err(Error::Invalid("paper table: no header".into()));
    }
    if header.iter().ne(COLUMNS) {
        return Err(bad(1, format!("header is not {}", COLUMNS.join(","))));
    }
    let mut rows = Vec::new();
    for raw in reader.records() {
        let raw = raw.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            bad(line, e.to_string())
        })?;
        let ln = raw.position().map_or(0, |p| p.line());
        let rec: Record = raw
            .deserialize(Some(&header))
            .map_err(|e| bad(ln, e.to_string()))?;
        let num = |name: &str, s: &str| {
            PrintedNumber::parse(s)
                .ok_or_else(|| bad(ln, format!("{name} '{s}' is not a decimal number")))
        };
        let row = PaperRow {
            row: rec.row,
            length_mm: num("length_mm", &rec.length_mm)?,
            length_err_mm: num("length_err_mm", &rec.length_err_mm)?,
            breadth_mm: num("breadth_mm", &rec.breadth_mm)?,
            breadth_err_mm: num("breadth_err_mm", &rec.breadth_err_mm)?,
            width_mm: num("width_mm", &rec.width_mm)?,
            width_err_mm: num("width_err_mm", &rec.width_err_mm)?,
            r: num("r", &rec.r)?,
            r_err: num("r_err", &rec.r_err)?,
            predicted_ratio: num("predicted_ratio", &rec.predicted_ratio)?,
            predicted_ratio_err: num("predicted_ratio_err", &rec.predicted_ratio_err)?,
            block: rec
                .block
                .parse::<Material>()
                .ok()
                .ok_or_else(|| bad(ln, format!("block '{}' is not Pine/Printed", rec.block)))?,
            surface: rec.surface.parse::<Surface>().ok().ok_or_else(|| {
                bad(
                    ln,
                    format!("surface '{}' is not one of the paper's", rec.surface),
                )
            })?,
            set: rec
                .set
                .parse::<Set>()
                .ok()
                .ok_or_else(|| bad(ln, format!("set '{}' is not pine/mdf/carpet", rec.set)))?,
            extra_length: rec.extra_length,
            throws: rec.throws,
            length_vertical: rec.length_vertical,
            breadth_vertical: rec.breadth_vertical,
            width_vertical: rec.width_vertical,
            ratio: num("ratio", &rec.ratio)?,
            ratio_err: num("ratio_err", &rec.ratio_err)?,
            simulated: rec.simulated,
        };
        row.block_dims()?;
        rows.push(row);
    }
    let (discrepancies, rounded_up) = check(&rows);
    Ok(PaperTable {
        rows,
        discrepancies,
        rounded_up,
    })
}

/// How a printed number relates to the recomputed one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rounding {
    /// Rounded to nearest.
    Nearest,
    /// Rounded up by one unit beyond nearest (accepted for errors only).
    Up,
    /// Neither: a discrepancy.
    Off,
}

/// Classifies `recomputed` against `printed` by the module's rule.
pub fn rounding(printed: PrintedNumber, recomputed: f64) -> Rounding {
    let unit = printed.unit();
    let p = printed.value;
    if (recomputed - p).abs() <= 0.5 * unit + 1e-9 * unit {
        Rounding::Nearest
    } else if recomputed > p - unit + 1e-9 * unit && recomputed < p {
        Rounding::Up
    } else {
        Rounding::Off
    }
}

/// Checks every row by the module's rule: (discrepancies, errors rounded up).
pub fn check(rows: &[PaperRow]) -> (Vec<Discrepancy>, Vec<Discrepancy>) {
    let mut off = Vec::new();
    let mut up = Vec::new();
    for row in rows {
        let measured = row.measured_ratio();
        let theory = row.theory();
        let counted = row
            .length_vertical
            .checked_add(row.breadth_vertical)
            .and_then(|s| s.checked_add(row.width_vertical));
        let throws = PrintedNumber {
            value: row.throws as f64,
            decimals: 0,
        };
        // (field, printed, recomputed, is an error estimate)
        let fields: [(&'static str, PrintedNumber, f64, bool); 6] = [
            ("ratio", row.ratio, measured.value, false),
            ("ratio_err", row.ratio_err, measured.err, true),
            ("r", row.r, theory.r, false),
            ("r_err", row.r_err, theory.r_err, true),
            ("predicted_ratio", row.predicted_ratio, theory.ratio, false),
            (
                "predicted_ratio_err",
                row.predicted_ratio_err,
                theory.ratio_err,
                true,
            ),
        ];
        let finding = |field, printed, recomputed| Discrepancy {
            row: row.row,
            label: row.label(),
            field,
            printed,
            recomputed,
        };
        if counted != Some(row.throws) {
            let sum = counted.map_or(f64::INFINITY, |s| s as f64);
            off.push(finding("throws", throws, sum));
        }
        for (field, printed, recomputed, is_err) in fields {
            match rounding(printed, recomputed) {
                Rounding::Nearest => {}
                Rounding::Up if is_err => up.push(finding(field, printed, recomputed)),
                _ => off.push(finding(field, printed, recomputed)),
            }
        }
    }
    (off, up)
}

#[cfg(test)]
mod tests;
