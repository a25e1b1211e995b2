//! `dicephys validate`: the engines against the limits where a die's probabilities are known in
//! closed form (`dicephys::studies::validate`); writes `validate.json`, `report.md` and the
//! figures into --out.

use super::args::{parse_block, parse_engine};
use super::error::Result;
use super::sweeps::{check_common, finish, logged, to_json};
use clap::Args;
use dicephys::engine::EngineKind;
use dicephys::model::block::Block;
use dicephys::report::figures::validate as fig;
use dicephys::report::figures::Point;
use dicephys::studies::sweep::parse_dt;
use dicephys::studies::validate::{self as v, Case, Row, Validation};
use std::path::PathBuf;

/// `dicephys validate`'s arguments.
#[derive(Args, Debug)]
pub struct ValidateArgs {
    #[arg(long, value_delimiter = ',', default_value = "bullet,rapier", value_parser = parse_engine)]
    pub engines: Vec<EngineKind>,
    /// Rolls per limit cell (block × engine × case).
    #[arg(long, default_value_t = v::Config::default().rolls)]
    pub rolls: u64,
    /// Rolls per point of the trend.
    #[arg(long, default_value_t = v::Config::default().trend_rolls)]
    pub trend_rolls: u64,
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// The 2D no-bounce case's blocks (several R).
    #[arg(long = "blocks-2d", value_delimiter = ',', default_value = "140x24x24,140x24x20,140x22x13,140x30x10", value_parser = parse_block)]
    pub blocks_2d: Vec<Block>,
    /// The 3D quasi-static case's blocks (a cube, a square cuboid, three different sides).
    #[arg(long = "blocks-3d", value_delimiter = ',', default_value = "20x20x20,40x20x20,30x20x10", value_parser = parse_block)]
    pub blocks_3d: Vec<Block>,
    /// The trend's block (2D, the paper's throw).
    #[arg(long, default_value = "140x22x13", value_parser = parse_block)]
    pub trend_block: Block,
    /// The trend's points, E:MU, bouncier and grippier in turn ("none" skips it).
    #[arg(long, value_delimiter = ',', default_value = "0:0.1,0.2:0.29,0.5:0.5,0.7:1,0.9:1.5", value_parser = parse_point)]
    pub trend: Vec<Option<(f64, f64)>>,
    /// The free flight's time steps.
    #[arg(long, value_delimiter = ',', default_value = "1/60,1/250,1/1000,1/4000", value_parser = parse_dt)]
    pub flight_dts: Vec<f64>,
    /// The departure in probability each limit case should resolve at 3σ; a case whose rolls
    /// cannot says how many would.
    #[arg(long, default_value_t = v::Config::default().resolve)]
    pub resolve: f64,
    #[arg(long, default_value = "validate-out")]
    pub out: PathBuf,
    /// Print validate.json to stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `E:MU` (or `none`) as clap reads it.
fn parse_point(s: &str) -> std::result::Result<Option<(f64, f64)>, dicephys::Error> {
    if s.trim() == "none" {
        return Ok(None);
    }
    let bad = || dicephys::Error::Invalid(format!("trend point '{s}' is not E:MU (or none)"));
    let (e, mu) = s.split_once(':').ok_or_else(bad)?;
    Ok(Some((
        e.trim().parse().map_err(|_| bad())?,
        mu.trim().parse().map_err(|_| bad())?,
    )))
}

/// Runs `dicephys validate`.
pub fn run(a: &ValidateArgs) -> Result<()> {
    let cfg = v::Config {
        engines: a.engines.clone(),
        rolls: a.rolls,
        trend_rolls: a.trend_rolls,
        seed: a.seed,
        blocks_2d: a.blocks_2d.clone(),
        blocks_3d: a.blocks_3d.clone(),
        trend_block: a.trend_block,
        trend: a.trend.iter().flatten().copied().collect(),
        flight_dts: a.flight_dts.clone(),
        resolve: a.resolve,
        ..v::Config::default()
    };
    cfg.validate()?;
    let study = check_common(a.rolls, cfg.max_steps, a.threads, &a.out, "validate.json")?;
    let Some(res) = logged(a.json, &v::header(), |log| v::run(&cfg, &study, log))? else {
        return Ok(());
    };
    let figures = figures(&a.out, &res)?;
    finish(
        &a.out,
        "validate.json",
        &to_json(&res)?,
        &report(&res, &figures),
        a.json,
    )
}

fn rows(res: &Validation, case: Case) -> impl Iterator<Item = &Row> {
    res.rows.iter().filter(move |r| r.case == case)
}

/// Draws the figures; returns their stems.
fn figures(out: &std::path::Path, res: &Validation) -> Result<Vec<&'static str>> {
    let cfg = &res.config;
    let mut stems = Vec::new();
    let mut s2 = Vec::new();
    for e in &cfg.engines {
        for (case, what, triangles) in [
            (Case::NoBounce2d, "over-damped", false),
            (Case::Momentum2d, "damping lifted", true),
        ] {
            let points: Vec<Point> = cfg
                .blocks_2d
                .iter()
                .zip(rows(res, case).filter(|r| r.engine == e.name()))
                .map(|(b, r)| Point {
                    x: b.r(),
                    y: r.measured,
                    y_err: r.err,
                })
                .collect();
            if !points.is_empty() {
                s2.push(fig::Series {
                    label: format!("{e}, {what}"),
                    points,
                    triangles,
                    joined: false,
                });
            }
        }
    }
    if !s2.is_empty() {
        fig::no_bounce_2d(
            out,
            "validate_2d",
            &format!(
                "2D, released at rest, e = 0, μ = {} ({} rolls a point)",
                cfg.friction, cfg.rolls
            ),
            &s2,
        )?;
        stems.push("validate_2d");
    }
    let s3: Vec<fig::Series> = cfg
        .engines
        .iter()
        .map(|e| fig::Series {
            label: format!("{e}"),
            points: rows(res, Case::QuasiStatic3d)
                .filter(|r| r.engine == e.name())
                .map(|r| Point {
                    x: r.closed_form,
                    y: r.measured,
                    y_err: r.err,
                })
                .collect(),
            triangles: false,
            joined: false,
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    if !s3.is_empty() {
        fig::solid_angles(
            out,
            "validate_3d",
            &format!(
                "3D, released at rest in a random orientation, over-damped ({} rolls a block)",
                cfg.rolls
            ),
            &s3,
        )?;
        stems.push("validate_3d");
    }
    let mut sf = Vec::new();
    let mut integrators: Vec<_> = res.flights.iter().map(|f| f.integrator).collect();
    integrators.dedup();
    for i in integrators {
        let runs: Vec<_> = res.flights.iter().filter(|f| f.integrator == i).collect();
        for (what, triangles, get) in [
            (
                "angular momentum",
                false,
                (|f: &v::flight::FlightRun| f.angular_momentum_drift)
                    as fn(&v::flight::FlightRun) -> f64,
            ),
            ("rotational energy", true, |f: &v::flight::FlightRun| {
                f.rotational_energy_drift
            }),
        ] {
            sf.push(fig::Series {
                label: format!("{}: {what}", i.name()),
                points: runs
                    .iter()
                    .map(|f| Point {
                        x: f.dt,
                        y: get(f),
                        y_err: 0.0,
                    })
                    .collect(),
                triangles,
                joined: true,
            });
        }
    }
    if !sf.is_empty() {
        fig::flight_drift(
            out,
            "validate_flight",
            &format!(
                "Free flight, {} s tumbling at {} rad/s: drift against dt",
                cfg.flight_time, cfg.flight_spin
            ),
            &sf,
        )?;
        stems.push("validate_flight");
    }
    let st: Vec<fig::Series> = cfg
        .engines
        .iter()
        .map(|e| fig::Series {
            label: format!("{e}"),
            points: res
                .trend
                .iter()
                .filter(|p| p.engine == *e)
                .map(|p| Point {
                    x: p.restitution,
                    y: p.p_breadth,
                    y_err: p.p_breadth_err,
                })
                .collect(),
            triangles: false,
            joined: true,
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    if let Some(p) = res.trend.first() {
        let mus: Vec<String> = cfg.trend.iter().map(|(_, m)| m.to_string()).collect();
        fig::trend(
            out,
            "validate_trend",
            &format!(
                "{} in 2D, the paper's throw: bouncier and grippier ({} rolls a point)",
                p.block, cfg.trend_rolls
            ),
            &format!("restitution e (μ with it: {})", mus.join(", ")),
            dicephys::theory::two_d(cfg.trend_block.r()).breadth_vertical,
            dicephys::theory::no_bounce_2d(cfg.trend_block.r()).breadth_vertical,
            &st,
        )?;
        stems.push("validate_trend");
    }
    Ok(stems)
}

fn report(res: &Validation, figures: &[&str]) -> String {
    let c = &res.config;
    let mut md = format!(
        "# Engine validation against exact limits\n\n\
         Engines: {}. Seed {}. Limit cases: {} rolls a cell, released at rest (`--throw rest`), \
         e = 0, μ = {}, damping {} 1/s (linear and angular; 0 where lifted), sleeping off, \
         ended by DicePhys's rest rule, cap {} steps of 1 ms. Trend: {} rolls a point, the \
         paper's throw. Free flight: {} s, 140x24x20 tumbling at {} rad/s. Verdict: |z| ≤ {} \
         (z from the closed form's binomial error), or the stated tolerance where deterministic. \
         {} rows pass, {} fail; wall {:.0} s, CPU {:.0} s.\n\n",
        c.engines
            .iter()
            .map(|e| e.version())
            .collect::<Vec<_>>()
            .join(", "),
        c.seed,
        c.rolls,
        c.friction,
        c.damping,
        c.max_steps,
        c.trend_rolls,
        c.flight_time,
        c.flight_spin,
        v::Z_PASS,
        res.passed,
        res.failed,
        res.wall_s,
        res.cpu_s
    );
    md += &v::markdown_table(res);
    md += "\n## Findings\n\n";
    for f in &res.findings {
        md += &format!("- {f}\n");
    }
    md.push('\n');
    for f in figures {
        md += &format!("![{f}]({f}.svg)\n\n");
    }
    md
}
