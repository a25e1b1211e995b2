//! The paper's figures, drawn with `plotters`, each as `<stem>.svg` and `<stem>.png`.
//!
//! * [`master_graph`]: figure MasterGraph2, the probability ratio against R = width/breadth:
//!   theory (MasterEqu), no bounce (InElasK), measured points and simulations;
//! * [`prob_2d`]: figure 2Dprob, P(width vertical) and P(breadth vertical) against R;
//! * [`len_graph`]: figure LenGraph, the measured ratio against the block's length;
//! * [`dreidel`]: the slightly off-square dreidel's four side probabilities against δ.
//!
//! Plain data in, files out: every function takes numbers and labels, writes both files into
//! `dir` (created if missing) and returns `Err(message)` on failure. Non-finite points are
//! skipped, never a panic. [`paper_experiment_points`] and [`paper_length_groups`] turn the
//! paper's table ([`crate::theory::paper_data`]) into the points the figures take.
//!
//! Text is drawn with the DejaVu Sans font embedded by the `dejavu` crate and registered with
//! plotters' `ab_glyph` renderer: no system fonts or fontconfig are needed. The SVG files name
//! the family `sans-serif` and leave the glyphs to the viewer.

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::theory::paper_data::{self, PaperRow};
use crate::theory::{self, dreidel as dr};

pub mod sweeps;
pub mod validate;

/// One plotted value with its one-standard-error bar (`y_err` 0, negative or non-finite: no bar).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Abscissa.
    pub x: f64,
    /// Ordinate.
    pub y: f64,
    /// One standard error on `y`.
    pub y_err: f64,
}

/// A measured ratio at R. `set` is the paper's data set, by its colour in MasterGraph2:
/// `"pine"` (pine blocks on carpet and towelling), `"mdf"` (printed blocks on MDF) or `"carpet"`
/// (printed blocks on tough carpet); any other name is drawn in grey under its own label.
#[derive(Clone, Debug, PartialEq)]
pub struct ExpPoint {
    /// R = width/breadth.
    pub r: f64,
    /// Measured ratio N(breadth vertical)/N(width vertical).
    pub ratio: f64,
    /// Its binomial error.
    pub err: f64,
    /// The data set: "pine", "mdf", "carpet", or another name.
    pub set: String,
}

/// One simulation's ratios against R (`x` = R). 2D series are drawn as connected circles, 3D
/// series as separate triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct SimSeries {
    /// The series' name in the legend.
    pub label: String,
    /// A 2D simulation (connected circles), else 3D (separate triangles).
    pub two_d: bool,
    /// The ratio at each R.
    pub points: Vec<Point>,
}

/// Blocks of one cross-section measured at several lengths (`x` = length in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct LenGroup {
    /// The group's name in the legend, e.g. "printed 24x20 on MDF".
    pub label: String,
    /// The measured ratio at each length (`x`, mm).
    pub points: Vec<Point>,
}

/// Pixel size of every figure (the SVG uses the same user units).
const SIZE: (u32, u32) = (1000, 720);
const FONT: &str = "sans-serif";

const DARK_BLUE: RGBColor = RGBColor(0, 0, 139);
const LIGHT_BLUE: RGBColor = RGBColor(80, 140, 230);
const SIENNA: RGBColor = RGBColor(160, 82, 45);
const MDF_RED: RGBColor = RGBColor(210, 0, 0);
const CARPET_GREEN: RGBColor = RGBColor(0, 140, 0);
const GREY: RGBColor = RGBColor(110, 110, 110);
const SIM_2D: [RGBColor; 4] = [
    RGBColor(0, 170, 120),
    RGBColor(230, 130, 0),
    RGBColor(0, 150, 200),
    RGBColor(120, 120, 0),
];
const SIM_3D: [RGBColor; 4] = [
    RGBColor(128, 0, 128),
    RGBColor(200, 0, 200),
    RGBColor(90, 60, 170),
    RGBColor(150, 80, 110),
];
const GROUPS: [RGBColor; 6] = [
    SIENNA,
    MDF_RED,
    RGBColor(0, 90, 200),
    CARPET_GREEN,
    RGBColor(128, 0, 128),
    RGBColor(230, 130, 0),
];

/// Registers DejaVu Sans (regular and bold) as plotters' `sans-serif`, once per process.
fn ensure_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            for (style, bytes) in [
                (FontStyle::Normal, dejavu::sans::regular()),
                (FontStyle::Bold, dejavu::sans::bold()),
            ] {
                plotters::style::register_font(FONT, style, bytes)
                    .map_err(|_| "figures: the embedded DejaVu font did not load".to_string())?;
            }
            Ok(())
        })
        .clone()
}

fn plot_err<E: std::fmt::Display>(e: E) -> String {
    format!("figures: {e}")
}

/// A figure that can draw itself on any plotters backend.
trait Figure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Draws `fig` into `dir/<stem>.svg` and `dir/<stem>.png`, each whole or not at all: drawn
/// into a temporary file beside it (plotters writes in place), synced, then renamed.
fn write_both(dir: &Path, stem: &str, fig: &impl Figure) -> crate::Result<()> {
    use crate::Error;
    if stem.is_empty() || stem.contains(['/', '\\']) {
        return Err(Error::Invalid(format!("figures: bad file stem '{stem}'")));
    }
    ensure_font().map_err(Error::Failed)?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    for ext in ["svg", "png"] {
        let path = dir.join(format!("{stem}.{ext}"));
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{stem}."))
            .suffix(&format!(".{ext}"))
            .tempfile_in(dir)
            .map_err(|e| Error::io(&path, e))?;
        let drawn = if ext == "svg" {
            let root = SVGBackend::new(tmp.path(), SIZE).into_drawing_area();
            fig.draw(&root)
                .and_then(|()| root.present().map_err(plot_err))
        } else {
            let root = BitMapBackend::new(tmp.path(), SIZE).into_drawing_area();
            fig.draw(&root)
                .and_then(|()| root.present().map_err(plot_err))
        };
        drawn.map_err(|e| Error::Failed(format!("{}: {e}", path.display())))?;
        let file = std::fs::File::open(tmp.path()).map_err(|e| Error::io(&path, e))?;
        file.sync_all().map_err(|e| Error::io(&path, e))?;
        tmp.persist(&path).map_err(|e| Error::io(&path, e.error))?;
    }
    Ok(())
}

/// A closed interval grown to hold finite values.
#[derive(Clone, Copy, Debug)]
struct Span {
    lo: f64,
    hi: f64,
}

impl Span {
    fn new(lo: f64, hi: f64) -> Span {
        Span { lo, hi }
    }

    fn add(&mut self, v: f64) {
        if v.is_finite() {
            self.lo = self.lo.min(v);
            self.hi = self.hi.max(v);
        }
    }

    /// A point with its bar.
    fn add_point(&mut self, p: &Point) {
        if p.x.is_finite() && p.y.is_finite() {
            let e = bar(p.y_err);
            self.add(p.y - e);
            self.add(p.y + e);
        }
    }

    /// Widened by `frac` of the width at the top (and `frac_lo` at the bottom), never empty.
    fn padded(self, frac_lo: f64, frac: f64) -> std::ops::Range<f64> {
        let w = (self.hi - self.lo).max(1e-9);
        (self.lo - frac_lo * w)..(self.hi + frac * w)
    }
}

/// The bar half-length to draw: the error if finite and positive, else 0.
fn bar(err: f64) -> f64 {
    if err.is_finite() && err > 0.0 {
        err
    } else {
        0.0
    }
}

fn finite(points: &[Point]) -> Vec<Point> {
    points
        .iter()
        .filter(|p| p.x.is_finite() && p.y.is_finite())
        .copied()
        .collect()
}

/// `f` sampled at `n` + 1 points from `x0` to `x1`, keeping finite values inside `y`.
fn curve(
    x0: f64,
    x1: f64,
    n: usize,
    y: &std::ops::Range<f64>,
    f: impl Fn(f64) -> f64,
) -> Vec<(f64, f64)> {
    (0..=n)
        .map(|i| x0 + (x1 - x0) * i as f64 / n as f64)
        .map(|x| (x, f(x)))
        .filter(|&(x, v)| x.is_finite() && v.is_finite() && v >= y.start && v <= y.end)
        .collect()
}

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A tick label with no trailing zeros: 100, 0.1, 0.25.
fn tick(v: &f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// White background, caption, axes, mesh and axis labels.
fn chart<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    x_desc: &str,
    y_desc: &str,
) -> Result<Chart<'a, DB>, String> {
    root.fill(&WHITE).map_err(plot_err)?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, 26))
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(80)
        .build_cartesian_2d(x, y)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style((FONT, 20))
        .label_style((FONT, 16))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .light_line_style(RGBColor(243, 243, 243))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(plot_err)?;
    Ok(chart)
}

/// A solid line with its legend entry.
fn solid<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    pts: Vec<(f64, f64)>,
    style: ShapeStyle,
    label: &str,
) -> Result<(), String> {
    chart
        .draw_series(LineSeries::new(pts, style))
        .map_err(plot_err)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
    Ok(())
}

/// A dashed line with its legend entry.
fn dashed<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    pts: Vec<(f64, f64)>,
    style: ShapeStyle,
    label: &str,
) -> Result<(), String> {
    chart
        .draw_series(DashedLineSeries::new(pts, 9, 6, style))
        .map_err(plot_err)?
        .label(label)
        .legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (9, 0)], style)
                + PathElement::new(vec![(15, 0), (24, 0)], style)
        });
    Ok(())
}

#[derive(Clone, Copy)]
enum Marker {
    Circle,
    Triangle,
}

/// Points with error bars in one colour, optionally joined by a line, with a legend entry.
fn points<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    pts: &[Point],
    color: RGBColor,
    marker: Marker,
    joined: bool,
    label: &str,
) -> Result<(), String> {
    let pts = finite(pts);
    let line = color.stroke_width(2);
    if joined {
        let mut xy: Vec<(f64, f64)> = pts.iter().map(|p| (p.x, p.y)).collect();
        xy.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(xy, line))
            .map_err(plot_err)?;
    }
    chart
        .draw_series(pts.iter().filter(|p| bar(p.y_err) > 0.0).map(|p| {
            let e = bar(p.y_err);
            ErrorBar::new_vertical(p.x, p.y - e, p.y, p.y + e, color.stroke_width(1), 10)
        }))
        .map_err(plot_err)?;
    let fill = color.filled();
    let anno = match marker {
        Marker::Circle => chart
            .draw_series(pts.iter().map(|p| Circle::new((p.x, p.y), 5, fill)))
            .map_err(plot_err)?,
        Marker::Triangle => chart
            .draw_series(pts.iter().map(|p| TriangleMarker::new((p.x, p.y), 7, fill)))
            .map_err(plot_err)?,
    };
    let anno = anno.label(label);
    match (marker, joined) {
        (Marker::Circle, true) => anno.legend(move |(x, y)| {
            EmptyElement::at((x + 12, y))
                + PathElement::new(vec![(-12, 0), (12, 0)], line)
                + Circle::new((0, 0), 5, fill)
        }),
        (Marker::Circle, false) => {
            anno.legend(move |(x, y)| EmptyElement::at((x + 12, y)) + Circle::new((0, 0), 5, fill))
        }
        (Marker::Triangle, _) => anno.legend(move |(x, y)| {
            EmptyElement::at((x + 12, y)) + TriangleMarker::new((0, 0), 7, fill)
        }),
    };
    Ok(())
}

/// Draws the legend box.
fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    pos: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(pos)
        .margin(12)
        .legend_area_size(36)
        .label_font((FONT, 17))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(plot_err)
}

const RATIO_DESC: &str = "P(breadth vertical) / P(width vertical)";
const R_DESC: &str = "R = width / breadth";

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
            "Probability ratio against R: theory, experiment and simulation",
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
            "theory, eq. (MasterEqu)",
        )?;
        dashed(
            &mut chart,
            curve(x0, x1, 400, &y, theory::no_bounce_ratio),
            LIGHT_BLUE.stroke_width(2),
            "no bounce, eq. (InElasK)",
        )?;
        for set in &sets {
            let (label, color) = set_style(set);
            points(
                &mut chart,
                &exp_points(set),
                color,
                Marker::Circle,
                false,
                &label,
            )?;
        }
        let (mut n2, mut n3) = (0, 0);
        for s in self.sims {
            let (color, marker) = if s.two_d {
                n2 += 1;
                (SIM_2D[(n2 - 1) % SIM_2D.len()], Marker::Circle)
            } else {
                n3 += 1;
                (SIM_3D[(n3 - 1) % SIM_3D.len()], Marker::Triangle)
            };
            points(&mut chart, &s.points, color, marker, s.two_d, &s.label)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// Figure MasterGraph2: the ratio P(breadth vertical)/P(width vertical) against R over (0, 1]
/// (wider if points lie beyond): the theory (MasterEqu) as a solid dark blue line, the no-bounce
/// ratio (InElasK) dashed in lighter blue, the measured points with their error bars coloured by
/// set (pine sienna, MDF red, carpet green), each 2D simulation as connected circles and each 3D
/// simulation as separate triangles. Every series is named in the legend.
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
            "P(K) = P(width vertical), theory",
        )?;
        solid(
            &mut chart,
            curve(x0, x1, n, &y, l(theory::two_d)),
            MDF_RED.stroke_width(3),
            "P(L) = P(breadth vertical), theory",
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
            "Probability ratio against block length",
            xs.padded(0.0, 0.06),
            ys.padded(0.0, 0.25),
            "block length m (mm)",
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
mod tests {
    use super::*;
    use std::path::PathBuf;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh directory under the system temp dir, removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> TempDir {
            static N: AtomicUsize = AtomicUsize::new(0);
            let dir = std::env::temp_dir().join(format!(
                "dicephys-figures-{}-{}-{name}",
                std::process::id(),
                N.fetch_add(1, Ordering::Relaxed)
            ));
            let _ = std::fs::remove_dir_all(&dir);
            TempDir(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// Checks that the tags of an XML document balance: every `<name ...>` is closed by
    /// `</name>` in order, `<.../>` closes itself, `<?...?>` and `<!...>` are skipped, and the
    /// root is `svg`. Returns the number of elements.
    fn balanced(xml: &str) -> Result<usize, String> {
        let mut stack: Vec<&str> = Vec::new();
        let mut count = 0;
        let mut rest = xml;
        let mut saw_root = false;
        while let Some(i) = rest.find('<') {
            let after = &rest[i + 1..];
            let end = after.find('>').ok_or("unterminated tag")?;
            let tag = &after[..end];
            rest = &after[end + 1..];
            if tag.starts_with('?') || tag.starts_with('!') {
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                let open = stack.pop().ok_or(format!("</{name}> closes nothing"))?;
                if open != name.trim() {
                    return Err(format!("<{open}> closed by </{name}>"));
                }
                continue;
            }
            let name = tag
                .split(|c: char| c.is_whitespace() || c == '/')
                .next()
                .unwrap_or("");
            if name.is_empty() {
                return Err(format!("bad tag <{tag}>"));
            }
            if stack.is_empty() {
                if saw_root {
                    return Err("more than one root element".into());
                }
                if name != "svg" {
                    return Err(format!("root is <{name}>, not <svg>"));
                }
                saw_root = true;
            }
            count += 1;
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        if let Some(open) = stack.pop() {
            return Err(format!("<{open}> never closed"));
        }
        if !saw_root {
            return Err("no root element".into());
        }
        Ok(count)
    }

    /// Reads `<stem>.svg` and checks it and `<stem>.png`; returns the SVG text.
    fn check_files(dir: &Path, stem: &str) -> String {
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
        let start = svg.trim_start();
        assert!(
            start.starts_with("<svg") || start.starts_with("<?xml"),
            "{stem}.svg starts {:?}",
            &start[..start.len().min(40)]
        );
        assert!(svg.contains("</svg>"));
        let n = balanced(&svg).unwrap_or_else(|e| panic!("{stem}.svg: {e}"));
        assert!(n > 20, "{stem}.svg has only {n} elements");
        let png = std::fs::read(dir.join(format!("{stem}.png"))).unwrap();
        assert!(
            png.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{stem}.png is not a PNG"
        );
        assert!(png.len() > 5000, "{stem}.png is only {} bytes", png.len());
        svg
    }

    fn has_all(svg: &str, labels: &[&str]) {
        for l in labels {
            assert!(svg.contains(l), "no {l:?} in the SVG");
        }
    }

    fn sims() -> Vec<SimSeries> {
        let rs = [1.0 / 3.0, 0.379, 0.481, 0.591, 0.833];
        let series = |label: &str, two_d: bool, scale: f64| SimSeries {
            label: label.into(),
            two_d,
            points: rs
                .iter()
                .map(|&r| Point {
                    x: r,
                    y: scale * theory::ratio_from_r(r),
                    y_err: 0.01,
                })
                .collect(),
        };
        vec![
            series("Bullet 2D", true, 1.3),
            series("Rapier 2D", true, 1.2),
            series("Bullet 3D", false, 1.1),
        ]
    }

    #[test]
    fn master_graph_writes_both_files_with_every_series() {
        let dir = TempDir::new("master");
        master_graph(&dir.0, "master", &paper_experiment_points(), &sims()).unwrap();
        let svg = check_files(&dir.0, "master");
        has_all(
            &svg,
            &[
                "theory",
                "no bounce",
                "pine blocks",
                "MDF",
                "tough carpet",
                "Bullet 2D",
                "Rapier 2D",
                "Bullet 3D",
                R_DESC,
                "P(breadth vertical) / P(width vertical)",
            ],
        );
    }

    #[test]
    fn master_graph_survives_bad_and_empty_input() {
        let dir = TempDir::new("master-nan");
        let nan = f64::NAN;
        let exp = vec![
            ExpPoint {
                r: nan,
                ratio: 0.5,
                err: 0.1,
                set: "mdf".into(),
            },
            ExpPoint {
                r: 0.5,
                ratio: f64::INFINITY,
                err: nan,
                set: "pine".into(),
            },
            ExpPoint {
                r: 0.6,
                ratio: 0.2,
                err: f64::INFINITY,
                set: "Marble <&>".into(),
            },
        ];
        let sims = vec![
            SimSeries {
                label: "all NaN".into(),
                two_d: true,
                points: vec![Point {
                    x: nan,
                    y: nan,
                    y_err: nan,
                }],
            },
            SimSeries {
                label: "empty 3D".into(),
                two_d: false,
                points: vec![],
            },
            SimSeries {
                label: "beyond one".into(),
                two_d: false,
                points: vec![Point {
                    x: 1.4,
                    y: 2.5,
                    y_err: -1.0,
                }],
            },
        ];
        master_graph(&dir.0, "bad", &exp, &sims).unwrap();
        let svg = check_files(&dir.0, "bad");
        has_all(
            &svg,
            &["all NaN", "empty 3D", "beyond one", "Marble &lt;&amp;&gt;"],
        );
        master_graph(&dir.0, "empty", &[], &[]).unwrap();
        has_all(&check_files(&dir.0, "empty"), &["theory", "no bounce"]);
    }

    #[test]
    fn prob_2d_draws_theory_and_no_bounce() {
        let dir = TempDir::new("prob2d");
        prob_2d(&dir.0, "prob2d").unwrap();
        let svg = check_files(&dir.0, "prob2d");
        has_all(
            &svg,
            &[
                "P(K) = P(width vertical), theory",
                "P(L) = P(breadth vertical), theory",
                "P(width vertical), no bounce",
                "P(breadth vertical), no bounce",
            ],
        );
    }

    #[test]
    fn len_graph_draws_the_papers_groups() {
        let dir = TempDir::new("len");
        // A directory that does not exist yet is created.
        let nested = dir.0.join("a").join("b");
        len_graph(&nested, "len", &paper_length_groups()).unwrap();
        let svg = check_files(&nested, "len");
        has_all(
            &svg,
            &[
                "pine 25x18 on Carpet",
                "printed 24x20 on MDF",
                "printed 22x13 on MDF",
                "block length m (mm)",
            ],
        );
        let bad = vec![
            LenGroup {
                label: "NaN group".into(),
                points: vec![Point {
                    x: f64::NAN,
                    y: 0.3,
                    y_err: 0.1,
                }],
            },
            LenGroup {
                label: "empty group".into(),
                points: vec![],
            },
        ];
        len_graph(&dir.0, "len-bad", &bad).unwrap();
        has_all(
            &check_files(&dir.0, "len-bad"),
            &["NaN group", "empty group"],
        );
        len_graph(&dir.0, "len-none", &[]).unwrap();
        check_files(&dir.0, "len-none");
    }

    #[test]
    fn dreidel_draws_exact_and_first_order() {
        let dir = TempDir::new("dreidel");
        dreidel(&dir.0, "dreidel", 0.1).unwrap();
        let svg = check_files(&dir.0, "dreidel");
        has_all(
            &svg,
            &[
                "each long side (l), exact",
                "each short side (k), exact",
                "each long side, first order",
                "each short side, first order",
            ],
        );
        // Far beyond first order's range: still drawn.
        dreidel(&dir.0, "dreidel-wide", 5.0).unwrap();
        check_files(&dir.0, "dreidel-wide");
        for bad in [f64::NAN, 0.0, -0.1, f64::INFINITY] {
            assert!(dreidel(&dir.0, "no", bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn bad_stem_is_an_error() {
        let dir = TempDir::new("stem");
        assert!(prob_2d(&dir.0, "").is_err());
        assert!(prob_2d(&dir.0, "a/b").is_err());
    }

    #[test]
    fn paper_points_are_the_coloured_rows() {
        let pts = paper_experiment_points();
        assert_eq!(pts.len(), 15);
        for set in ["pine", "mdf", "carpet"] {
            assert_eq!(pts.iter().filter(|p| p.set == set).count(), 5, "{set}");
        }
        // Row 7: 140x24x20 printed on MDF, 361 breadth vertical, 639 width vertical.
        let p = &pts[5];
        assert_eq!(p.set, "mdf");
        assert!((p.r - 20.0 / 24.0).abs() < 1e-12);
        assert!((p.ratio - 361.0 / 639.0).abs() < 1e-12);
        let want = (361.0f64 * 639.0 * 1000.0 / 639f64.powi(4)).sqrt();
        assert!((p.err - want).abs() < 1e-12);
        assert!(pts
            .iter()
            .all(|p| p.r > 0.0 && p.r <= 1.0 && p.ratio.is_finite() && p.err > 0.0));
    }

    #[test]
    fn paper_length_groups_are_the_three_sets() {
        let groups = paper_length_groups();
        let summary: Vec<(&str, Vec<f64>)> = groups
            .iter()
            .map(|g| (g.label.as_str(), g.points.iter().map(|p| p.x).collect()))
            .collect();
        assert_eq!(
            summary,
            vec![
                ("pine 25x18 on Carpet", vec![782.0, 98.0]),
                ("printed 24x20 on MDF", vec![140.0, 100.0, 80.0]),
                ("printed 22x13 on MDF", vec![140.0, 80.0]),
            ]
        );
        // Row 11: 80 mm 22x13 on MDF, 84/416.
        assert!((groups[2].points[1].y - 84.0 / 416.0).abs() < 1e-12);
    }

    #[test]
    fn tick_labels_drop_trailing_zeros() {
        assert_eq!(tick(&100.0), "100");
        assert_eq!(tick(&0.0), "0");
        assert_eq!(tick(&-0.0), "0");
        assert_eq!(tick(&0.1), "0.1");
        assert_eq!(tick(&(0.1 + 0.2)), "0.3");
        assert_eq!(tick(&0.25), "0.25");
        assert_eq!(tick(&-2.5), "-2.5");
    }

    #[test]
    fn tag_check_catches_broken_xml() {
        assert_eq!(
            balanced("<svg a=\"1\"><g><path d=\"M 1\"/></g></svg>"),
            Ok(3)
        );
        assert!(balanced("<?xml version=\"1.0\"?>\n<svg></svg>").is_ok());
        assert!(balanced("<svg><g></svg>").is_err());
        assert!(balanced("<svg><g>").is_err());
        assert!(balanced("<svg></svg><svg></svg>").is_err());
        assert!(balanced("<html></html>").is_err());
        assert!(balanced("<svg><text>a").is_err());
    }
}
