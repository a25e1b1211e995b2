//! `dicephys tradeoff`: accuracy against cost, resolved. A method is an engine, a time step, a
//! settling rule (DicePhys's rest rule with every step stepped, or the exact early stop with
//! closed-form flight) and a scene variant (box floor or plane; in 2D also Rapier's locked 3D
//! body against its true 2D one). Cost: CPU seconds per 1,000 rolls. Accuracy: the ratio's
//! departure from the reference, Bullet's converged answer (box floor, the exact levers, at the
//! finest dt), each mode (2D, 3D) its own.
//!
//! Precision is the input, rolls the output: every method rolls the same keyed throw stream
//! (`stream::Stream`) in rounds until 2σ of its departure is at most the precision, or its CPU
//! budget is spent; the reference first, to 2σ ≤ precision/2 so that its own noise takes at
//! most a quarter of each departure's variance. A departure's error is paired: the method
//! and the reference share their first throws, and where they end alike (the same dt, another
//! rule) the noise cancels; at another dt or engine the outcomes decorrelate (measured: about
//! 54 % agreement, what chance gives) and the pairing changes nothing.

use super::departure::{chunks_to_resolve, paired_departure, rolls_for_ratio, Departure};
use super::precision::{
    plan_cpu, precision_in_an_hour, resolve_departure, resolve_reference, NO_BUDGET,
    PRECISION_SEARCH_MAX,
};
use super::stream::Stream;
use super::study::{Progress, Study};
use super::sweep::{check_budget, check_rolls_and_steps, nonempty};
use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::block::Block;
use crate::model::scene::{Floor, Mode, Scene};
use crate::report::text::dt_label;
use crate::report::tradeoff::{
    format_row, MethodAcross, ModeAcross, ModeResult, Role, Row, Tradeoff, TradeoffBlocks,
};
use crate::run::runner::CHUNK_ROLLS;
use crate::sim::roll::{RollConfig, Rule};
use serde::{Deserialize, Serialize};

/// What the trade-off study runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The blocks: each block and mode has its own reference and methods.
    pub blocks: Vec<Block>,
    /// The modes run, 3D and/or 2D (3D is run first).
    pub modes: Vec<Mode>,
    /// Bullet's time steps, s.
    pub dts: Vec<f64>,
    /// Rapier's time steps, s.
    pub rapier_dts: Vec<f64>,
    /// The reference's dt (finer than every method's).
    pub reference_dt: f64,
    /// The reference's ladder: Bullet with the exact levers at these other fine steps, each a
    /// departure from the reference that shows it converged (or not).
    pub ladder: Vec<f64>,
    /// The 2σ half-width asked of every departure, a fraction of the ratio.
    pub precision: f64,
    /// CPU seconds a method may spend.
    pub budget_s: f64,
    /// CPU seconds the reference (each mode's) may spend.
    pub reference_budget_s: f64,
    /// The throws' seed (keyed throws, the same stream for every method).
    pub seed: u64,
    /// The step cap per roll.
    pub max_steps: u64,
    /// Stop after the pilot and the plan (no methods in the result).
    pub plan_only: bool,
    /// Roll this many chunks of every stream and stop, deciding nothing (no methods in the
    /// result): a cluster's tasks roll ahead so, and the study run after reads them back.
    pub preroll_chunks: Option<u64>,
}

impl Default for Config {
    /// `dicephys tradeoff` with no flags: 140x24x20 in 3D and 2D, Bullet at 1/100, 1/250 and
    /// 1/1000 s and Rapier at 1/250 and 1/1000 s against Bullet at 1/5000 s (with 1/2000 and
    /// 1/10000 as its ladder), each departure to 2 % at 2σ (what about an hour on 2 cores
    /// buys: docs/results/tradeoff.md), 600 CPU s a method and 1,800 the reference.
    fn default() -> Config {
        Config {
            blocks: vec!["140x24x20".parse().expect("a valid block")],
            modes: vec![Mode::ThreeD, Mode::TwoD],
            dts: vec![1.0 / 100.0, 1.0 / 250.0, 1.0 / 1000.0],
            rapier_dts: vec![1.0 / 250.0, 1.0 / 1000.0],
            reference_dt: 1.0 / 5000.0,
            ladder: vec![1.0 / 2000.0, 1.0 / 10000.0],
            precision: 0.02,
            budget_s: 600.0,
            reference_budget_s: 1800.0,
            seed: crate::model::throws::DEFAULT_SEED,
            max_steps: 2_000_000,
            plan_only: false,
            preroll_chunks: None,
        }
    }
}

impl Config {
    /// What makes two runs of it one run (`StudyConfig::identity`): less the precision, the
    /// budgets, `plan_only` and `preroll_chunks`.
    pub fn identity(&self) -> Config {
        Config {
            precision: 0.0,
            budget_s: 0.0,
            reference_budget_s: 0.0,
            plan_only: false,
            preroll_chunks: None,
            ..self.clone()
        }
    }

    /// What a cluster run's finishing job runs: its tasks only rolled ahead, so it runs whole
    /// (no `preroll_chunks`), reading their chunks back and rolling on where a method needs
    /// more.
    pub fn finishing(&self) -> Config {
        Config {
            preroll_chunks: None,
            ..self.clone()
        }
    }

    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        nonempty(&self.blocks, Field::Blocks)?;
        if let Some(b) = self
            .blocks
            .iter()
            .enumerate()
            .find_map(|(i, b)| self.blocks[..i].contains(b).then_some(b))
        {
            return Err(Error::field(Field::Blocks, b, "named twice"));
        }
        nonempty(&self.modes, Field::Modes)?;
        nonempty(&self.dts, Field::Dts)?;
        if self
            .dts
            .iter()
            .chain(&self.rapier_dts)
            .any(|&d| d <= self.reference_dt)
        {
            return Err(Error::field(
                Field::ReferenceDt,
                dt_label(self.reference_dt),
                crate::text![
                    "must be finer than every ",
                    Field::Dts,
                    " and ",
                    Field::RapierDts
                ],
            ));
        }
        if self.ladder.contains(&self.reference_dt) {
            return Err(Error::field(
                Field::Ladder,
                "",
                "the reference's dt is not a rung",
            ));
        }
        if let Some(k) = self.preroll_chunks {
            let max = crate::run::spec::MAX_ROLLS / crate::run::runner::CHUNK_ROLLS;
            if k == 0 || k > max {
                return Err(Error::field(
                    Field::PrerollChunks,
                    k.saturating_mul(crate::run::runner::CHUNK_ROLLS),
                    format!("must be in 1..={} rolls", crate::run::spec::MAX_ROLLS),
                ));
            }
        }
        check_budget(self.budget_s, Field::BudgetS)?;
        check_budget(self.reference_budget_s, Field::ReferenceBudgetS)?;
        check_rolls_and_steps(1, self.max_steps)
    }

    /// The modes asked, 3D first.
    pub fn modes_in_order(&self) -> Vec<Mode> {
        [Mode::ThreeD, Mode::TwoD]
            .into_iter()
            .filter(|m| self.modes.contains(m))
            .collect()
    }
}

/// Chunks every stream rolls first, to measure its cost and its variance.
pub const PILOT_CHUNKS: u64 = 1;

#[derive(Clone, Copy)]
struct Method {
    role: Role,
    engine: EngineKind,
    dt: f64,
    faithful: bool,
    floor: Floor,
}

impl Method {
    fn name(&self, mode: Mode) -> String {
        format!(
            "{} {} {} {} {}",
            self.engine.name(),
            mode.name(),
            dt_label(self.dt),
            if self.faithful { "faithful" } else { "fast" },
            match self.floor {
                Floor::Box => "box",
                Floor::Plane => "plane",
            }
        )
    }

    fn stream(&self, cfg: &Config, block: Block, mode: Mode) -> Stream {
        let mut scene = Scene::paper(block, mode);
        scene.dt = self.dt;
        scene.floor = self.floor;
        let settle = RollConfig {
            max_steps: cfg.max_steps,
            // `fast` is the defaults: the early stop only where it is audited exact.
            rule: if self.faithful || !crate::sim::roll::early_stop_exact(self.dt) {
                Rule::Dicephys
            } else {
                Rule::Certificate
            },
            fast_flight: !self.faithful,
            ..RollConfig::default()
        };
        Stream::new(self.engine, scene, settle, cfg.seed)
    }
}

/// Every stream of a mode: the reference first, then its checks, then the methods.
fn methods(cfg: &Config, mode: Mode) -> Vec<Method> {
    let bullet = |role, dt, faithful| Method {
        role,
        engine: EngineKind::Bullet,
        dt,
        faithful,
        floor: Floor::Box,
    };
    let mut out = vec![
        bullet(Role::Reference, cfg.reference_dt, false),
        bullet(Role::Levers, cfg.reference_dt, true),
    ];
    out.extend(cfg.ladder.iter().map(|&dt| bullet(Role::Ladder, dt, false)));
    let rapier: &[EngineKind] = match mode {
        Mode::ThreeD => &[EngineKind::Rapier],
        Mode::TwoD => &[EngineKind::Rapier, EngineKind::RapierLocked],
    };
    let engines = std::iter::once((EngineKind::Bullet, &cfg.dts))
        .chain(rapier.iter().map(|&e| (e, &cfg.rapier_dts)));
    for (engine, dts) in engines {
        for &dt in dts {
            for faithful in [true, false] {
                for floor in [Floor::Box, Floor::Plane] {
                    out.push(Method {
                        role: Role::Method,
                        engine,
                        dt,
                        faithful,
                        floor,
                    });
                }
            }
        }
    }
    out
}

/// A method that fails (non-finite, tunnelled, engine error) or does not settle on more than
/// this fraction of its rolls is not a candidate, however close its ratio from the rest.
pub const MAX_BAD_FRACTION: f64 = 0.01;

fn eligible(r: &Row) -> bool {
    r.resolved
        && r.error.is_finite()
        && ((r.failed + r.unconverged) as f64) <= MAX_BAD_FRACTION * r.rolls as f64
}

/// The Pareto front in cost and |error| over eligible (resolved) methods: sorted by cost, each
/// method closer to the reference than every cheaper one.
pub fn pareto(rows: &[Row]) -> Vec<String> {
    let mut sorted: Vec<&Row> = rows.iter().filter(|r| eligible(r)).collect();
    sorted.sort_by(|a, b| a.cpu_s_per_1000.total_cmp(&b.cpu_s_per_1000));
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for r in sorted {
        if r.error.abs() < best {
            best = r.error.abs();
            front.push(r.method.clone());
        }
    }
    front
}

/// One block and mode: its reference first, then its checks, then its methods, each a stream.
struct Group {
    block: Block,
    mode: Mode,
    streams: Vec<(Method, Stream)>,
}

impl Group {
    fn cpu_s(&self) -> f64 {
        self.streams.iter().map(|(_, s)| s.cpu_s).sum()
    }

    fn streams(&self) -> Vec<&Stream> {
        self.streams.iter().map(|(_, s)| s).collect()
    }
}

/// What the pilot says the rest costs: at the precision asked (budgets as given), at 1 % (no
/// budget), and the precision an hour of the run's threads buys.
#[derive(Clone, Copy)]
struct Plan {
    planned: f64,
    at_one: f64,
    in_an_hour: f64,
}

fn plan(cfg: &Config, groups: &[&Group], threads: usize) -> Plan {
    let streams: Vec<Vec<&Stream>> = groups.iter().map(|g| g.streams()).collect();
    let spent = groups.iter().map(|g| g.cpu_s()).sum();
    Plan {
        planned: plan_cpu(
            &streams,
            cfg.precision,
            Some((cfg.reference_budget_s, cfg.budget_s)),
        ),
        at_one: plan_cpu(&streams, 0.01, None),
        in_an_hour: precision_in_an_hour(&streams, threads, spent),
    }
}

/// One stream per method of every block and mode, in the order they are resolved.
fn groups(cfg: &Config, modes: &[Mode]) -> Vec<Group> {
    let mut groups = Vec::new();
    for &block in &cfg.blocks {
        for &mode in modes {
            let streams = methods(cfg, mode)
                .into_iter()
                .map(|m| (m, m.stream(cfg, block, mode)))
                .collect();
            groups.push(Group {
                block,
                mode,
                streams,
            });
        }
    }
    groups
}

/// A block's result: its plan, and its modes' results (none when only planned), its CPU the
/// rolls they hold.
fn one_block(cfg: &Config, block: Block, p: Plan, modes: Vec<ModeResult>) -> Tradeoff {
    let cpu_s = modes
        .iter()
        .flat_map(|m| {
            m.rows
                .iter()
                .chain(&m.checks)
                .chain(std::iter::once(&m.reference))
        })
        .map(|r| r.cpu_s_per_1000 * r.rolls as f64 / 1000.0)
        .sum();
    Tradeoff {
        block: block.to_string(),
        precision: cfg.precision,
        budget_s: cfg.budget_s,
        seed: cfg.seed,
        reference_dt: cfg.reference_dt,
        planned_cpu_s: p.planned,
        planned_cpu_s_at_one_percent: p.at_one,
        precision_in_an_hour: p.in_an_hour,
        cpu_s,
        modes,
    }
}

/// The whole study's result from its blocks' and its plan.
fn result(
    cfg: &Config,
    modes: &[Mode],
    p: Plan,
    cpu_s: f64,
    per_block: Vec<Tradeoff>,
) -> TradeoffBlocks {
    TradeoffBlocks {
        blocks: cfg.blocks.iter().map(|b| b.to_string()).collect(),
        precision: cfg.precision,
        budget_s: cfg.budget_s,
        reference_budget_s: cfg.reference_budget_s,
        seed: cfg.seed,
        reference_dt: cfg.reference_dt,
        planned_cpu_s: p.planned,
        planned_cpu_s_at_one_percent: p.at_one,
        precision_in_an_hour: p.in_an_hour,
        cpu_s,
        across: modes
            .iter()
            .map(|&mode| across(cfg, &per_block, mode))
            .collect(),
        per_block,
    }
}

/// Logs what the pilot says the rest costs, block by block where there are several.
fn log_plan(
    cfg: &Config,
    log: &dyn Fn(&str),
    pilot: f64,
    whole: Plan,
    blocks: &[Plan],
    threads: usize,
) {
    if cfg.blocks.len() > 1 {
        for (b, p) in cfg.blocks.iter().zip(blocks) {
            log(&format!(
                "plan for {b}: at ±{:.2} % the rest takes about {:.0} CPU s; ±1 % would take \
                 {:.0} CPU s",
                100.0 * cfg.precision,
                p.planned,
                p.at_one
            ));
        }
    }
    log(&format!(
        "plan: the pilot took {:.0} CPU s; at ±{:.2} % (2σ, budgets as given) the rest takes \
         about {:.0} CPU s ({:.1} min on {} threads); ±1 % would take {:.0} CPU s ({:.1} h); \
         an hour on {} threads buys {}",
        pilot,
        100.0 * cfg.precision,
        whole.planned,
        whole.planned / 60.0 / threads as f64,
        threads,
        whole.at_one,
        whole.at_one / 3600.0 / threads as f64,
        threads,
        hour_buys(whole.in_an_hour)
    ));
}

/// Resolves one block and mode: the reference to 2σ ≤ precision/2, in rounds, then every
/// method against it; `progress` is given the CPU spent so far (`done_cpu`, kept up to date).
fn resolve_group(
    cfg: &Config,
    g: Group,
    study: &Study,
    log: &dyn Fn(&str),
    done_cpu: &mut f64,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<ModeResult> {
    let mode = g.mode;
    if cfg.blocks.len() > 1 {
        log(&format!("{} {}:", g.block, mode.name()));
    }
    let mut streams = g.streams;
    let (rm, rest) = streams.split_first_mut().expect("the reference is first");
    let reference = &mut rm.1;
    let (base, before) = (*done_cpu, reference.cpu_s);
    resolve_reference(
        reference,
        cfg.precision,
        cfg.reference_budget_s,
        study,
        &|c| progress(base + c),
    )?;
    *done_cpu += reference.cpu_s - before;
    let mut rows = Vec::new();
    let mut checks = Vec::new();
    for (m, s) in rest.iter_mut() {
        let (base, before) = (*done_cpu, s.cpu_s);
        resolve_departure(s, reference, cfg.precision, cfg.budget_s, study, &|c| {
            progress(base + c)
        })?;
        *done_cpu += s.cpu_s - before;
        let row = row(cfg, mode, m, s, Some(reference));
        log(&format_row(&row));
        if m.role == Role::Method {
            rows.push(row);
        } else {
            checks.push(row);
        }
    }
    let reference_row = row(cfg, mode, &rm.0, reference, None);
    log(&format!("{}  (reference)", format_row(&reference_row)));
    let pareto_front = pareto(&rows);
    let best = cheapest(cfg, rows.iter());
    let note = note(cfg, &reference_row, &rows, best);
    let cheapest_within = best.map(|r| r.method.clone());
    Ok(ModeResult {
        mode,
        reference: reference_row,
        checks,
        rows,
        pareto_front,
        cheapest_within,
        note,
    })
}

/// Measures every method against its reference, block by block and mode by mode, to the
/// precision asked, logging the plan and each method as it is resolved, reporting progress in
/// estimated CPU seconds. Two other modes end early: rolling ahead (`preroll_chunks`) and
/// the plan alone (`plan_only`).
pub fn run(
    cfg: &Config,
    study: &Study,
    log: &dyn Fn(&str),
    progress: Progress,
) -> Result<TradeoffBlocks> {
    cfg.validate()?;
    let modes = cfg.modes_in_order();
    let mut groups = groups(cfg, &modes);
    let threads = study.runner.threads;
    // Rolling ahead: the same chunks whatever the results, so a cluster's tasks, each seeing
    // only its share, agree on which chunk is whose.
    if let Some(k) = cfg.preroll_chunks {
        for g in groups.iter_mut() {
            for (_, s) in g.streams.iter_mut() {
                s.extend(k, study, &|_| {})?;
            }
        }
        let nothing = Plan {
            planned: 0.0,
            at_one: 0.0,
            in_an_hour: f64::NAN,
        };
        let cpu = groups.iter().map(Group::cpu_s).sum();
        let per_block = cfg
            .blocks
            .iter()
            .map(|&b| one_block(cfg, b, nothing, Vec::new()))
            .collect();
        return Ok(result(cfg, &modes, nothing, cpu, per_block));
    }
    // The pilot: a chunk of every stream, its cost and its variance.
    for g in groups.iter_mut() {
        for (_, s) in g.streams.iter_mut() {
            s.extend(PILOT_CHUNKS, study, &|_| {})?;
        }
    }
    let pilot: f64 = groups.iter().map(Group::cpu_s).sum();
    let of_block = |b: Block| -> Vec<&Group> { groups.iter().filter(|g| g.block == b).collect() };
    let block_plans: Vec<Plan> = cfg
        .blocks
        .iter()
        .map(|&b| plan(cfg, &of_block(b), threads))
        .collect();
    let whole = plan(cfg, &groups.iter().collect::<Vec<_>>(), threads);
    log_plan(cfg, log, pilot, whole, &block_plans, threads);
    if cfg.plan_only {
        let per_block = cfg
            .blocks
            .iter()
            .zip(&block_plans)
            .map(|(&b, &p)| Tradeoff {
                cpu_s: of_block(b).iter().map(|g| g.cpu_s()).sum(),
                ..one_block(cfg, b, p, Vec::new())
            })
            .collect();
        return Ok(result(cfg, &modes, whole, pilot, per_block));
    }
    // Progress counts the planned rolls only (the pilot is done), so that the bar's rate, and
    // its ETA, are this run's.
    let total = whole.planned;
    let mut done_cpu = pilot;
    progress(0.0, total);
    let mut results: Vec<(Block, ModeResult)> = Vec::new();
    for g in groups {
        let block = g.block;
        let m = resolve_group(cfg, g, study, log, &mut done_cpu, &|c| {
            progress(c - pilot, total)
        })?;
        results.push((block, m));
    }
    progress(total, total);
    let per_block: Vec<Tradeoff> = cfg
        .blocks
        .iter()
        .zip(&block_plans)
        .map(|(&b, &p)| {
            let modes = results
                .iter()
                .filter(|(x, _)| *x == b)
                .map(|(_, m)| m.clone())
                .collect();
            one_block(cfg, b, p, modes)
        })
        .collect();
    let cpu_s = per_block.iter().map(|t| t.cpu_s).sum();
    Ok(result(cfg, &modes, whole, cpu_s, per_block))
}

/// The cheapest eligible (resolved) method whose |departure| is within the precision.
fn cheapest<'a>(cfg: &Config, rows: impl Iterator<Item = &'a Row>) -> Option<&'a Row> {
    rows.filter(|r| eligible(r) && r.error.abs() <= cfg.precision)
        .min_by(|a, b| a.cpu_s_per_1000.total_cmp(&b.cpu_s_per_1000))
}

/// Each method of `mode` across the blocks: its worst departure, on how many blocks it is
/// resolved, whether it is within the precision on every one, its mean cost; and the cheapest
/// method within the precision on every block at once.
fn across(cfg: &Config, per_block: &[Tradeoff], mode: Mode) -> ModeAcross {
    let rows_of = |t: &Tradeoff| -> Vec<Row> {
        t.modes
            .iter()
            .filter(|m| m.mode == mode)
            .flat_map(|m| m.rows.clone())
            .collect()
    };
    let names: Vec<String> = per_block
        .first()
        .map(|t| rows_of(t).into_iter().map(|r| r.method).collect())
        .unwrap_or_default();
    let mut methods = Vec::new();
    for name in names {
        let on: Vec<(&str, Row)> = per_block
            .iter()
            .filter_map(|t| {
                rows_of(t)
                    .into_iter()
                    .find(|r| r.method == name)
                    .map(|r| (t.block.as_str(), r))
            })
            .collect();
        // NaN (a ratio with no width-vertical throws) counts as the worst.
        let size = |r: &Row| {
            if r.error.is_nan() {
                f64::INFINITY
            } else {
                r.error.abs()
            }
        };
        let Some((block, worst)) = on.iter().max_by(|a, b| size(&a.1).total_cmp(&size(&b.1)))
        else {
            continue;
        };
        let within = |r: &Row| eligible(r) && r.error.abs() <= cfg.precision;
        methods.push(MethodAcross {
            method: name.clone(),
            worst_error: worst.error,
            worst_error_err: worst.error_err,
            worst_block: block.to_string(),
            resolved_on: on.iter().filter(|(_, r)| eligible(r)).count() as u64,
            within_everywhere: on.len() == per_block.len() && on.iter().all(|(_, r)| within(r)),
            cpu_s_per_1000: on.iter().map(|(_, r)| r.cpu_s_per_1000).sum::<f64>() / on.len() as f64,
        });
    }
    let cheapest = methods
        .iter()
        .filter(|m| m.within_everywhere)
        .min_by(|a, b| a.cpu_s_per_1000.total_cmp(&b.cpu_s_per_1000))
        .map(|m| m.method.clone());
    let note = across_note(cfg, per_block.len(), &methods, &cheapest);
    ModeAcross {
        mode,
        methods,
        cheapest_everywhere: cheapest,
        note,
    }
}

fn across_note(
    cfg: &Config,
    blocks: usize,
    methods: &[MethodAcross],
    cheapest: &Option<String>,
) -> String {
    let p = 100.0 * cfg.precision;
    let within: Vec<&str> = methods
        .iter()
        .filter(|m| m.within_everywhere)
        .map(|m| m.method.as_str())
        .collect();
    match cheapest
        .as_ref()
        .and_then(|c| methods.iter().find(|m| &m.method == c))
    {
        Some(m) => format!(
            "{} is the cheapest method within ±{p:.2} % of the reference on all {blocks} blocks \
             (resolved at 2σ), at {:.3} CPU s per 1,000 rolls on average; its worst departure is \
             {:+.2} ± {:.2} % (2σ) on {}. Within ±{p:.2} % on every block: {}.",
            m.method,
            m.cpu_s_per_1000,
            100.0 * m.worst_error,
            200.0 * m.worst_error_err,
            m.worst_block,
            within.join("; ")
        ),
        None => format!(
            "No method is resolved within ±{p:.2} % of the reference on all {blocks} blocks."
        ),
    }
}

fn row(cfg: &Config, mode: Mode, m: &Method, s: &Stream, reference: Option<&Stream>) -> Row {
    let res = s.measured();
    let r = res.ratio();
    let d = match reference {
        Some(rf) => paired_departure(s, rf),
        None => Departure::zero(),
    };
    let (resolved, rolls_needed) = match reference {
        Some(rf) => (
            2.0 * d.err <= cfg.precision,
            chunks_to_resolve(&d, rf.rolls(), cfg.precision, NO_BUDGET).map(|k| k * CHUNK_ROLLS),
        ),
        None => {
            let need = rolls_for_ratio(s, 0.5 * cfg.precision);
            (need.is_some_and(|n| n <= s.rolls()), need)
        }
    };
    Row {
        method: m.name(mode),
        role: m.role,
        engine: m.engine,
        mode,
        dt: m.dt,
        rule: if m.faithful { "faithful" } else { "fast" }.into(),
        floor: m.floor,
        rolls: res.tally.rolls,
        ratio: r.value,
        ratio_err: r.err,
        cpu_s_per_1000: 1000.0 * res.cpu_s_per_roll(),
        steps_per_roll: res.steps_per_roll(),
        error: d.value,
        error_err: d.err,
        error_err_unpaired: d.err_unpaired,
        agreement: d.agreement,
        error_sigma: if d.err > 0.0 { d.value / d.err } else { 0.0 },
        resolved,
        rolls_needed: (!resolved).then_some(rolls_needed).flatten(),
        unconverged: res.tally.unconverged,
        failed: res.tally.failed_total(),
        energy_gain: res.tally.energy_gain,
        dipped: res.tally.dipped,
        reference: reference.is_none(),
    }
}

fn note(cfg: &Config, reference: &Row, rows: &[Row], cheapest: Option<&Row>) -> String {
    let p = 100.0 * cfg.precision;
    let mut s = match cheapest.map(|r| &r.method) {
        Some(m) => format!(
            "{m} is the cheapest method within ±{p:.2} % of the reference (resolved at 2σ)."
        ),
        None => format!("No resolved method is within {p:.2} % of the reference."),
    };
    if !reference.resolved {
        s += &format!(
            " The reference is not resolved to ±{:.2} % (2σ) within its budget: it needs about {} rolls.",
            p / 2.0,
            reference.rolls_needed.unwrap_or(0)
        );
    }
    let open: Vec<String> = rows
        .iter()
        .filter(|r| !r.resolved)
        .map(|r| match r.rolls_needed {
            Some(n) => format!("{} (needs about {n} rolls)", r.method),
            None => format!("{} (not with this reference)", r.method),
        })
        .collect();
    if !open.is_empty() {
        s += &format!(
            " Unresolved within the budget ({:.0} CPU s a method), off the front: {}.",
            cfg.budget_s,
            open.join("; ")
        );
    }
    s
}

/// What an hour buys, in words: `precision_in_an_hour` searches up to ±50 %, so at that bound
/// it means "±50 % or worse", not ±50 %.
fn hour_buys(p: f64) -> String {
    if p >= PRECISION_SEARCH_MAX {
        "no better than ±50 %".into()
    } else {
        format!("±{:.2} %", 100.0 * p)
    }
}
