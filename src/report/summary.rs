//! A run's result as it is reported: configuration, exact counts, the ratio with its error,
//! the theory beside it, and what it cost.

use crate::engine::EngineKind;
use crate::model::faces;
use crate::model::scene::{Floor, Mode, Preset};
use crate::model::throws::{ThrowKind, ThrowRanges, ThrowStyle};
use crate::report::precision::Reached;
use crate::report::shape_outcomes::{shape_faces, ShapeOutcomes};
use crate::run::spec::RunSpec;
use crate::run::tally::{Counts, Tally};
use crate::sim::roll::{Failure, Rule};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What a run cost, and on how many threads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cost {
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Process CPU seconds, all threads.
    pub cpu_s: f64,
    /// Worker threads.
    pub threads: usize,
}

/// A run's report: its specification spelled out, its counts, ratio, theory and cost. The
/// `--json` of `roll`, and each cell of `paper` and `crosscheck`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunSummary {
    /// The engine.
    pub engine: EngineKind,
    /// The engine's name and version, for provenance.
    pub engine_version: String,
    /// Bullet's solver settings.
    pub preset: Preset,
    /// Length, breadth, width in mm.
    pub block_mm: [f64; 3],
    /// 2D or 3D.
    pub mode: Mode,
    /// Rolls made.
    pub rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The throws' source.
    pub throws: ThrowKind,
    /// The throws' ranges.
    pub ranges: ThrowRanges,
    /// Time step, s.
    pub dt: f64,
    /// The contact's μ.
    pub friction: f64,
    /// The contact's e.
    pub restitution: f64,
    /// The die's density, kg/m³.
    pub density: f64,
    /// Box or plane.
    pub floor: Floor,
    /// The step cap.
    pub max_steps: u64,
    /// What ended each roll: DicePhys's rest rule or the energy certificate.
    pub settle: Rule,
    /// Settled rolls by the side vertical.
    pub counts: Counts,
    /// Rolls not at rest at the step cap.
    pub unconverged: u64,
    /// Failed rolls by why.
    pub failed: BTreeMap<Failure, u64>,
    /// Failed rolls in all.
    pub failed_total: u64,
    /// Rolls in which the engine injected energy: kinetic + potential rose above its lowest
    /// value so far by more than `energy_gain_tolerance` of the starting energy. A flag on
    /// rolls of any fate, not a failure.
    #[serde(default)]
    pub energy_gain: u64,
    /// The energy-gain flag's tolerance, a fraction of the starting energy.
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
    /// In 3D: P(breadth vertical), P(width vertical), P(length vertical), each ± its binomial
    /// error, beside the solid-angle prediction (absent in 2D, or with no die on a face).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcomes: Option<crate::report::outcomes::Outcomes3d>,
    /// (ratio − theory) / ratio_err.
    pub z_theory: f64,
    /// How the numbers sit on the faces (`faces`' keys).
    #[serde(default)]
    pub layout: faces::Layout,
    /// Settled rolls by the number on the face up, `"1"`…`"6"` (in 2D the four sides'
    /// numbers), under `layout`: each pair of opposite faces adds up to its side's count.
    /// Absent when some rolls came from chunks written before faces were kept. For a die of
    /// any shape, by the label it shows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<BTreeMap<String, u64>>,
    /// A die of any shape: each outcome's probability against a fair die's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeOutcomes>,
    /// Physics that broke, said in words (`physics_warnings`): absent when none did.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Steps simulated over all rolls.
    pub steps_total: u64,
    /// Steps simulated per roll.
    pub steps_mean: f64,
    /// Steps the engine took per roll (below steps_mean where free flight was coasted).
    pub engine_steps_mean: f64,
    /// Free flight integrated in closed form.
    pub fast_flight: bool,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Process CPU seconds, all threads (summed over a resumed run's segments).
    pub cpu_s: f64,
    /// CPU milliseconds per roll.
    pub cpu_ms_per_roll: f64,
    /// Worker threads.
    pub threads: usize,
    /// This program's version.
    pub dicephys_version: String,
    /// The run's specification: what `--resume` continues and `merge` compares.
    pub spec: RunSpec,
    /// Stopped before all rolls were made (Ctrl-C): the counts cover `rolls` only.
    pub partial: bool,
    /// The exact integer tally, for `merge`.
    pub tally: Tally,
    /// Present when auditing the early stop (`--audit`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub audit: Option<Audit>,
    /// Present when rolled to a precision (`--precision`): asked, reached, rolls it took.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub precision: Option<Reached>,
}

/// How the energy certificate would have done on these rolls.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Audit {
    /// The certificate's margin.
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

/// Settled rolls by the number on the face up, under `layout` (the faces a 2D die can show
/// only); `None` if some were read from chunks written before faces were kept.
pub fn faces_up(tally: &Tally, mode: Mode, layout: faces::Layout) -> Option<BTreeMap<String, u64>> {
    if tally.counts.face > 0 {
        return None;
    }
    if !tally.faces_complete() {
        return None;
    }
    let (numbers, up) = (layout.numbers(), tally.by_direction());
    let shown = match mode {
        Mode::ThreeD => 6,
        Mode::TwoD => 4,
    };
    Some(
        (0..shown)
            .map(|d| (numbers[d].to_string(), up[d]))
            .collect(),
    )
}

/// The share of rolls above which a sign of broken physics is reported (`physics_warnings`).
pub const BROKEN_SHARE: f64 = 0.5;

/// What says the engine's physics broke at this step (issue 50: `--dt 1/30` used to pass in
/// silence with 1,986 of 2,000 rolls sunk into the floor): more than half the rolls with the
/// die's centre pushed below the floor's top face (sunk by more than its own half-size), or
/// more than half gaining energy. One line each, naming the step and `stability`.
pub fn physics_warnings(tally: &Tally, dt: f64) -> Vec<String> {
    let n = tally.rolls as f64;
    let mut out = Vec::new();
    if n > 0.0 && tally.dipped as f64 > BROKEN_SHARE * n {
        out.push(format!(
            "at dt {dt} s {} of {} rolls sank their centre below the floor (as deep as {:.1} mm): \
             the step is too coarse for this die; `dicephys stability` maps where each engine holds",
            tally.dipped,
            tally.rolls,
            tally.deepest_dip_m() * 1e3
        ));
    }
    if n > 0.0 && tally.energy_gain as f64 > BROKEN_SHARE * n {
        out.push(format!(
            "at dt {dt} s {} of {} rolls gained energy (more than {} % of their start): the \
             engine injects it; `dicephys stability` maps where each engine holds",
            tally.energy_gain,
            tally.rolls,
            100.0 * crate::sim::roll::ENERGY_GAIN_TOLERANCE
        ));
    }
    out
}

impl RunSummary {
    /// The report of a run of `spec` that made the rolls in `tally`.
    pub fn new(spec: &RunSpec, tally: &Tally, cost: Cost) -> RunSummary {
        let (scene, settle) = (&spec.scene, &spec.roll);
        let Cost {
            wall_s,
            cpu_s,
            threads,
        } = cost;
        let r = crate::theory::stats::ratio(tally.counts.breadth, tally.counts.width);
        let (ratio, ratio_err) = (r.value, r.err);
        let theory_ratio = crate::theory::ratio_from_r(scene.die.block().r());
        RunSummary {
            engine: spec.engine,
            engine_version: spec.engine.version(),
            preset: scene.preset,
            block_mm: scene.die.block().mm(),
            mode: scene.mode,
            rolls: tally.rolls,
            seed: spec.throws.seed,
            throws: spec.throws.kind,
            ranges: spec.throws.ranges,
            dt: scene.dt,
            friction: scene.friction,
            restitution: scene.restitution,
            density: scene.density,
            floor: scene.floor,
            max_steps: settle.max_steps,
            settle: settle.rule,
            counts: tally.counts.clone(),
            unconverged: tally.unconverged,
            failed: tally.failed.clone(),
            failed_total: tally.failed_total(),
            energy_gain: tally.energy_gain,
            energy_gain_tolerance: crate::sim::roll::ENERGY_GAIN_TOLERANCE,
            dipped: tally.dipped,
            deepest_dip_m: tally.deepest_dip_m(),
            max_dip_steps: crate::sim::roll::MAX_DIP_STEPS,
            ratio,
            ratio_err,
            theory_ratio,
            outcomes: match scene.mode {
                Mode::ThreeD => {
                    crate::report::outcomes::Outcomes3d::of(&scene.die.block(), &tally.counts)
                }
                Mode::TwoD => None,
            },
            z_theory: (ratio - theory_ratio) / ratio_err,
            // The run's own numbering (its specification's), whoever reads it back.
            layout: scene.features.layout,
            faces: match shape_faces(tally, scene) {
                Some(f) => Some(f.into_iter().collect()),
                None => faces_up(tally, scene.mode, scene.features.layout),
            },
            shape: ShapeOutcomes::of(tally, scene),
            warnings: physics_warnings(tally, scene.dt),
            steps_total: tally.steps,
            steps_mean: tally.steps as f64 / tally.rolls.max(1) as f64,
            engine_steps_mean: tally.engine_steps as f64 / tally.rolls.max(1) as f64,
            fast_flight: settle.fast_flight,
            wall_s,
            cpu_s,
            cpu_ms_per_roll: 1000.0 * cpu_s / tally.rolls.max(1) as f64,
            threads,
            dicephys_version: env!("CARGO_PKG_VERSION").into(),
            spec: spec.clone(),
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
            precision: None,
        }
    }

    /// The same summary with its faces numbered by `layout`.
    pub fn with_layout(mut self, layout: faces::Layout) -> RunSummary {
        if self.spec.scene.die.as_shape().is_some() {
            return self;
        }
        self.layout = layout;
        self.faces = faces_up(&self.tally, self.mode, layout);
        self
    }

    /// What of the run is not DicePhys's (damping, no sleeping), as a line; empty when all is
    fn not_dicephys(&self) -> String {
        let scene = &self.spec.scene;
        let mut extra = Vec::new();
        if scene.damped() {
            extra.push(format!(
                "damping {} (linear), {} (angular) 1/s",
                scene.linear_damping, scene.angular_damping
            ));
        }
        if !scene.sleeping {
            extra.push("never asleep".into());
        }
        if scene.rolling_resistance > 0.0 {
            extra.push(format!(
                "rolling resistance {} mm",
                scene.rolling_resistance * 1e3
            ));
        }
        if scene.bounce_threshold > 0.0 {
            extra.push(format!("bounce threshold {} m/s", scene.bounce_threshold));
        }
        if scene.contact_time > 0.0 {
            extra.push(format!("a soft contact of {} ms", scene.contact_time * 1e3));
        }
        if scene.static_ratio != 1.0 {
            extra.push(format!(
                "static friction {} × the sliding",
                scene.static_ratio
            ));
        }
        if extra.is_empty() {
            String::new()
        } else {
            format!("  {}\n", extra.join(", "))
        }
    }

    /// The summary's lines of outcomes: a die of any shape's faces against 1/N, or the
    /// block's sides, its ratio with theory, and its three outcomes (3D).
    fn outcome_lines(&self) -> String {
        let c = &self.counts;
        let mut s = String::new();
        if let Some(o) = &self.shape {
            s += &format!(
                "  {}: on a face {:>8}   unknown (leaning) {:>6}\n",
                o.shape, c.face, c.unknown
            );
            s += &o.lines();
        } else {
            s += &format!(
                "  breadth vertical {:>8}   width vertical {:>8}   length vertical {:>6}   unknown {:>6}\n",
                c.breadth, c.width, c.length, c.unknown
            );
            s += &format!(
                "  ratio breadth/width  {:.4} ± {:.4}   theory {:.4}   ({:+.1} σ)\n",
                self.ratio, self.ratio_err, self.theory_ratio, self.z_theory
            );
        }
        if let Some(o) = &self.outcomes {
            s += &format!("  {}\n", o.line());
        }
        s
    }

    /// The human summary: counts, the ratio with its error, theory and σ, failures, cost.
    pub fn human(&self) -> String {
        let mut s = String::new();
        if self.partial {
            s += "PARTIAL: stopped before all rolls were made; the counts cover these rolls only\n";
        }
        for w in &self.warnings {
            s += &format!("WARNING: {w}\n");
        }
        let die = self.spec.scene.die.title();
        // The throw is always named: a fair cube under the paper's throw shows 1 and 6 less
        // often, and a reader must see which throw made the counts.
        let throw = throw_name(&self.spec.throws);
        let source = match self.throws {
            ThrowKind::Keyed => "",
            ThrowKind::Dicephys => " from DicePhys's rand()",
        };
        s += &format!(
            "{} {} {}, {} rolls, {throw}{source}, seed {}, dt {} s, μ {}, e {}, preset {}, floor {}\n",
            self.engine,
            self.mode,
            die,
            self.rolls,
            self.seed,
            self.dt,
            self.friction,
            self.restitution,
            self.preset,
            self.floor
        );
        s += &self.not_dicephys();
        s += &self.outcome_lines();
        if let (Some(f), None) = (&self.faces, &self.shape) {
            let each: Vec<String> = f.iter().map(|(k, v)| format!("{k}: {v}")).collect();
            s += &format!("  face up ({} layout)  {}\n", self.layout, each.join("   "));
        }
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
            "  steps/roll {:.0} ({:.0} by the engine)   wall {:.2} s   CPU {:.2} s ({:.3} ms/roll, {} thread{})   {}\n",
            self.steps_mean,
            self.engine_steps_mean,
            self.wall_s,
            self.cpu_s,
            self.cpu_ms_per_roll,
            self.threads,
            if self.threads == 1 { "" } else { "s" },
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
        if let Some(p) = &self.precision {
            s += &format!("  {}\n", p.line());
        }
        s
    }
}

/// What `merge` reads of a shard's `roll --json`: its specification, exact tally and cost
/// (the derived numbers, which may be null where NaN, are recomputed).
#[derive(Clone, Debug, Deserialize)]
pub struct ShardResult {
    /// The shard's run.
    pub spec: RunSpec,
    /// Its exact counts.
    pub tally: Tally,
    /// Interrupted before its end.
    pub partial: bool,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// CPU seconds.
    pub cpu_s: f64,
    /// Worker threads.
    pub threads: usize,
}

impl ShardResult {
    /// A shard's `roll --json` output from `p`, if it is there, whole, and of the run `want`;
    /// else why not.
    pub fn read(p: &std::path::Path, want: &RunSpec) -> std::result::Result<ShardResult, String> {
        let text = std::fs::read_to_string(p).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => format!("no {}", p.display()),
            _ => format!("{}: {e}", p.display()),
        })?;
        let s: ShardResult =
            crate::run::seal::open(&text).map_err(|e| format!("{}: {e}", p.display()))?;
        if s.spec != *want {
            return Err(format!("{} is of another run", p.display()));
        }
        if s.partial {
            return Err(format!("{} is partial", p.display()));
        }
        Ok(s)
    }
}

impl RunSummary {
    /// Combines the shards of one run into the unsharded run's summary: the same exact counts.
    /// Refuses shards of different runs (compared by specification, however their command
    /// lines were spelled), partial, missing or repeated shards, and tallies that do not add up.
    pub fn merge(parts: &[ShardResult]) -> crate::Result<RunSummary> {
        use crate::Error::Mismatch;
        let first = parts
            .first()
            .ok_or_else(|| Mismatch("merge: no shards".into()))?;
        let whole = first.spec.unsharded();
        let n = first.spec.shard.map_or(1, |s| s.n);
        let mut seen = vec![false; n.min(1 << 20) as usize];
        let mut tally = Tally::default();
        let (mut wall, mut cpu) = (0.0f64, 0.0f64);
        for p in parts {
            if p.spec.unsharded() != whole {
                return Err(Mismatch("merge: shards of different runs".into()));
            }
            if p.partial {
                return Err(Mismatch(
                    "merge: a shard is partial (interrupted); resume it first".into(),
                ));
            }
            let s = p.spec.shard.ok_or_else(|| {
                Mismatch("merge: an input is not a shard (it names no shard)".into())
            })?;
            s.validate()?;
            p.tally.check()?;
            if s.n != n || seen.get(s.k as usize).copied().unwrap_or(true) {
                return Err(Mismatch(format!(
                    "merge: shard {}/{} is repeated or of another split",
                    s.k, s.n
                )));
            }
            if p.tally.rolls != p.spec.indices().len() {
                return Err(Mismatch(format!(
                    "merge: shard {}/{} counts {} rolls, not its {}",
                    s.k,
                    s.n,
                    p.tally.rolls,
                    p.spec.indices().len()
                )));
            }
            seen[s.k as usize] = true;
            tally.merge(&p.tally)?;
            wall += p.wall_s;
            cpu += p.cpu_s;
        }
        if let Some(k) = seen.iter().position(|&x| !x) {
            return Err(Mismatch(format!("merge: shard {k}/{n} is missing")));
        }
        Ok(RunSummary::new(
            &whole,
            &tally,
            Cost {
                wall_s: wall,
                cpu_s: cpu,
                threads: first.threads,
            },
        ))
    }
}

/// A run's throw, named for its summary line.
fn throw_name(t: &crate::run::spec::ThrowSpec) -> String {
    match (t.style, t.kappa) {
        (ThrowStyle::Paper, _) => "the paper's throw".into(),
        (ThrowStyle::Tumble, _) => "a tumble".into(),
        (ThrowStyle::Hand, _) => "a hand's throw".into(),
        (ThrowStyle::Rest, _) => "released at rest".into(),
        (ThrowStyle::Toss, None) => "a hand's toss".into(),
        (ThrowStyle::Toss, Some(k)) => format!("a hand's toss in a hand's directions (κ {k})"),
        (ThrowStyle::Flip, _) => "a flip".into(),
    }
}
