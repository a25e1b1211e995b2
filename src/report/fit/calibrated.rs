//! `paper --calibrated`'s report: the paper's rows predicted by a fit of the others, the
//! models compared, the main fit and its check.

use super::fitted::{markdown, num, write_figures};
use crate::calibration::check::Verdict;
use crate::calibration::paper::CalibratedPaper;
use crate::error::Result;
use crate::report::figures::fit::{self as fig, RowRatio};
use crate::report::figures::Point;
use std::fmt::Write;
use std::path::Path;

/// `calibrated.md`: `paper --calibrated`'s report; `figures` are the stems written beside it.
fn calibrated_markdown(c: &CalibratedPaper, figures: &[&str]) -> String {
    let f = &c.fit;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# The paper's 19 rows, simulated with calibrated e, μ and throw\n"
    );
    let _ = writeln!(
        s,
        "`{}` — dicephys {}, {}. {} rolls in all ({:.0} s wall, {:.0} s CPU). Method: {} at dt \
         = {} s; each block simulated at {} parameter points × {} rolls per pass{}.\n",
        f.command_line,
        f.dicephys_version,
        f.date_utc,
        c.rolls,
        c.wall_s,
        c.cpu_s,
        f.config.method.engine,
        f.config.method.dt,
        f.config.design.points,
        f.config.design.rolls,
        if f.config.design.refine {
            ", two passes or more (the second over the box the first narrowed to, any later one \
             widening a box that cut a parameter or tightening one looser than its region)"
        } else {
            ""
        }
    );
    loo_section(&mut s, c);
    models_section(&mut s, c);
    main_fit_section(&mut s, c);
    check_section(&mut s, c);
    if !figures.is_empty() {
        let _ = writeln!(s, "\n## Figures\n");
        for f in figures {
            let _ = writeln!(s, "![{f}]({f}.png)");
        }
    }
    s
}

/// `calibrated.md`'s rows each predicted without itself, beside the theory.
fn loo_section(s: &mut String, c: &CalibratedPaper) {
    let f = &c.fit;
    let zs = |v: Vec<f64>| -> (usize, usize, usize) {
        let v: Vec<f64> = v.into_iter().filter(|z| z.is_finite()).collect();
        (
            v.iter().filter(|z| z.abs() <= 1.0).count(),
            v.iter().filter(|z| z.abs() <= 2.0).count(),
            v.len(),
        )
    };
    let sim = zs(c.loo.iter().filter_map(|r| r.z).collect());
    let theory = zs(c
        .loo
        .iter()
        .filter(|r| r.z.is_some())
        .filter_map(|r| c.theory.iter().find(|t| t.label == r.label).map(|t| t.z))
        .collect());
    let ends = zs(c.loo.iter().filter_map(|r| r.end.map(|e| e.z)).collect());
    let _ = writeln!(s, "## Each row predicted without itself\n");
    let _ = writeln!(
        s,
        "Every row is predicted by a fit of the other 18 (leave one out): its ratio \
         N(breadth vertical)/N(width vertical) with an error from the parameters' posterior and \
         from the simulation, against its measurement. On the same rows:\n"
    );
    let _ = writeln!(s, "| | within 1σ | within 2σ | rows |");
    let _ = writeln!(s, "|---|---:|---:|---:|");
    let _ = writeln!(
        s,
        "| calibrated simulator (leave one out) | {} | {} | {} |",
        sim.0, sim.1, sim.2
    );
    let _ = writeln!(
        s,
        "| the paper's theory (eq. MasterEqu) | {} | {} | {} |",
        theory.0, theory.1, theory.2
    );
    let _ = writeln!(
        s,
        "| simulator, end counts (length vertical; no theory) | {} | {} | {} |\n",
        ends.0, ends.1, ends.2
    );
    let _ = writeln!(
        s,
        "A Gaussian error would put 68 % of rows within 1σ and 95 % within 2σ. The theory's \
         error is its own (the sides' tolerances) combined with the measurement's; the \
         simulator's is the prediction's (parameters and simulation) combined with the \
         measurement's.\n"
    );
    if !c.single_row_surfaces.is_empty() {
        let _ = writeln!(
            s,
            "Surfaces with one row: {}. Left out, such a row leaves the fit nothing about its \
             surface: its e and μ are then drawn over their whole ranges, and its prediction's \
             error says so.\n",
            c.single_row_surfaces.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "| row | surface | block | measured ratio | predicted | z | theory | z | ends: counted | predicted P(length) | z |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---:|---|---:|---|---|---:|");
    for (r, row) in c.loo.iter().zip(&f.config.rows) {
        let t = c.theory.iter().find(|t| t.label == r.label);
        let cell = |v: Option<String>| v.unwrap_or_else(|| "–".into());
        let _ = writeln!(
            s,
            "| {} | {}{} | {} {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.label,
            r.surface,
            if r.alone { " (alone)" } else { "" },
            row.block,
            row.mode.name(),
            cell(
                r.measured_ratio
                    .map(|m| format!("{:.3} ± {:.3}", m.value, m.err))
            ),
            cell(r.ratio.map(|p| format!("{:.3} ± {:.3}", p.value, p.err))),
            cell(r.z.map(|z| format!("{z:+.2}"))),
            cell(t.map(|t| format!("{:.3} ± {:.3}", t.ratio.value, t.ratio.err))),
            cell(t.map(|t| format!("{:+.2}", t.z))),
            cell(r.end.map(|e| format!("{} / {}", e.counted, e.throws))),
            cell(
                r.end
                    .map(|e| format!("{:.4} ± {:.4}", e.predicted.value, e.predicted.err))
            ),
            cell(r.end.map(|e| format!("{:+.2}", e.z))),
        );
    }
}

/// `calibrated.md`'s models compared, and the decisions they make.
fn models_section(s: &mut String, c: &CalibratedPaper) {
    let _ = writeln!(s, "\n## Which model the data need\n");
    let _ = writeln!(
        s,
        "Each model fitted to all rows (−2 ln L, AIC) and scored on the rows it did not see (the \
         sum of the leave-one-out log predictive probabilities; higher is better). 2D rows \
         cannot land on an end, so models that differ in 2D and 3D are compared on the side \
         outcomes only.\n"
    );
    let _ = writeln!(
        s,
        "| model | what | free | −2 ln L | AIC | LOO log score | LOO log score, sides | rows within 1σ / 2σ |"
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---|");
    for m in &c.models {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {} / {} of {} |",
            m.name,
            m.description,
            m.params,
            m.minus_two_ln_l,
            m.aic,
            m.loo_log_score,
            m.loo_side_log_score,
            m.within_one_sigma,
            m.within_two_sigma,
            m.rows_scored
        );
    }
    let _ = writeln!(s);
    for d in &c.decisions {
        let lr = d.lr_test.map_or(String::new(), |(stat, dof, p)| {
            format!(
                " Likelihood ratio: −2 ln Λ = {stat:.1} on {dof} degrees of freedom, p = {p:.3}."
            )
        });
        let _ = writeln!(s, "- **{}** {}.{}", d.question, d.verdict, lr);
    }
}

/// `calibrated.md`'s main model fitted to all rows (the fit's own report, less its title).
fn main_fit_section(s: &mut String, c: &CalibratedPaper) {
    let f = &c.fit;
    let _ = writeln!(s, "\n## The main model's fit (all rows)\n");
    let inner = markdown(f, &[]);
    // The fit's own report, less its title and provenance (said above).
    if let Some(at) = inner.find("## Parameters") {
        let _ = write!(s, "{}", inner[at..].replace("\n## ", "\n### "));
    }
    if let Some(mu) = f.estimate.params.iter().find(|p| p.name == "mu[MDF]") {
        let _ = writeln!(
            s,
            "\nThe paper measured the printed blocks' friction on MDF on an inclined board: \
             dynamic μ = 0.29 ± 0.01, static 0.50 ± 0.03 (its appendix). The fit gives μ[MDF] = \
             {} (2σ {} – {}), from the outcome counts alone.",
            num(mu.value),
            num(mu.two_sigma[0]),
            num(mu.two_sigma[1])
        );
    }
}

/// `calibrated.md`'s method checked at the fitted values against a finer step.
fn check_section(s: &mut String, c: &CalibratedPaper) {
    let ck = &c.check;
    let _ = writeln!(s, "\n## The method at the fitted values\n");
    let _ = writeln!(
        s,
        "Each block rolled at its fitted e, μ and κ by the fit's method (dt = {} s) and by a \
         reference at dt = {} s, on the same throws; the departures, paired throw by throw, \
         against the data's binomial error on that block. Within: |departure| + 2σ below the \
         data's error for both probabilities; outside: |departure| − 2σ above it for one; \
         unresolved: neither, the check's own error too wide (with the rolls that would resolve \
         it were the departures to stay where they are). {}\n",
        ck.dt,
        ck.reference_dt,
        {
            let n = |v: fn(&Verdict) -> bool| ck.blocks.iter().filter(|b| v(&b.verdict())).count();
            format!(
                "Of {} blocks: {} within, {} outside, {} unresolved.",
                ck.blocks.len(),
                n(|v| *v == Verdict::Within),
                n(|v| *v == Verdict::Outside),
                n(|v| matches!(v, Verdict::Unresolved(_)))
            )
        }
    );
    let _ = writeln!(
        s,
        "| block | rolls | P(breadth) departure | P(length) departure | data's error | verdict |"
    );
    let _ = writeln!(s, "|---|---:|---|---|---:|---|");
    for b in &ck.blocks {
        let _ = writeln!(
            s,
            "| {} {} | {} | {:+.4} ± {:.4} | {:+.4} ± {:.4} | {:.4} | {} |",
            b.block,
            b.mode.name(),
            b.rolls,
            b.breadth.value,
            b.breadth.err,
            b.length.value,
            b.length.err,
            b.data_err,
            match b.verdict() {
                Verdict::Within => "within".to_string(),
                Verdict::Outside => "**outside**".to_string(),
                Verdict::Unresolved(Some(n)) => format!("unresolved (~{n} rolls would resolve it)"),
                Verdict::Unresolved(None) => {
                    "unresolved (a departure is at the data's error)".to_string()
                }
            }
        );
    }
}

/// Writes `paper --calibrated`'s figures into `dir`; returns their stems.
fn write_calibrated_figures(dir: &Path, c: &CalibratedPaper) -> Result<Vec<&'static str>> {
    let rows: Vec<RowRatio> = c
        .loo
        .iter()
        .filter_map(|r| {
            let m = r.measured_ratio?;
            let p = r.ratio?;
            let t = c.theory.iter().find(|t| t.label == r.label)?;
            Some(RowRatio {
                label: r.label.clone(),
                measured: Some(Point {
                    x: 0.0,
                    y: m.value,
                    y_err: m.err,
                }),
                simulated: Point {
                    x: 0.0,
                    y: p.value,
                    y_err: p.err,
                },
                theory: Some(Point {
                    x: 0.0,
                    y: t.ratio.value,
                    y_err: t.ratio.err,
                }),
            })
        })
        .collect();
    fig::rows(
        dir,
        "calibrated_rows",
        "The paper's rows: measured, predicted without each row, and the theory",
        "calibrated simulator (leave one out)",
        &rows,
    )?;
    let mut stems = vec!["calibrated_rows"];
    stems.extend(write_figures(dir, &c.fit)?);
    Ok(stems)
}

impl crate::report::Report for CalibratedPaper {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        Ok(crate::report::owned(write_calibrated_figures(dir, self)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        calibrated_markdown(self, &crate::report::stems(stems))
    }
}
