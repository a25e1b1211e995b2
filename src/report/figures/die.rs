//! The die map (`die_map`): the six faces laid out as a net, each with its number, its
//! probability and its departure from a fair die's in σ, shaded red where it comes up more
//! often and blue where less, as the paper's DiceMap figure sets a fair die beside a biased
//! one.

use super::*;

/// One face on the map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapFace {
    /// Its number.
    pub number: u8,
    /// Its probability and binomial error.
    pub p: f64,
    /// Its error.
    pub err: f64,
    /// Its departure from the null in σ.
    pub z: f64,
}

struct DieMap<'a> {
    title: &'a str,
    faces: &'a [MapFace],
}

/// Where each number sits on the net (column, row): 1 in the middle, 5 and 2 either side,
/// 3 above, 4 below, 6 beyond 2, so that the net folds into the right-handed die (for the
/// left layout, 2 and 3 swap with 5 and 4's sides, as on that die).
fn cell(number: u8) -> (u32, u32) {
    match number {
        1 => (1, 1),
        5 => (0, 1),
        2 => (2, 1),
        6 => (3, 1),
        3 => (1, 0),
        _ => (1, 2),
    }
}

/// The shade of a departure: white at 0, full red (more often) or blue (less) at 5σ.
fn shade(z: f64) -> RGBColor {
    let t = (z.abs() / 5.0).clamp(0.0, 1.0);
    let fade = |full: u8| (255.0 - t * (255.0 - full as f64)).round() as u8;
    if z >= 0.0 {
        RGBColor(255, fade(90), fade(90))
    } else {
        RGBColor(fade(90), fade(140), 255)
    }
}

impl Figure for DieMap<'_> {
    fn size(&self) -> (u32, u32) {
        (880, 720)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(plot_err)?;
        let (top, body) = root.split_vertically(60);
        top.titled(self.title, (FONT, 19)).map_err(plot_err)?;
        let side = 200i32;
        let (x0, y0) = (40i32, 20i32);
        for f in self.faces {
            let (c, r) = cell(f.number);
            let (x, y) = (x0 + c as i32 * side, y0 + r as i32 * side);
            body.draw(&Rectangle::new(
                [(x, y), (x + side, y + side)],
                shade(f.z).filled(),
            ))
            .map_err(plot_err)?;
            body.draw(&Rectangle::new(
                [(x, y), (x + side, y + side)],
                BLACK.stroke_width(2),
            ))
            .map_err(plot_err)?;
            let text = |s: String, dy: i32, size: i32| {
                Text::new(s, (x + 16, y + dy), (FONT, size).into_font())
            };
            body.draw(&text(f.number.to_string(), 14, 48))
                .map_err(plot_err)?;
            body.draw(&text(format!("{:.4}", f.p), 90, 24))
                .map_err(plot_err)?;
            body.draw(&text(format!("± {:.4}", f.err), 120, 20))
                .map_err(plot_err)?;
            body.draw(&text(format!("{:+.1} σ", f.z), 152, 24))
                .map_err(plot_err)?;
        }
        Ok(())
    }
}

/// Writes the die map as `dir/<stem>.svg` and `.png`.
pub fn die_map(dir: &Path, stem: &str, title: &str, faces: &[MapFace]) -> crate::Result<()> {
    write_both(dir, stem, &DieMap { title, faces })
}

/// One outcome's bar on the faces figure: its label, probability, binomial error and the
/// null's probability.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceBar {
    /// What the die shows (a number, `heads`, `edge`).
    pub label: String,
    /// Its probability.
    pub p: f64,
    /// Its binomial error (1σ).
    pub err: f64,
    /// The null's probability.
    pub null: f64,
}

struct Faces<'a> {
    title: &'a str,
    null: &'a str,
    bars: &'a [FaceBar],
}

impl Figure for Faces<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let n = self.bars.len();
        let mut ys = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        for b in self.bars {
            ys.add(b.p - 2.0 * bar(b.err));
            ys.add(b.p + 2.0 * bar(b.err));
            ys.add(b.null);
        }
        root.fill(&WHITE).map_err(plot_err)?;
        let labels: Vec<String> = self.bars.iter().map(|b| b.label.clone()).collect();
        let name = move |v: &f64| {
            let k = v.round();
            if (v - k).abs() < 1e-6 && k >= 1.0 && k as usize <= labels.len() {
                labels[k as usize - 1].clone()
            } else {
                String::new()
            }
        };
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, (FONT, 22))
            .margin(20)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d(0.4..n as f64 + 0.6, ys.padded(0.1, 0.3))
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("face (the label it shows)")
            .y_desc("P(face), with its 2σ interval")
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
        // The null: a short grey bar across each face's place.
        let grey = RGBColor(90, 90, 90).stroke_width(3);
        chart
            .draw_series(self.bars.iter().enumerate().map(|(k, b)| {
                let x = k as f64 + 1.0;
                PathElement::new(vec![(x - 0.35, b.null), (x + 0.35, b.null)], grey)
            }))
            .map_err(plot_err)?
            .label(self.null)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey));
        let pts: Vec<Point> = self
            .bars
            .iter()
            .enumerate()
            .map(|(k, b)| Point {
                x: k as f64 + 1.0,
                y: b.p,
                y_err: 2.0 * b.err,
            })
            .collect();
        points(
            &mut chart,
            &pts,
            RGBColor(200, 30, 30),
            Marker::Circle,
            false,
            "measured, ± 2σ",
        )?;
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Writes the faces figure as `dir/<stem>.svg` and `.png`: each outcome's probability with
/// its 2σ interval beside the null's, for a die of any number of faces (issue 48: the die map
/// is a cube's net; issue 50: a bar chart with error bars).
pub fn faces(
    dir: &Path,
    stem: &str,
    title: &str,
    null: &str,
    bars: &[FaceBar],
) -> crate::Result<()> {
    write_both(dir, stem, &Faces { title, null, bars })
}

/// One number's curve on the bias figure.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceCurve {
    /// Its place among the die's faces, from 1.
    pub number: u8,
    /// What it shows, named in the legend (a cube's number; a shape's label).
    pub label: String,
    /// Its probability at each value, with its error.
    pub points: Vec<Point>,
    /// The null's probability at each value.
    pub null: Vec<(f64, f64)>,
}

struct Bias<'a> {
    title: &'a str,
    x_desc: &'a str,
    series: &'a [FaceCurve],
}

/// A colour for each number, 1 to 6.
const FACE_COLORS: [RGBColor; 6] = [
    RGBColor(200, 30, 30),
    RGBColor(230, 130, 0),
    RGBColor(40, 150, 40),
    RGBColor(0, 150, 170),
    RGBColor(40, 70, 200),
    RGBColor(140, 40, 160),
];

impl Figure for Bias<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut xs = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        let mut ys = Span::new(1.0 / 6.0, 1.0 / 6.0);
        for c in self.series {
            c.points.iter().for_each(|p| {
                xs.add(p.x);
                ys.add_point(p)
            });
            c.null.iter().for_each(|(_, y)| ys.add(*y));
        }
        if !xs.lo.is_finite() {
            xs = Span::new(0.0, 1.0);
        }
        let mut chart = chart(
            root,
            self.title,
            xs.padded(0.04, 0.04),
            ys.padded(0.08, 0.3),
            self.x_desc,
            "P(face up)",
        )?;
        let n = self.series.len();
        for c in self.series {
            // A cube's six colours; a die of more faces, hues round the wheel.
            let color = match n {
                0..=6 => FACE_COLORS[(c.number as usize).clamp(1, 6) - 1],
                _ => {
                    let hsl = HSLColor((c.number as f64 - 1.0) / n as f64, 0.75, 0.42);
                    let (r, g, b) = hsl.rgb();
                    RGBColor(r, g, b)
                }
            };
            points(
                &mut chart,
                &c.points,
                color,
                Marker::Circle,
                false,
                &format!("face {}", c.label),
            )?;
            chart
                .draw_series(LineSeries::new(
                    c.null.clone(),
                    color.mix(0.6).stroke_width(1),
                ))
                .map_err(plot_err)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// Writes the bias figure as `dir/<stem>.svg` and `.png`: for each number (1 to 6), its
/// probability at each value of a feature with its error (points) and the null's (a thin line
/// in the same colour).
pub fn bias(
    dir: &Path,
    stem: &str,
    title: &str,
    x_desc: &str,
    series: &[FaceCurve],
) -> crate::Result<()> {
    write_both(
        dir,
        stem,
        &Bias {
            title,
            x_desc,
            series,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_net_folds_into_a_die_whose_opposite_faces_never_touch() {
        // On a cross-shaped net, two faces are opposite on the folded cube when they share a
        // row or a column two cells apart (the one between them folds up between them).
        let opposite = |a: u8, b: u8| {
            let ((ca, ra), (cb, rb)) = (cell(a), cell(b));
            (ra == rb && ca.abs_diff(cb) == 2) || (ca == cb && ra.abs_diff(rb) == 2)
        };
        for (a, b) in [(1, 6), (2, 5), (3, 4)] {
            assert!(opposite(a, b), "{a} and {b}");
        }
        // Every cell distinct.
        let mut cells: Vec<(u32, u32)> = (1..=6).map(cell).collect();
        cells.sort();
        cells.dedup();
        assert_eq!(cells.len(), 6);
        assert_eq!(shade(0.0), RGBColor(255, 255, 255));
        assert_eq!(shade(9.0), RGBColor(255, 90, 90));
    }
}
