//! Accuracy against cost, and where methods fail: three sweeps over the same roll code.
//!
//! * [`converge`](super::converge): the paper's convergence test (its appendix): the ratio against dt for
//!   several blocks, engines, 2D and 3D, and whether dt = 0.001 s is within 1 % of the finest;
//! * [`tradeoff`](super::tradeoff): CPU cost against departure from the reference (the finest-dt faithful
//!   result) across methods, and the Pareto front;
//! * [`stability`](super::stability): the fractions of rolls that end unconverged, unknown, non-finite or
//!   tunnelled, or that gain energy, across dt, restitution, friction and aspect ratio.
//!
//! Every cell rolls the same keyed throws (seed, index), so cells differ only in the method.

use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::model::block::Outcome;
use crate::model::scene::Scene;
use crate::run::cputime::process_cpu_seconds;
use crate::run::io::write_atomic;
use crate::run::runner::{Runner, CHUNK_ROLLS};
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::run::tally::Tally;
use crate::sim::roll::{Fate, RollConfig, RollRecord};
use crate::theory::stats;
use std::path::PathBuf;

/// The relative departure asked of a method: the paper's "within 1 %".
pub const ONE_PERCENT: f64 = 0.01;

/// One measured cell: the exact tally and the CPU seconds (all threads) it took.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Measured {
    /// The cell's exact counts.
    pub tally: Tally,
    /// Process CPU seconds the cell took, all threads.
    pub cpu_s: f64,
}

impl Measured {
    /// N(breadth vertical)/N(width vertical) ± binomial error.
    pub fn ratio(&self) -> stats::Ratio {
        stats::ratio(self.tally.counts.breadth, self.tally.counts.width)
    }
    /// Process CPU seconds per roll.
    pub fn cpu_s_per_roll(&self) -> f64 {
        self.cpu_s / self.tally.rolls.max(1) as f64
    }
    /// Simulated steps per roll.
    pub fn steps_per_roll(&self) -> f64 {
        self.tally.steps as f64 / self.tally.rolls.max(1) as f64
    }
    /// A count as a fraction of the rolls.
    pub fn frac(&self, n: u64) -> f64 {
        n as f64 / self.tally.rolls.max(1) as f64
    }
}

/// How a sweep runs its cells: the runner (threads, stop, progress), and where finished cells
/// are kept (`--out/checkpoint`): a finished cell, with the CPU time it took, is not rolled
/// again when the same command is run again after a crash or Ctrl-C. A cell is kept whole or
/// not at all, so its cost stays true.
pub struct Study<'a> {
    /// Threads and stop requests.
    pub runner: Runner<'a>,
    /// Where finished cells are kept, if anywhere.
    pub checkpoint: Option<PathBuf>,
}

/// A sweep cell's run: `rolls` keyed throws of the paper's ranges from `seed`.
pub fn cell_spec(
    engine: EngineKind,
    scene: Scene,
    roll: RollConfig,
    seed: u64,
    rolls: u64,
) -> RunSpec {
    RunSpec {
        engine,
        scene,
        throws: ThrowSpec::keyed(seed),
        roll,
        rolls,
        shard: None,
    }
}

/// Rolls a cell; memory stays flat (chunked, records dropped); a finished cell is kept under
/// the study's checkpoint directory, in a directory named by the cell's key. A stop request
/// is an error here: a sweep's cell is whole or not reported.
pub fn measure(spec: &RunSpec, study: &Study) -> Result<Measured> {
    let cpu = process_cpu_seconds();
    let dir = study
        .checkpoint
        .as_ref()
        .map(|root| root.join(format!("{}-{}", spec.engine, spec.key())));
    // A cluster task's tally is its share only: it neither reads nor keeps a cell's result.
    let task = study.runner.share.is_partial();
    let kept = dir
        .as_ref()
        .filter(|_| !task)
        .map(|d| d.join("result.json"));
    if let Some(m) = kept
        .as_ref()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .and_then(|t| serde_json::from_str::<Measured>(&t).ok())
    {
        return Ok(m);
    }
    let ck = match &dir {
        Some(d) => Some(study.runner.open_cell(d, spec)?),
        None => None,
    };
    let run = study.runner.run(spec, ck.as_ref(), &mut |_| Ok(()))?;
    if !run.complete {
        return Err(Error::Stopped);
    }
    let m = Measured {
        tally: run.tally,
        cpu_s: process_cpu_seconds() - cpu + run.resumed_cpu_s,
    };
    if let Some(f) = &kept {
        let json = serde_json::to_string(&m).map_err(|e| Error::Failed(e.to_string()))?;
        write_atomic(f, json.as_bytes())?;
    }
    Ok(m)
}

/// A ratio's relative departure from a reference, r/ref − 1, with its error (the two taken as
/// independent: at another dt or engine the same throws soon follow other paths).
pub fn departure(r: stats::Ratio, reference: stats::Ratio) -> (f64, f64) {
    let q = r.value / reference.value;
    let err = q * ((r.err / r.value).powi(2) + (reference.err / reference.value).powi(2)).sqrt();
    (q - 1.0, err)
}

/// Rolls per cell needed for a departure's error to resolve 1 % at 2σ (σ ≤ 0.5 %), from one
/// measured at `rolls` per cell: the error falls as 1/√rolls.
pub fn rolls_for_one_percent(err: f64, rolls: u64) -> Option<u64> {
    (err.is_finite() && err > 0.0)
        .then(|| (rolls as f64 * (err / (0.5 * ONE_PERCENT)).powi(2)).ceil() as u64)
}

/// Parses a number of seconds written as a decimal (0.001) or a fraction (1/1000); its range
/// is the caller's to check.
pub fn parse_seconds(s: &str) -> Result<f64> {
    let bad = || Error::Invalid(format!("bad dt '{s}'"));
    Ok(match s.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) = (
                a.trim().parse().map_err(|_| bad())?,
                b.trim().parse().map_err(|_| bad())?,
            );
            a / b
        }
        None => s.trim().parse().map_err(|_| bad())?,
    })
}

/// Parses a time step: seconds (0.001) or a fraction (1/1000), in (0, 0.1] s.
pub fn parse_dt(s: &str) -> Result<f64> {
    let v = parse_seconds(s)?;
    if v.is_finite() && v > 0.0 && v <= 0.1 {
        Ok(v)
    } else {
        Err(Error::Invalid(format!("dt '{s}' must be in (0, 0.1] s")))
    }
}

/// A time step as people write it: 1/1000 for 0.001.
pub fn dt_label(dt: f64) -> String {
    let n = 1.0 / dt;
    if (n - n.round()).abs() < 1e-6 * n {
        format!("1/{}", n.round())
    } else {
        format!("{dt}")
    }
}

/// The `rolls` of a stream's specification: a fixed cap, never rolled whole. A method's rolls
/// are a prefix of this one keyed throw stream, so its checkpoint's key stays the same however
/// many rounds are added, and a cluster could roll chunks ahead of the rounds.
pub const STREAM_ROLLS: u64 = crate::run::spec::MAX_ROLLS;

/// A roll's outcome as the ratio sees it: 1 breadth vertical, 2 width vertical, 0 anything
/// else (length vertical, unknown, unconverged, failed).
fn class(r: &RollRecord) -> u8 {
    match r.fate {
        Fate::Settled(Outcome::Breadth) => 1,
        Fate::Settled(Outcome::Width) => 2,
        _ => 0,
    }
}

/// One method's rolls: the first `rolls()` throws of its keyed stream, with each throw's
/// outcome (for the paired error of a departure), the exact tally and the CPU seconds they
/// took (read back with the chunks on a resumed run, so costs stay true).
pub struct Stream {
    /// The specification, its `rolls` the cap `STREAM_ROLLS`.
    pub spec: RunSpec,
    /// Each throw's `class`, in index order.
    pub outcomes: Vec<u8>,
    /// The exact counts of the rolls made.
    pub tally: Tally,
    /// Process CPU seconds they took, all threads.
    pub cpu_s: f64,
}

impl Stream {
    /// The stream of `rolls: STREAM_ROLLS` keyed throws of this method; nothing rolled yet.
    pub fn new(engine: EngineKind, scene: Scene, roll: RollConfig, seed: u64) -> Stream {
        Stream {
            spec: cell_spec(engine, scene, roll, seed, STREAM_ROLLS),
            outcomes: Vec::new(),
            tally: Tally::default(),
            cpu_s: 0.0,
        }
    }

    /// Rolls made.
    pub fn rolls(&self) -> u64 {
        self.outcomes.len() as u64
    }

    /// The cell's measurement so far.
    pub fn measured(&self) -> Measured {
        Measured {
            tally: self.tally.clone(),
            cpu_s: self.cpu_s,
        }
    }

    /// CPU seconds per roll so far (NaN before any roll).
    pub fn cpu_s_per_roll(&self) -> f64 {
        self.cpu_s / self.rolls() as f64
    }

    /// Rolls the stream on to its first `chunks` chunks (a no-op if it has them), reading
    /// chunks already in the study's checkpoint back instead of rolling them. `progress`
    /// hears the rolls made in this call. A stop request is `Error::Stopped`; every whole
    /// chunk rolled is kept for the next run.
    pub fn extend(
        &mut self,
        chunks: u64,
        study: &Study,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<()> {
        let have = self.rolls() / CHUNK_ROLLS;
        if chunks <= have {
            return Ok(());
        }
        let ck = match &study.checkpoint {
            Some(root) => {
                let dir = root.join(format!("{}-{}", self.spec.engine, self.spec.key()));
                Some(study.runner.open_cell(&dir, &self.spec)?)
            }
            None => None,
        };
        let cpu = process_cpu_seconds();
        let mut outcomes = Vec::new();
        let mut tally = Tally::default();
        let run = study.runner.with_progress(progress).run_range(
            &self.spec,
            ck.as_ref(),
            have..chunks,
            &mut |recs| {
                outcomes.extend(recs.iter().map(class));
                recs.iter().for_each(|r| tally.add(r));
                Ok(())
            },
        )?;
        if !run.complete {
            return Err(Error::Stopped);
        }
        self.outcomes.extend(outcomes);
        self.tally.merge(&tally);
        // A chunk read back costs what it cost when rolled (stored with it), not the reading.
        let rolled_now = run.tally.rolls > run.resumed;
        self.cpu_s += run.resumed_cpu_s
            + if rolled_now {
                process_cpu_seconds() - cpu
            } else {
                0.0
            };
        Ok(())
    }

    /// The ratio's per-throw influence on ln(ratio): a_i = [breadth]/p_b − [width]/p_w, whose
    /// mean is 0 and whose variance, 1/p_b + 1/p_w, over N rolls is the ratio's relative
    /// variance (err/ratio)². `None` while either outcome is missing.
    fn influence(&self) -> Option<[f64; 3]> {
        let n = self.rolls() as f64;
        let (b, w) = (
            self.tally.counts.breadth as f64,
            self.tally.counts.width as f64,
        );
        (b > 0.0 && w > 0.0).then(|| [0.0, n / b, -n / w])
    }
}

/// A departure r_m/r_ref − 1 of one stream from another, with the ingredients of its error
/// so that the error at other roll counts can be predicted.
///
/// The two streams share their first throws, and where one has rolled further, its extra
/// throws are used through a control variate: with the method at n throws and the reference
/// at N > n, ln q = ln r_m(n) − ln r_ref(N) − β (ln r_ref(n) − ln r_ref(N)), with β the
/// regression of the method's per-throw influence on the reference's over the shared throws,
/// cov/V_r there: the least-variance weight (the bracket has mean 0 whatever β). β = 0 is
/// the plain comparison of each stream's whole ratio; β = 1 compares the shared throws alone.
/// Two methods that end alike throw for throw (β ≈ 1) then differ by what their shared
/// throws say, not by how far the reference's first n throws happen to sit from its N (the
/// plain comparison measured mostly that). Symmetrically when the method has rolled further.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Departure {
    /// r_m/r_ref − 1.
    pub value: f64,
    /// Its standard error, paired: the two share their first throws, and where they end alike
    /// the noise cancels (with the control variate above).
    pub err: f64,
    /// The error as if the two were independent (`departure`), for comparison.
    pub err_unpaired: f64,
    /// Fraction of the shared throws with the same outcome class (breadth, width, other).
    pub agreement: f64,
    /// Per-throw variance of ln r_m's influence, 1/p_b + 1/p_w.
    var_m: f64,
    /// The same for the reference.
    var_r: f64,
    /// Covariance of the two influences over the shared throws.
    cov: f64,
    /// The method's influence's variance over the shared throws.
    var_m_shared: f64,
    /// The reference's, over the shared throws.
    var_r_shared: f64,
}

impl Departure {
    /// The standard error of the departure with `nm` rolls of the method and `nr` of the
    /// reference (the first n = min(nm, nr) shared), times q for the relative departure.
    /// With the reference the longer (N = nr), the estimate is ā_n − γ c̄_n − (1 − β) c̄_rest
    /// (N − n)/N, γ = β + (1 − β) n/N, so var = V(a − γc)/n + (1 − β)² (N − n) V_r/N², V(a − γc)
    /// over the shared throws (never negative); the mirror image when the method is the longer.
    /// At nm = nr this is the plain paired (V_m + V_r − 2cov)/n. Without a variance to
    /// regress on, the plain comparison: V_m/nm + V_r/nr − 2·cov·n/(nm·nr).
    pub fn err_at(&self, nm: u64, nr: u64) -> f64 {
        let (m, r) = (nm as f64, nr as f64);
        let n = m.min(r);
        let cov = self.cov;
        // (shared variance of the shorter, of the longer, whole variance of the longer, its rolls)
        let (short, long, long_whole, big) = if m <= r {
            (self.var_m_shared, self.var_r_shared, self.var_r, r)
        } else {
            (self.var_r_shared, self.var_m_shared, self.var_m, m)
        };
        let var = if long > 0.0 {
            let beta = cov / long;
            let g = beta + (1.0 - beta) * n / big;
            (short - 2.0 * g * cov + g * g * long) / n
                + (1.0 - beta).powi(2) * (big - n) * long_whole / (big * big)
        } else {
            self.var_m / m + self.var_r / r - 2.0 * cov * n / (m * r)
        };
        (1.0 + self.value) * var.max(0.0).sqrt()
    }
}

/// The departure of `m` from `reference` on the same keyed throws, with its paired error
/// (delta method on ln of each ratio; the covariance from the throws both rolled).
pub fn paired_departure(m: &Stream, reference: &Stream) -> Departure {
    let nan = Departure {
        value: f64::NAN,
        err: f64::NAN,
        err_unpaired: f64::NAN,
        agreement: f64::NAN,
        var_m: f64::NAN,
        var_r: f64::NAN,
        cov: f64::NAN,
        var_m_shared: f64::NAN,
        var_r_shared: f64::NAN,
    };
    let (Some(a), Some(c)) = (m.influence(), reference.influence()) else {
        return nan;
    };
    let n = m.outcomes.len().min(reference.outcomes.len());
    if n == 0 {
        return nan;
    }
    // The covariance and the shared variances take each influence at its shared throws' own
    // proportions, so two streams that end alike there regress with β = 1 exactly (at the
    // whole streams' proportions ln r would be linearised about two points).
    let (ms, rs) = (&m.outcomes[..n], &reference.outcomes[..n]);
    let (a_s, c_s) = match (influence_of(ms), influence_of(rs)) {
        (Some(x), Some(y)) => (x, y),
        _ => (a, c),
    };
    let (mut sa, mut sc, mut saa, mut scc, mut sac, mut same) = (0.0, 0.0, 0.0, 0.0, 0.0, 0u64);
    for (&x, &y) in ms.iter().zip(rs) {
        let (ai, ci) = (a_s[x as usize], c_s[y as usize]);
        sa += ai;
        sc += ci;
        saa += ai * ai;
        scc += ci * ci;
        sac += ai * ci;
        same += (x == y) as u64;
    }
    let nf = n as f64;
    let (ma, mc) = (sa / nf, sc / nf);
    let (rm, rr) = (m.measured().ratio(), reference.measured().ratio());
    let (plain, err_unpaired) = departure(rm, rr);
    let mut d = Departure {
        value: plain,
        err: f64::NAN,
        err_unpaired,
        agreement: same as f64 / nf,
        var_m: a[1] * a[1] * m.tally.counts.breadth as f64 / m.rolls() as f64
            + a[2] * a[2] * m.tally.counts.width as f64 / m.rolls() as f64,
        var_r: c[1] * c[1] * reference.tally.counts.breadth as f64 / reference.rolls() as f64
            + c[2] * c[2] * reference.tally.counts.width as f64 / reference.rolls() as f64,
        cov: sac / nf - ma * mc,
        var_m_shared: saa / nf - ma * ma,
        var_r_shared: scc / nf - mc * mc,
    };
    // The control variate: the longer stream's ratio on the shared throws against its whole
    // (a factor (r(n)/r(N))^−β on q). Left out if the shared throws lack an outcome.
    // The reference's drift divides q, the method's multiplies it.
    let (longer, v, sign) = if m.rolls() <= reference.rolls() {
        (reference, d.var_r_shared, -1.0)
    } else {
        (m, d.var_m_shared, 1.0)
    };
    if let (Some(shared), true) = (ratio_of(&longer.outcomes[..n]), v > 0.0) {
        let beta = d.cov / v;
        let whole = longer.tally.counts.breadth as f64 / longer.tally.counts.width as f64;
        d.value = (1.0 + plain) * (shared / whole).powf(sign * beta) - 1.0;
    }
    d.err = d.err_at(m.rolls(), reference.rolls());
    d
}

/// N(breadth)/N(width) over some throws' outcome classes; `None` if either is missing.
fn ratio_of(outcomes: &[u8]) -> Option<f64> {
    let (b, w) = breadth_width(outcomes);
    (b > 0.0 && w > 0.0).then(|| b / w)
}

/// `Stream::influence` over some throws' outcome classes, at their own proportions.
fn influence_of(outcomes: &[u8]) -> Option<[f64; 3]> {
    let (b, w) = breadth_width(outcomes);
    let n = outcomes.len() as f64;
    (b > 0.0 && w > 0.0).then(|| [0.0, n / b, -n / w])
}

fn breadth_width(outcomes: &[u8]) -> (f64, f64) {
    let b = outcomes.iter().filter(|&&x| x == 1).count();
    let w = outcomes.iter().filter(|&&x| x == 2).count();
    (b as f64, w as f64)
}

/// The chunks a method needs for 2σ of its departure to be at most `precision`, with the
/// reference at `nr` rolls; `None` if none up to `max_chunks` would do.
pub fn chunks_to_resolve(d: &Departure, nr: u64, precision: f64, max_chunks: u64) -> Option<u64> {
    if !d.err.is_finite() {
        return None;
    }
    // err_at falls as nm grows, so the first chunk count that resolves is found by bisection.
    let ok = |k: u64| 2.0 * d.err_at(k * CHUNK_ROLLS, nr) <= precision;
    if !ok(max_chunks.max(1)) {
        return None;
    }
    let (mut lo, mut hi) = (0u64, max_chunks.max(1));
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// Rolls for 2σ of a ratio's own relative error to be at most `precision` (its influence
/// variance from the rolls so far); `None` before both outcomes are seen.
pub fn rolls_for_ratio(s: &Stream, precision: f64) -> Option<u64> {
    let c = s.influence()?;
    let n = s.rolls() as f64;
    let var = c[1] * c[1] * s.tally.counts.breadth as f64 / n
        + c[2] * c[2] * s.tally.counts.width as f64 / n;
    Some((var / (0.5 * precision).powi(2)).ceil() as u64)
}

impl Departure {
    /// The reference's departure from itself.
    pub fn zero() -> Departure {
        Departure {
            value: 0.0,
            err: 0.0,
            err_unpaired: 0.0,
            agreement: 1.0,
            var_m: 0.0,
            var_r: 0.0,
            cov: 0.0,
            var_m_shared: 0.0,
            var_r_shared: 0.0,
        }
    }
}

/// The chunks a stream may roll in `budget_s` CPU seconds, at its cost so far (at least the
/// chunks it has).
pub fn max_chunks(s: &Stream, budget_s: f64) -> u64 {
    let per_chunk = s.cpu_s_per_roll() * CHUNK_ROLLS as f64;
    if per_chunk.is_finite() && per_chunk > 0.0 {
        ((budget_s / per_chunk).floor() as u64).max(s.rolls() / CHUNK_ROLLS)
    } else {
        s.rolls() / CHUNK_ROLLS
    }
}

/// The chunks a reference is planned to: 2σ of its own ratio at most half the precision, so
/// that its noise takes at most a quarter of each departure's variance.
pub fn reference_chunks(s: &Stream, precision: f64) -> Option<u64> {
    rolls_for_ratio(s, 0.5 * precision).map(|n| n.div_ceil(CHUNK_ROLLS).max(1))
}

/// Rolls a reference in rounds until 2σ of its ratio is at most precision/2 or its budget is
/// spent. `progress` hears the CPU seconds spent so far (estimated).
pub fn resolve_reference(
    s: &mut Stream,
    precision: f64,
    budget_s: f64,
    study: &Study,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<()> {
    let cap = max_chunks(s, budget_s);
    let mut spent = 0.0;
    loop {
        let want = reference_chunks(s, precision).unwrap_or(cap).min(cap);
        let have = s.rolls() / CHUNK_ROLLS;
        if want <= have {
            return Ok(());
        }
        spent = round(s, want, study, spent, progress)?;
    }
}

/// Extends `s` to `chunks`, telling `progress` the CPU seconds spent so far in this
/// resolution (estimated at the stream's cost per roll); returns the new total.
fn round(
    s: &mut Stream,
    chunks: u64,
    study: &Study,
    spent: f64,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<f64> {
    let (have, per) = (s.rolls(), s.cpu_s_per_roll());
    s.extend(chunks, study, &|n| progress(spent + n as f64 * per))?;
    let spent = spent + (s.rolls() - have) as f64 * per;
    progress(spent);
    Ok(spent)
}

/// Rolls a method in rounds of its keyed stream until 2σ of its departure from `reference` is
/// at most `precision`; it stops, unresolved, as soon as the rolls that would resolve it (at
/// its measured variance and cost) exceed its budget: rolling on to the budget would not
/// resolve it, and the rolls it needs are reported instead. `progress` hears the rolls made
/// the CPU seconds spent so far (estimated).
pub fn resolve_departure(
    s: &mut Stream,
    reference: &Stream,
    precision: f64,
    budget_s: f64,
    study: &Study,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<()> {
    let cap = max_chunks(s, budget_s);
    let mut spent = 0.0;
    loop {
        let d = paired_departure(s, reference);
        let have = s.rolls() / CHUNK_ROLLS;
        if 2.0 * d.err <= precision {
            return Ok(());
        }
        let Some(k) = chunks_to_resolve(&d, reference.rolls(), precision, cap) else {
            return Ok(());
        };
        // A round adds at least a chunk: the estimate may say "resolved" just short of it.
        let k = k.max(have + 1);
        if k > cap {
            return Ok(());
        }
        spent = round(s, k, study, spent, progress)?;
    }
}

impl Departure {
    /// Rolls of both streams (the same number, sharing their throws) for 2σ of the departure
    /// to be at most `precision`, at the variances measured; `None` if not measured.
    pub fn rolls_both(&self, precision: f64) -> Option<u64> {
        let var = (1.0 + self.value).powi(2) * (self.var_m + self.var_r - 2.0 * self.cov);
        (var.is_finite() && var >= 0.0)
            .then(|| ((var / (0.5 * precision).powi(2)).ceil() as u64).max(1))
    }
}

/// The most chunks one stream is ever planned to (`STREAM_ROLLS`).
pub const NO_BUDGET: u64 = STREAM_ROLLS / CHUNK_ROLLS;

/// The CPU seconds still to spend, at the streams' measured costs and variances, for every
/// group (its reference first, then the streams compared with it) to be resolved to
/// `precision` by `resolve_reference` and `resolve_departure`; with `budgets` (reference's,
/// each other's, CPU s) as they would cut it, without them in full.
pub fn plan_cpu(groups: &[Vec<&Stream>], precision: f64, budgets: Option<(f64, f64)>) -> f64 {
    let mut cpu = 0.0;
    for g in groups {
        let Some((reference, rest)) = g.split_first() else {
            continue;
        };
        let cap = budgets.map_or(NO_BUDGET, |(b, _)| max_chunks(reference, b));
        let kr = reference_chunks(reference, precision)
            .unwrap_or(cap)
            .min(cap)
            .max(reference.rolls() / CHUNK_ROLLS);
        cpu += kr as f64 * CHUNK_ROLLS as f64 * reference.cpu_s_per_roll() - reference.cpu_s;
        for s in rest {
            let cap = budgets.map_or(NO_BUDGET, |(_, b)| max_chunks(s, b));
            let d = paired_departure(s, reference);
            // Past its budget a method stops at once (`resolve_departure`).
            let k = chunks_to_resolve(&d, kr * CHUNK_ROLLS, precision, cap)
                .unwrap_or(if budgets.is_some() { 0 } else { cap })
                .max(s.rolls() / CHUNK_ROLLS);
            cpu += k as f64 * CHUNK_ROLLS as f64 * s.cpu_s_per_roll() - s.cpu_s;
        }
    }
    cpu.max(0.0)
}

/// The precision an hour of `threads` buys with `spent` CPU seconds already spent: the plan
/// (no budgets) falls as 1/precision², so bisect on its log.
pub fn precision_in_an_hour(groups: &[Vec<&Stream>], threads: usize, spent: f64) -> f64 {
    let hour = 3600.0 * threads as f64 - spent;
    let (mut lo, mut hi) = (1e-4f64, 0.5f64);
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        if plan_cpu(groups, mid, None) > hour {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::block::Block;
    use crate::model::scene::Mode;

    /// A stream that has rolled these outcome classes (1 breadth, 2 width, 0 other).
    fn stream(outcomes: Vec<u8>) -> Stream {
        let scene = Scene::paper(Block::from_mm(140.0, 24.0, 20.0).unwrap(), Mode::ThreeD);
        let mut s = Stream::new(EngineKind::Bullet, scene, RollConfig::default(), 1);
        let (b, w) = breadth_width(&outcomes);
        (s.tally.counts.breadth, s.tally.counts.width) = (b as u64, w as u64);
        s.tally.rolls = outcomes.len() as u64;
        s.outcomes = outcomes;
        s
    }

    /// splitmix64, as a uniform in [0, 1): the tests' own fixed-seed throws.
    struct Uniform(u64);
    impl Uniform {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            (z ^ (z >> 31)) as f64 / 2f64.powi(64)
        }
        fn class(&mut self, p_breadth: f64) -> u8 {
            if self.next() < p_breadth {
                1
            } else {
                2
            }
        }
    }

    /// The plain paired error (β = 0): each stream's whole ratio, the shared throws only
    /// correlating them.
    fn plain_err(d: &Departure, nm: u64, nr: u64) -> f64 {
        let (m, r) = (nm as f64, nr as f64);
        let var = d.var_m / m + d.var_r / r - 2.0 * d.cov * m.min(r) / (m * r);
        (1.0 + d.value) * var.sqrt()
    }

    #[test]
    fn a_method_that_ends_as_the_reference_departs_by_what_the_shared_throws_say() {
        // A reference of 20,000 throws; a method that ends as its first 4,000 but for 2 %,
        // redrawn. The plain paired comparison of the whole ratios also measures how far the
        // reference's first 4,000 sit from its 20,000; the control variate takes that out
        // (all but (1 − β) of it), so its departure is the shared throws' within its error,
        // and that error is a fraction of the plain one.
        let mut u = Uniform(7);
        let reference: Vec<u8> = (0..20_000).map(|_| u.class(0.36)).collect();
        let method: Vec<u8> = reference[..4_000]
            .iter()
            .map(|&x| if u.next() < 0.02 { u.class(0.36) } else { x })
            .collect();
        let shared = ratio_of(&method).unwrap() / ratio_of(&reference[..4_000]).unwrap() - 1.0;
        let d = paired_departure(&stream(method), &stream(reference));
        assert!(
            (d.value - shared).abs() < d.err,
            "departure {} ± {} against the shared throws' {shared}",
            d.value,
            d.err
        );
        assert!(
            d.err < 0.3 * plain_err(&d, 4_000, 20_000),
            "{d:?}: its error should be a fraction of the plain paired one"
        );
    }

    #[test]
    fn the_control_variate_departure_is_unbiased_and_its_error_is_its_spread() {
        // 400 pairs of streams with the same physics (true departure 0): one of 8,000 throws
        // at p = 0.36, the other of 2,000 ending as its first 2,000 but for 5 %, redrawn;
        // the longer one the reference, then the method. Over the pairs the departures average
        // 0 within 3 standard errors of their mean, and their standard deviation is the
        // predicted error within 15 %.
        let mut u = Uniform(2385);
        for method_longer in [false, true] {
            let (mut values, mut errs) = (Vec::new(), Vec::new());
            for _ in 0..400 {
                let long: Vec<u8> = (0..8_000).map(|_| u.class(0.36)).collect();
                let short: Vec<u8> = long[..2_000]
                    .iter()
                    .map(|&x| if u.next() < 0.05 { u.class(0.36) } else { x })
                    .collect();
                let (long, short) = (stream(long), stream(short));
                let d = if method_longer {
                    paired_departure(&long, &short)
                } else {
                    paired_departure(&short, &long)
                };
                values.push(d.value);
                errs.push(d.err);
            }
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let err = errs.iter().sum::<f64>() / n;
            let case = if method_longer { "method" } else { "reference" };
            assert!(
                mean.abs() < 3.0 * sd / n.sqrt(),
                "{case} longer: mean {mean}, sd {sd}"
            );
            assert!(
                (sd / err - 1.0).abs() < 0.15,
                "{case} longer: spread {sd} against predicted {err}"
            );
        }
    }
}
