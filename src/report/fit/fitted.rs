//! A fit's own report: `report.md`, its figures and its terminal lines.

use crate::calibration::crossval::ModelScore;
use crate::calibration::discrepancy::Discrepancy;
use crate::calibration::estimate::{Estimate, Identified, ParamFit, RangeEnd, MISFIT_P};
use crate::calibration::params::{FixedThrow, Kind};
use crate::calibration::predict::Predicted;
use crate::calibration::recovery::Recovery;
use crate::calibration::{FitResult, LOOSE, MAX_MORE_PASSES};
use crate::error::Result;
use crate::report::figures::fit::{self as fig, Profile, RowRatio};
use crate::report::figures::Point;
use crate::theory::stats;
use std::fmt::Write;
use std::path::Path;

pub(super) fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1000.0 || v.abs() < 0.01 {
        format!("{v:.3e}")
    } else {
        format!("{v:.3}")
    }
}

/// The fixed values of the kinds not free, as a sentence.
pub fn fixed_text(res: &FitResult) -> String {
    let m = &res.config.model;
    let mut parts = Vec::new();
    let f = m.fixed;
    if !m.is_free(Kind::E) {
        parts.push(format!("e = {}", f.e));
    }
    if !m.is_free(Kind::Mu) {
        parts.push(format!("μ = {}", f.mu));
    }
    if !m.is_free(Kind::Rolling) && f.rolling > 0.0 {
        parts.push(format!("rolling resistance {} mm", f.rolling));
    }
    if !m.is_free(Kind::Bounce) && f.bounce > 0.0 {
        parts.push(format!("bounce threshold {} m/s", f.bounce));
    }
    if !m.is_free(Kind::ContactTime) && f.contact_time > 0.0 {
        parts.push(format!("contact time {} ms", f.contact_time));
    }
    if !m.is_free(Kind::StaticRatio) && f.static_ratio != 1.0 {
        parts.push(format!("static friction {} × the sliding", f.static_ratio));
    }
    if !m.is_free(Kind::Kappa) {
        parts.push(match f.throw {
            FixedThrow::Paper => "the paper's throw".into(),
            FixedThrow::Hand(k) => format!("a hand's throw with κ = {k}"),
            FixedThrow::Tumble => "a tumble".into(),
            FixedThrow::Toss => "a hand's toss".into(),
            FixedThrow::Rest => "released at rest".into(),
            FixedThrow::HandToss(k) => format!("a hand's toss in a hand's directions, κ = {k}"),
            FixedThrow::Flip => "a flip".into(),
        });
    } else if matches!(f.throw, FixedThrow::Toss | FixedThrow::HandToss(_)) {
        parts.push("a hand's toss in a hand's directions (κ free)".into());
    }
    if !m.is_free(Kind::Spin) {
        parts.push(format!("spin scale {}", f.spin));
    }
    let die = &res.config.method.die.features;
    if let Some(c) = die.com {
        let free = [Kind::ComX, Kind::ComY, Kind::ComZ].map(|k| m.is_free(k));
        if free.iter().any(|x| !x) {
            let mm = |i: usize| {
                if free[i] {
                    "free".into()
                } else {
                    format!("{}", c[i] * 1000.0)
                }
            };
            parts.push(format!(
                "the die's centre of mass ({}, {}, {}) mm",
                mm(0),
                mm(1),
                mm(2)
            ));
        }
    }
    if let Some(p) = die.pips {
        let depth = if m.is_free(Kind::PipDepth) {
            "free".into()
        } else {
            format!("{}", p.depth * 1000.0)
        };
        parts.push(format!(
            "pips {} mm across, {depth} mm deep",
            p.diameter * 1000.0
        ));
    }
    if die.edge_radius > 0.0 {
        parts.push(format!("edges rounded to {} mm", die.edge_radius * 1000.0));
    }
    let shell = match (die.shell, m.is_free(Kind::Infill)) {
        (Some(s), false) => Some((s.wall, format!("{}", s.infill))),
        (s, true) => Some((
            s.map_or(crate::model::mass::DEFAULT_WALL, |s| s.wall),
            "free".into(),
        )),
        (None, false) => None,
    };
    if let Some((wall, infill)) = shell {
        parts.push(format!(
            "printed with a {} mm wall, infill {infill}",
            wall * 1000.0
        ));
    }
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join(", ")
    }
}

/// What a first pass of two prints: each parameter's maximum and profile 2σ interval (under
/// χ²'s bounds: the bootstrap's factor is the last pass's), from which the second pass's box
/// is drawn.
pub fn first_pass_text(res: &FitResult) -> String {
    let mut s = format!(
        "First pass of a fit ({} rolls; the second pass narrows its box from it):\n",
        res.cost.rolls
    );
    for p in &res.estimate.params {
        let _ = writeln!(
            s,
            "  {:<16} {:>9}   2σ {} – {}",
            p.name,
            num(p.value),
            num(p.two_sigma[0]),
            num(p.two_sigma[1])
        );
    }
    s
}

/// The report's parameters: each one's value and intervals, and what bounds them.
fn parameters(res: &FitResult) -> String {
    let e = &res.estimate;
    let mut s = String::new();
    let _ = writeln!(s, "## Parameters\n");
    let k = e.bartlett * e.overdispersion;
    let profiles = if k > 1.0 {
        format!(
            "Δ(−2 ln L) = {:.2} for 1σ, {:.2} for 2σ: χ²'s 1 and 4 times {}",
            k,
            4.0 * k,
            widened_by(e)
        )
    } else {
        "Δ(−2 ln L) = 1 for 1σ, 4 for 2σ".into()
    };
    let n = res.params.len();
    use crate::calibration::bootstrap::{bound_rank, region_delta, TWO_SIGMA};
    // The overdispersion's widening is said below, with the goodness of fit.
    let chi2 = region_delta(n, TWO_SIGMA);
    let own = e.region_delta / e.overdispersion;
    let sets = e.bootstrap.as_ref().map_or(0, |b| b.sets);
    let region = if e.bootstrap.is_none() || (own - chi2).abs() < 1e-9 * chi2 {
        "χ² at 95.45 %".to_string()
    } else {
        let which = match bound_rank(sets) {
            Some(k) => format!("the {k}th smallest Δ of the bootstrap's {sets} fits"),
            None => "the bootstrap's fits".into(),
        };
        format!(
            "χ²'s {chi2:.2} at 95.45 % {} {own:.2} by {which}, which rolled the design again",
            if own > chi2 {
                "widened to"
            } else {
                "narrowed to"
            }
        )
    };
    let _ = writeln!(
        s,
        "Maximum likelihood, with profile-likelihood intervals ({profiles}) inside the searched \
         range. The joint 2σ region of all {n} is Δ(−2 ln L) ≤ {:.2} ({region}).\n",
        e.region_delta
    );
    let _ = writeln!(s, "| parameter | range | fitted | 1σ | 2σ | |");
    let _ = writeln!(s, "|---|---|---:|---|---|---|");
    for p in &e.params {
        let r = p.param.range;
        let r = format!("{}–{}", num(r.lo), num(r.hi));
        let says = match p.identified {
            _ if p.asks_for_more.is_some() => asks_for_more(p),
            Identified::Cut if res.passes.len() > 2 => format!(
                "still cut: its maximum or 2σ region reaches an edge of the last pass's narrowed \
                 box, after {} more passes; the value is that box's, not the data's",
                res.passes.len() - 2
            ),
            // At the range's own end, not a box's: the range asked for bounds it.
            Identified::UpperBoundOnly | Identified::LowerBoundOnly => format!(
                "{}: the range's own end, not a narrowed box's (a wider --range, where the \
                 physics allows, shows where it ends)",
                p.identified.says()
            ),
            other => other.says().into(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} – {} | {} – {} | {} |",
            p.name,
            r,
            fitted(p),
            num(p.one_sigma[0]),
            num(p.one_sigma[1]),
            num(p.two_sigma[0]),
            num(p.two_sigma[1]),
            says
        );
    }
    let _ = write!(s, "{}", maxima_text(e));
    s
}

/// What widened the profiles' bounds: the Bartlett factor, the overdispersion, or both.
fn widened_by(e: &Estimate) -> String {
    match (e.bartlett > 1.0, e.overdispersion > 1.0) {
        (true, true) => format!(
            "the Bartlett factor {:.2} and the overdispersion {:.2}",
            e.bartlett, e.overdispersion
        ),
        (true, false) => format!("the Bartlett factor {:.2}", e.bartlett),
        _ => format!("the overdispersion {:.2}", e.overdispersion),
    }
}

/// A parameter's fitted value as the report prints it: a value at its range's end is marked as
/// the range's, not the data's.
fn fitted(p: &ParamFit) -> String {
    match p.asks_for_more {
        Some(end) => format!("{} (the range's {} end)", num(p.value), end.name()),
        None => num(p.value),
    }
}

/// What a parameter whose maximum lies on its range's own end says: the model asks for more.
fn asks_for_more(p: &ParamFit) -> String {
    let end = p.asks_for_more.map_or("", RangeEnd::name);
    format!(
        "**the model asks for more**: the likelihood still rises at the range's {end} end, so \
         the value is the range's, not the data's; widen `--range {}` where the physics allows, \
         or free what the model lacks (the throw: `--free spin`)",
        p.param.kind
    )
}

/// What the search's starts found: how many ended at each maximum; the islands of the region
/// (other maxima within its threshold), which its intervals span and its draws come from; or
/// the global maximum's margin over the next.
pub fn maxima_text(e: &Estimate) -> String {
    let mut s = String::new();
    let starts: usize = e.maxima.iter().map(|m| m.starts).sum();
    if e.maxima.len() > 1 {
        let _ = writeln!(
            s,
            "\nThe search's {starts} starts ended at {} distinct maxima (starts at each, best \
             first: {}).",
            e.maxima.len(),
            e.maxima
                .iter()
                .map(|m| m.starts.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let delta = |f: f64| format!("{:.2}", f - e.minus_two_ln_l);
    if !e.islands.is_empty() {
        let _ = writeln!(
            s,
            "The joint 2σ region is {} islands: the best maximum and {} more within its \
             threshold Δ(−2 ln L) ≤ {:.2} (at Δ {}). The intervals above span every island \
             that can reach them (each profile is also traced from the islands within 4 × \
             the Bartlett factor of the best, the nearest three), and the posterior draws, so \
             the predictions, come from each island in proportion to exp(−Δ/2).",
            e.islands.len() + 1,
            e.islands.len(),
            e.region_delta,
            e.islands
                .iter()
                .map(|m| delta(m.minus_two_ln_l))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let outside: Vec<String> = e
        .other_maxima
        .iter()
        .filter(|&&f| f - e.minus_two_ln_l > e.region_delta)
        .map(|&f| delta(f))
        .collect();
    if !outside.is_empty() {
        let _ = writeln!(
            s,
            "Other local maxima lie outside the region (Δ(−2 ln L) {}, above its {:.2}): the \
             region is the global maximum's, by that margin.",
            outside.join(", "),
            e.region_delta
        );
    }
    s
}

/// The passes a refined fit took: each one's box, rolls and estimate, the parameters its box
/// cut, and whether they settled (nothing for a fit of one pass).
fn passes(res: &FitResult) -> String {
    let mut s = String::new();
    if res.passes.len() < 2 {
        return s;
    }
    let _ = writeln!(
        s,
        "\n### Passes\n\nThe first pass simulates the whole ranges; the second, the box narrowed \
         to the first's 2σ intervals. A pass whose box cuts a parameter (its maximum or 2σ \
         interval on an edge of the box that is not its range's) is followed by one over a box \
         moved and widened on that side; one whose box is more than {LOOSE} times as wide as \
         its 2σ interval asks (until a box has been widened), by one over the box drawn around \
         that interval — at most \
         {MAX_MORE_PASSES} more, until a pass's estimate asks for the box it was rolled over. A \
         block whose parameters' ranges stay as they were is not rolled again, and each pass's \
         surrogates are fitted through the earlier passes' points inside its box as well.\n"
    );
    let _ = writeln!(s, "| pass | box | rolls | maximum | cut by its box |");
    let _ = writeln!(s, "|---:|---|---:|---|---|");
    for (i, p) in res.passes.iter().enumerate() {
        let bounds: Vec<String> = p
            .bounds
            .iter()
            .map(|b| format!("{} {}–{}", b.param, num(b.range.lo), num(b.range.hi)))
            .collect();
        let values: Vec<String> = p.values.iter().map(|&v| num(v)).collect();
        let cut: Vec<String> = p
            .cut
            .iter()
            .map(|c| {
                let side = match (c.lower, c.upper) {
                    (true, true) => "both edges",
                    (true, false) => "lower edge",
                    _ => "upper edge",
                };
                format!("{} ({side})", c.param)
            })
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            i + 1,
            bounds.join(", "),
            p.rolls,
            if values.is_empty() {
                "—".into()
            } else {
                values.join(", ")
            },
            if cut.is_empty() {
                "—".into()
            } else {
                cut.join(", ")
            }
        );
    }
    match &res.unresolved {
        Some(why) => {
            let _ = writeln!(
                s,
                "\n**Unresolved**: {why}. Rerun with more `--points` or `--point-rolls` (a \
                 surer surrogate), or with `--no-refine` (one pass over the whole `--range`)."
            );
        }
        None => {
            let widened = res.passes.iter().any(|p| !p.cut.is_empty());
            let _ = writeln!(
                s,
                "\nThe passes settled: pass {}'s {}.",
                res.passes.len(),
                if widened {
                    "box cuts no parameter (after a widening, the passes only widen)"
                } else {
                    "estimate asks for the box it was rolled over"
                }
            );
        }
    }
    s
}

/// `report.md` for a fit; `figures` are the stems written beside it.
pub(super) fn markdown(res: &FitResult, figures: &[&str]) -> String {
    let e = &res.estimate;
    let c = &res.config;
    let mut s = String::new();
    let _ = writeln!(s, "# Fit of the simulator to measured counts\n");
    let _ = writeln!(
        s,
        "`{}` — dicephys {}, {}.\n",
        res.command_line, res.dicephys_version, res.date_utc
    );
    let _ = writeln!(
        s,
        "Method: {} at dt = {} s, {} rows on {} {}, each simulated at {} parameter points × {} \
         rolls (seed {}); {} rolls in all ({} did not settle on a face and are left out), {:.0} s \
         wall, {:.0} s CPU. Fixed: {}.\n",
        c.method.engine,
        c.method.dt,
        c.rows.len(),
        res.designs.len(),
        match &c.method.die.shape {
            Some(shape) => format!("designs of {}", shape.name),
            None => "blocks".into(),
        },
        res.designs.first().map_or(0, |d| d.points.len()),
        c.design.rolls,
        c.seed,
        res.cost.rolls,
        res.cost.unsettled,
        res.cost.wall_s,
        res.cost.cpu_s,
        fixed_text(res),
    );
    if let Some(why) = &res.unresolved {
        let _ = writeln!(s, "**Unresolved**: {why} (the passes below).\n");
    }
    s += &parameters(res);
    s += &passes(res);
    s += &goodness_of_fit(e);
    if let Some(r) = &res.rolled {
        s += &rolled_line(r, e.overdispersion);
    }
    s += &left_out(res);
    let _ = writeln!(s, "\n## Surrogates\n");
    let _ = writeln!(
        s,
        "Each block's outcome probabilities as a polynomial multinomial logit in the free \
         parameters, fitted to its design's counts. Lack of fit: the deviance against its \
         degrees of freedom; a dispersion above 1 widens the surrogate's error by it.\n"
    );
    let _ = writeln!(
        s,
        "| block | degree | deviance / dof | lack-of-fit p | dispersion | not settled |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|");
    for d in &res.designs {
        let sg = &d.surrogate;
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} / {} | {:.3} | {:.2} | {} of {} |",
            c.method
                .die
                .shape
                .as_ref()
                .map_or_else(|| d.name(), |shape| shape.name.clone()),
            sg.degree,
            sg.deviance,
            sg.dof,
            sg.lack_of_fit_p(),
            sg.dispersion,
            d.unsettled,
            d.rolls
        );
    }
    if !figures.is_empty() {
        let _ = writeln!(s, "\n## Figures\n");
        for f in figures {
            let _ = writeln!(s, "![{f}]({f}.png)");
        }
    }
    s
}

/// The fit's estimate rolled: the model's own Pearson χ² at its values, beside the surrogate's.
fn rolled_line(r: &crate::calibration::rolled::Rolled, phi: f64) -> String {
    let p = match r.p_value {
        Some(p) if p >= 1e-3 => format!("p = {p:.3}"),
        Some(p) => format!("p = {p:.1e}"),
        None => "no degrees of freedom left".into(),
    };
    let mut s = format!(
        "\nRolled at the estimate ({} fresh throws a row): Pearson's χ² = {:.2} on {} degrees \
         of freedom, {p}, each count against the rolled share with the binomial error of the \
         counts and of the rolls, unwidened. The χ² above is the surrogate's, its errors widened \
         by the overdispersion φ = {phi:.2}: where the two part, the model at this estimate misses by \
         this one (the surrogate's own error may have moved the estimate, or hidden the miss).\n\n",
        r.rolls, r.chi2, r.dof
    );
    s += "| row | outcomes counted | rolled shares | χ² |\n|---|---|---|---:|\n";
    for row in &r.rows {
        let shares: Vec<String> = row.shares.iter().map(|q| format!("{q:.3}")).collect();
        let counts: Vec<String> = row.counts.iter().map(u64::to_string).collect();
        s += &format!(
            "| {} | {} | {} | {:.2} |\n",
            row.label,
            counts.join(", "),
            shares.join(", "),
            row.chi2
        );
    }
    s
}

/// The report's goodness of fit: Pearson's χ², the bootstrap's verdict, a misfit's widening,
/// and each row's counts against the fit.
fn goodness_of_fit(e: &Estimate) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "\n## Goodness of fit\n");
    let _ = writeln!(
        s,
        "Pearson's χ² = {:.2} on {} degrees of freedom (independent counts less free parameters), \
         p = {}. Each count's z is (measured − N p)/σ with σ the Dirichlet-multinomial's (the \
         binomial widened by the simulation's noise).\n",
        e.chi2,
        e.dof,
        match e.p_value {
            Some(p) => format!("{p:.3}"),
            None => "undefined (no degrees of freedom left)".into(),
        }
    );
    if let Some(b) = &e.bootstrap {
        let _ = writeln!(s, "{}\n", bootstrap_line(b, e.chi2));
    }
    if let Some(line) = misfit_line(e) {
        let _ = writeln!(s, "{line}\n");
    }
    let _ = writeln!(s, "| row | surface | outcome | counted | fitted p | z |");
    let _ = writeln!(s, "|---|---|---|---:|---|---:|");
    for r in &e.rows {
        let n: u64 = r.counts.iter().sum();
        for (g, name) in r.outcomes.iter().enumerate() {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} / {} | {:.4} ± {:.4} | {:+.2} |",
                r.label, r.surface, name, r.counts[g], n, r.p[g], r.p_err[g], r.z[g]
            );
        }
    }
    s
}

/// The rows of faces predicted without themselves: each row's outcomes and log score.
fn faces_table(s: &mut String, loo: &[crate::calibration::scores::LooRow]) {
    let _ = writeln!(s, "| row | surface | outcomes | log score |");
    let _ = writeln!(s, "|---|---|---:|---:|");
    for r in loo {
        let _ = writeln!(
            s,
            "| {}{} | {}{} | {} | {:.2} |",
            r.label,
            r.die.as_ref().map_or(String::new(), |d| format!(" ({d})")),
            r.surface,
            if r.alone { " (alone)" } else { "" },
            r.outcomes.len(),
            r.log_score
        );
    }
}

/// The report's rows each predicted by a fit of the others (none for a fit of fewer than
/// three rows).
fn left_out(res: &FitResult) -> String {
    let mut s = String::new();
    if res.loo.is_empty() {
        return s;
    }
    let score = ModelScore::of(
        "",
        "",
        res.params.len(),
        res.estimate.minus_two_ln_l,
        &res.loo,
    );
    let _ = writeln!(s, "\n## Each row predicted without itself\n");
    let dice = crate::calibration::dice::names(&res.config.rows).len();
    let who = if dice > 0 {
        format!(
            "Each die's rows predicted together by a fit of the other {} (leave one die out)",
            if dice == 2 {
                "die".to_string()
            } else {
                format!("{} dice", dice - 1)
            }
        )
    } else {
        format!(
            "Every row predicted by a fit of the other {} (leave one out)",
            res.loo.len() - 1
        )
    };
    let cell = |v: Option<String>| v.unwrap_or_else(|| "–".into());
    // Rows that count faces have no ratio and no end count: their scores say it all.
    if res.loo.iter().all(|r| r.ratio.is_none() && r.end.is_none()) {
        let _ = writeln!(
            s,
            "{who}, at that fit's posterior draws; the rows count faces (no ratio, no end count), \
             so each is judged by its proper scores (below). Summed log predictive probability \
             of the rows' counts: {:.1} — what `dicephys compare` sets this fit beside another \
             model's fit of the same counts by.\n",
            score.loo_log_score
        );
        faces_table(&mut s, &res.loo);
    } else {
        let _ = writeln!(
            s,
            "{who}, at that fit's posterior draws: its ratio N(breadth)/N(width) and its end \
             count (length vertical), each with the prediction's error (parameters and \
             simulation) combined with the measurement's. Ratios within 1σ: {} of {}, within \
             2σ: {} (a Gaussian error puts 68 % and 95 % there). Summed log predictive \
             probability of the rows' counts: {:.1} — what `dicephys compare` sets this fit \
             beside another model's fit of the same counts by.\n",
            score.within_one_sigma, score.rows_scored, score.within_two_sigma, score.loo_log_score
        );
        let _ = writeln!(
            s,
            "| row | surface | measured ratio | predicted | z | ends: counted | predicted P(length) | z | log score |"
        );
        let _ = writeln!(s, "|---|---|---|---|---:|---|---|---:|---:|");
        for r in &res.loo {
            let _ = writeln!(
                s,
                "| {}{} | {}{} | {} | {} | {} | {} | {} | {} | {:.2} |",
                r.label,
                r.die.as_ref().map_or(String::new(), |d| format!(" ({d})")),
                r.surface,
                if r.alone { " (alone)" } else { "" },
                cell(
                    r.measured_ratio
                        .map(|m| format!("{:.3} ± {:.3}", m.value, m.err))
                ),
                cell(r.ratio.map(|p| format!("{:.3} ± {:.3}", p.value, p.err))),
                cell(r.z.map(|z| format!("{z:+.2}"))),
                cell(r.end.map(|e| format!("{} / {}", e.counted, e.throws))),
                cell(
                    r.end
                        .map(|e| format!("{:.4} ± {:.4}", e.predicted.value, e.predicted.err))
                ),
                cell(r.end.map(|e| format!("{:+.2}", e.z))),
                r.log_score
            );
        }
    }
    let _ = write!(
        s,
        "\n{}\n",
        discrepancy_text(res.discrepancy.as_ref()).unwrap_or_else(|| {
            "The rows predicted without themselves miss within their errors: no discrepancy \
             widens a prediction from this fit."
                .into()
        })
    );
    s += &loo_scores_text(res);
    s
}

/// The leave-one-out rows' proper scores, each row's and in total, beside the baselines'.
fn loo_scores_text(res: &FitResult) -> String {
    let Some(total) = &res.loo_scores else {
        return String::new();
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n### Proper scores of the rows predicted without themselves\n\nEach row's log \
         predictive density (a Dirichlet-multinomial whose mean is the prediction and whose \
         scatter its error's), Σz² and the outcomes within 1σ and 2σ, and the mean predicted σ \
         against the counts' own; with the discrepancy a row's prediction takes from the other \
         rows' misses, and without; beside the uncalibrated default scene (the fit's fixed \
         values, {} rolls a row) and the quasi-static theory where it applies.\n",
        res.config.design.rolls * crate::calibration::scores::LOO_BASELINE_POINTS
    );
    for r in &res.loo {
        if let Some(sc) = &r.scores {
            let die = r.die.as_ref().map_or(String::new(), |d| format!(" ({d})"));
            let _ = writeln!(s, "{}{die}:\n\n{}", r.label, sc.lines("- "));
        }
    }
    // Each die's rows together, where there is a die of several rows to sum.
    if res.loo_dice.iter().any(|d| d.rows.len() > 1) {
        for d in &res.loo_dice {
            let _ = writeln!(
                s,
                "Die {} ({} rows, predicted by a fit of the other dice):\n\n{}",
                d.die,
                d.rows.len(),
                d.scores.lines("- ")
            );
        }
    }
    let _ = writeln!(s, "All rows:\n\n{}", total.lines("- "));
    s
}

/// What a fit's discrepancy says: which outcomes' rows, predicted without themselves, miss
/// beyond their errors, and by how much a prediction of a block the fit did not see is
/// widened. `None` where none does (or none was learnt: fewer than three rows).
pub fn discrepancy_text(d: Option<&Discrepancy>) -> Option<String> {
    let d = d.filter(|d| d.any())?;
    let asked: Vec<String> = d
        .outcomes
        .iter()
        .filter(|o| o.asked)
        .map(|o| {
            format!(
                "{} (Σz² {:.1} on {}, p {}: log-odds {})",
                o.outcome,
                o.chi2,
                o.rows,
                p_shown(o.p_value),
                o.describe()
            )
        })
        .collect();
    let judged = match (d.applied, d.held_out_gain) {
        (true, Some(g)) => format!(
            " Applied: with it, the rows predicted without themselves (each taking the line the \
             other rows' misses draw) score {g:+.2} nats of log score over without it."
        ),
        (true, None) => " Applied, not judged: too few rows to learn it without each.".into(),
        (false, Some(g)) if g <= 0.0 => format!(
            " **Not applied**: with it, the rows predicted without themselves score {g:+.2} nats \
             of log score over without it (`predict --discrepancy on` applies it)."
        ),
        (false, _) => " **Not applied** (`predict --discrepancy off`).".into(),
    };
    Some(format!(
        "**The model misses rows it did not see beyond their errors**, in {}: the rows \
         predicted without themselves say how far a block's log-odds are missed, as a line in \
         the predicted log-odds η with a spread τ about it beyond the counts' noise, and a \
         prediction of a block this fit did not see is moved along that line and widened by \
         the line's error there and τ (`err_model`) where that improved the rows' held-out \
         log score. A bias that differs from block to block is not extra scatter in the \
         counts: it does not shrink with the throws counted.{judged}",
        asked.join("; ")
    ))
}

/// The rows' measured ratio and the fit's, for [`fig::rows`].
pub fn row_ratios(res: &FitResult) -> Vec<RowRatio> {
    res.estimate
        .rows
        .iter()
        .filter_map(|r| {
            let b = r.outcomes.iter().position(|o| o == "breadth")?;
            let w = r.outcomes.iter().position(|o| o == "width")?;
            let m = stats::ratio(r.counts[b], r.counts[w]);
            let (pb, pw) = (r.p[b], r.p[w]);
            let err = ((r.p_err[b] / pw).powi(2) + (r.p_err[w] * pb / (pw * pw)).powi(2)).sqrt();
            Some(RowRatio {
                label: r.label.clone(),
                measured: Some(Point {
                    x: 0.0,
                    y: m.value,
                    y_err: m.err,
                }),
                simulated: Point {
                    x: 0.0,
                    y: pb / pw,
                    y_err: err,
                },
                theory: None,
            })
        })
        .collect()
}

/// Writes the fit's figures into `dir`; returns their stems.
pub(super) fn write_figures(dir: &Path, res: &FitResult) -> Result<Vec<&'static str>> {
    let profiles: Vec<Profile> = res
        .estimate
        .params
        .iter()
        .map(|p| Profile {
            name: p.name.clone(),
            points: p.profile.iter().map(|v| (v[0], v[1])).collect(),
            best: p.value,
            log: p.param.kind == Kind::Kappa,
        })
        .collect();
    let mut stems = Vec::new();
    if !profiles.is_empty() {
        fig::profiles(dir, "Profile likelihood of each parameter", &profiles)?;
        stems.push("fit_profiles");
    }
    let rows = row_ratios(res);
    if !rows.is_empty() {
        fig::rows(
            dir,
            "fit_rows",
            "Each row: measured against fitted",
            "fitted",
            &rows,
        )?;
        stems.push("fit_rows");
    }
    Ok(stems)
}

pub(super) fn predicted(p: &Predicted) -> String {
    let model = if p.err_model > 0.0 {
        format!(", discrepancy {:.4}", p.err_model)
    } else {
        String::new()
    };
    let moved = p
        .fit_value
        .map_or(String::new(), |f| format!("the fit's own {f:.4}; "));
    format!(
        "{:.4} ± {:.4} ({moved}parameters {:.4}, simulation {:.4}{model})",
        p.value, p.err, p.err_params, p.err_sim
    )
}

/// A p-value as the reports give one: three decimals, or two digits' exponent below 0.001.
fn p_shown(p: f64) -> String {
    if p >= 1e-3 {
        format!("{p:.3}")
    } else {
        format!("{p:.1e}")
    }
}

/// What the parametric bootstrap says of the fit's errors, in a sentence.
pub fn bootstrap_line(b: &crate::calibration::bootstrap::Bootstrap, chi2: f64) -> String {
    let sigma = (b.coverage * (1.0 - b.coverage) / b.sets as f64).sqrt();
    // The bound is the k-th smallest of the sets' Δ where there are enough of them: a new set
    // drawn as they were falls under it with probability k/(n + 1), not 95.45 % exactly.
    let stated = crate::calibration::bootstrap::bound_rank(b.sets)
        .map_or(95.45, |k| 100.0 * k as f64 / (b.sets + 1) as f64);
    format!(
        "Parametric bootstrap ({} data sets drawn from the fitted model and fitted back): χ² \
         at least the data's {chi2:.2} in a share p = {:.3} of them (their mean χ² {:.2}); the \
         joint 2σ region held the values they were drawn at in {:.1} % ± {:.1} % of as many \
         sets again (stated {stated:.2} %).",
        b.sets,
        b.chi2_p,
        b.chi2_mean,
        100.0 * b.coverage,
        100.0 * sigma
    )
}

/// What a fit that misfits says of its widening: the overdispersion, what it widens, and the
/// widened region's coverage on data drawn with it. `None` for a fit that fits.
pub fn misfit_line(e: &Estimate) -> Option<String> {
    let phi = e.overdispersion;
    if phi <= 1.0 {
        return None;
    }
    let b = e.bootstrap.as_ref()?;
    let mut line = format!(
        "**The model misfits** (p = {:.3}, below {MISFIT_P}): the counts scatter more than it \
         says, by the overdispersion φ = {phi:.2} (χ² {:.2} over the bootstrap's mean χ² {:.2}). \
         Every interval \
         above, the joint region and the posterior draws (so every prediction made from this \
         fit) are widened by it: each bound on Δ(−2 ln L) times φ, an interval by about √φ = \
         {:.2}. A parameter's value is then the least-bad compromise, not a measurement: what \
         the data ask for lies outside the model.",
        b.chi2_p,
        e.chi2,
        b.chi2_mean,
        phi.sqrt()
    );
    if let Some(w) = b.widened_coverage.map(|c| (c, b.sets)) {
        let sigma = (w.0 * (1.0 - w.0) / w.1 as f64).sqrt();
        let _ = write!(
            line,
            " Data sets drawn with that overdispersion and fitted back: the widened region held \
             their values in {:.1} % ± {:.1} % of {} (stated 95.45 %).",
            100.0 * w.0,
            100.0 * sigma,
            w.1
        );
    }
    Some(line)
}

/// A recovery check's lines for the terminal.
pub fn recovery_text(r: &Recovery) -> String {
    let n = r.repetitions.len();
    let covered = r.repetitions.iter().filter(|x| x.covered).count();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "recovery: {n} repetitions, {} rolls; the truth inside the joint 2σ region (Δ(−2 ln L) ≤ {:.2}) in {covered} of {n} ({:.0} %; stated 95.45 %)",
        r.rolls,
        r.region_delta,
        100.0 * r.coverage
    );
    let mean = r.repetitions.iter().map(|x| x.truth_delta).sum::<f64>() / n.max(1) as f64;
    let _ = writeln!(
        s,
        "  the truth's Δ(−2 ln L): mean {mean:.2} (χ² with {} degrees of freedom: {})",
        r.names.len(),
        r.names.len()
    );
    for (j, name) in r.names.iter().enumerate() {
        let vals: Vec<f64> = r.repetitions.iter().map(|x| x.values[j]).collect();
        let m = vals.iter().sum::<f64>() / vals.len().max(1) as f64;
        let sd = (vals.iter().map(|v| (v - m).powi(2)).sum::<f64>()
            / (vals.len().max(2) - 1) as f64)
            .sqrt();
        let _ = writeln!(
            s,
            "  {name}: truth {}, fitted {} ± {} (mean ± sd over repetitions), inside its 2σ interval in {:.0} %",
            num(r.truth[j]),
            num(m),
            num(sd),
            100.0 * r.interval_coverage[j]
        );
    }
    s
}

impl crate::report::Report for FitResult {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        Ok(crate::report::owned(write_figures(dir, self)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown(self, &crate::report::stems(stems))
    }
}
