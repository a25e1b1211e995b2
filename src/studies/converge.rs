//! `dicephys converge`: the paper's convergence test. For each block, engine and 2D/3D the
//! ratio at every dt, and its relative departure from the finest dt's. The paper claims that
//! dt = 0.001 s is within 1 % of dt = 0.0001 s; here that is tested as 0.001 s against the
//! finest dt of the run, and the verdict says whether the data can resolve 1 % at all.
//!
//! Rolls end by DicePhys's own rule with every step stepped (no early stop, no closed-form
//! flight): this is a study of the integrator, so nothing else may change with dt.

use super::departure::{
    paired_departure, rolls_for_one_percent, rolls_for_ratio, unpaired_departure, Departure,
};
use super::precision::{plan_cpu, resolve_departure, resolve_reference};
use super::stream::Stream;
use super::study::{Progress, Study};
use super::sweep::{
    cell_spec, check_budget, check_rolls_and_steps, measure, nonempty, Measured, ONE_PERCENT,
};
use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::block::Block;
use crate::model::scene::{Mode, Scene};
use crate::report::converge::{format_cell, Cell, Claim, Converge};
use crate::report::text::dt_label;
use crate::sim::roll::{RollConfig, Rule};
use serde::{Deserialize, Serialize};

/// What the convergence test runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The blocks.
    pub blocks: Vec<Block>,
    /// The time steps, s (`run` sorts them coarse to fine, without repeats).
    pub dts: Vec<f64>,
    /// The engines.
    pub engines: Vec<EngineKind>,
    /// Rolls per cell.
    pub rolls: u64,
    /// The throws' seed (keyed throws, the same in every cell).
    pub seed: u64,
    /// The step cap per roll.
    pub max_steps: u64,
    /// Precision as the input: every cell's departure from the finest dt rolled in rounds of
    /// one keyed stream until its 2σ is at most this (a fraction), the finest to half of it;
    /// `rolls` is then ignored.
    pub precision: Option<f64>,
    /// With `precision`: CPU seconds a cell may spend.
    pub budget_s: f64,
    /// With `precision`: CPU seconds the finest dt's cell may spend.
    pub reference_budget_s: f64,
    /// Roll with the exact levers (early stop, closed-form flight) instead of DicePhys's rule
    /// with every step stepped.
    pub fast: bool,
}

impl Default for Config {
    /// `dicephys converge` with no flags: three of the paper's blocks at four steps from
    /// 1/60 to 1/5000 s on both engines, 200 rolls a cell, DicePhys's rule.
    fn default() -> Config {
        let b = |s: &str| s.parse::<Block>().expect("a valid block");
        Config {
            blocks: vec![b("140x24x20"), b("140x22x13"), b("140x30x10")],
            dts: vec![1.0 / 60.0, 1.0 / 250.0, 1.0 / 1000.0, 1.0 / 5000.0],
            engines: crate::studies::paper::DEFAULT_ENGINES.to_vec(),
            rolls: 200,
            seed: crate::model::throws::DEFAULT_SEED,
            max_steps: 2_000_000,
            precision: None,
            budget_s: 600.0,
            reference_budget_s: 1800.0,
            fast: false,
        }
    }
}

impl Cell {
    /// A cell from its measurement and its departure (value, error) from the finest dt.
    fn of(
        block: &Block,
        engine: EngineKind,
        mode: Mode,
        dt: f64,
        m: &Measured,
        (departure, departure_err): (f64, f64),
        resolved: Option<bool>,
    ) -> Cell {
        let r = m.ratio();
        Cell {
            block: block.to_string(),
            engine: engine.name().into(),
            mode: mode.name().into(),
            dt,
            rolls: m.tally.rolls,
            ratio: r.value,
            ratio_err: r.err,
            steps_per_roll: m.steps_per_roll(),
            cpu_s_per_roll: m.cpu_s_per_roll(),
            unconverged: m.tally.unconverged,
            failed: m.tally.failed_total(),
            energy_gain: m.tally.energy_gain,
            departure,
            departure_err,
            resolved,
        }
    }
}

impl Claim {
    /// The claim about a cell at `CLAIM_DT` against the finest dt: its departure and error,
    /// resolved when 2σ ≤ 1 %, decided at 2σ (`decide`).
    fn of(
        cell: &Cell,
        dt_finest: f64,
        (departure, departure_err): (f64, f64),
        rolls_needed: Option<u64>,
        rolls: (u64, u64),
    ) -> Claim {
        Claim {
            block: cell.block.clone(),
            engine: cell.engine.clone(),
            mode: cell.mode.clone(),
            dt: cell.dt,
            dt_finest,
            departure,
            departure_err,
            resolved: 2.0 * departure_err <= ONE_PERCENT,
            within_one_percent: decide(departure, departure_err),
            rolls_needed,
            rolls,
        }
    }
}

impl Config {
    /// What makes two runs of it one run (`StudyConfig::identity`): rolled to a precision, less
    /// the precision, the budgets and the rolls it sets.
    pub fn identity(&self) -> Config {
        if self.precision.is_none() {
            return self.clone();
        }
        Config {
            precision: Some(0.0),
            budget_s: 0.0,
            reference_budget_s: 0.0,
            rolls: 0,
            ..self.clone()
        }
    }

    /// Checks every value before anything runs.
    pub fn validate(&self) -> Result<()> {
        nonempty(&self.blocks, Field::Blocks)?;
        nonempty(&self.dts, Field::Dts)?;
        nonempty(&self.engines, Field::Engines)?;
        check_rolls_and_steps(self.rolls, self.max_steps)?;
        check_budget(self.budget_s, Field::BudgetS)?;
        check_budget(self.reference_budget_s, Field::ReferenceBudgetS)
    }
}

/// The dt the paper's claim is about.
pub const CLAIM_DT: f64 = 0.001;

/// Runs the convergence test, logging each cell as it is measured.
pub fn run(
    cfg: &Config,
    study: &Study,
    log: &dyn Fn(&str),
    progress: Progress,
) -> Result<Converge> {
    cfg.validate()?;
    let mut dts = cfg.dts.clone();
    dts.sort_by(|a, b| b.total_cmp(a));
    dts.dedup();
    let finest = *dts
        .last()
        .ok_or_else(|| Error::Invalid("no dt given".into()))?;
    if let Some(p) = cfg.precision {
        return run_resolved(cfg, p, &dts, study, log, progress);
    }
    let settle = settle(cfg, finest);
    let mut cells = Vec::new();
    let mut claims = Vec::new();
    // Progress in cells.
    let total = (cfg.blocks.len() * cfg.engines.len() * 2 * dts.len()) as f64;
    for block in &cfg.blocks {
        for &engine in &cfg.engines {
            for mode in [Mode::ThreeD, Mode::TwoD] {
                let mut row = Vec::new();
                for &dt in &dts {
                    let mut scene = Scene::paper(*block, mode);
                    scene.dt = dt;
                    let m = measure(
                        &cell_spec(engine, scene, settle, cfg.seed, cfg.rolls),
                        study,
                    )?;
                    row.push((dt, m));
                    progress((cells.len() + row.len()) as f64, total);
                }
                let reference = row
                    .last()
                    .map(|(_, m)| m.ratio())
                    .ok_or_else(|| Error::Invalid("no dt given".into()))?;
                for (dt, m) in &row {
                    let r = m.ratio();
                    let (d, d_err) = unpaired_departure(r, reference);
                    let cell = Cell::of(block, engine, mode, *dt, m, (d, d_err), None);
                    log(&format_cell(&cell));
                    if (dt - CLAIM_DT).abs() < 1e-12 && *dt > finest {
                        claims.push(Claim::of(
                            &cell,
                            finest,
                            (d, d_err),
                            rolls_for_one_percent(d_err, cfg.rolls),
                            (cfg.rolls, cfg.rolls),
                        ));
                    }
                    cells.push(cell);
                }
            }
        }
    }
    let resolved = !claims.is_empty() && claims.iter().all(|c| c.resolved);
    let verdict = verdict(
        &claims,
        finest,
        &format!("with {} rolls per cell", cfg.rolls),
    );
    Ok(Converge {
        settle: settle_words(cfg),
        rolls: cfg.rolls,
        seed: cfg.seed,
        dts,
        max_steps: cfg.max_steps,
        cells,
        claims,
        resolved,
        verdict,
    })
}

/// How rolls end: DicePhys's rule, every step stepped; or, with `fast`, the exact levers
/// (at every dt of a convergence test the early stop is exact only at dt <= 1/250 s, so it
/// is used there only, as in `roll`).
fn settle(cfg: &Config, dt: f64) -> RollConfig {
    RollConfig {
        max_steps: cfg.max_steps,
        rule: if cfg.fast && crate::sim::roll::early_stop_exact(dt) {
            Rule::Certificate
        } else {
            Rule::Dicephys
        },
        fast_flight: cfg.fast,
        ..RollConfig::default()
    }
}

fn settle_words(cfg: &Config) -> String {
    if cfg.fast {
        "the exact levers: closed-form flight, the early stop at dt <= 1/250 s (else DicePhys's rule)".into()
    } else {
        "dicephys rest rule, every step stepped (faithful)".into()
    }
}

/// A block, engine and mode, and its streams, one per dt, the finest first (the group's
/// reference).
struct DtGroup {
    block: Block,
    engine: EngineKind,
    mode: Mode,
    streams: Vec<(f64, Stream)>,
}

/// One group per block, engine and mode.
fn dt_groups(cfg: &Config, dts: &[f64]) -> Vec<DtGroup> {
    let mut groups = Vec::new();
    for &block in &cfg.blocks {
        for &engine in &cfg.engines {
            for mode in [Mode::ThreeD, Mode::TwoD] {
                let streams: Vec<(f64, Stream)> = dts
                    .iter()
                    .rev()
                    .map(|&dt| {
                        let mut scene = Scene::paper(block, mode);
                        scene.dt = dt;
                        (dt, Stream::new(engine, scene, settle(cfg, dt), cfg.seed))
                    })
                    .collect();
                groups.push(DtGroup {
                    block,
                    engine,
                    mode,
                    streams,
                });
            }
        }
    }
    groups
}

/// Logs what the pilot says the rest costs; returns the CPU seconds it plans within the
/// budgets.
fn plan_rest(
    cfg: &Config,
    precision: f64,
    groups: &[DtGroup],
    spent: f64,
    log: &dyn Fn(&str),
) -> f64 {
    let plan: Vec<Vec<&Stream>> = groups
        .iter()
        .map(|g| g.streams.iter().map(|(_, s)| s).collect())
        .collect();
    let total = plan_cpu(
        &plan,
        precision,
        Some((cfg.reference_budget_s, cfg.budget_s)),
    );
    log(&format!(
        "plan: the pilot took {spent:.0} CPU s; ±{:.2} % (2σ) takes about {total:.0} CPU s \
         more within the budgets, {:.0} without; ±1 % {:.0} CPU s",
        100.0 * precision,
        plan_cpu(&plan, precision, None),
        plan_cpu(&plan, ONE_PERCENT, None),
    ));
    total
}

/// A resolved group's cells, coarse to fine as without --precision, each logged; and its
/// claim, where it has `CLAIM_DT` and a finer dt.
fn cells_of(
    g: &DtGroup,
    precision: f64,
    finest: f64,
    log: &dyn Fn(&str),
) -> (Vec<Cell>, Option<Claim>) {
    let streams = &g.streams;
    let mut cells = Vec::new();
    let mut claim = None;
    for (dt, s) in streams.iter().rev() {
        let is_ref = *dt == finest;
        let d = if is_ref {
            Departure::zero()
        } else {
            paired_departure(s, &streams[0].1)
        };
        let m = s.measured();
        let resolved = if is_ref {
            rolls_for_ratio(s, 0.5 * precision).is_some_and(|n| n <= s.rolls())
        } else {
            2.0 * d.err <= precision
        };
        let cell = Cell::of(
            &g.block,
            g.engine,
            g.mode,
            *dt,
            &m,
            (d.value, d.err),
            Some(resolved),
        );
        log(&format_cell(&cell));
        if (dt - CLAIM_DT).abs() < 1e-12 && *dt > finest {
            claim = Some(Claim::of(
                &cell,
                finest,
                (d.value, d.err),
                d.rolls_both(ONE_PERCENT),
                (s.rolls(), streams[0].1.rolls()),
            ));
        }
        cells.push(cell);
    }
    (cells, claim)
}

/// The convergence test with precision as the input: per block × engine × mode, the finest
/// dt's stream to 2σ ≤ precision/2 of its own ratio, then every other dt's departure from it
/// to 2σ ≤ precision, in rounds of one keyed stream each, within the budgets.
fn run_resolved(
    cfg: &Config,
    precision: f64,
    dts: &[f64],
    study: &Study,
    log: &dyn Fn(&str),
    progress: Progress,
) -> Result<Converge> {
    let finest = *dts
        .last()
        .ok_or_else(|| Error::Invalid("no dt given".into()))?;
    let mut groups = dt_groups(cfg, dts);
    let mut spent = 0.0;
    for g in groups.iter_mut() {
        for (_, s) in g.streams.iter_mut() {
            s.extend(1, study, &|_| {})?;
            spent += s.cpu_s;
        }
    }
    let total = plan_rest(cfg, precision, &groups, spent, log);
    let mut done = 0.0;
    progress(0.0, total);
    let mut cells = Vec::new();
    let mut claims = Vec::new();
    for mut g in groups {
        let (reference, rest) = g.streams.split_first_mut().expect("a dt is given");
        let before = reference.1.cpu_s;
        let base = done;
        resolve_reference(
            &mut reference.1,
            precision,
            cfg.reference_budget_s,
            study,
            &|c| progress(base + c, total),
        )?;
        done += reference.1.cpu_s - before;
        for (_, s) in rest.iter_mut() {
            let (base, before) = (done, s.cpu_s);
            resolve_departure(s, &reference.1, precision, cfg.budget_s, study, &|c| {
                progress(base + c, total)
            })?;
            done += s.cpu_s - before;
        }
        let (c, claim) = cells_of(&g, precision, finest, log);
        cells.extend(c);
        claims.extend(claim);
    }
    let resolved = !claims.is_empty() && claims.iter().all(|c| c.resolved);
    let verdict = verdict(
        &claims,
        finest,
        &format!(
            "rolled to ±{:.2} % (2σ) within the budgets ({} and {} CPU s a cell)",
            100.0 * precision,
            cfg.budget_s,
            cfg.reference_budget_s
        ),
    );
    Ok(Converge {
        settle: settle_words(cfg),
        rolls: cfg.rolls,
        seed: cfg.seed,
        dts: dts.to_vec(),
        max_steps: cfg.max_steps,
        cells,
        claims,
        resolved,
        verdict,
    })
}

fn verdict(claims: &[Claim], finest: f64, how: &str) -> String {
    if claims.is_empty() {
        return format!(
            "The paper's claim (dt = 0.001 s within 1 % of 0.0001 s) is not tested: the run \
             needs dt = 1/1000 and a finer dt (finest here {}).",
            dt_label(finest)
        );
    }
    let vs = if (finest - 1e-4).abs() < 1e-12 {
        "0.0001 s, as the paper".to_string()
    } else {
        format!(
            "the finest dt here, {} s (the paper: 0.0001 s)",
            dt_label(finest)
        )
    };
    let name = |c: &Claim| format!("{} {} {}", c.block, c.engine, c.mode);
    let unresolved: Vec<&Claim> = claims.iter().filter(|c| !c.resolved).collect();
    // A departure whose 2σ interval lies wholly beyond ±1 % decides "no" before 2σ ≤ 1 %.
    let no: Vec<String> = claims
        .iter()
        .filter(|c| c.within_one_percent == Some(false))
        .map(|c| {
            format!(
                "{} ({:+.1} ± {:.1} %)",
                name(c),
                100.0 * c.departure,
                200.0 * c.departure_err
            )
        })
        .collect();
    let beyond = if no.is_empty() {
        String::new()
    } else {
        format!(
            " dt = 0.001 s departs by more than 1 % from {vs} (2σ) for {}.",
            no.join(", ")
        )
    };
    if unresolved.is_empty() {
        if no.is_empty() {
            format!("Resolved: dt = 0.001 s is within 1 % of {vs} in every cell (2σ ≤ 1 %).")
        } else {
            format!("Resolved:{beyond}")
        }
    } else {
        let need = |c: &&&Claim| c.rolls_needed.unwrap_or(u64::MAX);
        let open: Vec<&&Claim> = unresolved
            .iter()
            .filter(|c| c.within_one_percent.is_none())
            .collect();
        if open.is_empty() {
            return format!("Decided at 2σ, not within 1 %:{beyond}");
        }
        let (Some(least), Some(most)) = (
            open.iter().copied().min_by_key(need),
            open.iter().copied().max_by_key(need),
        ) else {
            return String::new();
        };
        format!(
            "Not resolved: {how}, the departure of dt = 0.001 s from {vs} is \
             known only to ±{:.0} % to ±{:.0} % (2σ), so 1 % cannot be told from 0 ({} of {} \
             cells open). Resolving it needs about {} rolls per cell for {} and {} for {} \
             (small ratios need the most).{beyond}",
            100.0 * 2.0 * least.departure_err,
            100.0 * 2.0 * most.departure_err,
            open.len(),
            claims.len(),
            least.rolls_needed.unwrap_or(0),
            name(least),
            most.rolls_needed
                .map_or("unknown".into(), |n| n.to_string()),
            name(most),
        )
    }
}

/// The paper's claim for one departure d ± err (1σ), at 2σ: `Some(true)` if 2σ ≤ 1 % and
/// |d| ≤ 1 %; `Some(false)` if 2σ ≤ 1 % and |d| > 1 %, or if |d| − 2σ > 1 % (the interval
/// lies wholly beyond ±1 %); `None` while the interval straddles the line.
pub fn decide(d: f64, err: f64) -> Option<bool> {
    if !(d.is_finite() && err.is_finite()) {
        None
    } else if 2.0 * err <= ONE_PERCENT {
        Some(d.abs() <= ONE_PERCENT)
    } else if d.abs() - 2.0 * err > ONE_PERCENT {
        Some(false)
    } else {
        None
    }
}
