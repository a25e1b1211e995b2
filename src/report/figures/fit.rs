//! `fit`'s figures: the profile likelihood of every parameter, one panel each
//! (`fit_profiles`), and each row's ratio measured beside fitted or predicted (`fit_rows`).

use super::*;

/// One parameter's profile: Δ(−2 ln L) against its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// The parameter's name, e.g. "e[MDF]".
    pub name: String,
    /// (value, Δ(−2 ln L)) along its range.
    pub points: Vec<(f64, f64)>,
    /// Its maximum-likelihood value.
    pub best: f64,
    /// Draw the value axis on a log scale (κ).
    pub log: bool,
}

struct Profiles<'a> {
    title: &'a str,
    profiles: &'a [Profile],
}

impl Figure for Profiles<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(plot_err)?;
        let n = self.profiles.len().max(1);
        let cols = (n as f64).sqrt().ceil() as usize;
        let rows = n.div_ceil(cols);
        let (top, body) = root.split_vertically(40);
        top.titled(self.title, (FONT, 24)).map_err(plot_err)?;
        let panels = body.split_evenly((rows, cols));
        for (p, area) in self.profiles.iter().zip(panels.iter()) {
            // κ on log₁₀(1 + κ), the fit's own coordinate.
            let tx = |v: f64| if p.log { (1.0 + v).log10() } else { v };
            let pts: Vec<(f64, f64)> = p
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|&(x, y)| (tx(x), y.min(12.0)))
                .collect();
            let mut xs = Span::new(f64::INFINITY, f64::NEG_INFINITY);
            pts.iter().for_each(|(x, _)| xs.add(*x));
            if !xs.lo.is_finite() {
                continue;
            }
            let x_desc = if p.log {
                format!("log10(1 + {})", p.name)
            } else {
                p.name.clone()
            };
            let mut c = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(45)
                .build_cartesian_2d(xs.padded(0.02, 0.02), 0.0..12.5)
                .map_err(plot_err)?;
            c.configure_mesh()
                .x_desc(x_desc)
                .y_desc("Δ(−2 ln L)")
                .axis_desc_style((FONT, 15))
                .label_style((FONT, 12))
                .x_label_formatter(&tick)
                .y_label_formatter(&tick)
                .light_line_style(RGBColor(243, 243, 243))
                .draw()
                .map_err(plot_err)?;
            for (level, color) in [(1.0, LIGHT_BLUE), (4.0, SIENNA)] {
                c.draw_series(DashedLineSeries::new(
                    vec![(xs.lo, level), (xs.hi, level)],
                    6,
                    4,
                    color.stroke_width(1),
                ))
                .map_err(plot_err)?;
            }
            c.draw_series(LineSeries::new(pts.clone(), DARK_BLUE.stroke_width(2)))
                .map_err(plot_err)?;
            c.draw_series(
                pts.iter()
                    .map(|&(x, y)| Circle::new((x, y), 3, DARK_BLUE.filled())),
            )
            .map_err(plot_err)?;
            let b = tx(p.best);
            c.draw_series(LineSeries::new(
                vec![(b, 0.0), (b, 12.5)],
                MDF_RED.stroke_width(1),
            ))
            .map_err(plot_err)?;
        }
        Ok(())
    }
}

/// Writes `fit_profiles.svg`/`.png`: each parameter's profile, dashed at Δ = 1 (1σ) and 4 (2σ).
pub fn profiles(dir: &Path, title: &str, profiles: &[Profile]) -> crate::Result<()> {
    write_both(dir, "fit_profiles", &Profiles { title, profiles })
}

/// A row's ratio measured and simulated.
#[derive(Clone, Debug, PartialEq)]
pub struct RowRatio {
    /// The row's label.
    pub label: String,
    /// Measured N(breadth vertical)/N(width vertical) ± binomial error, if measured.
    pub measured: Option<Point>,
    /// The fit's (or the leave-one-out prediction's) ratio ± its error.
    pub simulated: Point,
    /// The paper's theory (eq. MasterEqu), if drawn.
    pub theory: Option<Point>,
}

struct Rows<'a> {
    title: &'a str,
    simulated: &'a str,
    rows: &'a [RowRatio],
}

impl Figure for Rows<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let n = self.rows.len();
        let mut ys = Span::new(0.0, 0.0);
        for r in self.rows {
            if let Some(m) = &r.measured {
                ys.add_point(m);
            }
            ys.add_point(&r.simulated);
            if let Some(t) = &r.theory {
                ys.add_point(t);
            }
        }
        let mut c = chart(
            root,
            self.title,
            0.3..n as f64 + 0.7,
            ys.padded(0.0, 0.25),
            "row (in the order of the data)",
            RATIO_DESC,
        )?;
        let at = |i: usize, p: &Point, dx: f64| Point {
            x: i as f64 + 1.0 + dx,
            ..*p
        };
        let measured: Vec<Point> = self
            .rows
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.measured.map(|m| at(i, &m, -0.12)))
            .collect();
        let simulated: Vec<Point> = self
            .rows
            .iter()
            .enumerate()
            .map(|(i, r)| at(i, &r.simulated, 0.12))
            .collect();
        points(
            &mut c,
            &measured,
            MDF_RED,
            Marker::Circle,
            false,
            "measured",
        )?;
        points(
            &mut c,
            &simulated,
            SIM_3D[0],
            Marker::Triangle,
            false,
            self.simulated,
        )?;
        let theory: Vec<Point> = self
            .rows
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.theory.map(|t| at(i, &t, 0.0)))
            .collect();
        if !theory.is_empty() {
            points(
                &mut c,
                &theory,
                DARK_BLUE,
                Marker::Circle,
                false,
                "theory (MasterEqu)",
            )?;
        }
        legend(&mut c, SeriesLabelPosition::UpperRight)
    }
}

/// Writes `<stem>.svg`/`.png`: every row's measured ratio beside the simulated one.
pub fn rows(
    dir: &Path,
    stem: &str,
    title: &str,
    simulated: &str,
    rows: &[RowRatio],
) -> crate::Result<()> {
    write_both(
        dir,
        stem,
        &Rows {
            title,
            simulated,
            rows,
        },
    )
}
