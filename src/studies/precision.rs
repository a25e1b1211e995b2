//! Precision as the input, rolls the output: a reference rolled in rounds until its own ratio
//! is resolved, each method until its departure from it is, within CPU budgets; and the plan,
//! the CPU seconds that costs, from the streams' measured costs and variances.

use super::departure::{chunks_to_resolve, paired_departure, rolls_for_ratio};
use super::stream::{Stream, STREAM_ROLLS};
use super::study::Study;
use crate::error::Result;
use crate::report::precision::{Reached, Target};
use crate::run::runner::{Checkpoint, Rolled, Runner, CHUNK_ROLLS};
use crate::run::spec::RunSpec;
use crate::run::tally::Tally;
use crate::sim::roll::RollRecord;

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

/// The coarsest precision `precision_in_an_hour` reports (±50 %).
pub const PRECISION_SEARCH_MAX: f64 = 0.5;

/// The precision an hour of `threads` buys with `spent` CPU seconds already spent: the plan
/// (no budgets) falls as 1/precision², so bisect on its log.
/// The bisection's bounds are 0.01 % and [`PRECISION_SEARCH_MAX`]: at the upper one, an hour
/// buys that or worse.
pub fn precision_in_an_hour(groups: &[Vec<&Stream>], threads: usize, spent: f64) -> f64 {
    let hour = 3600.0 * threads as f64 - spent;
    let (mut lo, mut hi) = (1e-4f64, PRECISION_SEARCH_MAX);
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

/// Rolls `spec` chunk by chunk (each chunk on all the runner's threads) until the ratio's
/// relative 2σ error is at most `precision`, tested at chunk boundaries only, or until the
/// spec's `rolls` (the cap) are made or a stop is requested. Chunks come from and go to
/// `checkpoint` as in `Runner::run`, so the same command run again continues. `expect` hears,
/// after each chunk, the rolls the run now expects to make in all (for progress lines).
pub fn roll_to_precision(
    runner: &Runner,
    spec: &RunSpec,
    checkpoint: Option<&Checkpoint>,
    precision: f64,
    target: Target,
    expect: &dyn Fn(u64),
    sink: &mut dyn FnMut(&[RollRecord]) -> Result<()>,
) -> Result<(Rolled, Reached)> {
    let chunks = spec.indices().len().div_ceil(CHUNK_ROLLS);
    let mut all = Rolled {
        tally: Tally::default(),
        complete: true,
        resumed: 0,
        resumed_cpu_s: 0.0,
        resumed_wall_s: 0.0,
    };
    for c in 0..chunks {
        if Reached::of_target(&all.tally, target, precision).resolved {
            break;
        }
        let base = all.tally.rolls;
        let progress = |n: u64| (runner.progress)(base + n);
        let r = runner
            .with_progress(&progress)
            .run_range(spec, checkpoint, c..c + 1, sink)?;
        all.tally.merge(&r.tally)?;
        if let Some(n) = target.rolls_for(&all.tally, precision) {
            let n = n.div_ceil(CHUNK_ROLLS) * CHUNK_ROLLS;
            expect(n.clamp(all.tally.rolls, spec.indices().len()));
        }
        all.resumed += r.resumed;
        all.resumed_cpu_s += r.resumed_cpu_s;
        all.resumed_wall_s += r.resumed_wall_s;
        if !r.complete {
            all.complete = false;
            break;
        }
    }
    let reached = Reached::of_target(&all.tally, target, precision);
    Ok((all, reached))
}
