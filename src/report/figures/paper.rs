//! The paper's figures:
//!
//! * [`master_graph`]: figure MasterGraph2, the probability ratio against R = width/breadth:
//!   theory (MasterEqu), no bounce (InElasK), measured points and simulations;
//! * [`prob_2d`]: figure 2Dprob, P(width vertical) and P(breadth vertical) against R;
//! * [`len_graph`]: figure LenGraph, the measured ratio against the block's length;
//! * [`dreidel`]: the slightly off-square dreidel's four side probabilities against δ.
//!
//! [`paper_experiment_points`] and [`paper_length_groups`] turn the paper's table
//! ([`crate::theory::paper_data`]) into the points the figures take.

use super::*;
use crate::theory::paper_data::{self, PaperRow};
use crate::theory::{self, dreidel as dr};

/// How a set's points are drawn: legend label and colour.
fn set_style(set: &str) -> (String, RGBColor) {
    match set.trim().to_ascii_lowercase().as_str() {
        "pine" => ("pine blocks (experiment)".into(), SIENNA),
        "mdf" => ("printed on MDF (experiment)".into(), MDF_RED),
        "carpet" => ("printed on tough carpet (experiment)".into(), CARPET_GREEN),
        _ => (format!("{} (experiment)", set.trim()), GREY),
    }
}

struct MasterGraph<'a> {
    exp: &'a [ExpPoint],
    sims: &'a [SimSeries],
}

impl Figure for MasterGraph<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        // The sets in the paper's order, then any others as they come.
        let mut sets: Vec<String> = ["pine", "mdf", "carpet"]
            .iter()
            .filter(|s| {
                self.exp
                    .iter()
                    .any(|p| p.set.trim().eq_ignore_ascii_case(s))
            })
            .map(|s| s.to_string())
            .collect();
        for p in self.exp {
            if !sets.iter().any(|s| p.set.trim().eq_ignore_ascii_case(s)) {
                sets.push(p.set.trim().to_string());
            }
        }
        let exp_points = |set: &str| -> Vec<Point> {
            self.exp
                .iter()
                .filter(|p| p.set.trim().eq_ignore_ascii_case(set))
                .map(|p| Point {
                    x: p.r,
                    y: p.ratio,
                    y_err: p.err,
                })
                .collect()
        };
        let all: Vec<Point> = sets
            .iter()
            .flat_map(|s| exp_points(s))
            .chain(self.sims.iter().flat_map(|s| s.points.iter().copied()))
            .collect();
        let mut xs = Span::new(0.0, 1.0);
        let mut ys = Span::new(0.0, 1.0);
        for p in finite(&all) {
            xs.add(p.x);
            ys.add_point(&p);
        }
        let x = if xs.hi > 1.0 {
            xs.padded(0.0, 0.03)
        } else {
            0.0..1.0
        };
        let y = if ys.hi > 1.0 || ys.lo < 0.0 {
            ys.padded(0.02, 0.05)
        } else {
            0.0..1.0
        };
        let mut chart = chart(
            root,
            "Probability ratio against R: theory, experiment and simulation (bars ±1σ)",
            x.clone(),
            y.clone(),
            R_DESC,
            RATIO_DESC,
        )?;
        let (x0, x1) = (x.end / 400.0, x.end);
        solid(
            &mut chart,
            curve(x0, x1, 400, &y, theory::ratio_from_r),
            DARK_BLUE.stroke_width(3),
            "theory with bounces (the paper's eq. 8)",
        )?;
        dashed(
            &mut chart,
            curve(x0, x1, 400, &y, theory::no_bounce_ratio),
            LIGHT_BLUE.stroke_width(2),
            "theory without a bounce (eq. 1)",
        )?;
        // The simulations first, so that the measurements, drawn last, are never hidden
        // under their markers (the MDF points at R = 0.833 were).
        let n = self.sims.len() + sets.len();
        let dodge = |k: usize, pts: &[Point]| dodged(k, n, pts);
        let (mut n2, mut n3) = (0, 0);
        for (k, s) in self.sims.iter().enumerate() {
            let (color, marker) = if s.two_d {
                n2 += 1;
                (SIM_2D[(n2 - 1) % SIM_2D.len()], Marker::Circle)
            } else {
                n3 += 1;
                (SIM_3D[(n3 - 1) % SIM_3D.len()], Marker::Triangle)
            };
            points(
                &mut chart,
                &dodge(k, &s.points),
                color,
                marker,
                s.two_d,
                &s.label,
            )?;
        }
        for (k, set) in sets.iter().enumerate() {
            let (label, color) = set_style(set);
            points(
                &mut chart,
                &dodge(self.sims.len() + k, &exp_points(set)),
                color,
                Marker::Circle,
                false,
                &label,
            )?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// How far apart in R the master graph draws its series at one R (about a marker's width).
const DODGE: f64 = 0.005;

/// Series `k` of `n` that share their blocks' R, each drawn a little to the side of the
/// others ([`DODGE`] apart, centred on the true R), so that no marker hides another.
fn dodged(k: usize, n: usize, pts: &[Point]) -> Vec<Point> {
    let dx = DODGE * (k as f64 - 0.5 * (n as f64 - 1.0));
    pts.iter().map(|p| Point { x: p.x + dx, ..*p }).collect()
}

/// Figure MasterGraph2: the ratio P(breadth vertical)/P(width vertical) against R over (0, 1]
/// (wider if points lie beyond): the theory (MasterEqu) as a solid dark blue line, the no-bounce
/// ratio (InElasK) dashed in lighter blue, the measured points with their error bars coloured by
/// set (pine sienna, MDF red, carpet green) drawn above each 2D simulation (connected circles)
/// and each 3D simulation (separate triangles), every error bar ±1σ as the title says; the
/// series at one R side by side, [`DODGE`] apart, centred on it. Every
/// series is named in the legend in words (the paper's equation by its number).
pub fn master_graph(
    dir: &Path,
    stem: &str,
    exp: &[ExpPoint],
    sims: &[SimSeries],
) -> crate::Result<()> {
    write_both(dir, stem, &MasterGraph { exp, sims })
}

struct Prob2d;

impl Figure for Prob2d {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let y = 0.0..1.0;
        let mut chart = chart(
            root,
            "2D probabilities of each outcome against R",
            0.0..1.0,
            y.clone(),
            R_DESC,
            "probability",
        )?;
        let (x0, x1, n) = (0.0025, 1.0, 400);
        let k = |f: fn(f64) -> theory::SideProbabilities| move |r| f(r).width_vertical;
        let l = |f: fn(f64) -> theory::SideProbabilities| move |r| f(r).breadth_vertical;
        solid(
            &mut chart,
            curve(x0, x1, n, &y, k(theory::two_d)),
            DARK_BLUE.stroke_width(3),
            "P(K) = P(width vertical), theory (eqs. 8, 9)",
        )?;
        solid(
            &mut chart,
            curve(x0, x1, n, &y, l(theory::two_d)),
            MDF_RED.stroke_width(3),
            "P(L) = P(breadth vertical), theory (eqs. 8, 9)",
        )?;
        dashed(
            &mut chart,
            curve(x0, x1, n, &y, k(theory::no_bounce_2d)),
            LIGHT_BLUE.stroke_width(2),
            "P(width vertical), no bounce",
        )?;
        dashed(
            &mut chart,
            curve(x0, x1, n, &y, l(theory::no_bounce_2d)),
            RGBColor(240, 110, 110).stroke_width(2),
            "P(breadth vertical), no bounce",
        )?;
        legend(&mut chart, SeriesLabelPosition::MiddleLeft)
    }
}

/// Figure 2Dprob: P(K) = P(width vertical) and P(L) = P(breadth vertical) against R over (0, 1],
/// from the theory ((MasterEqu) with (rattoprob), solid) and the no-bounce model ((InElasK),
/// dashed).
pub fn prob_2d(dir: &Path, stem: &str) -> crate::Result<()> {
    write_both(dir, stem, &Prob2d)
}

struct LenGraph<'a> {
    groups: &'a [LenGroup],
}

impl Figure for LenGraph<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut xs = Span::new(0.0, 100.0);
        let mut ys = Span::new(0.0, 0.8);
        for g in self.groups {
            for p in finite(&g.points) {
                xs.add(p.x);
                ys.add_point(&p);
            }
        }
        let mut chart = chart(
            root,
            "Measured probability ratio against block length (bars ±1σ)",
            xs.padded(0.0, 0.06),
            ys.padded(0.0, 0.25),
            "block length (mm)",
            RATIO_DESC,
        )?;
        for (i, g) in self.groups.iter().enumerate() {
            let color = GROUPS[i % GROUPS.len()];
            points(
                &mut chart,
                &g.points,
                color,
                Marker::Circle,
                false,
                &g.label,
            )?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Figure LenGraph: the measured ratio against the block's length in mm, one colour per group
/// of blocks with the same cross-section, with error bars and a legend.
pub fn len_graph(dir: &Path, stem: &str, groups: &[LenGroup]) -> crate::Result<()> {
    write_both(dir, stem, &LenGraph { groups })
}

struct Dreidel {
    delta_max: f64,
}

impl Figure for Dreidel {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (d1, n) = (self.delta_max, 200);
        let long_exact: fn(f64) -> f64 = |d| dr::sides_exact(d).each_l_side;
        let short_exact: fn(f64) -> f64 = |d| dr::sides_exact(d).each_k_side;
        let long_first: fn(f64) -> f64 = |d| dr::sides_first_order(d).each_l_side;
        let short_first: fn(f64) -> f64 = |d| dr::sides_first_order(d).each_k_side;
        let mut ys = Span::new(0.25, 0.25);
        let all = -f64::MAX..f64::MAX;
        for f in [long_exact, short_exact, long_first, short_first] {
            for (_, v) in curve(0.0, d1, n, &all, f) {
                ys.add(v);
            }
        }
        // Room above the curves for the legend.
        let y = ys.padded(0.05, 0.6);
        let mut chart = chart(
            root,
            "Slightly off-square dreidel: probability of each side",
            0.0..d1,
            y.clone(),
            "δ, with sides k and l = (1 + δ) k",
            "probability of landing on each side",
        )?;
        dashed(
            &mut chart,
            vec![(0.0, 0.25), (d1, 0.25)],
            GREY.stroke_width(1),
            "square dreidel, 1/4",
        )?;
        solid(
            &mut chart,
            curve(0.0, d1, n, &y, long_exact),
            MDF_RED.stroke_width(3),
            "each long side (l), exact: P(L)/2",
        )?;
        solid(
            &mut chart,
            curve(0.0, d1, n, &y, short_exact),
            DARK_BLUE.stroke_width(3),
            "each short side (k), exact: P(K)/2",
        )?;
        dashed(
            &mut chart,
            curve(0.0, d1, n, &y, long_first),
            RGBColor(240, 110, 110).stroke_width(2),
            "each long side, first order: 1/4 + (1 + √2 + 4/π) δ/8",
        )?;
        dashed(
            &mut chart,
            curve(0.0, d1, n, &y, short_first),
            LIGHT_BLUE.stroke_width(2),
            "each short side, first order: 1/4 − (1 + √2 + 4/π) δ/8",
        )?;
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// The slightly off-square dreidel (section "The slightly off-square dreidel"): the probability
/// of each of its four sides, the two long ones (P(L)/2) and the two short ones (P(K)/2), against
/// δ = R − 1 over [0, `delta_max`]: exact from (MasterEqu) (solid) and to first order,
/// 1/4 ± (1 + √2 + 4/π)/8 · δ (dashed, lighter). `delta_max` must be finite and positive.
pub fn dreidel(dir: &Path, stem: &str, delta_max: f64) -> crate::Result<()> {
    if !(delta_max.is_finite() && delta_max > 0.0) {
        return Err(crate::Error::Invalid(format!(
            "figures: dreidel needs a finite positive delta_max, not {delta_max}"
        )));
    }
    write_both(dir, stem, &Dreidel { delta_max })
}

/// R = width/breadth from the row's printed dimensions, and the ratio ± binomial error from its
/// counts.
fn row_point(row: &PaperRow, x: f64) -> Point {
    let m = row.measured_ratio();
    Point {
        x,
        y: m.value,
        y_err: m.err,
    }
}

fn row_r(row: &PaperRow) -> f64 {
    row.width_mm.value / row.breadth_mm.value
}

/// The measured points of figure MasterGraph2 from the paper's table: every coloured row (the
/// extra-length rows, uncoloured in the table, belong to figure LenGraph), with R from the
/// printed dimensions, the ratio and its binomial error from the counts, and the row's set.
/// Empty if the table fails to load (it is compiled in and tested, so it does not).
pub fn paper_experiment_points() -> Vec<ExpPoint> {
    let Ok(table) = paper_data::load() else {
        return Vec::new();
    };
    table
        .rows
        .iter()
        .filter(|row| !row.extra_length)
        .map(|row| {
            let p = row_point(row, row_r(row));
            ExpPoint {
                r: p.x,
                ratio: p.y,
                err: p.y_err,
                set: row.set.name().to_string(),
            }
        })
        .collect()
}

/// The groups of figure LenGraph from the paper's table: each cross-section and surface that was
/// measured at more than one length, in table order (25×18 pine on carpet at 782 and 98 mm;
/// 24×20 printed on MDF at 140, 100 and 80 mm; 22×13 printed on MDF at 140 and 80 mm). Each
/// group's points are longest first, as in the table, with the ratio and its binomial error from
/// the counts. Labelled e.g. `pine 25x18 on Carpet`.
pub fn paper_length_groups() -> Vec<LenGroup> {
    let Ok(table) = paper_data::load() else {
        return Vec::new();
    };
    let same = |a: &PaperRow, b: &PaperRow| {
        a.set == b.set
            && a.block == b.block
            && a.surface == b.surface
            && a.breadth_mm.value == b.breadth_mm.value
            && a.width_mm.value == b.width_mm.value
    };
    let mut groups: Vec<(&PaperRow, LenGroup)> = Vec::new();
    for extra in table.rows.iter().filter(|r| r.extra_length) {
        if groups.iter().any(|(first, _)| same(first, extra)) {
            continue;
        }
        let mut points: Vec<Point> = table
            .rows
            .iter()
            .filter(|r| same(r, extra))
            .map(|r| row_point(r, r.length_mm.value))
            .collect();
        points.sort_by(|a, b| b.x.total_cmp(&a.x));
        let label = format!(
            "{} {}x{} on {}",
            extra.block.name().to_lowercase(),
            extra.breadth_mm.value,
            extra.width_mm.value,
            extra.surface.name()
        );
        groups.push((extra, LenGroup { label, points }));
    }
    groups.into_iter().map(|(_, g)| g).collect()
}

#[cfg(test)]
mod tests;
