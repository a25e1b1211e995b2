//! Figures, drawn with `plotters`, each as `<stem>.svg` and `<stem>.png`: the paper's own
//! ([`paper`]) and the sweeps' ([`sweeps`]). This module holds what they share: the data
//! they take, the style, the axes and series, and the atomic writing of both files.
//!
//! Plain data in, files out: every function takes numbers and labels, writes both files into
//! `dir` (created if missing) and returns an error on failure. Non-finite points are skipped,
//! never a panic.
//!
//! Each is drawn once, as SVG; the PNG is that SVG rendered by resvg (anti-aliased, text
//! shaped and kerned) with the DejaVu Sans font embedded by the `dejavu` crate: no system
//! fonts or fontconfig are needed. The SVG files name the family `sans-serif` and leave the
//! glyphs to the viewer. Plotters' `ab_glyph` still measures text for its layout.

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

pub mod design;
pub mod die;
pub mod fit;
pub mod paper;
pub mod sweeps;
pub mod tradeoff;
pub mod validate;

#[cfg(test)]
mod text_test;

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

/// Pixel size of a figure unless it says otherwise (the SVG uses the same user units).
const RATIO_DESC: &str = "P(breadth vertical) / P(width vertical)";
const R_DESC: &str = "R = width / breadth";
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
    /// Its size in pixels (the SVG's user units).
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Draws `fig` into `dir/<stem>.svg` and `dir/<stem>.png`, each whole or not at all: drawn
/// in memory, then written through `run::io` (a temporary file beside it, renamed).
fn write_both(dir: &Path, stem: &str, fig: &impl Figure) -> crate::Result<()> {
    use crate::Error;
    if stem.is_empty() || stem.contains(['/', '\\']) {
        return Err(Error::Invalid(format!("figures: bad file stem '{stem}'")));
    }
    ensure_font().map_err(Error::failed)?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let failed = |ext: &str, e: String| {
        Error::failed(format!(
            "{}: {e}",
            dir.join(format!("{stem}.{ext}")).display()
        ))
    };
    let size = fig.size();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        fig.draw(&root)
            .and_then(|()| root.present().map_err(plot_err))
            .map_err(|e| failed("svg", e))?;
    }
    let png = png_of(&svg, size).map_err(|e| failed("png", e))?;
    crate::run::io::write_atomic(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;
    crate::run::io::write_atomic(&dir.join(format!("{stem}.png")), &png)
}

/// The fonts the PNGs' text is drawn with: the embedded DejaVu Sans (regular and bold), the
/// SVG's `sans-serif`.
fn fonts() -> std::sync::Arc<resvg::usvg::fontdb::Database> {
    static FONTS: OnceLock<std::sync::Arc<resvg::usvg::fontdb::Database>> = OnceLock::new();
    FONTS
        .get_or_init(|| {
            let mut db = resvg::usvg::fontdb::Database::new();
            db.load_font_data(dejavu::sans::regular().to_vec());
            db.load_font_data(dejavu::sans::bold().to_vec());
            db.set_sans_serif_family("DejaVu Sans");
            std::sync::Arc::new(db)
        })
        .clone()
}

/// The PNG of `svg` (`w` × `h` px) as resvg renders it: anti-aliased, its text shaped (kerned)
/// in the embedded DejaVu Sans, on white. (Plotters' own bitmap drew the text glyph by glyph
/// at rounded places, "Probabili ty", and the curves aliased.)
fn png_of(svg: &str, (w, h): (u32, u32)) -> Result<Vec<u8>, String> {
    use resvg::tiny_skia;
    let options = resvg::usvg::Options {
        font_family: "DejaVu Sans".into(),
        fontdb: fonts(),
        ..resvg::usvg::Options::default()
    };
    let tree = resvg::usvg::Tree::from_str(svg, &options).map_err(|e| e.to_string())?;
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or("an empty figure")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    // Opaque on white: the premultiplied RGBA is the RGB.
    let rgb: Vec<u8> = pixmap
        .data()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&rgb, w, h, image::ColorType::Rgb8)
        .map_err(|e| e.to_string())?;
    Ok(png)
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

/// White background, caption (its text and size), and axes for one bar a label at x = 1 … n,
/// each label written under its place, y over `y`: the die's faces and a design's outcomes.
fn labelled_chart<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    (title, size): (&str, u32),
    labels: Vec<String>,
    y: std::ops::Range<f64>,
    (x_desc, y_desc): (&str, &str),
) -> Result<Chart<'a, DB>, String> {
    let n = labels.len();
    root.fill(&WHITE).map_err(plot_err)?;
    let name = move |v: &f64| {
        let k = v.round();
        if (v - k).abs() < 1e-6 && k >= 1.0 && k as usize <= labels.len() {
            labels[k as usize - 1].clone()
        } else {
            String::new()
        }
    };
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, size))
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(80)
        .build_cartesian_2d(0.4..n as f64 + 0.6, y)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style((FONT, 20))
        .label_style((FONT, 16))
        .x_labels(n + 1)
        .x_label_formatter(&name)
        .y_label_formatter(&tick)
        .disable_x_mesh()
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

/// Items grouped by a key, in first-seen order: a figure's series or panels.
pub fn group<T>(items: &[T], key: impl Fn(&T) -> String) -> Vec<(String, Vec<&T>)> {
    let mut out: Vec<(String, Vec<&T>)> = Vec::new();
    for it in items {
        let k = key(it);
        match out.iter_mut().find(|(g, _)| *g == k) {
            Some((_, v)) => v.push(it),
            None => out.push((k, vec![it])),
        }
    }
    out
}
