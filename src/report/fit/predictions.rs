//! A prediction's report: one block's lines for the terminal, and `predict --blocks`'s table,
//! CSV and figure.

use super::fitted::{discrepancy_text, predicted};
use crate::calibration::predict::{BlockPrediction, Predicted};
use crate::error::Result;
use crate::report::figures::fit::{self as fig, RowRatio};
use crate::report::figures::Point;
use std::fmt::Write;
use std::path::Path;

/// A prediction's lines for the terminal.
pub fn prediction_text(p: &BlockPrediction) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} {} on {} (thrower {}): {} posterior draws × {} rolls",
        p.shape.clone().unwrap_or_else(|| p.block.to_string()),
        p.mode.name(),
        p.surface,
        p.thrower,
        p.draws,
        p.rolls
    );
    for (name, v) in ["length", "breadth", "width"].iter().zip(&p.p) {
        let _ = writeln!(s, "  P({name} vertical)  {}", predicted(v));
    }
    if let (Some(r), Some(t)) = (p.ratio, p.theory_ratio) {
        let _ = writeln!(
            s,
            "  ratio breadth/width  {}   theory (MasterEqu) {t:.4}",
            predicted(&r)
        );
    }
    let faces = p.faces.as_deref().unwrap_or_default();
    let fair = 1.0 / faces.len().max(1) as f64;
    let n = faces.len();
    for (k, v) in faces.iter().enumerate() {
        let label = p
            .labels
            .get(k)
            .cloned()
            .unwrap_or_else(|| (k + 1).to_string());
        // Reliability round 5, class K: over an error of 0 (a face never or always up in
        // every draw) a departure in σ means nothing; it is not printed.
        let z = if v.err > 0.0 && v.err.is_finite() {
            format!("   {:+.1}σ from 1/{n}", (v.value - fair) / v.err)
        } else {
            format!("   (no error: not compared with 1/{n})")
        };
        let _ = writeln!(s, "  P(face {label} up)  {}{z}", predicted(v));
    }
    if p.unsettled > 0 {
        let _ = writeln!(
            s,
            "  {} rolls did not settle on a face (left out)",
            p.unsettled
        );
    }
    if let Some(x) = &p.extrapolation {
        let _ = writeln!(s, "  an extrapolation: {x}");
    }
    if p.overdispersion > 1.0 {
        let _ = writeln!(
            s,
            "  the fit misfits: its errors widened by its overdispersion φ = {:.2}, and counts \
             measured against this taken to scatter φ times the binomial's",
            p.overdispersion
        );
    }
    if let Some(why) = p.discrepancy.as_ref().and_then(|d| d.not_applied()) {
        let _ = writeln!(s, "  {why}");
    }
    if let Some(d) = p.discrepancy.as_ref().filter(|d| d.in_force()) {
        let lines: Vec<String> = d
            .outcomes
            .iter()
            .filter(|o| o.asked)
            .map(|o| format!("{}: {}", o.outcome, o.describe()))
            .collect();
        let _ = writeln!(
            s,
            "  the fit misses rows it did not see beyond their errors: each share moved along \
             its discrepancy's line on the log-odds and widened by it ({})",
            lines.join("; ")
        );
    }
    if let Some(o) = &p.other_die {
        let _ = writeln!(
            s,
            "  another die than the fit's ({o}): the fit's surface and throw, its own geometry and \
             mass"
        );
    }
    for t in &p.tests {
        let counts: Vec<String> = t
            .outcomes
            .iter()
            .zip(&t.counts)
            .map(|(o, c)| format!("{o} {c}"))
            .collect();
        let _ = writeln!(
            s,
            "  against the counts of {} ({}):\n{}",
            t.label,
            counts.join(", "),
            t.scores.lines("    ")
        );
    }
    s
}

/// `predict --blocks`: the table of every block's predicted probabilities and ratio, with its
/// measurement and z where the file has counts, and the χ² of the whole.
pub fn predictions_markdown(p: &crate::calibration::heldout::Predictions, stem: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Predictions from {}\n", p.fit);
    let _ = writeln!(s, "`{}`\n", p.command_line);
    if !p.rows.is_empty() {
        let _ = writeln!(
            s,
            "| row | block | surface | P(length) | P(breadth) | P(width) | ratio | theory | measured | z |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---:|---|---:|");
    }
    for r in &p.rows {
        let q = &r.prediction;
        let _ = writeln!(
            s,
            "| {} | {} {} | {} | {} | {} | {} | {} | {:.3} | {} | {} |",
            r.label,
            q.block,
            q.mode.name(),
            q.surface,
            short(&q.p[0]),
            short(&q.p[1]),
            short(&q.p[2]),
            short(&q.ratio.unwrap_or(Predicted::NONE)),
            q.theory_ratio.unwrap_or(f64::NAN),
            r.measured_ratio
                .map_or("–".into(), |m| format!("{:.3} ± {:.3}", m.value, m.err)),
            r.z.map_or("–".into(), |z| format!("{z:+.2}")),
        );
    }
    if let (Some(c), Some(d)) = (p.chi2, p.dof) {
        let _ = writeln!(
            s,
            "\nHeld-out test over the measured rows: Pearson's χ² = {c:.2} on {d} degrees of \
             freedom{} (each count's variance the multinomial's widened by the prediction's \
             error).",
            p.p_value.map_or(String::new(), |v| format!(", p = {v:.3}"))
        );
    }
    for d in &p.dice {
        let _ = writeln!(
            s,
            "\n## {} ({})\n\n```text\n{}```",
            d.label,
            d.die,
            prediction_text(&d.prediction)
        );
    }
    scores_section(&mut s, p);
    let first = p
        .rows
        .first()
        .map(|r| &r.prediction)
        .or(p.dice.first().map(|d| &d.prediction));
    if let Some(phi) = first.map(|q| q.overdispersion).filter(|&v| v > 1.0) {
        let _ = writeln!(
            s,
            "\nThe fit misfits: its overdispersion φ = {phi:.2} widens every prediction above, and \
             each measured count's variance is taken φ times the multinomial's."
        );
    }
    if let Some(t) = discrepancy_text(first.and_then(|q| q.discrepancy.as_ref())) {
        let _ = writeln!(s, "\n{t}");
    }
    let far: Vec<String> = p
        .rows
        .iter()
        .filter_map(|r| {
            r.prediction
                .extrapolation
                .as_ref()
                .map(|x| format!("{}: {x}", r.label))
        })
        .collect();
    if !far.is_empty() {
        let _ = writeln!(s, "\nExtrapolations:\n");
        for f in far {
            let _ = writeln!(s, "- {f}");
        }
    }
    if !p.rows.is_empty() {
        let _ = writeln!(s, "\n![{stem}]({stem}.svg)");
    }
    s
}

/// The proper scores of the measured rows, each row's and in total, beside the baselines'
/// (`calibration::proper`).
fn scores_section(s: &mut String, p: &crate::calibration::heldout::Predictions) {
    let Some(total) = &p.scores else { return };
    let _ = writeln!(
        s,
        "\n## Proper scores\n\nThe log predictive density of the counts (a Dirichlet-multinomial \
         whose mean is the prediction and whose scatter is its error's and the fit's \
         overdispersion's), Σz² with its degrees of freedom and the outcomes within 1σ and 2σ \
         (calibration), and the mean predicted σ against the counts' own (sharpness), beside \
         the uncalibrated default scene and the quasi-static theory where it applies.\n"
    );
    for r in &p.rows {
        if let Some(sc) = &r.scores {
            let _ = writeln!(s, "{}:\n\n{}", r.label, sc.lines("- "));
        }
    }
    for d in &p.dice {
        for t in &d.prediction.tests {
            let _ = writeln!(s, "{} ({}):\n\n{}", t.label, d.die, t.scores.lines("- "));
        }
    }
    let _ = writeln!(s, "All measured rows:\n\n{}", total.lines("- "));
}

/// A prediction as a table cell: value ± whole error.
fn short(p: &Predicted) -> String {
    format!("{:.4} ± {:.4}", p.value, p.err)
}

/// `predict --blocks-file`'s dice (a `die` column's) as CSV: one line an outcome of a row,
/// its predicted share and error beside its count.
pub fn dice_csv(p: &crate::calibration::heldout::Predictions) -> String {
    let mut s = String::from("label,die,outcome,p,p_err,count\n");
    let quote = |v: &str| {
        if v.contains([',', '"', '\n']) {
            format!("\"{}\"", v.replace('"', "\"\""))
        } else {
            v.to_string()
        }
    };
    for d in &p.dice {
        for t in &d.prediction.tests {
            for ((name, q), c) in t.outcomes.iter().zip(&t.predicted).zip(&t.counts) {
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{c}",
                    quote(&t.label),
                    quote(&d.die),
                    quote(name),
                    q.value,
                    q.err
                );
            }
        }
    }
    s
}

/// `predict --blocks`'s table as CSV: one row a block.
pub fn predictions_csv(p: &crate::calibration::heldout::Predictions) -> String {
    let mut s = String::from(
        "label,length_mm,breadth_mm,width_mm,mode,surface,thrower,p_length,p_length_err,\
         p_breadth,p_breadth_err,p_width,p_width_err,ratio,ratio_err,theory_ratio,\
         length_vertical,breadth_vertical,width_vertical,measured_ratio,measured_ratio_err,z,\
         chi2,dof,extrapolation\n",
    );
    let opt = |v: Option<String>| v.unwrap_or_default();
    let quote = |v: &str| {
        if v.contains([',', '"', '\n']) {
            format!("\"{}\"", v.replace('"', "\"\""))
        } else {
            v.to_string()
        }
    };
    for r in &p.rows {
        let q = &r.prediction;
        let b = q.block;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            quote(&r.label),
            b.length * 1000.0,
            b.breadth * 1000.0,
            b.width * 1000.0,
            q.mode.name(),
            quote(&q.surface),
            quote(&q.thrower),
            q.p[0].value,
            q.p[0].err,
            q.p[1].value,
            q.p[1].err,
            q.p[2].value,
            q.p[2].err,
            q.ratio.unwrap_or(Predicted::NONE).value,
            q.ratio.unwrap_or(Predicted::NONE).err,
            q.theory_ratio.unwrap_or(f64::NAN),
            opt(r.counts.map(|c| c[0].to_string())),
            opt(r.counts.map(|c| c[1].to_string())),
            opt(r.counts.map(|c| c[2].to_string())),
            opt(r.measured_ratio.map(|m| m.value.to_string())),
            opt(r.measured_ratio.map(|m| m.err.to_string())),
            opt(r.z.map(|z| z.to_string())),
            opt(r.chi2.map(|c| c.to_string())),
            opt(r.dof.map(|d| d.to_string())),
            quote(q.extrapolation.as_deref().unwrap_or("")),
        );
    }
    s
}

/// `predict --blocks`'s figure: each block's predicted ratio with its error, beside its
/// measurement (where counted) and the paper's theory.
pub fn predictions_figure(
    dir: &Path,
    stem: &str,
    p: &crate::calibration::heldout::Predictions,
) -> Result<()> {
    let rows: Vec<RowRatio> = p
        .rows
        .iter()
        .map(|r| RowRatio {
            label: r.label.clone(),
            measured: r.measured_ratio.map(|m| Point {
                x: 0.0,
                y: m.value,
                y_err: m.err,
            }),
            simulated: Point {
                x: 0.0,
                y: r.prediction.ratio.unwrap_or(Predicted::NONE).value,
                y_err: r.prediction.ratio.unwrap_or(Predicted::NONE).err,
            },
            theory: r.prediction.theory_ratio.map(|y| Point {
                x: 0.0,
                y,
                y_err: 0.0,
            }),
        })
        .collect();
    fig::rows(
        dir,
        stem,
        "Blocks predicted from the fit, beside their measurement and the theory",
        "predicted (posterior draws)",
        &rows,
    )
}
