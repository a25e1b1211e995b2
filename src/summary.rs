//! A run's result as it is reported: configuration, exact counts, the ratio with its error,
//! the theory beside it, and what it cost.

use crate::batch::{Counts, Tally};
use crate::engine::EngineKind;
use crate::roll::{Rule, Settle};
use crate::scene::Scene;
use crate::throws::{ThrowKind, ThrowRanges};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunSummary {
    pub engine: String,
    pub engine_version: String,
    pub preset: String,
    pub block_mm: [f64; 3],
    pub mode: String,
    pub rolls: u64,
    pub seed: u64,
    pub throws: ThrowKind,
    pub ranges: ThrowRanges,
    pub dt: f64,
    pub friction: f64,
    pub restitution: f64,
    pub density: f64,
    pub floor: String,
    pub max_steps: u64,
    /// What ended each roll: DicePhys's rest rule or the energy certificate.
    pub settle: Rule,
    pub counts: Counts,
    pub unconverged: u64,
    pub failed: BTreeMap<String, u64>,
    pub failed_total: u64,
    /// Rolls in which the engine injected energy: kinetic + potential rose above its lowest
    /// value so far by more than `energy_gain_tolerance` of the starting energy. A flag on
    /// rolls of any fate, not a failure.
    #[serde(default)]
    pub energy_gain: u64,
    #[serde(default)]
    pub energy_gain_tolerance: f64,
    /// Rolls whose die's centre went below the floor's top face at some step, whatever their
    /// fate: a flag, not a failure (`roll::Dip`).
    #[serde(default)]
    pub dipped: u64,
    /// The deepest any point of a die went below the floor's top face, over all rolls, m.
    #[serde(default)]
    pub deepest_dip_m: f64,
    /// A centre below the top face for more steps in a row than this is a die through the
    /// floor (`roll::MAX_DIP_STEPS`).
    #[serde(default)]
    pub max_dip_steps: u64,
    /// N(breadth vertical) / N(width vertical), the paper's ratio.
    pub ratio: f64,
    /// The paper's binomial error of the ratio.
    pub ratio_err: f64,
    /// The 2D theory's ratio (eq. MasterEqu) for this block.
    pub theory_ratio: f64,
    /// (ratio − theory) / ratio_err.
    pub z_theory: f64,
    pub steps_total: u64,
    pub steps_mean: f64,
    /// Steps the engine took per roll (below steps_mean where free flight was coasted).
    pub engine_steps_mean: f64,
    pub fast_flight: bool,
    pub wall_s: f64,
    pub cpu_s: f64,
    pub cpu_ms_per_roll: f64,
    pub threads: usize,
    pub dicephys_version: String,
    /// The run's result-defining arguments (as `merge` compares them), when run from the
    /// command line.
    pub args: Vec<String>,
    /// This run's share of the throws, `k` of `n` (indices ≡ k mod n).
    pub shard: Option<Shard>,
    /// Stopped before all rolls were made (Ctrl-C): the counts cover `rolls` only.
    pub partial: bool,
    /// The exact integer tally, for `merge`.
    pub tally: Tally,
    /// Present when auditing the early stop (`--audit`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub audit: Option<Audit>,
}

/// A share of a run's throws: indices i with i mod n = k.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub k: u64,
    pub n: u64,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("shard '{s}' is not K/N with 0 <= K < N");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (k, n): (u64, u64) = (k.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
        if n == 0 || k >= n {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }
}

/// How the energy certificate would have done on these rolls.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Audit {
    pub margin: f64,
    /// Rolls on which it fired before DicePhys's rule stopped them.
    pub certified: u64,
    /// Of those, rolls that came to rest on another face than the one it named.
    pub wrong: u64,
    /// Of those, rolls the full settle left "unknown" (stopped tilted, mid-rock).
    #[serde(default)]
    pub full_settle_unknown: u64,
    /// Mean step at which it fired, over the rolls it fired on.
    pub certified_steps_mean: f64,
    /// Mean steps of the full settle.
    pub full_steps_mean: f64,
}

impl RunSummary {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        engine: EngineKind,
        scene: &Scene,
        seed: u64,
        throws: ThrowKind,
        ranges: &ThrowRanges,
        settle: &Settle,
        tally: &Tally,
        wall_s: f64,
        cpu_s: f64,
        threads: usize,
    ) -> RunSummary {
        let r = crate::stats::ratio(tally.counts.breadth, tally.counts.width);
        let (ratio, ratio_err) = (r.value, r.err);
        let theory_ratio = crate::theory::ratio_from_r(scene.block.r());
        RunSummary {
            engine: engine.name().into(),
            engine_version: engine.version(),
            preset: scene.preset.name().into(),
            block_mm: scene.block.mm(),
            mode: scene.mode.name().into(),
            rolls: tally.rolls,
            seed,
            throws,
            ranges: *ranges,
            dt: scene.dt,
            friction: scene.friction,
            restitution: scene.restitution,
            density: scene.density,
            floor: format!("{:?}", scene.floor).to_lowercase(),
            max_steps: settle.max_steps,
            settle: settle.rule,
            counts: tally.counts.clone(),
            unconverged: tally.unconverged,
            failed: tally.failed.clone(),
            failed_total: tally.failed_total(),
            energy_gain: tally.energy_gain,
            energy_gain_tolerance: crate::roll::ENERGY_GAIN_TOLERANCE,
            dipped: tally.dipped,
            deepest_dip_m: tally.deepest_dip_m(),
            max_dip_steps: crate::roll::MAX_DIP_STEPS,
            ratio,
            ratio_err,
            theory_ratio,
            z_theory: (ratio - theory_ratio) / ratio_err,
            steps_total: tally.steps,
            steps_mean: tally.steps as f64 / tally.rolls.max(1) as f64,
            engine_steps_mean: tally.engine_steps as f64 / tally.rolls.max(1) as f64,
            fast_flight: settle.fast_flight,
            wall_s,
            cpu_s,
            cpu_ms_per_roll: 1000.0 * cpu_s / tally.rolls.max(1) as f64,
            threads,
            dicephys_version: env!("CARGO_PKG_VERSION").into(),
            args: Vec::new(),
            shard: None,
            partial: false,
            tally: tally.clone(),
            audit: settle.audit.then(|| Audit {
                margin: settle.margin,
                certified: tally.certified,
                wrong: tally.certified_wrong,
                full_settle_unknown: tally.certified_unknown,
                certified_steps_mean: tally.certified_steps as f64 / tally.certified.max(1) as f64,
                full_steps_mean: tally.steps as f64 / tally.rolls.max(1) as f64,
            }),
        }
    }

    /// The human summary: counts, the ratio with its error, theory and σ, failures, cost.
    pub fn human(&self) -> String {
        let c = &self.counts;
        let mut s = String::new();
        if self.partial {
            s += "PARTIAL: stopped before all rolls were made; the counts cover these rolls only\n";
        }
        s += &format!(
            "{} {} {} mm, {} rolls, {} throws seed {}, dt {} s, μ {}, e {}, preset {}, floor {}\n",
            self.engine,
            self.mode,
            crate::block::Block::from_mm(self.block_mm[0], self.block_mm[1], self.block_mm[2])
                .map(|b| b.to_string())
                .unwrap_or_default(),
            self.rolls,
            self.throws.name(),
            self.seed,
            self.dt,
            self.friction,
            self.restitution,
            self.preset,
            self.floor
        );
        s += &format!(
            "  breadth vertical {:>8}   width vertical {:>8}   length vertical {:>6}   unknown {:>6}\n",
            c.breadth, c.width, c.length, c.unknown
        );
        s += &format!(
            "  ratio breadth/width  {:.4} ± {:.4}   theory {:.4}   ({:+.1} σ)\n",
            self.ratio, self.ratio_err, self.theory_ratio, self.z_theory
        );
        let failed: Vec<String> = self
            .failed
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        s += &format!(
            "  unconverged {} (cap {} steps)   failed {}{}   energy gain {} (> {} % of the start)\n",
            self.unconverged,
            self.max_steps,
            self.failed_total,
            if failed.is_empty() {
                String::new()
            } else {
                format!(" ({})", failed.join(", "))
            },
            self.energy_gain,
            100.0 * self.energy_gain_tolerance
        );
        s += &format!(
            "  dipped {} (centre below the floor's top face at a step; not a failure)   deepest {:.1} mm into the floor\n",
            self.dipped,
            1000.0 * self.deepest_dip_m
        );
        s += &format!(
            "  steps/roll {:.0} ({:.0} by the engine)   wall {:.2} s   CPU {:.2} s ({:.3} ms/roll, {} threads)   {}\n",
            self.steps_mean,
            self.engine_steps_mean,
            self.wall_s,
            self.cpu_s,
            self.cpu_ms_per_roll,
            self.threads,
            self.engine_version
        );
        if let Some(a) = &self.audit {
            s += &format!(
                "  audit of the early stop (margin {}): fired on {} rolls, wrong on {} (full settle \
                 unknown on {}); mean step {:.0} against {:.0} for the full settle\n",
                a.margin,
                a.certified,
                a.wrong,
                a.full_settle_unknown,
                a.certified_steps_mean,
                a.full_steps_mean
            );
        }
        s
    }
}
