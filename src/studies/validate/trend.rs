//! The trend: the paper's throw in 2D as e and μ rise together, from near the no-bounce ratio
//! towards eq. (MasterEqu). A curve, not a verdict.

use super::rows::Rows;
use crate::error::Result;
use crate::model::scene::{Mode, Scene};
use crate::report::validate::Config;
use crate::report::validate::{Case, Row, TrendPoint, Verdict};
use crate::sim::roll::{RollConfig, Rule};
use crate::studies::study::Study;
use crate::studies::sweep::{cell_spec, measure};
use crate::theory;

/// The trend's scene: the paper's 2D scene for its block, with e and μ.
pub fn trend_scene(cfg: &Config, e: f64, mu: f64) -> Scene {
    let mut s = Scene::paper(cfg.trend_block, Mode::TwoD);
    s.restitution = e;
    s.friction = mu;
    s
}

/// The trend: per engine, the paper's throw in 2D at each (e, μ); a row pushed per point as
/// it is measured (a curve, not a verdict).
pub(super) fn points(cfg: &Config, study: &Study, rows: &mut Rows) -> Result<Vec<TrendPoint>> {
    let mut trend = Vec::new();
    for &engine in &cfg.engines {
        for &(e, mu) in &cfg.trend {
            let roll = RollConfig {
                max_steps: cfg.trend_max_steps,
                rule: Rule::Dicephys,
                fast_flight: true,
                ..RollConfig::default()
            };
            let m = measure(
                &cell_spec(
                    engine,
                    trend_scene(cfg, e, mu),
                    roll,
                    cfg.seed,
                    cfg.trend_rolls,
                ),
                study,
            )?;
            let r = m.ratio();
            let p = crate::theory::stats::probability(m.tally.counts.breadth, m.tally.counts.width);
            let big_r = cfg.trend_block.r();
            let (t, nb) = (theory::ratio_from_r(big_r), theory::no_bounce_ratio(big_r));
            let point = TrendPoint {
                engine,
                block: cfg.trend_block.to_string(),
                restitution: e,
                friction: mu,
                rolls: m.tally.rolls,
                ratio: r.value,
                ratio_err: r.err,
                theory: t,
                no_bounce: nb,
                towards_no_bounce: (r.value - t) / (nb - t),
                p_breadth: p.value,
                p_breadth_err: p.err,
                unconverged: m.tally.unconverged,
                energy_gain: m.tally.energy_gain,
            };
            let z = (r.value - t) / r.err;
            rows.push(Row {
                case: Case::Trend,
                engine: engine.name().into(),
                subject: format!("{} e {e} μ {mu}", cfg.trend_block),
                quantity: "ratio b/w vs (MasterEqu)".into(),
                closed_form: t,
                measured: r.value,
                err: r.err,
                n: m.tally.counts.breadth + m.tally.counts.width,
                z,
                verdict: Verdict::Curve,
                note: format!(
                    "{:.0} % of the way from (MasterEqu) {t:.3} to no bounce {nb:.3}{}{}",
                    100.0 * point.towards_no_bounce,
                    if m.tally.unconverged > 0 {
                        format!("; {} unconverged", m.tally.unconverged)
                    } else {
                        String::new()
                    },
                    if m.tally.energy_gain > 0 {
                        format!(
                            "; {} of {} rolls gained energy",
                            m.tally.energy_gain, m.tally.rolls
                        )
                    } else {
                        String::new()
                    }
                ),
                rolls_to_resolve: None,
            });
            trend.push(point);
        }
    }
    Ok(trend)
}
