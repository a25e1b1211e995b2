//! Measured counts to fit: one row per block thrown on one surface, read from a CSV file.
//!
//! ```text
//! label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical[,thrower]
//! row 7,MDF,140,24,20,3d,0,361,639
//! cube-ish,felt,50,20,20,3d,12,700,-
//! ```
//!
//! Or, for a die whose faces were told apart, the six faces' counts in place of the three
//! sides' (`face_1`…`face_6`: how often each number came up; 3D rows only, breadth ≥ width as
//! given, since the numbers sit on the body's axes by the die's layout):
//!
//! ```text
//! label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,face_4,face_5,face_6
//! suspect,felt,16,16,16,3d,1702,1650,1671,1648,1660,1569
//! ```
//!
//! Or, for a die of any shape (`--shape`, a mesh `--die`: its size is the shape's, so no sides
//! are given, and it is thrown in 3D), one `face_<label>` column for each of its faces, named by
//! what the face shows, in any order ([`on_shape`] checks them against the die):
//!
//! ```text
//! label,surface,face_heads,face_tails,face_edge
//! thick coin,felt,412,398,190
//! ```
//!
//! Several dice in one file: a `die` column after the surface names each row's die, a shape
//! name as `--shape` takes it (`d8`, `coin:24,2`) or a die file as `--die` takes it (a TOML or
//! a mesh, by its extension), a path relative to the file's folder ([`read`] joins it). Each
//! row fills its own die's `face_<label>` columns and leaves the others empty (or `-`); a row
//! whose die cell is empty is the command line's die's (`--shape`/`--die`):
//!
//! ```text
//! label,surface,die,face_1,face_2,face_3,face_4,face_5,face_6,face_7,face_8
//! cube,felt,d6,170,162,171,165,168,164,,
//! octahedron,felt,d8,126,118,131,122,125,127,120,131
//! ```
//!
//! - `mode`: how the row is simulated, `3d` (a free body) or `2d` (DicePhys's plane-locked
//!   block). A 2D block cannot land on its end: a `2d` row is fitted on its two side outcomes,
//!   and its length-vertical count is kept but set aside.
//! - Counts are whole numbers. Where two sides are equal their outcomes land on congruent
//!   faces and may be counted together: the sum in one column and `-` in the other (the fit
//!   then merges its simulated outcomes the same way). `-` is refused where the sides differ.
//! - `thrower` (optional): rows thrown the same way share the throw's parameters; one thrower
//!   when the column is absent.
//! - Breadth is the larger side of the cross-section; a row that gives the smaller first has
//!   its two sides, and their counts, swapped, as `--block` does.
//! - `#` starts a comment line. Every error names the file, line and column.

use crate::error::{Error, Result};
use crate::model::block::Block;
use crate::model::scene::Mode;
use serde::{Deserialize, Serialize};

/// The outcomes in the order rows and simulations keep them.
pub const OUTCOMES: [&str; 3] = ["length", "breadth", "width"];

/// The face counts' columns, which may stand in place of the three `*_vertical` columns.
pub const FACE_COLUMNS: [&str; 6] = ["face_1", "face_2", "face_3", "face_4", "face_5", "face_6"];

/// What a row counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcomes {
    /// Which side stood vertical: length, breadth, width ([`OUTCOMES`]).
    #[default]
    Sides,
    /// Which number came up: 1 to 6, by the die's layout.
    Faces,
}

impl Outcomes {
    /// True for side counts (the default, left out of a row's JSON).
    pub fn is_sides(&self) -> bool {
        *self == Outcomes::Sides
    }
}

/// The CSV's columns, in order (`thrower` may be left out).
pub const COLUMNS: [&str; 10] = [
    "label",
    "surface",
    "length_mm",
    "breadth_mm",
    "width_mm",
    "mode",
    "length_vertical",
    "breadth_vertical",
    "width_vertical",
    "thrower",
];

/// One row of measured counts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DataRow {
    /// The row's name.
    pub label: String,
    /// The surface it was thrown on (rows on one surface share its e and μ).
    pub surface: String,
    /// Who threw it (rows of one thrower share the throw's parameters).
    pub thrower: String,
    /// The block.
    pub block: Block,
    /// How it is simulated.
    pub mode: Mode,
    /// What it counts: sides (the default) or faces.
    #[serde(default, skip_serializing_if = "Outcomes::is_sides")]
    pub outcomes: Outcomes,
    /// Counts of length, breadth and width vertical, or of faces 1 to 6; a merged outcome's
    /// count is in its group's first member and 0 in the others.
    pub counts: Vec<u64>,
    /// The outcomes counted apart, as groups of indices into `counts` (a 2D row: breadth and
    /// width only).
    pub groups: Vec<Vec<usize>>,
    /// A die of any shape: what each count's face shows, in the order of `counts` (the die's
    /// faces' order once [`on_shape`] has read the row against it). Empty for a block's rows.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub labels: Vec<String>,
    /// The row's own die, as its `die` column names it (a shape name, or a die file's path
    /// joined to the counts file's folder); `None`: the fit's die (`--shape`/`--die`), or a
    /// block.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub die: Option<String>,
}

impl DataRow {
    /// The counts of each group, in the groups' order.
    pub fn grouped(&self) -> Vec<u64> {
        self.groups
            .iter()
            .map(|g| g.iter().map(|&k| self.counts[k]).sum())
            .collect()
    }

    /// True if the row counts the faces of a die of any shape (`face_<label>` columns).
    pub fn of_shape(&self) -> bool {
        !self.labels.is_empty()
    }

    /// Throws counted in the fit (a 2D row: its side outcomes).
    pub fn n(&self) -> u64 {
        self.grouped().iter().sum()
    }

    /// The groups' names: "breadth", "width", "length", or "breadth+width" when merged; "face
    /// 1" … "face 6" for a row of faces, "face <label>" for a die of any shape.
    pub fn group_names(&self) -> Vec<String> {
        let name = |k: usize| match (self.outcomes, self.labels.get(k)) {
            (Outcomes::Faces, Some(l)) => format!("face {l}"),
            (Outcomes::Sides, _) => OUTCOMES[k].to_string(),
            (Outcomes::Faces, None) => format!("face {}", k + 1),
        };
        self.groups
            .iter()
            .map(|g| g.iter().map(|&k| name(k)).collect::<Vec<_>>().join("+"))
            .collect()
    }

    /// The same row with `counts` in its groups (a merged group's in its first member).
    pub fn with_grouped(&self, grouped: &[u64]) -> DataRow {
        let mut counts = vec![0; self.counts.len()];
        for (g, c) in self.groups.iter().zip(grouped) {
            counts[g[0]] = *c;
        }
        DataRow {
            counts,
            ..self.clone()
        }
    }
}

/// The outcome groups of a row: every outcome apart, less a 2D row's length, with each `-`
/// merged into the congruent outcome that carries the count. `sides`: length, breadth, width.
fn groups(
    mode: Mode,
    sides: [f64; 3],
    dashed: [bool; 3],
) -> std::result::Result<Vec<Vec<usize>>, String> {
    let live: Vec<usize> = match mode {
        Mode::ThreeD => vec![0, 1, 2],
        Mode::TwoD => vec![1, 2],
    };
    let mut groups: Vec<Vec<usize>> = live
        .iter()
        .filter(|&&k| !dashed[k])
        .map(|&k| vec![k])
        .collect();
    for &k in live.iter().filter(|&&k| dashed[k]) {
        let into = groups
            .iter_mut()
            .find(|g| sides[g[0]] == sides[k])
            .ok_or_else(|| {
                format!(
                    "'-' counts {} vertical with a congruent outcome, but no counted side equals \
                     its {} mm",
                    OUTCOMES[k], sides[k]
                )
            })?;
        into.push(k);
    }
    if groups.len() < 2 {
        return Err("all outcomes merged into one: the row tells nothing".into());
    }
    Ok(groups)
}

/// The largest counts file read: a row is a few dozen bytes, so 16 MiB is hundreds of
/// thousands of rows. A larger file (or `/dev/zero`) is refused without being read whole.
pub const MAX_DATA_BYTES: u64 = 16 << 20;

/// The most throws one row may count: 10¹² (the estimate's cost does not grow with them, but
/// no table of real throws comes near).
pub const MAX_ROW_THROWS: u64 = 1_000_000_000_000;

/// Reads a counts CSV from `path`, no further than [`MAX_DATA_BYTES`], honouring `stop` while
/// it waits (a named pipe with no writer blocks in `open`). Invalid UTF-8 is located by line
/// and column.
pub fn read(path: &std::path::Path, stop: &crate::run::stop::Stop) -> Result<Vec<DataRow>> {
    let name = path.display().to_string();
    let bytes = crate::run::io::read_capped(path, MAX_DATA_BYTES, stop)?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        let (line, col) = line_col(&bytes, e.valid_up_to());
        Error::Invalid(format!(
            "{name}: line {line}, byte {col}: not UTF-8 (save the file as UTF-8 text)"
        ))
    })?;
    let mut rows = parse(text, &name)?;
    // A row's die file is found beside the counts file, wherever the command runs.
    let dir = path.parent().unwrap_or(std::path::Path::new(""));
    for r in &mut rows {
        if let Some(d) = r.die.as_mut().filter(|d| is_die_file(d)) {
            *d = dir.join(&*d).display().to_string();
        }
    }
    Ok(rows)
}

/// True if a `die` cell names a die file (a TOML or a mesh, by its extension) rather than a
/// shape (`d8`, `coin:24.5,2`).
pub fn is_die_file(die: &str) -> bool {
    let p = std::path::Path::new(die);
    crate::model::mass::is_mesh(p)
        || p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// The 1-based line and column (in bytes) of byte `at`.
fn line_col(bytes: &[u8], at: usize) -> (usize, usize) {
    let before = &bytes[..at];
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    (line, at - start + 1)
}

/// A field's text as an error message shows it: control characters escaped (a quoted field
/// may hold a newline or a terminal's escape sequence), and cut after 40 characters.
pub fn shown(v: &str) -> String {
    let mut out = String::new();
    for (i, c) in v.chars().enumerate() {
        if i == 40 {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// A counter of lines: the line of each record's byte offset, counted forward as the records
/// come (CRLF, blank lines and quoted newlines all count as the file's own lines).
fn line_counter(text: &str) -> impl FnMut(usize) -> usize + '_ {
    let mut counted = (0usize, 1usize);
    let bytes = text.as_bytes();
    move |mut byte: usize| {
        // A record's position may sit before the line ends, blank lines and comments that
        // precede it: step over them to its first character.
        loop {
            while byte < bytes.len() && matches!(bytes[byte], b'\r' | b'\n') {
                byte += 1;
            }
            if bytes.get(byte) != Some(&b'#') {
                break;
            }
            while byte < bytes.len() && bytes[byte] != b'\n' {
                byte += 1;
            }
        }
        let byte = byte.max(counted.0);
        let (from, line) = counted;
        let line = line + bytes[from..byte].iter().filter(|&&b| b == b'\n').count();
        counted = (byte, line);
        line
    }
}

/// What a header says is counted.
#[derive(Clone, Debug, PartialEq)]
enum Form {
    /// Sides or a cube's six faces, with this many count columns.
    Block(Outcomes, usize),
    /// A die of any shape, by these labels (the header's `face_<label>`, in its order), and
    /// whether a `die` column names each row's die (before the labels).
    Shape(Vec<String>, bool),
}

impl Form {
    /// The file's column of the first count (0-based).
    fn first_count_column(&self) -> usize {
        match self {
            Form::Block(..) => 6,
            Form::Shape(_, with_die) => 2 + usize::from(*with_die),
        }
    }
}

/// What a header says (sides, a cube's faces or a shape's, and whether a `thrower` column ends
/// it); a header that is none of the forms is refused.
fn columns(have: &[&str], name: &str) -> Result<(Form, bool)> {
    let with_thrower = have.last() == Some(&"thrower");
    let with_die = have.get(2) == Some(&"die");
    let first = 2 + usize::from(with_die);
    if have.len() > first && have[..2] == COLUMNS[..2] && have[first].starts_with("face_") {
        let faces = &have[first..have.len() - usize::from(with_thrower)];
        let labels: Vec<String> = faces
            .iter()
            .map(|c| c.strip_prefix("face_").unwrap_or("").to_string())
            .collect();
        if labels.len() < 2 || labels.iter().any(String::is_empty) {
            return Err(Error::Invalid(format!(
                "{name}: line 1: a die of any shape is counted as label,surface[,die],face_<label>,… (a column for each face, at least two)[,thrower], got {}",
                shown(&have.join(","))
            )));
        }
        return Ok((Form::Shape(labels, with_die), with_thrower));
    }
    let (outcomes, counted) = if have.get(6) == Some(&FACE_COLUMNS[0]) {
        (Outcomes::Faces, 6)
    } else {
        (Outcomes::Sides, 3)
    };
    let want: Vec<&str> = match outcomes {
        Outcomes::Sides => COLUMNS[..9].to_vec(),
        Outcomes::Faces => COLUMNS[..6].iter().chain(&FACE_COLUMNS).copied().collect(),
    };
    let with_thrower = with_thrower && have.len() == want.len() + 1;
    if !(have == want || with_thrower && have[..want.len()] == want[..]) {
        return Err(Error::Invalid(format!(
            "{name}: line 1: the header must be {}[,thrower] (or face_1,…,face_6 in place of \
             the three *_vertical; or label,surface,face_<label>,… for a die of any shape), \
             got {}",
            COLUMNS[..9].join(","),
            shown(&have.join(","))
        )));
    }
    Ok((Form::Block(outcomes, counted), with_thrower))
}

/// A count as a field (or `fair --counts`'s `LABEL=N`) gives it, a whole number; else what is
/// wrong with `v`, quoted: not a whole number, or one past [`MAX_ROW_THROWS`].
pub fn count(v: &str) -> std::result::Result<u64, String> {
    let too_large = || {
        format!(
            "'{}' is too large a count (at most {MAX_ROW_THROWS} throws)",
            shown(v)
        )
    };
    match v.parse::<u64>() {
        Ok(n) if n <= MAX_ROW_THROWS => Ok(n),
        Ok(_) => Err(too_large()),
        Err(e) if *e.kind() == std::num::IntErrorKind::PosOverflow => Err(too_large()),
        Err(_) => Err(format!("'{}' is not a count (a whole number)", shown(v))),
    }
}

/// A record's counts and which of them are `-` (sides only); a field that is not a count is
/// the error `(column, what is wrong)`.
fn counts_of(
    rec: &csv::StringRecord,
    outcomes: Outcomes,
    counted: usize,
) -> std::result::Result<(Vec<u64>, Vec<bool>), (usize, String)> {
    let mut counts = vec![0u64; counted];
    let mut dashed = vec![false; counted];
    for k in 0..counted {
        let c = 6 + k;
        match &rec[c] {
            "-" if outcomes == Outcomes::Sides => dashed[k] = true,
            v => {
                counts[k] = count(v).map_err(|m| match v.parse::<f64>() {
                    // A side's count may also be '-' (an equal side's, counted with it).
                    Err(_) if outcomes == Outcomes::Sides => {
                        (c, m.replace("(a whole number)", "(a whole number, or '-')"))
                    }
                    _ => (c, m),
                })?
            }
        }
    }
    Ok((counts, dashed))
}

/// Reads a counts CSV; `name` is the file's name for messages. Linear in the file's size.
pub fn parse(text: &str, name: &str) -> Result<Vec<DataRow>> {
    // The header's names, once it is read (an error before it names no column).
    let names: std::cell::RefCell<Vec<String>> = Default::default();
    let bad = |line: usize, col: usize, msg: String| {
        let column = names.borrow().get(col).cloned().unwrap_or("?".into());
        Error::Invalid(format!(
            "{name}: line {line}, column {} ({column}): {msg}",
            col + 1
        ))
    };
    let mut line_of = line_counter(text);
    let csv_error = |e: csv::Error| {
        let line = e
            .position()
            .map_or(String::new(), |p| format!(" line {},", p.line()));
        Error::Invalid(shown(&format!("{name}:{line} {e}")))
    };
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .has_headers(true)
        .flexible(true)
        .from_reader(text.as_bytes());
    let header = reader.headers().map_err(csv_error)?.clone();
    let have: Vec<&str> = header.iter().collect();
    let (form, with_thrower) = columns(&have, name)?;
    *names.borrow_mut() = have.iter().map(|s| s.to_string()).collect();
    let mut rows: Vec<DataRow> = Vec::new();
    let mut labels = std::collections::HashSet::new();
    for rec in reader.records() {
        let rec = rec.map_err(csv_error)?;
        let line = line_of(rec.position().map_or(0, |p| p.byte() as usize));
        let row =
            row_of(&rec, have.len(), &form, with_thrower).map_err(|(c, m)| bad(line, c, m))?;
        if !labels.insert(row.label.clone()) {
            return Err(bad(
                line,
                0,
                format!("label '{}' is used twice", shown(&row.label)),
            ));
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(Error::Invalid(format!("{name}: no rows of counts")));
    }
    Ok(rows)
}

/// A record's length, breadth and width, mm, each positive.
fn sides_of(rec: &csv::StringRecord) -> std::result::Result<[f64; 3], (usize, String)> {
    let mut sides = [0.0; 3];
    for (i, s) in sides.iter_mut().enumerate() {
        let c = 2 + i;
        *s = rec[c]
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                (
                    c,
                    format!("'{}' is not a positive number of mm", shown(&rec[c])),
                )
            })?;
    }
    Ok(sides)
}

/// One record as a row, with the header's `fields`, what it counts (`form`) and whether a
/// thrower ends it; an error is `(its column, what is wrong)`.
fn row_of(
    rec: &csv::StringRecord,
    fields: usize,
    form: &Form,
    with_thrower: bool,
) -> std::result::Result<DataRow, (usize, String)> {
    if rec.len() != fields {
        return Err((
            rec.len().min(fields),
            format!("{} fields where the header has {}", rec.len(), fields),
        ));
    }
    let text = |c: usize| -> std::result::Result<String, (usize, String)> {
        let v = rec[c].to_string();
        if v.is_empty() {
            return Err((c, "empty".into()));
        }
        if v.chars().any(char::is_control) {
            return Err((c, format!("'{}' holds a control character", shown(&v))));
        }
        Ok(v)
    };
    let label = text(0)?;
    let surface = text(1)?;
    let thrower = if with_thrower {
        text(fields - 1)?
    } else {
        "all".into()
    };
    let row = match form {
        Form::Block(outcomes, counted) => block_row(rec, *outcomes, *counted)?,
        Form::Shape(labels, with_die) => shape_row(rec, labels, *with_die)?,
    };
    let row = DataRow {
        label,
        surface,
        thrower,
        ..row
    };
    let total = row.counts.iter().try_fold(0u64, |a, &c| a.checked_add(c));
    if total.is_none_or(|t| t > MAX_ROW_THROWS) {
        return Err((
            form.first_count_column(),
            format!("counts too large: at most {MAX_ROW_THROWS} throws a row"),
        ));
    }
    if row.n() == 0 {
        return Err((form.first_count_column(), "no throws counted".into()));
    }
    Ok(row)
}

/// A record's counts of a die of any shape, one a label, from column 3 (or 4 after a `die`
/// column, `with_die`: then a column left empty or `-` is another die's, and the row has no
/// such face); its block is a placeholder until [`on_shape`] reads the row against the die.
fn shape_row(
    rec: &csv::StringRecord,
    labels: &[String],
    with_die: bool,
) -> std::result::Result<DataRow, (usize, String)> {
    let first = 2 + usize::from(with_die);
    let die = (with_die && !matches!(&rec[2], "" | "-")).then(|| rec[2].to_string());
    if let Some(d) = &die {
        if d.chars().any(char::is_control) {
            return Err((2, format!("'{}' holds a control character", shown(d))));
        }
    }
    let mut counts = Vec::new();
    let mut kept = Vec::new();
    for (k, label) in labels.iter().enumerate() {
        let c = first + k;
        if with_die && matches!(&rec[c], "" | "-") {
            continue;
        }
        counts.push(count(&rec[c]).map_err(|m| (c, m))?);
        kept.push(label.clone());
    }
    if kept.len() < 2 {
        return Err((
            first,
            "a die's row counts at least two of its faces (the other dice's columns left empty)"
                .into(),
        ));
    }
    Ok(DataRow {
        label: String::new(),
        surface: String::new(),
        thrower: String::new(),
        block: Block::from_mm(1.0, 1.0, 1.0).expect("a unit block"),
        mode: Mode::ThreeD,
        outcomes: Outcomes::Faces,
        groups: (0..counts.len()).map(|k| vec![k]).collect(),
        counts,
        labels: kept,
        die,
    })
}

/// A record's block and counts of its sides or of a cube's six faces.
fn block_row(
    rec: &csv::StringRecord,
    outcomes: Outcomes,
    counted: usize,
) -> std::result::Result<DataRow, (usize, String)> {
    let mut sides = sides_of(rec)?;
    let mode: Mode = rec[5]
        .parse()
        .map_err(|_| (5, format!("'{}' is not 2d or 3d", shown(&rec[5]))))?;
    if outcomes == Outcomes::Faces && mode == Mode::TwoD {
        return Err((
            5,
            "face counts are thrown in 3D (a 2D block shows a side, not a number)".into(),
        ));
    }
    let (mut counts, mut dashed) = counts_of(rec, outcomes, counted)?;
    // Breadth is the larger side: swap a row given the other way, with its counts.
    if sides[1] < sides[2] {
        if outcomes == Outcomes::Faces {
            return Err((
                3,
                "give breadth_mm >= width_mm for face counts: the numbers sit on the \
                 body's axes (x breadth, y width, z length) by the die's layout"
                    .into(),
            ));
        }
        sides.swap(1, 2);
        counts.swap(1, 2);
        dashed.swap(1, 2);
    }
    let block = Block::from_mm(sides[0], sides[1], sides[2]).map_err(|e| (2, e.to_string()))?;
    let groups = match outcomes {
        Outcomes::Sides => {
            groups(mode, sides, [dashed[0], dashed[1], dashed[2]]).map_err(|m| (6, m))?
        }
        Outcomes::Faces => (0..6).map(|k| vec![k]).collect(),
    };
    Ok(DataRow {
        label: String::new(),
        surface: String::new(),
        thrower: String::new(),
        block,
        mode,
        outcomes,
        counts,
        groups,
        labels: Vec::new(),
        die: None,
    })
}

/// `rows` read against the die of any shape they count: each row's `face_<label>` columns must
/// be the die's faces, each once (in any order); its counts are put in the die's order and its
/// block is the die's bounding box. Rows of a block's sides or a cube's numbers are refused, as
/// is a die whose faces share a label (its counts could not be told apart).
pub fn on_shape(rows: &[DataRow], shape: &crate::model::shape::Shape) -> Result<Vec<DataRow>> {
    // A label on several facets (a mirror pair that shares one printed number) is one
    // outcome: the rows count it, the fit sums its facets.
    let labels = shape.outcome_labels();
    let want: Vec<&str> = labels.iter().map(String::as_str).collect();
    let bad = |m: String| Error::Invalid(m);
    let block = shape.block();
    rows.iter()
        .map(|r| {
            if !r.of_shape() {
                return Err(bad(format!(
                    "row '{}': {} is counted by its faces, one face_<label> column each \
                     (label,surface,face_{},…), not by a block's sides or a cube's numbers",
                    shown(&r.label),
                    shape.name,
                    want.join(",face_")
                )));
            }
            let missing: Vec<&str> = want
                .iter()
                .filter(|l| !r.labels.iter().any(|m| m == *l))
                .copied()
                .collect();
            let extra: Vec<&str> = r
                .labels
                .iter()
                .filter(|m| !want.contains(&m.as_str()))
                .map(String::as_str)
                .collect();
            if !missing.is_empty() || !extra.is_empty() || r.labels.len() != want.len() {
                return Err(bad(format!(
                    "row '{}': the columns must be {}'s faces, face_{} (each once){}{}",
                    shown(&r.label),
                    shape.name,
                    want.join(",face_"),
                    if missing.is_empty() {
                        String::new()
                    } else {
                        format!("; missing face_{}", missing.join(", face_"))
                    },
                    if extra.is_empty() {
                        String::new()
                    } else {
                        format!("; not its faces: face_{}", shown(&extra.join(", face_")))
                    }
                )));
            }
            let counts = want
                .iter()
                .map(|l| r.counts[r.labels.iter().position(|m| m == l).expect("found")])
                .collect();
            Ok(DataRow {
                block,
                counts,
                labels: want.iter().map(|l| l.to_string()).collect(),
                ..r.clone()
            })
        })
        .collect()
}

/// The paper's 19 rows (its table "sidewaystable"), as a counts file would give them: every
/// row thrown in 3D by one thrower, labelled "row N", on its surface.
pub fn paper_rows() -> Result<Vec<DataRow>> {
    let table = crate::theory::paper_data::load()?;
    let mut text = COLUMNS[..9].join(",");
    text.push('\n');
    for r in &table.rows {
        text.push_str(&format!(
            "row {},{},{},{},{},3d,{},{},{}\n",
            r.row,
            r.surface.name(),
            r.length_mm.value,
            r.breadth_mm.value,
            r.width_mm.value,
            r.length_vertical,
            r.breadth_vertical,
            r.width_vertical
        ));
    }
    parse(&text, "the paper's table")
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\n";

    #[test]
    fn rows_read_with_their_groups() {
        let rows = parse(
            &format!("{HEAD}a,MDF,140,24,20,3d,0,361,639\n# note\nb,felt,50,20,20,3d,12,700,-\nc,MDF,140,13,22,2d,3,40,160\n"),
            "f.csv",
        )
        .unwrap();
        assert_eq!(rows[0].groups, vec![vec![0], vec![1], vec![2]]);
        assert_eq!(rows[1].groups, vec![vec![0], vec![1, 2]]);
        assert_eq!(rows[1].grouped(), vec![12, 700]);
        assert_eq!(rows[1].group_names(), vec!["length", "breadth+width"]);
        // Given the smaller side first: swapped, with its counts; 2D: the sides only.
        assert_eq!(rows[2].counts, [3, 160, 40]);
        assert_eq!(rows[2].groups, vec![vec![1], vec![2]]);
        assert_eq!(rows[2].n(), 200);
        assert_eq!(rows[0].thrower, "all");
    }

    #[test]
    fn bad_files_name_line_and_column() {
        let cases = [
            (
                format!("{HEAD}a,MDF,140,24,20,3d,0,x,639\n"),
                "line 2, column 8 (breadth_vertical)",
            ),
            (
                format!("{HEAD}a,MDF,140,24,20,3d,0,361,-\n"),
                "line 2, column 7",
            ),
            (
                format!("{HEAD}a,MDF,140,-2,20,3d,0,361,6\n"),
                "line 2, column 4 (breadth_mm)",
            ),
            (
                format!("{HEAD}a,MDF,140,24,20,4d,0,361,6\n"),
                "line 2, column 6 (mode)",
            ),
            (format!("{HEAD}a,MDF,140,24,20,3d,0,361\n"), "line 2"),
            (
                format!("{HEAD}a,MDF,140,24,20,3d,0,1,1\na,MDF,140,24,20,3d,0,1,1\n"),
                "line 3, column 1 (label)",
            ),
            (
                format!("{HEAD}a,,140,24,20,3d,0,1,1\n"),
                "line 2, column 2 (surface)",
            ),
            (format!("{HEAD}a,MDF,140,24,20,3d,0,0,0\n"), "no throws"),
            ("label,surface\n".to_string(), "line 1: the header"),
            (HEAD.to_string(), "no rows"),
            (
                format!("{HEAD}a,MDF,140,24,20,3d,0,-18446744073709551615,1\n"),
                "column 8",
            ),
        ];
        for (text, want) in cases {
            let e = parse(&text, "f.csv").unwrap_err().to_string();
            assert!(
                e.starts_with("f.csv: ") && e.contains(want),
                "{e} (wanted {want})"
            );
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn face_counts_are_six_outcomes_and_refused_where_they_cannot_be_read() {
        let head = "label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,face_4,face_5,face_6";
        let rows = parse(
            &format!("{head},thrower\nd,felt,16,16,16,3d,10,11,12,13,14,15,me\n"),
            "f.csv",
        )
        .unwrap();
        assert_eq!(rows[0].outcomes, Outcomes::Faces);
        assert_eq!(rows[0].counts, vec![10, 11, 12, 13, 14, 15]);
        assert_eq!(rows[0].groups.len(), 6);
        assert_eq!(rows[0].n(), 75);
        assert_eq!(rows[0].thrower, "me");
        assert_eq!(rows[0].group_names()[5], "face 6");
        let cases = [
            (
                format!("{head}\nd,felt,16,16,16,2d,1,1,1,1,1,1\n"),
                "column 6 (mode)",
            ),
            (
                format!("{head}\nd,felt,16,15,16,3d,1,1,1,1,1,1\n"),
                "column 4 (breadth_mm): give breadth_mm >= width_mm",
            ),
            (
                format!("{head}\nd,felt,16,16,16,3d,1,-,1,1,1,1\n"),
                "column 8 (face_2)",
            ),
            (format!("{head}\nd,felt,16,16,16,3d,1,1,1,1,1\n"), "line 2"),
            (
                "label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2\n".into(),
                "line 1: the header",
            ),
        ];
        for (text, want) in cases {
            let e = parse(&text, "f.csv").unwrap_err().to_string();
            assert!(e.contains(want), "{e} (wanted {want})");
        }
    }

    #[test]
    fn a_shapes_faces_are_read_by_label_into_its_order_and_refused_where_they_are_not_its() {
        let coin = crate::model::shape::named("coin:24,8", None).unwrap();
        assert_eq!(coin.labels(), ["heads", "tails", "edge"]);
        let rows = parse(
            "label,surface,face_edge,face_heads,face_tails,thrower\nthick,felt,190,412,398,me\n",
            "f.csv",
        )
        .unwrap();
        assert!(rows[0].of_shape());
        assert_eq!(rows[0].labels, ["edge", "heads", "tails"]);
        assert_eq!(rows[0].thrower, "me");
        let read = on_shape(&rows, &coin).unwrap();
        // The die's order, whatever the file's; the block its bounding box.
        assert_eq!(read[0].counts, [412, 398, 190]);
        assert_eq!(read[0].labels, ["heads", "tails", "edge"]);
        assert_eq!(
            read[0].group_names(),
            ["face heads", "face tails", "face edge"]
        );
        assert_eq!(read[0].n(), 1000);
        assert!((read[0].block.breadth - 0.024).abs() < 1e-12);
        assert!((read[0].block.length - 0.008).abs() < 1e-12);
        let refused = |text: &str, says: &str| {
            let rows = parse(text, "f.csv");
            let e = match rows {
                Ok(rows) => on_shape(&rows, &coin).unwrap_err().to_string(),
                Err(e) => e.to_string(),
            };
            assert!(e.contains(says), "{e} (wanted {says})");
            assert!(!e.contains('\n'), "{e}");
        };
        refused(
            "label,surface,face_heads,face_tails\nc,felt,1,2\n",
            "missing face_edge",
        );
        refused(
            "label,surface,face_heads,face_tails,face_edge,face_rim\nc,felt,1,2,3,4\n",
            "not its faces: face_rim",
        );
        refused(
            "label,surface,face_heads,face_tails,face_edge\nc,felt,1,x,3\n",
            "line 2, column 4 (face_tails): 'x' is not a count",
        );
        refused(
            "label,surface,face_heads,face_tails,face_edge\nc,felt,0,0,0\n",
            "column 3 (face_heads): no throws",
        );
        refused(
            "label,surface,face_\nc,felt,1\n",
            "line 1: a die of any shape",
        );
        refused(
            &format!("{HEAD}a,MDF,140,24,20,3d,0,361,639\n"),
            "row 'a': coin:24,8 is counted by its faces",
        );
    }

    #[test]
    fn a_die_column_names_each_rows_die_and_its_faces_are_the_cells_it_fills() {
        let rows = parse(
            "label,surface,die,face_1,face_2,face_3,face_4,face_5,face_6,face_7,face_8,thrower\n\
             a,felt,d6,1,2,3,4,5,6,,-,me\n\
             b,felt,d8,1,2,3,4,5,6,7,8,me\n\
             c,felt,,1,2,3,4,5,6,,,me\n",
            "f.csv",
        )
        .unwrap();
        assert_eq!(rows[0].die.as_deref(), Some("d6"));
        assert_eq!(rows[0].labels, ["1", "2", "3", "4", "5", "6"]);
        assert_eq!(rows[1].labels.len(), 8);
        assert_eq!(rows[1].n(), 36);
        assert_eq!(
            (rows[2].die.as_deref(), rows[2].thrower.as_str()),
            (None, "me")
        );
        // Read against its die: a d6's row is the d6's, and a face it lacks is refused.
        let d6 = crate::model::shape::named("d6", None).unwrap();
        assert_eq!(on_shape(&rows[..1], &d6).unwrap()[0].counts.len(), 6);
        let e = on_shape(&rows[1..2], &d6).unwrap_err().to_string();
        assert!(e.contains("not its faces: face_7, face_8"), "{e}");
        // A cell of a count column still says what is wrong, at its column.
        let e = parse("label,surface,die,face_1,face_2\na,felt,d6,1,x\n", "f.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2, column 5 (face_2)"), "{e}");
        assert!(is_die_file("v1.toml") && is_die_file("m/c.OBJ") && !is_die_file("coin:24.5,2"));
    }

    #[test]
    fn the_papers_rows_are_all_nineteen() {
        let rows = paper_rows().unwrap();
        assert_eq!(rows.len(), 19);
        assert_eq!(rows[6].label, "row 7");
        assert_eq!(rows[6].counts, [0, 361, 639]);
        assert_eq!(rows[18].surface, "Tough Carpet");
    }

    #[test]
    fn a_quoted_header_is_read_as_csv_and_counts_say_what_is_wrong() {
        // A header's names are CSV fields: quoted, with a comma or a quote in them.
        let rows = parse(
            "label,surface,\"face_a,b\",\"face_say \"\"c\"\"\"\n\"r, 1\",felt,3,4\n",
            "f.csv",
        )
        .unwrap();
        assert_eq!(rows[0].labels, ["a,b", "say \"c\""]);
        assert_eq!(rows[0].label, "r, 1");
        assert_eq!(rows[0].counts, [3, 4]);
        assert_eq!(count("170"), Ok(170));
        assert!(count("x")
            .unwrap_err()
            .contains("'x' is not a count (a whole number)"));
        assert!(count("-").unwrap_err().contains("is not a count"));
        for big in [
            "1234567890123456789012",
            "18446744073709551615",
            "1000000000001",
        ] {
            let e = count(big).unwrap_err();
            assert!(e.contains("too large"), "{e}");
        }
    }
}
