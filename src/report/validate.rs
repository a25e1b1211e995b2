//! `validate`'s results and report: the engines against the limits known in closed form (the
//! study: `studies::validate`). The rows as the log prints them and as report.md holds them,
//! report.md itself, and the figures.

use crate::engine::EngineKind;
use crate::error::Result;
use crate::model::block::{Block, Side};
use crate::model::scene::Mode;
use crate::report::figures::validate as fig;
use crate::report::figures::Point;
use crate::report::text::{left, right, Columns};
use crate::run::tally::Tally;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A verdict's bound: |z| at most this many standard errors.
pub const Z_PASS: f64 = 3.0;

/// What `validate` runs: its defaults and checks are the study's (`studies::validate`);
/// the results echo it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// The engines (Bullet brings its presets and the fast flight to the free-flight case).
    pub engines: Vec<EngineKind>,
    /// Rolls per limit cell (block × engine × case).
    pub rolls: u64,
    /// Rolls per point of the trend.
    pub trend_rolls: u64,
    /// The throws' seed.
    pub seed: u64,
    /// The 2D blocks, for several R.
    pub blocks_2d: Vec<Block>,
    /// The 3D blocks: a cube, a square cuboid, three different sides.
    pub blocks_3d: Vec<Block>,
    /// The trend's block (2D).
    pub trend_block: Block,
    /// The trend's (e, μ) points, bouncier and grippier in turn.
    pub trend: Vec<(f64, f64)>,
    /// The free flight's time steps, s.
    pub flight_dts: Vec<f64>,
    /// The free flight's length, s.
    pub flight_time: f64,
    /// The free flight's spin, rad/s.
    pub flight_spin: f64,
    /// The limit cases' damping rate, 1/s.
    pub damping: f64,
    /// The limit cases' μ.
    pub friction: f64,
    /// The limit cases' step cap.
    pub max_steps: u64,
    /// The trend's step cap.
    pub trend_max_steps: u64,
    /// The departure in probability each limit case should resolve at 3σ; a case that
    /// cannot says how many rolls would.
    pub resolve: f64,
}

/// The cases.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::Display, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Case {
    /// 2D, released at rest, over-damped: eq. (InElasK).
    #[serde(rename = "2d_no_bounce")]
    #[strum(serialize = "2d_no_bounce")]
    NoBounce2d,
    /// 2D, released at rest, the damping lifted: how far momentum alone moves it.
    #[serde(rename = "2d_momentum")]
    #[strum(serialize = "2d_momentum")]
    Momentum2d,
    /// 3D, released at rest in a Haar-random orientation, over-damped: the solid angles.
    #[serde(rename = "3d_quasi_static")]
    #[strum(serialize = "3d_quasi_static")]
    QuasiStatic3d,
    /// A long tumbling flight: energy and angular momentum against dt.
    FreeFlight,
    /// The paper's throw in 2D as e and μ rise: towards eq. (MasterEqu).
    Trend,
}

/// A row's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, strum::Display)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Verdict {
    /// Within the bound (|z| ≤ 3, or a deterministic tolerance).
    Pass,
    /// Outside it; the row's note says why.
    Fail,
    /// A point of a curve, shown and not judged.
    Curve,
}

/// One line of the table: a quantity with its closed form, its measurement and a verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The case.
    pub case: Case,
    /// The engine (or, in free flight, the integrator).
    pub engine: String,
    /// The block (`LxBxW` mm, with R in 2D) or, in free flight, the time step.
    pub subject: String,
    /// What is compared, e.g. `P(breadth vertical)`.
    pub quantity: String,
    /// The closed form's value.
    pub closed_form: f64,
    /// The measured value.
    pub measured: f64,
    /// Its standard error: binomial, from the closed form's p (null where deterministic).
    pub err: f64,
    /// Rolls counted (dice that ended on a face), or steps flown.
    pub n: u64,
    /// (measured − closed form)/err; null where deterministic.
    pub z: f64,
    /// Pass, fail, or a curve's point.
    pub verdict: Verdict,
    /// What else the reader needs: dice moving at the cap, why a row fails.
    pub note: String,
    /// Where 3σ is wider than `Config::resolve`: the rolls that would resolve it.
    pub rolls_to_resolve: Option<u64>,
}

/// Dice counted by face.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Faces {
    /// Breadth vertical.
    pub breadth: u64,
    /// Width vertical.
    pub width: u64,
    /// Length vertical.
    pub length: u64,
}

impl Faces {
    pub(crate) fn add(&mut self, o: Side) {
        match o {
            Side::Breadth => self.breadth += 1,
            Side::Width => self.width += 1,
            Side::Length => self.length += 1,
            Side::Unknown => {}
        }
    }

    /// All three.
    pub fn total(&self) -> u64 {
        self.breadth + self.width + self.length
    }

    /// The count of one face.
    pub fn of(&self, o: Side) -> u64 {
        match o {
            Side::Breadth => self.breadth,
            Side::Width => self.width,
            Side::Length => self.length,
            Side::Unknown => 0,
        }
    }
}

/// One limit cell as rolled: how its dice ended, kept under the study's checkpoint.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LimitCell {
    /// The engine.
    pub engine: EngineKind,
    /// 2D or 3D.
    pub mode: Mode,
    /// The block, `LxBxW` mm.
    pub block: String,
    /// The damping rate, 1/s (0: lifted).
    pub damping: f64,
    /// The run's exact tally (DicePhys's rest rule, the certificate audited).
    pub tally: Tally,
    /// Dice at rest on a face.
    pub at_rest: Faces,
    /// Dice still moving at the cap, certified in a face region they cannot leave (creeping
    /// or rocking on that face).
    pub moving_at_cap: Faces,
    /// Dice at rest on no face, or moving at the cap and not certified.
    pub unknown: u64,
    /// Failed rolls.
    pub failed: u64,
    /// Dice that ended on a face (at rest or moving at the cap) and, of those, the ones that
    /// ended on the face whose solid angle they started in (`start_face`): all of them, in the
    /// quasi-static limit.
    pub ended_on_a_face: u64,
    /// See `ended_on_a_face`.
    pub ended_where_started: u64,
    /// Each throw's face, in index order: b, w, l, ? for none, x for failed (kept with the
    /// cell's checkpoint, not written to `validate.json`).
    #[serde(skip)]
    pub outcomes: String,
    /// Process CPU seconds the cell took.
    pub cpu_s: f64,
}

impl LimitCell {
    /// Dice on each face, at rest or moving at the cap.
    pub fn faces(&self) -> Faces {
        Faces {
            breadth: self.at_rest.breadth + self.moving_at_cap.breadth,
            width: self.at_rest.width + self.moving_at_cap.width,
            length: self.at_rest.length + self.moving_at_cap.length,
        }
    }

    /// The fraction of throws that ended on the same face in both cells (of the same throws).
    pub fn same_outcome(&self, other: &LimitCell) -> f64 {
        let n = self.outcomes.len().min(other.outcomes.len());
        let same = self
            .outcomes
            .bytes()
            .zip(other.outcomes.bytes())
            .filter(|(a, b)| a == b && *a != b'?' && *a != b'x')
            .count();
        same as f64 / n.max(1) as f64
    }
}

/// One point of the trend.
#[derive(Clone, Debug, Serialize)]
pub struct TrendPoint {
    /// The engine.
    pub engine: EngineKind,
    /// The block, `LxBxW` mm.
    pub block: String,
    /// e.
    pub restitution: f64,
    /// μ.
    pub friction: f64,
    /// Rolls.
    pub rolls: u64,
    /// N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// Eq. (MasterEqu).
    pub theory: f64,
    /// Eq. (InElasK)'s ratio, no bounce.
    pub no_bounce: f64,
    /// Where the ratio lies from theory (0) to no bounce (1).
    pub towards_no_bounce: f64,
    /// P(breadth vertical) = N(breadth)/(N(breadth) + N(width)).
    pub p_breadth: f64,
    /// Its binomial error.
    pub p_breadth_err: f64,
    /// Rolls still moving at the cap.
    pub unconverged: u64,
    /// Rolls flagged with an energy gain.
    pub energy_gain: u64,
}

/// `validate`'s results.
#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    /// What was run.
    pub config: Config,
    /// Every judged (or plotted) quantity.
    pub rows: Vec<Row>,
    /// The limit cells as rolled.
    pub cells: Vec<LimitCell>,
    /// The free flights.
    pub flights: Vec<FlightRun>,
    /// The trend's points.
    pub trend: Vec<TrendPoint>,
    /// Rows passed, failed.
    pub passed: usize,
    /// Rows failed.
    pub failed: usize,
    /// A sentence per finding.
    pub findings: Vec<String>,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Process CPU seconds, all threads.
    pub cpu_s: f64,
}

/// What integrates the flight.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Bullet with the `dicephys281` preset: no gyroscopic term, as the paper ran it.
    Bullet,
    /// Bullet with the `bullet3` preset: its implicit gyroscopic term on.
    BulletGyroscopic,
    /// Rapier (rapier3d), which keeps the gyroscopic term (explicit).
    Rapier,
    /// dicephys's own closed-form flight (`sim::flight::Flight`), Bullet's without the term.
    FastFlight,
}

impl Integrator {
    /// The integrator's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Bullet => "bullet",
            Integrator::BulletGyroscopic => "bullet (bullet3 preset)",
            Integrator::Rapier => "rapier",
            Integrator::FastFlight => "fast flight",
        }
    }

    /// True if it keeps the gyroscopic term (so L should be conserved).
    pub fn gyroscopic(self) -> bool {
        matches!(self, Integrator::BulletGyroscopic | Integrator::Rapier)
    }
}

/// One flight: an integrator at one time step.
#[derive(Clone, Debug, Serialize)]
pub struct FlightRun {
    /// What integrated it.
    pub integrator: Integrator,
    /// The time step, s.
    pub dt: f64,
    /// Steps flown (the flight's time over dt, rounded).
    pub steps: u64,
    /// Symplectic Euler steps the integrator takes per step: Rapier's solver substeps (its
    /// `num_solver_iterations`, 4), else 1.
    pub substeps: u64,
    /// The translational energy lost over the flight, J.
    pub translational_loss_j: f64,
    /// Symplectic Euler's loss, ½mg²(dt/n)² a substep, n substeps a step, over the flight, J.
    pub symplectic_loss_j: f64,
    /// The largest |½ω·Iω/(its start) − 1| over the flight.
    pub rotational_energy_drift: f64,
    /// The largest |L − L₀|/|L₀| over the flight (world axes).
    pub angular_momentum_drift: f64,
}

impl FlightRun {
    /// Measured over predicted translational loss: 1 for symplectic Euler.
    pub fn loss_ratio(&self) -> f64 {
        self.translational_loss_j / self.symplectic_loss_j
    }
}

const TABLE: Columns = Columns(&[
    left("case", 15),
    left("engine", 23),
    left("subject", 24),
    left("quantity", 26),
    right("closed form", 11),
    right("measured ± err", 18),
    right("n", 7),
    right("z", 6),
    left("verdict", 7),
]);

/// The table's header.
pub fn header() -> String {
    TABLE.header()
}

fn num(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e4) {
        format!("{v:.2e}")
    } else {
        format!("{v:.4}")
    }
}

/// The Markdown table of the rows, as docs/results/validation.md quotes it.
pub fn markdown_table(res: &Validation) -> String {
    let mut s = String::from(
        "| case | engine | subject | quantity | closed form | measured ± err | n | z | verdict | note |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &res.rows {
        let measured = if r.err.is_finite() {
            format!("{} ± {:.4}", num(r.measured), r.err)
        } else {
            num(r.measured)
        };
        let z = if r.z.is_finite() {
            format!("{:+.1}", r.z)
        } else {
            "–".into()
        };
        let mut note = r.note.clone();
        if let Some(n) = r.rolls_to_resolve {
            if !note.is_empty() {
                note += "; ";
            }
            note += &format!("{n} rolls would resolve ±{}", res.config.resolve);
        }
        let verdict = match r.verdict {
            Verdict::Fail => "**fail**".to_string(),
            v => v.to_string(),
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.case,
            r.engine,
            r.subject,
            r.quantity,
            num(r.closed_form),
            measured,
            r.n,
            z,
            verdict,
            note
        );
    }
    s
}

/// One row as text; its note, and the rolls that would resolve it, after it.
pub fn format_row(r: &Row) -> String {
    let measured = if r.err.is_finite() {
        format!("{} ± {:.4}", num(r.measured), r.err)
    } else {
        num(r.measured)
    };
    let z = if r.z.is_finite() {
        format!("{:+.1}", r.z)
    } else {
        "–".into()
    };
    let mut s = TABLE.row(&[
        r.case.to_string(),
        r.engine.clone(),
        r.subject.clone(),
        r.quantity.clone(),
        num(r.closed_form),
        measured,
        r.n.to_string(),
        z,
        r.verdict.to_string(),
    ]);
    let mut extra = Vec::new();
    if !r.note.is_empty() {
        extra.push(r.note.clone());
    }
    if let Some(n) = r.rolls_to_resolve {
        extra.push(format!("{n} rolls would resolve the asked departure at 3σ"));
    }
    if !extra.is_empty() {
        s += &format!("\n{:>16}{}", "", extra.join("; "));
    }
    s
}

/// report.md: the settings, the table, the findings and the figures.
fn markdown(res: &Validation, figures: &[&str]) -> String {
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
        Z_PASS,
        res.passed,
        res.failed,
        res.wall_s,
        res.cpu_s
    );
    md += &markdown_table(res);
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

fn rows(res: &Validation, case: Case) -> impl Iterator<Item = &Row> {
    res.rows.iter().filter(move |r| r.case == case)
}

/// Draws the figures into `out`; returns their stems (for `markdown`).
fn write_figures(out: &Path, res: &Validation) -> Result<Vec<&'static str>> {
    let mut stems = Vec::new();
    for figure in [figure_2d, figure_3d, figure_flight, figure_trend] {
        stems.extend(figure(out, res)?);
    }
    Ok(stems)
}

/// The 2D figure: each engine's ratio released at rest, over-damped and with damping lifted, against R.
fn figure_2d(out: &Path, res: &Validation) -> Result<Option<&'static str>> {
    let cfg = &res.config;
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
        return Ok(Some("validate_2d"));
    }
    Ok(None)
}

/// The 3D figure: each engine's probabilities released at rest against the solid angles.
fn figure_3d(out: &Path, res: &Validation) -> Result<Option<&'static str>> {
    let cfg = &res.config;
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
        return Ok(Some("validate_3d"));
    }
    Ok(None)
}

/// The free flight's drift of angular momentum and rotational energy against dt.
fn figure_flight(out: &Path, res: &Validation) -> Result<Option<&'static str>> {
    let cfg = &res.config;
    let mut sf = Vec::new();
    let mut integrators: Vec<_> = res.flights.iter().map(|f| f.integrator).collect();
    integrators.dedup();
    for i in integrators {
        let runs: Vec<_> = res.flights.iter().filter(|f| f.integrator == i).collect();
        for (what, triangles, get) in [
            (
                "angular momentum",
                false,
                (|f: &FlightRun| f.angular_momentum_drift) as fn(&FlightRun) -> f64,
            ),
            ("rotational energy", true, |f: &FlightRun| {
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
        return Ok(Some("validate_flight"));
    }
    Ok(None)
}

/// The 2D trend: P(breadth) against restitution (and friction with it).
fn figure_trend(out: &Path, res: &Validation) -> Result<Option<&'static str>> {
    let cfg = &res.config;
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
            crate::theory::two_d(cfg.trend_block.r()).breadth_vertical,
            crate::theory::no_bounce_2d(cfg.trend_block.r()).breadth_vertical,
            &st,
        )?;
        return Ok(Some("validate_trend"));
    }
    Ok(None)
}

impl super::Report for Validation {
    fn write_figures(&self, dir: &Path) -> Result<Vec<String>> {
        Ok(super::owned(write_figures(dir, self)?))
    }
    fn markdown(&self, stems: &[String]) -> String {
        markdown(self, &super::stems(stems))
    }
}
