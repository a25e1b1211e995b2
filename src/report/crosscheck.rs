//! `crosscheck`'s results and report: the same throws on several engines, each engine's run
//! and each against the baseline (the study: `studies::crosscheck`). It writes no files: its
//! report is what it prints.

use crate::engine::EngineKind;
use crate::report::summary::RunSummary;
use serde::Serialize;

/// One engine against the baseline, on identical throws.
#[derive(Clone, Debug, Serialize)]
pub struct Versus {
    /// The engine compared.
    pub engine: EngineKind,
    /// The baseline engine.
    pub baseline: EngineKind,
    /// (ratio − baseline ratio) / combined binomial error.
    pub z: f64,
    /// Throws both engines settled: how many, and the fraction of them with the same outcome.
    pub both_settled: u64,
    /// Same outcome over the throws both settled.
    pub same_outcome_fraction: f64,
    /// This engine's CPU time per roll over the baseline's.
    pub cpu_ratio: f64,
    /// Every outcome compared (a die's faces; a block's sides): the two engines' counts
    /// against their common proportions.
    pub outcomes: OutcomesCompared,
}

/// Two runs' outcome counts compared: Pearson's χ² of homogeneity over the outcomes either
/// saw, and each outcome's difference in probability in σ.
#[derive(Clone, Debug, Serialize)]
pub struct OutcomesCompared {
    /// χ².
    pub chi2: f64,
    /// Its degrees of freedom: the outcomes either engine saw, less one.
    pub dof: usize,
    /// Its p-value.
    pub p_value: f64,
    /// Each outcome: its name, the two probabilities and (p − p_baseline) in σ of their
    /// difference.
    pub each: Vec<OutcomeCompared>,
}

/// One outcome of two runs.
#[derive(Clone, Debug, Serialize)]
pub struct OutcomeCompared {
    /// The face's label, or the side ("breadth", "width", "length").
    pub outcome: String,
    /// Its probability on the engine compared.
    pub p: f64,
    /// On the baseline.
    pub p_baseline: f64,
    /// (p − p_baseline) / the pooled binomial error of the difference.
    pub z: f64,
}

/// A run's outcomes by name: a die of any shape's faces, a made cube's six faces (when
/// every settled roll's face is known), else the block's sides.
pub fn outcome_counts(r: &RunSummary) -> Vec<(String, u64)> {
    if let Some(f) = crate::report::shape_outcomes::shape_faces(&r.tally, &r.spec.scene) {
        return f;
    }
    if let (Some(f), false) = (&r.faces, r.spec.scene.features.plain()) {
        return f.iter().map(|(k, v)| (k.clone(), *v)).collect();
    }
    let c = &r.counts;
    vec![
        ("breadth".into(), c.breadth),
        ("width".into(), c.width),
        ("length".into(), c.length),
    ]
}

impl OutcomesCompared {
    /// `run` against `baseline`, outcome by outcome (by name).
    pub fn of(run: &RunSummary, baseline: &RunSummary) -> OutcomesCompared {
        let (a, b) = (outcome_counts(run), outcome_counts(baseline));
        let (na, nb) = (
            a.iter().map(|x| x.1).sum::<u64>() as f64,
            b.iter().map(|x| x.1).sum::<u64>() as f64,
        );
        let (mut chi2, mut seen) = (0.0, 0usize);
        let mut each = Vec::new();
        for (name, x) in &b {
            let y = a.iter().find(|(n, _)| n == name).map_or(0, |v| v.1);
            let (x, y) = (*x as f64, y as f64);
            let p = (x + y) / (na + nb);
            if p == 0.0 || na == 0.0 || nb == 0.0 {
                continue;
            }
            seen += 1;
            chi2 += (y - p * na).powi(2) / (p * na) + (x - p * nb).powi(2) / (p * nb);
            let err = (p * (1.0 - p) * (1.0 / na + 1.0 / nb)).sqrt();
            let (pa, pb) = (y / na, x / nb);
            each.push(OutcomeCompared {
                outcome: name.clone(),
                p: pa,
                p_baseline: pb,
                z: if err > 0.0 { (pa - pb) / err } else { 0.0 },
            });
        }
        let dof = seen.saturating_sub(1);
        OutcomesCompared {
            chi2,
            dof,
            p_value: crate::theory::stats::chi_square_p_value(chi2, dof),
            each,
        }
    }

    /// The outcomes more than 3σ apart, as "name +z σ".
    pub fn differing(&self) -> Vec<String> {
        self.each
            .iter()
            .filter(|o| o.z.abs() > 3.0)
            .map(|o| {
                format!(
                    "{} {:+.1}σ ({:.4} against {:.4})",
                    o.outcome, o.z, o.p, o.p_baseline
                )
            })
            .collect()
    }
}

/// The whole cross-check.
#[derive(Clone, Debug, Serialize)]
pub struct Crosscheck {
    /// Each engine's run, baseline first.
    pub runs: Vec<RunSummary>,
    /// Each other engine against the baseline.
    pub versus: Vec<Versus>,
    /// With --precision: asked, reached (the worst engine's) and the rolls each engine made.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub precision: Option<crate::report::precision::Reached>,
}

/// The report as `crosscheck` prints it: each engine's run, then a line per engine against
/// the baseline.
pub fn human(res: &Crosscheck) -> String {
    let mut s: String = res.runs.iter().map(RunSummary::human).collect();
    for v in &res.versus {
        let ratio = if v.z.is_finite() {
            format!("ratio {:+.1} σ apart; ", v.z)
        } else {
            String::new()
        };
        s += &format!(
            "{} vs {}: {ratio}same outcome on {:.1} % of the {} throws both settled; CPU per roll {:.2}x\n",
            v.engine,
            v.baseline,
            100.0 * v.same_outcome_fraction,
            v.both_settled,
            v.cpu_ratio
        );
        let o = &v.outcomes;
        let differ = o.differing();
        s += &format!(
            "  every outcome: χ² {:.1} on {} degrees of freedom, p {:.3}; more than 3σ apart: {}\n",
            o.chi2,
            o.dof,
            o.p_value,
            if differ.is_empty() {
                "none".to_string()
            } else {
                differ.join(", ")
            }
        );
    }
    if let Some(p) = &res.precision {
        s += &format!("{} (the worst engine's)\n", p.line());
    }
    s
}
