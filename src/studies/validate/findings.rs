//! A sentence per finding: what passed and failed per engine, where the dice ended against
//! where they started, what they did at the cap, the free flights, the trend.

use super::flight::at_one_ms;
use crate::engine::EngineKind;
use crate::model::scene::Mode;
use crate::report::text::dt_label;
use crate::report::validate::Config;
use crate::report::validate::{
    Case, FlightRun, Integrator, LimitCell, Row, TrendPoint, Verdict, Z_PASS,
};
use crate::theory;

/// A sentence per finding: what passed and failed per engine, what the dice did at the cap,
/// the trend.
pub(super) fn findings(
    cfg: &Config,
    rows: &[Row],
    cells: &[LimitCell],
    flights: &[FlightRun],
    trend: &[TrendPoint],
) -> Vec<String> {
    let mut out = Vec::new();
    for &engine in &cfg.engines {
        out.extend(of_engine(cfg, engine, rows, cells));
    }
    out.extend(of_flights(rows, flights));
    out.extend(of_trend(cfg, trend));
    out
}

/// An engine's limit rows passed and failed, where its dice released at rest ended, and those
/// still moving at the cap.
fn of_engine(cfg: &Config, engine: EngineKind, rows: &[Row], cells: &[LimitCell]) -> Vec<String> {
    let mut out = Vec::new();
    let mine: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            r.engine == engine.name()
                && matches!(
                    r.case,
                    Case::NoBounce2d | Case::Momentum2d | Case::QuasiStatic3d
                )
        })
        .collect();
    let fails: Vec<String> = mine
        .iter()
        .filter(|r| r.verdict == Verdict::Fail)
        .map(|r| format!("{} {} {} (z {:+.1})", r.case, r.subject, r.quantity, r.z))
        .collect();
    out.push(format!(
        "{engine}: {} of {} limit rows pass at |z| ≤ {Z_PASS}{}.",
        mine.len() - fails.len(),
        mine.len(),
        if fails.is_empty() {
            String::new()
        } else {
            format!("; fail: {}", fails.join(", "))
        }
    ));
    let mut where_started = Vec::new();
    for mode in [Mode::TwoD, Mode::ThreeD] {
        let (mut k, mut n) = (0, 0);
        for c in cells
            .iter()
            .filter(|c| c.engine == engine && c.mode == mode)
        {
            k += c.ended_where_started;
            n += c.ended_on_a_face;
        }
        if n > 0 {
            where_started.push(format!("{k} of {n} in {mode}"));
        }
    }
    if !where_started.is_empty() {
        out.push(format!(
            "{engine}: dice released at rest that ended on the face whose solid angle they \
             started in (the quasi-static flow's exact answer, throw by throw): {}.",
            where_started.join(", ")
        ));
    }
    let moving: Vec<String> = cells
        .iter()
        .filter(|c| c.engine == engine && c.moving_at_cap.total() > 0)
        .map(|c| {
            format!(
                "{} {} {}: {} of {}",
                c.mode,
                c.block,
                if c.damping > 0.0 {
                    "damped"
                } else {
                    "undamped"
                },
                c.moving_at_cap.total(),
                c.tally.rolls
            )
        })
        .collect();
    if !moving.is_empty() {
        out.push(format!(
            "{engine}: dice never at rest by DicePhys's rule within {} s with sleeping off \
             (creeping or rocking on a face; counted on it): {}.",
            cfg.max_steps as f64 * 0.001,
            moving.join("; ")
        ));
    }
    out
}

/// Each integrator's free flight at 1 ms: its energy lost and its drifts.
fn of_flights(rows: &[Row], flights: &[FlightRun]) -> Vec<String> {
    let mut out = Vec::new();
    let mut integrators: Vec<Integrator> = flights.iter().map(|f| f.integrator).collect();
    integrators.dedup();
    for i in integrators {
        let runs: Vec<FlightRun> = flights
            .iter()
            .filter(|f| f.integrator == i)
            .cloned()
            .collect();
        let Some(f) = at_one_ms(&runs) else { continue };
        let verdicts: Vec<String> = rows
            .iter()
            .filter(|r| r.case == Case::FreeFlight && r.engine == i.name())
            .map(|r| format!("{} {}", r.quantity, r.verdict))
            .collect();
        out.push(format!(
            "free flight, {} at dt {}: energy lost {:.4e} J (symplectic Euler: {:.4e}), \
             rotational energy drift {:.2e}, angular momentum drift {:.2e} ({}).",
            i.name(),
            dt_label(f.dt),
            f.translational_loss_j,
            f.symplectic_loss_j,
            f.rotational_energy_drift,
            f.angular_momentum_drift,
            verdicts.join(", ")
        ));
    }
    out
}

/// Each engine's trend from theory toward no bounce.
fn of_trend(cfg: &Config, trend: &[TrendPoint]) -> Vec<String> {
    let mut out = Vec::new();
    for &engine in &cfg.engines {
        let pts: Vec<String> = trend
            .iter()
            .filter(|p| p.engine == engine)
            .map(|p| {
                format!(
                    "e {} μ {}: {:.3} ± {:.3} ({:.0} %)",
                    p.restitution,
                    p.friction,
                    p.ratio,
                    p.ratio_err,
                    100.0 * p.towards_no_bounce
                )
            })
            .collect();
        if !pts.is_empty() {
            out.push(format!(
                "trend, {engine}, {} in 2D (theory {:.3}, no bounce {:.3}; in brackets the \
                 way from theory to no bounce): {}.",
                cfg.trend_block,
                theory::ratio_from_r(cfg.trend_block.r()),
                theory::no_bounce_ratio(cfg.trend_block.r()),
                pts.join("; ")
            ));
        }
    }
    out
}
