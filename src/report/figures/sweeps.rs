//! The sweeps' figures: the ratio against dt (`convergence`) and failure fractions as heat maps
//! (`heatmap`); cost against error is [`super::tradeoff`]. Log axes are drawn
//! as log10 of the value with ticks labelled by the value itself.

use super::*;

/// One line of the convergence figure: points at x = dt.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// The line's name in the legend; one containing " 2d" is drawn with circles, else triangles.
    pub label: String,
    /// The ratio at each time step (`x` = dt, s).
    pub points: Vec<Point>,
}

/// One heat map: `values[y][x]` in [0, 1] (NaN: no data).
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// The panel's caption.
    pub title: String,
    /// The x axis's title.
    pub x_desc: String,
    /// The y axis's title.
    pub y_desc: String,
    /// The columns' labels, one per x cell.
    pub x_labels: Vec<String>,
    /// The rows' labels, one per y cell.
    pub y_labels: Vec<String>,
    /// The fractions, `values[y][x]`, in [0, 1]; NaN: no data.
    pub values: Vec<Vec<f64>>,
}

const LINES: [RGBColor; 12] = [
    RGBColor(0, 0, 139),
    RGBColor(210, 0, 0),
    RGBColor(0, 140, 0),
    RGBColor(128, 0, 128),
    RGBColor(230, 130, 0),
    RGBColor(0, 150, 200),
    RGBColor(160, 82, 45),
    RGBColor(120, 120, 0),
    RGBColor(200, 0, 200),
    RGBColor(80, 140, 230),
    RGBColor(0, 170, 120),
    RGBColor(110, 110, 110),
];

/// `x` rounded to two significant figures.
fn two_figures(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let p = 10f64.powf(x.log10().floor() - 1.0);
    (x / p).round() * p
}

/// A log10 tick for a time step: 1/N, N to two significant figures.
fn log_tick_dt(v: &f64) -> String {
    format!("1/{}", two_figures(10f64.powf(-*v)))
}

/// A log10 tick: the value to two significant figures.
pub(super) fn log_tick(v: &f64) -> String {
    tick(&two_figures(10f64.powf(*v)))
}

/// A tick label formatter.
type Ticks<'a> = &'a dyn Fn(&f64) -> String;

/// `chart` with its own tick labels, x and y.
fn chart_x<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    x_desc: &str,
    y_desc: &str,
    (x_fmt, y_fmt): (Ticks, Ticks),
) -> Result<Chart<'a, DB>, String> {
    root.fill(&WHITE).map_err(plot_err)?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, 24))
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
        .x_labels(7)
        .x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .light_line_style(RGBColor(243, 243, 243))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(plot_err)?;
    Ok(chart)
}

struct Convergence<'a> {
    title: &'a str,
    lines: &'a [Line],
}

impl Figure for Convergence<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut xs = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        let mut ys = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        let lines: Vec<Line> = self
            .lines
            .iter()
            .map(|l| Line {
                label: l.label.clone(),
                points: l
                    .points
                    .iter()
                    .filter(|p| p.x > 0.0)
                    .map(|p| Point {
                        x: p.x.log10(),
                        ..*p
                    })
                    .collect(),
            })
            .collect();
        for p in lines.iter().flat_map(|l| &l.points) {
            xs.add(p.x);
            ys.add_point(p);
        }
        if !(xs.lo.is_finite() && ys.lo.is_finite()) {
            xs = Span::new(-4.0, -1.0);
            ys = Span::new(0.0, 1.0);
        }
        let mut chart = chart_x(
            root,
            self.title,
            xs.padded(0.05, 0.05),
            ys.padded(0.05, 0.35),
            "time step dt, s (log scale)",
            RATIO_DESC,
            (&log_tick_dt, &tick),
        )?;
        for (i, l) in lines.iter().enumerate() {
            let marker = if l.label.contains(" 2d") {
                Marker::Circle
            } else {
                Marker::Triangle
            };
            points(
                &mut chart,
                &l.points,
                LINES[i % LINES.len()],
                marker,
                true,
                &l.label,
            )?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// The ratio against dt, one line per block × engine × mode.
pub fn convergence(dir: &Path, stem: &str, title: &str, lines: &[Line]) -> crate::Result<()> {
    write_both(dir, stem, &Convergence { title, lines })
}

/// A percentage to two significant figures: "1 %", "0.5 %".
pub(super) fn pct(p: f64) -> String {
    format!("{} %", tick(&two_figures(p)))
}

struct Heatmap<'a> {
    title: &'a str,
    panels: &'a [Panel],
}

/// White (0) to dark red (1).
fn heat(v: f64) -> RGBColor {
    if !v.is_finite() {
        return RGBColor(220, 220, 220);
    }
    let v = v.clamp(0.0, 1.0);
    let lerp = |a: f64, b: f64| (a + (b - a) * v).round() as u8;
    RGBColor(lerp(255.0, 170.0), lerp(255.0, 0.0), lerp(255.0, 0.0))
}

impl Figure for Heatmap<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(plot_err)?;
        let root = root.titled(self.title, (FONT, 24)).map_err(plot_err)?;
        let n = self.panels.len().max(1);
        let cols = if n > 1 { 2 } else { 1 };
        let rows = n.div_ceil(cols);
        let areas = root.split_evenly((rows, cols));
        for (p, area) in self.panels.iter().zip(areas.iter()) {
            let nx = p.x_labels.len().max(1);
            let ny = p.y_labels.len().max(1);
            let xl = p.x_labels.clone();
            let yl = p.y_labels.clone();
            let fx = move |v: &f64| label_at(&xl, *v);
            let fy = move |v: &f64| label_at(&yl, *v);
            let mut chart = ChartBuilder::on(area)
                .caption(&p.title, (FONT, 18))
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..nx as f64, 0.0..ny as f64)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(p.x_desc.as_str())
                .y_desc(p.y_desc.as_str())
                .axis_desc_style((FONT, 15))
                .label_style((FONT, 13))
                .x_labels(nx * 2 + 1)
                .y_labels(ny * 2 + 1)
                .x_label_formatter(&fx)
                .y_label_formatter(&fy)
                .draw()
                .map_err(plot_err)?;
            for (j, row) in p.values.iter().enumerate() {
                for (i, &v) in row.iter().enumerate() {
                    let (x, y) = (i as f64, j as f64);
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(x, y), (x + 1.0, y + 1.0)],
                            heat(v).filled(),
                        )))
                        .map_err(plot_err)?;
                    let text = if v.is_finite() {
                        format!("{:.0}%", 100.0 * v)
                    } else {
                        "–".into()
                    };
                    let color = if v > 0.5 { WHITE } else { BLACK };
                    chart
                        .draw_series(std::iter::once(Text::new(
                            text,
                            (x + 0.38, y + 0.55),
                            (FONT, 14).into_font().color(&color),
                        )))
                        .map_err(plot_err)?;
                }
            }
        }
        Ok(())
    }
}

/// The label of the cell whose centre is at `v` (ticks fall on centres and edges; edges get
/// none).
fn label_at(labels: &[String], v: f64) -> String {
    let c = v - 0.5;
    if (c - c.round()).abs() < 1e-6 && c >= 0.0 {
        labels.get(c.round() as usize).cloned().unwrap_or_default()
    } else {
        String::new()
    }
}

/// Heat maps of fractions, one panel per engine × mode (or whatever the caller groups).
pub fn heatmap(dir: &Path, stem: &str, title: &str, panels: &[Panel]) -> crate::Result<()> {
    write_both(dir, stem, &Heatmap { title, panels })
}
