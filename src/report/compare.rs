//! `dicephys compare`'s text: two models' fits of the same counts, each row's held-out log
//! score under each, and the decision.

use crate::calibration::compare::Comparison;
use std::fmt::Write;

/// The comparison as text: the two models' scores, the rows' gains, the verdict.
pub fn comparison_text(c: &Comparison) -> String {
    let mut s = String::new();
    let n = c.rows.len();
    let _ = writeln!(
        s,
        "Two models of the same {n} rows, each row predicted by a fit of the other {} \
         (leave one out):\n",
        n - 1
    );
    let _ = writeln!(
        s,
        "  {:<28} {:>6} {:>10} {:>16} {:>12}  file",
        "model (free)", "params", "−2 ln L", "held-out score", "ratio z ≤1σ/≤2σ"
    );
    for (m, file) in c.models.iter().zip(&c.files) {
        let _ = writeln!(
            s,
            "  {:<28} {:>6} {:>10.1} {:>16.1} {:>9}/{}/{}  {file}",
            m.name,
            m.params,
            m.minus_two_ln_l,
            m.loo_log_score,
            m.within_one_sigma,
            m.within_two_sigma,
            m.rows_scored
        );
    }
    let _ = writeln!(
        s,
        "\nEach row's held-out log score, {} less {}:",
        c.models[1].name, c.models[0].name
    );
    for r in &c.rows {
        let _ = writeln!(s, "  {:<20} {:+8.2}", r.label, r.gain);
    }
    let d = &c.decision;
    let _ = writeln!(
        s,
        "\nSummed: {:+.1} ± {:.1} (the error from the rows' scatter, √(n · var)).",
        d.score_gain, d.score_gain_err
    );
    if let Some((stat, dof, p)) = d.lr_test {
        let _ = writeln!(
            s,
            "On all rows, the likelihood ratio: −2 ln Λ = {stat:.1} on {dof}, p = {p:.3}."
        );
    }
    let _ = writeln!(s, "Verdict: {}.", d.verdict);
    s
}
