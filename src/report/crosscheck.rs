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
    pub precision: Option<crate::report::summary::Reached>,
}

/// The report as `crosscheck` prints it: each engine's run, then a line per engine against
/// the baseline.
pub fn human(res: &Crosscheck) -> String {
    let mut s: String = res.runs.iter().map(RunSummary::human).collect();
    for v in &res.versus {
        s += &format!(
            "{} vs {}: {:+.1} σ apart; same outcome on {:.1} % of the {} throws both settled; CPU per roll {:.2}x\n",
            v.engine,
            v.baseline,
            v.z,
            100.0 * v.same_outcome_fraction,
            v.both_settled,
            v.cpu_ratio
        );
    }
    if let Some(p) = &res.precision {
        s += &format!("{} (the worst engine's)\n", p.line());
    }
    s
}
