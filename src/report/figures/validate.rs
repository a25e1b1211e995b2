//! `validate`'s figures: the 2D no-bounce limit against R (`no_bounce_2d`), the 3D solid
//! angles measured against predicted (`solid_angles`), free-flight drift against dt on log
//! axes (`flight_drift`), and the trend of the 2D ratio as e and μ rise (`trend`).

use super::*;
use crate::theory;

/// Measured points of one series (an engine, a case), each with its error bar.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The series' name in the legend.
    pub label: String,
    /// Its points.
    pub points: Vec<Point>,
    /// Drawn with triangles (else circles).
    pub triangles: bool,
    /// Joined by a line.
    pub joined: bool,
}

const COLORS: [RGBColor; 8] = [
    RGBColor(210, 0, 0),
    RGBColor(0, 90, 200),
    RGBColor(230, 130, 0),
    RGBColor(0, 150, 120),
    RGBColor(128, 0, 128),
    RGBColor(160, 82, 45),
    RGBColor(120, 120, 0),
    RGBColor(110, 110, 110),
];

fn draw_series<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    series: &[Series],
    nudge: f64,
) -> Result<(), String> {
    let n = series.len() as f64;
    for (i, s) in series.iter().enumerate() {
        // Side by side, so that series at the same x do not hide each other.
        let dx = nudge * (i as f64 - 0.5 * (n - 1.0));
        let pts: Vec<Point> = s
            .points
            .iter()
            .map(|p| Point { x: p.x + dx, ..*p })
            .collect();
        let marker = if s.triangles {
            Marker::Triangle
        } else {
            Marker::Circle
        };
        points(
            chart,
            &pts,
            COLORS[i % COLORS.len()],
            marker,
            s.joined,
            &s.label,
        )?;
    }
    Ok(())
}

struct NoBounce<'a> {
    title: &'a str,
    series: &'a [Series],
}

impl Figure for NoBounce<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let y = 0.0..0.6;
        let mut chart = chart(
            root,
            self.title,
            0.0..1.05,
            y.clone(),
            R_DESC,
            "P(breadth vertical)",
        )?;
        solid(
            &mut chart,
            curve(0.0025, 1.05, 400, &y, |r| {
                theory::no_bounce_2d(r).breadth_vertical
            }),
            DARK_BLUE.stroke_width(3),
            "no bounce, eq. (InElasK): (2/π) arctan R",
        )?;
        dashed(
            &mut chart,
            curve(0.0025, 1.05, 400, &y, |r| theory::two_d(r).breadth_vertical),
            LIGHT_BLUE.stroke_width(2),
            "bouncing theory, eq. (MasterEqu)",
        )?;
        draw_series(&mut chart, self.series, 0.008)?;
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// P(breadth vertical) against R: eq. (InElasK) and (MasterEqu) as curves, the measured points
/// of each series.
pub fn no_bounce_2d(dir: &Path, stem: &str, title: &str, series: &[Series]) -> crate::Result<()> {
    write_both(dir, stem, &NoBounce { title, series })
}

struct SolidAngles<'a> {
    title: &'a str,
    series: &'a [Series],
}

impl Figure for SolidAngles<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut hi: f64 = 0.5;
        for p in self.series.iter().flat_map(|s| &s.points) {
            hi = hi.max(p.x).max(p.y + bar(p.y_err));
        }
        let hi = (hi * 1.08).min(1.0);
        let mut chart = chart(
            root,
            self.title,
            0.0..hi,
            0.0..hi,
            "solid-angle probability, (2/π) arctan(w_j w_k / (w_i |w|))",
            "measured probability",
        )?;
        solid(
            &mut chart,
            vec![(0.0, 0.0), (hi, hi)],
            DARK_BLUE.stroke_width(2),
            "measured = predicted",
        )?;
        draw_series(&mut chart, self.series, 0.004)?;
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// Each face pair's measured probability against its solid-angle prediction, with y = x.
pub fn solid_angles(dir: &Path, stem: &str, title: &str, series: &[Series]) -> crate::Result<()> {
    write_both(dir, stem, &SolidAngles { title, series })
}

/// A log10 tick: 10^k for whole k, else nothing.
fn power_tick(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("1e{}", v.round() as i64)
    } else {
        String::new()
    }
}

/// A log10 tick for a time step: 1/N, N to two significant figures.
fn dt_tick(v: &f64) -> String {
    let n = 10f64.powf(-*v);
    let p = 10f64.powf(n.log10().floor() - 1.0);
    format!("1/{}", (n / p).round() * p)
}

struct FlightDrift<'a> {
    title: &'a str,
    series: &'a [Series],
}

impl Figure for FlightDrift<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let logged: Vec<Series> = self
            .series
            .iter()
            .map(|s| Series {
                points: s
                    .points
                    .iter()
                    .filter(|p| p.x > 0.0 && p.y > 0.0)
                    .map(|p| Point {
                        x: p.x.log10(),
                        y: p.y.log10(),
                        y_err: 0.0,
                    })
                    .collect(),
                ..s.clone()
            })
            .collect();
        let mut xs = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        let mut ys = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        for p in logged.iter().flat_map(|s| &s.points) {
            xs.add(p.x);
            ys.add(p.y);
        }
        if !(xs.lo.is_finite() && ys.lo.is_finite()) {
            xs = Span::new(-4.0, -1.0);
            ys = Span::new(-6.0, 0.0);
        }
        let (y0, y1) = (ys.lo.floor() - 0.2, ys.hi.ceil() + 0.6);
        root.fill(&WHITE).map_err(plot_err)?;
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, (FONT, 24))
            .margin(20)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d(xs.padded(0.05, 0.05), y0..y1)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("time step dt, s (log scale)")
            .y_desc("largest relative drift over the flight (log scale)")
            .axis_desc_style((FONT, 20))
            .label_style((FONT, 16))
            .x_labels(5)
            .y_labels(((y1 - y0).ceil() as usize + 1).max(2))
            .x_label_formatter(&dt_tick)
            .y_label_formatter(&power_tick)
            .light_line_style(RGBColor(243, 243, 243))
            .bold_line_style(RGBColor(210, 210, 210))
            .draw()
            .map_err(plot_err)?;
        draw_series(&mut chart, &logged, 0.0)?;
        legend(&mut chart, SeriesLabelPosition::LowerRight)
    }
}

/// Largest relative drift (angular momentum, rotational energy) against dt, log-log, one line
/// per integrator and quantity. Drifts of 0 are left out.
pub fn flight_drift(dir: &Path, stem: &str, title: &str, series: &[Series]) -> crate::Result<()> {
    write_both(dir, stem, &FlightDrift { title, series })
}

struct Trend<'a> {
    title: &'a str,
    x_desc: &'a str,
    theory: f64,
    no_bounce: f64,
    series: &'a [Series],
}

impl Figure for Trend<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut xs = Span::new(0.0, 1.0);
        let mut ys = Span::new(
            self.theory.min(self.no_bounce),
            self.theory.max(self.no_bounce),
        );
        for p in self.series.iter().flat_map(|s| &s.points) {
            xs.add(p.x);
            ys.add_point(p);
        }
        let x = xs.padded(0.05, 0.05);
        let mut chart = chart(
            root,
            self.title,
            x.clone(),
            ys.padded(0.1, 0.35),
            self.x_desc,
            "P(breadth vertical)",
        )?;
        solid(
            &mut chart,
            vec![(x.start, self.theory), (x.end, self.theory)],
            DARK_BLUE.stroke_width(3),
            "theory, eq. (MasterEqu)",
        )?;
        dashed(
            &mut chart,
            vec![(x.start, self.no_bounce), (x.end, self.no_bounce)],
            LIGHT_BLUE.stroke_width(2),
            "no bounce, eq. (InElasK)",
        )?;
        draw_series(&mut chart, self.series, 0.006)?;
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// P(breadth vertical) in 2D against e (μ rising with it, as `x_desc` says), with the theory's
/// (eq. MasterEqu, through eq. rattoprob) and the no-bounce probability (eq. InElasK) as
/// horizontal lines. (The ratio itself runs off any linear scale where an engine fails.)
pub fn trend(
    dir: &Path,
    stem: &str,
    title: &str,
    x_desc: &str,
    theory: f64,
    no_bounce: f64,
    series: &[Series],
) -> crate::Result<()> {
    write_both(
        dir,
        stem,
        &Trend {
            title,
            x_desc,
            theory,
            no_bounce,
            series,
        },
    )
}
