//! The theory for one block and the paper's whole table set against it, as reports: data
//! (serialisable, for `--json` and `paper`) and their text.

use serde::Serialize;
use std::io::Write;

use crate::error::Result;
use crate::model::block::Block;
use crate::theory::markov::MarkovChain;
use crate::theory::paper_data::{
    self, Discrepancy, Material, PaperRow, PrintedNumber, Set, Surface,
};
use crate::theory::stats::{self, Comparison, Ratio};
use crate::theory::{self, propagation};

// ---------------------------------------------------------------------------------------------
// --block

/// The block's sides, mm.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SidesMm {
    /// Length, mm.
    pub length_mm: f64,
    /// Breadth, mm.
    pub breadth_mm: f64,
    /// Width, mm.
    pub width_mm: f64,
}

/// The 2D theory: (MasterEqu) and (rattoprob).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Theory2d {
    /// P(breadth vertical)/P(width vertical) ± propagated error.
    pub ratio: Ratio,
    /// P(breadth vertical), equation (rattoprob).
    pub p_breadth_vertical: f64,
    /// P(width vertical), equation (rattoprob).
    pub p_width_vertical: f64,
    /// Propagated error of either probability (they sum to 1).
    pub p_err: f64,
}

/// The 2D no-bounce (Simpson) model: (InElasK).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct NoBounce2d {
    /// The no-bounce ratio P(breadth vertical)/P(width vertical).
    pub ratio: f64,
    /// P(breadth vertical) = (2/π) arctan R.
    pub p_breadth_vertical: f64,
    /// P(width vertical) = (2/π) arctan(1/R).
    pub p_width_vertical: f64,
}

/// The 3D Simpson model, per face pair.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Simpson3d {
    /// P(breadth vertical): resting on either length × width face.
    pub p_breadth_vertical: f64,
    /// P(width vertical): resting on either length × breadth face.
    pub p_width_vertical: f64,
    /// P(length vertical): standing on either end.
    pub p_length_vertical: f64,
}

/// The five-state Markov chain of figure (MarkovChainCompleate), with k = breadth and
/// l = width, absorbed exactly: its P(L)/P(K) is (MasterEquM1), the same as (MasterEqu)
/// whatever the settling rate γ in its valid range.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Markov2d {
    /// The γ·½mg used, 1/m: half the largest valid value for this block.
    pub gamma_half_mg: f64,
    /// P(K): ending in K-static.
    pub p_k: f64,
    /// P(L): ending in L-static.
    pub p_l: f64,
    /// P(L)/P(K), to set beside `theory_2d.ratio`.
    pub ratio: f64,
}

/// Everything `theory --block` reports.
#[derive(Clone, Debug, Serialize)]
pub struct BlockReport {
    /// The block's sides.
    pub block: SidesMm,
    /// The ± on breadth and width, mm, propagated into R and the 2D theory.
    pub tolerance_mm: f64,
    /// R = width/breadth ± propagated error.
    pub r: Ratio,
    /// The 2D theory, (MasterEqu) and (rattoprob).
    pub theory_2d: Theory2d,
    /// The 2D no-bounce model, (InElasK).
    pub no_bounce_2d: NoBounce2d,
    /// The 3D Simpson model.
    pub simpson_3d: Simpson3d,
    /// The 2D Markov chain the theory is derived from, absorbed exactly (absent if the
    /// chain cannot be built for these sides).
    pub markov_2d: Option<Markov2d>,
}

/// The predictions for one block, with side uncertainty `tolerance_mm` on breadth and width.
pub fn block_report(block: &Block, tolerance_mm: f64) -> BlockReport {
    let [length_mm, breadth_mm, width_mm] = block.mm();
    let p = propagation::propagate(breadth_mm, tolerance_mm, width_mm, tolerance_mm);
    let two = theory::SideProbabilities::from_ratio(p.ratio);
    // dP(K)/d ratio = −1/(1 + ratio)².
    let p_err = p.ratio_err / (1.0 + p.ratio).powi(2);
    let nb = theory::no_bounce_2d(p.r);
    let (simpson, _) = theory::simpson_3d(block);
    let markov_2d = {
        let (k, l) = (block.breadth, block.width);
        let g = 0.5 * MarkovChain::max_gamma_half_mg(k, l);
        MarkovChain::new(k, l, g)
            .and_then(|c| c.absorption())
            .ok()
            .map(|a| Markov2d {
                gamma_half_mg: g,
                p_k: a.p_k,
                p_l: a.p_l,
                ratio: a.ratio(),
            })
    };
    BlockReport {
        block: SidesMm {
            length_mm,
            breadth_mm,
            width_mm,
        },
        tolerance_mm,
        r: Ratio {
            value: p.r,
            err: p.r_err,
        },
        theory_2d: Theory2d {
            ratio: Ratio {
                value: p.ratio,
                err: p.ratio_err,
            },
            p_breadth_vertical: two.breadth_vertical,
            p_width_vertical: two.width_vertical,
            p_err,
        },
        no_bounce_2d: NoBounce2d {
            ratio: theory::no_bounce_ratio(p.r),
            p_breadth_vertical: nb.breadth_vertical,
            p_width_vertical: nb.width_vertical,
        },
        simpson_3d: Simpson3d {
            p_breadth_vertical: simpson.breadth_vertical,
            p_width_vertical: simpson.width_vertical,
            p_length_vertical: simpson.length_vertical,
        },
        markov_2d,
    }
}

/// Decimals to show a number: 3 (the paper's), more for small values so that three significant
/// digits show.
fn decimals(v: f64) -> usize {
    if !v.is_finite() || v == 0.0 || v.abs() >= 0.01 {
        return 3;
    }
    let lead = -v.abs().log10().floor() as usize; // 0.001.. → 3
    (lead + 2).clamp(3, 12)
}

fn pm(v: Ratio) -> String {
    let d = decimals(v.value);
    format!("{:.d$} ± {:.d$}", v.value, v.err)
}

/// Writes a `BlockReport` as aligned text, one quantity a line.
pub fn write_block(out: &mut impl Write, r: &BlockReport) -> std::io::Result<()> {
    let b = &r.block;
    let sides = Block::from_mm(b.length_mm, b.breadth_mm, b.width_mm)
        .map(|b| b.to_string())
        .unwrap_or_else(|_| format!("{}x{}x{}", b.length_mm, b.breadth_mm, b.width_mm));
    let t = &r.theory_2d;
    let nb = &r.no_bounce_2d;
    let s = &r.simpson_3d;
    let pd = decimals(t.p_breadth_vertical).max(4);
    let mut rows: Vec<(String, String)> = vec![
        (
            "block (L x B x W)".into(),
            format!("{sides} mm, sides ± {} mm", r.tolerance_mm),
        ),
        ("R = width/breadth".into(), pm(r.r)),
        ("2D theory (MasterEqu)".into(), String::new()),
        ("  ratio B/W vertical".into(), pm(t.ratio)),
        (
            "  P(breadth vertical)".into(),
            format!("{:.pd$} ± {:.pd$}", t.p_breadth_vertical, t.p_err),
        ),
        (
            "  P(width vertical)".into(),
            format!("{:.pd$} ± {:.pd$}", t.p_width_vertical, t.p_err),
        ),
        ("2D no bounce (InElasK)".into(), String::new()),
        (
            "  ratio B/W vertical".into(),
            format!("{:.*}", decimals(nb.ratio), nb.ratio),
        ),
        (
            "  P(breadth vertical)".into(),
            format!("{:.pd$}", nb.p_breadth_vertical),
        ),
        (
            "  P(width vertical)".into(),
            format!("{:.pd$}", nb.p_width_vertical),
        ),
        ("3D Simpson, per face pair".into(), String::new()),
        (
            "  P(breadth vertical)".into(),
            format!("{:.pd$}", s.p_breadth_vertical),
        ),
        (
            "  P(width vertical)".into(),
            format!("{:.pd$}", s.p_width_vertical),
        ),
        (
            "  P(length vertical)".into(),
            format!(
                "{:.*}",
                decimals(s.p_length_vertical).max(4),
                s.p_length_vertical
            ),
        ),
    ];
    if let Some(m) = &r.markov_2d {
        rows.push((
            "2D Markov chain (MasterEquM1)".into(),
            format!("γ·½mg = {:.4} /m, absorbed exactly", m.gamma_half_mg),
        ));
        rows.push((
            "  ratio P(L)/P(K)".into(),
            format!("{:.*}", decimals(m.ratio).max(4), m.ratio),
        ));
    }
    let w = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    for (k, v) in rows {
        if v.is_empty() {
            writeln!(out, "{k}")?;
        } else {
            writeln!(out, "{k:<w$}  {v}")?;
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// --table

/// The printed numbers of a row that the check recomputes.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct PrintedColumns {
    /// Printed R.
    pub r: PrintedNumber,
    /// Printed error on R.
    pub r_err: PrintedNumber,
    /// Printed prediction of (MasterEqu).
    pub predicted_ratio: PrintedNumber,
    /// Printed error on the prediction.
    pub predicted_ratio_err: PrintedNumber,
    /// Printed measured ratio N(breadth vertical)/N(width vertical).
    pub ratio: PrintedNumber,
    /// Printed binomial error on the measured ratio.
    pub ratio_err: PrintedNumber,
}

/// One row of the paper's table beside the theory.
#[derive(Clone, Debug, Serialize)]
pub struct TableRow {
    /// The row, 1-based, in the paper's order.
    pub row: usize,
    /// e.g. `140x24x20 MDF`.
    pub label: String,
    /// Length, mm.
    pub length_mm: f64,
    /// ± on the length, mm.
    pub length_err_mm: f64,
    /// Breadth, mm.
    pub breadth_mm: f64,
    /// ± on the breadth, mm.
    pub breadth_err_mm: f64,
    /// Width, mm.
    pub width_mm: f64,
    /// ± on the width, mm.
    pub width_err_mm: f64,
    /// The block's material.
    pub block: Material,
    /// The surface it was thrown onto.
    pub surface: Surface,
    /// The data set (the row's colour).
    pub set: Set,
    /// An uncoloured row: the same cross-section as the set's row above, another length.
    pub extra_length: bool,
    /// One of the five rows the paper simulated.
    pub simulated: bool,
    /// Throws counted.
    pub throws: u64,
    /// Throws that ended length vertical.
    pub length_vertical: u64,
    /// Throws that ended breadth vertical.
    pub breadth_vertical: u64,
    /// Throws that ended width vertical.
    pub width_vertical: u64,
    /// R from the dimensions, ± propagated from the row's side errors.
    pub r: Ratio,
    /// (MasterEqu) at R, ± propagated.
    pub theory_ratio: Ratio,
    /// N(breadth vertical)/N(width vertical) from the counts, ± binomial.
    pub measured_ratio: Ratio,
    /// (measured − theory)/sqrt(σ_measured² + σ_theory²); null if undefined.
    pub z: f64,
    /// (InElasK) ratio at R.
    pub no_bounce_ratio: f64,
    /// The row's printed numbers that the data check recomputes.
    pub printed: PrintedColumns,
}

/// A finding of the data check.
#[derive(Clone, Debug, Serialize)]
pub struct Finding {
    /// The row, 1-based.
    pub row: usize,
    /// e.g. `140x24x20 MDF`.
    pub label: String,
    /// The CSV column of the printed number, e.g. `ratio_err`.
    pub field: &'static str,
    /// The number as printed.
    pub printed: PrintedNumber,
    /// What the row's own data give for it.
    pub recomputed: f64,
    /// One line saying so (`Discrepancy::describe`).
    pub message: String,
}

impl From<&Discrepancy> for Finding {
    fn from(d: &Discrepancy) -> Finding {
        Finding {
            row: d.row,
            label: d.label.clone(),
            field: d.field,
            printed: d.printed,
            recomputed: d.recomputed,
            message: d.describe(),
        }
    }
}

/// χ² of one data set's measured ratios against the theory.
#[derive(Clone, Debug, Serialize)]
pub struct SetChiSquare {
    /// The data set.
    pub set: Set,
    /// Its rows, 1-based.
    pub rows: Vec<usize>,
    /// χ², the sum of z² over the rows used.
    pub chi2: f64,
    /// Degrees of freedom: the rows used (no fitted parameter).
    pub dof: usize,
    /// Rows left out because their z was not finite.
    pub skipped: usize,
    /// P(χ² at least this large | theory right).
    pub p_value: f64,
}

/// Everything `theory --table` reports.
#[derive(Clone, Debug, Serialize)]
pub struct TableReport {
    /// Where the table comes from: the paper and its table's title.
    pub source: &'static str,
    /// Every row of the paper's table, in its order.
    pub rows: Vec<TableRow>,
    /// Printed numbers the row's own data do not give.
    pub discrepancies: Vec<Finding>,
    /// Printed errors rounded up rather than to nearest: accepted, listed.
    pub errors_rounded_up: Vec<Finding>,
    /// χ² of the measured ratios against the theory, one per set.
    pub chi_square: Vec<SetChiSquare>,
}

fn table_row(row: &PaperRow) -> TableRow {
    let theory = row.theory();
    let measured = row.measured_ratio();
    TableRow {
        row: row.row,
        label: row.label(),
        length_mm: row.length_mm.value,
        length_err_mm: row.length_err_mm.value,
        breadth_mm: row.breadth_mm.value,
        breadth_err_mm: row.breadth_err_mm.value,
        width_mm: row.width_mm.value,
        width_err_mm: row.width_err_mm.value,
        block: row.block,
        surface: row.surface,
        set: row.set,
        extra_length: row.extra_length,
        simulated: row.simulated,
        throws: row.throws,
        length_vertical: row.length_vertical,
        breadth_vertical: row.breadth_vertical,
        width_vertical: row.width_vertical,
        r: Ratio {
            value: theory.r,
            err: theory.r_err,
        },
        theory_ratio: Ratio {
            value: theory.ratio,
            err: theory.ratio_err,
        },
        measured_ratio: measured,
        z: stats::z_score(measured.value, measured.err, theory.ratio, theory.ratio_err),
        no_bounce_ratio: theory::no_bounce_ratio(theory.r),
        printed: PrintedColumns {
            r: row.r,
            r_err: row.r_err,
            predicted_ratio: row.predicted_ratio,
            predicted_ratio_err: row.predicted_ratio_err,
            ratio: row.ratio,
            ratio_err: row.ratio_err,
        },
    }
}

/// The paper's table beside the theory, with the data check and χ² per set.
pub fn table_report() -> Result<TableReport> {
    let table = paper_data::load()?;
    let rows: Vec<TableRow> = table.rows.iter().map(table_row).collect();
    let chi_square = Set::ALL
        .into_iter()
        .map(|set| {
            let of_set: Vec<&TableRow> = rows.iter().filter(|r| r.set == set).collect();
            let comparisons: Vec<Comparison> = of_set
                .iter()
                .map(|r| Comparison {
                    measured: r.measured_ratio.value,
                    measured_err: r.measured_ratio.err,
                    predicted: r.theory_ratio.value,
                    predicted_err: r.theory_ratio.err,
                })
                .collect();
            let c = stats::chi_square(&comparisons);
            SetChiSquare {
                set,
                rows: of_set.iter().map(|r| r.row).collect(),
                chi2: c.chi2,
                dof: c.dof,
                skipped: c.skipped,
                p_value: c.p_value(),
            }
        })
        .collect();
    Ok(TableReport {
        source: "Pender & Uhrin (2014), Eur. J. Phys., table \"Full Experimental Data\"",
        rows,
        discrepancies: table.discrepancies.iter().map(Finding::from).collect(),
        errors_rounded_up: table.rounded_up.iter().map(Finding::from).collect(),
        chi_square,
    })
}

/// Writes a `TableReport` as text: the rows beside the theory, the data check, χ² per set.
pub fn write_table(out: &mut impl Write, t: &TableReport) -> std::io::Result<()> {
    writeln!(out, "{}", t.source)?;
    writeln!(
        out,
        "ratio = N(breadth vertical)/N(width vertical); theory (MasterEqu) ± from the printed \
         side errors; measured ± binomial; z = (measured − theory)/combined error; * = simulated \
         in the paper"
    )?;
    writeln!(
        out,
        "{:>3}  {:<19} {:<12} {:<6} {:>6} {:>5} {:>5} {:>5}  {:<13}  {:<13}  {:>6}  {:>9}",
        "row",
        "block (mm)",
        "surface",
        "set",
        "throws",
        "L",
        "B",
        "W",
        "theory",
        "measured",
        "z",
        "no bounce"
    )?;
    for r in &t.rows {
        let dims = Block::from_mm(r.length_mm, r.breadth_mm, r.width_mm)
            .map(|b| b.to_string())
            .unwrap_or_else(|_| format!("{}x{}x{}", r.length_mm, r.breadth_mm, r.width_mm));
        let mark = if r.simulated { "*" } else { " " };
        writeln!(
            out,
            "{:>3}{mark} {:<19} {:<12} {:<6} {:>6} {:>5} {:>5} {:>5}  {:<13}  {:<13}  {:>6.2}  {:>9.3}",
            r.row,
            dims,
            r.surface.name(),
            r.set.name(),
            r.throws,
            r.length_vertical,
            r.breadth_vertical,
            r.width_vertical,
            pm(r.theory_ratio),
            pm(r.measured_ratio),
            r.z,
            r.no_bounce_ratio,
        )?;
    }
    write_data_check(out, t)?;
    write_chi_square(out, t)
}

/// The data check: the discrepancies, and the printed errors rounded up.
fn write_data_check(out: &mut impl Write, t: &TableReport) -> std::io::Result<()> {
    writeln!(out)?;
    if t.discrepancies.is_empty() {
        writeln!(
            out,
            "data check: every printed number follows from the row's own data"
        )?;
    } else {
        let n = t.discrepancies.len();
        let noun = if n == 1 {
            "discrepancy"
        } else {
            "discrepancies"
        };
        writeln!(
            out,
            "data check: {n} {noun} (printed number not given by the row's own data)"
        )?;
        for d in &t.discrepancies {
            writeln!(out, "  {}", d.message)?;
        }
    }
    if !t.errors_rounded_up.is_empty() {
        writeln!(
            out,
            "printed errors rounded up, not to nearest (accepted as conservative):"
        )?;
        for field in ["ratio_err", "r_err", "predicted_ratio_err"] {
            let rows: Vec<String> = t
                .errors_rounded_up
                .iter()
                .filter(|d| d.field == field)
                .map(|d| d.row.to_string())
                .collect();
            if !rows.is_empty() {
                writeln!(out, "  {field}: rows {}", rows.join(", "))?;
            }
        }
    }
    Ok(())
}

/// χ² of measured against theory, per set.
fn write_chi_square(out: &mut impl Write, t: &TableReport) -> std::io::Result<()> {
    writeln!(out)?;
    writeln!(
        out,
        "chi-square of measured against theory, per set (no fitted parameter):"
    )?;
    for c in &t.chi_square {
        let rows: Vec<String> = c.rows.iter().map(|r| r.to_string()).collect();
        write!(
            out,
            "  {:<6}  chi2 = {:>7.2}  dof = {:>2}  p = {}  rows {}",
            c.set.name(),
            c.chi2,
            c.dof,
            fmt_p(c.p_value),
            rows.join(",")
        )?;
        if c.skipped > 0 {
            write!(
                out,
                "  ({} rows without a usable error left out)",
                c.skipped
            )?;
        }
        writeln!(out)?;
    }
    Ok(())
}

fn fmt_p(p: f64) -> String {
    if p >= 0.001 || p == 0.0 || !p.is_finite() {
        format!("{p:.3}")
    } else {
        format!("{p:.1e}")
    }
}
