//! The die map (`die_map`): the six faces laid out as a net, each with its number, its
//! probability and its departure from a fair die's in σ, shaded red where it comes up more
//! often and blue where less (a key says how much), as the paper's DiceMap figure sets a fair
//! die beside a biased one.

use super::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One face on the map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapFace {
    /// Its number.
    pub number: u8,
    /// Where it sits on the die: its outward direction in body axes, an index into
    /// [`crate::model::faces::DIRECTIONS`] (`+x`, `−x`, `+y`, `−y`, `+z`, `−z`).
    pub direction: usize,
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

/// Where each face sits on the net (column, row), by its direction in body axes: +z in the
/// middle seen from outside, −x and +x either side, +y above, −y below, −z beyond +x, so that
/// the net folds into the die. The numbers are the layout's: a western (right-handed) die has
/// 1 in the middle, 5 and 2 either side, 3 above, 4 below and 6 beyond 2; its mirror shows
/// 4 and 3 either side and 2 above, as that die does.
fn cell(direction: usize) -> (u32, u32) {
    match direction {
        0 => (2, 1),
        1 => (0, 1),
        2 => (1, 0),
        3 => (1, 2),
        4 => (1, 1),
        _ => (3, 1),
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
        key(&body, (x0 + 2 * side + 30, y0 + 2 * side + 50))?;
        for f in self.faces {
            let (c, r) = cell(f.direction);
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

/// The colour key at `(x, y)`: the shade from 5σ less often (blue) through 0 (white) to 5σ
/// more often (red), with its ticks.
fn key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
) -> Result<(), String> {
    let (w, h) = (300i32, 22i32);
    for i in 0..w {
        let z = -5.0 + 10.0 * (i as f64 + 0.5) / w as f64;
        area.draw(&Rectangle::new(
            [(x + i, y), (x + i + 1, y + h)],
            shade(z).filled(),
        ))
        .map_err(plot_err)?;
    }
    area.draw(&Rectangle::new(
        [(x, y), (x + w, y + h)],
        BLACK.stroke_width(1),
    ))
    .map_err(plot_err)?;
    let style = (FONT, 15)
        .into_font()
        .into_text_style(area)
        .pos(Pos::new(HPos::Center, VPos::Top));
    for z in [-5, -2, 0, 2, 5] {
        let at = x + ((z + 5) as f64 / 10.0 * w as f64).round() as i32;
        let label = if z == 0 {
            "0".into()
        } else {
            format!("{z:+}σ")
        };
        area.draw(&Text::new(label, (at, y + h + 4), style.clone()))
            .map_err(plot_err)?;
    }
    area.draw(&Text::new(
        "departure from the null: less often … more often",
        (x, y - 22),
        (FONT, 15).into_font(),
    ))
    .map_err(plot_err)?;
    Ok(())
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
        let mut ys = Span::new(f64::INFINITY, f64::NEG_INFINITY);
        for b in self.bars {
            ys.add(b.p - 2.0 * bar(b.err));
            ys.add(b.p + 2.0 * bar(b.err));
            ys.add(b.null);
        }
        let labels: Vec<String> = self.bars.iter().map(|b| b.label.clone()).collect();
        let mut chart = labelled_chart(
            root,
            (self.title, 22),
            labels,
            ys.padded(0.1, 0.3),
            ("face (the label it shows)", "P(face), with its 2σ interval"),
        )?;
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
            "P(face up), bars ±1σ",
        )?;
        let n = self.series.len();
        // Each face's points nudged sideways, a little apart, so that six error bars at one
        // value do not hide each other (the null's lines stay where they are).
        let step = (xs.hi - xs.lo) * if n <= 6 { 0.008 } else { 0.003 };
        for (i, c) in self.series.iter().enumerate() {
            let dx = (i as f64 - (n as f64 - 1.0) / 2.0) * step;
            let nudged: Vec<Point> = c
                .points
                .iter()
                .map(|p| Point { x: p.x + dx, ..*p })
                .collect();
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
                &nudged,
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
        let opposite = |a: usize, b: usize| {
            let ((ca, ra), (cb, rb)) = (cell(a), cell(b));
            (ra == rb && ca.abs_diff(cb) == 2) || (ca == cb && ra.abs_diff(rb) == 2)
        };
        // ±x, ±y, ±z (DIRECTIONS' order) are opposite on the folded cube.
        for (a, b) in [(0, 1), (2, 3), (4, 5)] {
            assert!(opposite(a, b), "{a} and {b}");
        }
        // Seen from outside the middle face (+z), +x is to its right and +y above: the body's
        // axes right-handed, so the net is the die, not its mirror.
        assert_eq!(cell(0).0, cell(4).0 + 1);
        assert_eq!(cell(2).1 + 1, cell(4).1);
        // Every cell distinct.
        let mut cells: Vec<(u32, u32)> = (0..6).map(cell).collect();
        cells.sort();
        cells.dedup();
        assert_eq!(cells.len(), 6);
        assert_eq!(shade(0.0), RGBColor(255, 255, 255));
        assert_eq!(shade(9.0), RGBColor(255, 90, 90));
    }
}

/// One outcome of a die of any shape on its map: its label and how often the die came to
/// rest on that face.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeFace {
    /// What the die shows resting on the face.
    pub label: String,
    /// Its probability.
    pub p: f64,
    /// Its departure from the null in σ.
    pub z: f64,
}

/// A facet of the hull as the map draws it: its outline projected on the plane normal to the
/// view, seen from the front (`back` false) or from behind (mirrored, as one sees the far side
/// by turning the die over), and the outcome resting on it, if any.
#[derive(Clone, Debug, PartialEq)]
struct Drawn {
    outline: Vec<(f64, f64)>,
    back: bool,
    face: Option<usize>,
}

/// The view that sees every facet most squarely: of 64 directions spread over a hemisphere
/// (a Fibonacci lattice, fixed, so the map is the same every run), the one whose smallest
/// |normal · view| over the facets is largest. A facet seen edge-on (a cube's sides along an
/// axis) would vanish; this view sees each at a slant, half from the front, half from behind.
fn view(normals: &[nalgebra::Vector3<f64>]) -> nalgebra::Vector3<f64> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..64)
        .map(|i| {
            let z = 1.0 - (i as f64 + 0.5) / 64.0;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            nalgebra::Vector3::new(r * a.cos(), r * a.sin(), z)
        })
        .max_by(|a, b| {
            let worst = |v: &nalgebra::Vector3<f64>| {
                normals
                    .iter()
                    .map(|n| n.dot(v).abs())
                    .fold(f64::INFINITY, f64::min)
            };
            worst(a).total_cmp(&worst(b))
        })
        .expect("64 directions")
}

/// The hull's facets projected for the map, each matched to the outcome whose face it is (by
/// normal, within 1e-6; a facet the die cannot rest on has none).
fn projected(shape: &crate::model::shape::Shape) -> Vec<Drawn> {
    let facets = shape.facets();
    let normals: Vec<_> = facets.iter().map(|f| f.normal).collect();
    let v = view(&normals);
    // A basis of the view's plane: e1 horizontal (no z), e2 = v × e1 upward.
    let e1 = nalgebra::Vector3::new(-v.y, v.x, 0.0)
        .try_normalize(1e-9)
        .unwrap_or(nalgebra::Vector3::x());
    let e2 = v.cross(&e1);
    facets
        .iter()
        .map(|f| {
            let back = f.normal.dot(&v) < 0.0;
            let sign = if back { -1.0 } else { 1.0 };
            Drawn {
                outline: f
                    .polygon
                    .iter()
                    .map(|p| (sign * p.dot(&e1), p.dot(&e2)))
                    .collect(),
                back,
                face: shape
                    .faces
                    .iter()
                    .position(|o| (nalgebra::Vector3::from(o.normal) - f.normal).norm() < 1e-6),
            }
        })
        .collect()
}

struct ShapeMap<'a> {
    title: &'a str,
    drawn: Vec<Drawn>,
    faces: &'a [ShapeFace],
}

impl Figure for ShapeMap<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, 640)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(plot_err)?;
        let (top, body) = root.split_vertically(70);
        top.titled(self.title, (FONT, 18)).map_err(plot_err)?;
        let extent = self
            .drawn
            .iter()
            .flat_map(|d| &d.outline)
            .fold(0.0f64, |m, (x, y)| m.max(x.abs()).max(y.abs()));
        let (w, h) = body.dim_in_pixel();
        let half = (w / 2) as f64;
        let scale = 0.42 * half.min(h as f64 - 70.0) / extent.max(1e-12);
        body.draw(&Text::new(
            "Each face shaded by how much more (red) or less (blue) often the die came to rest \
             on it than the null says (full at 5σ), labelled with what the die then shows.",
            (20, h as i32 - 24),
            (FONT, 15).into_font(),
        ))
        .map_err(plot_err)?;
        for (panel, back) in [(0.0, false), (half, true)] {
            let (cx, cy) = (panel + half / 2.0, (h as f64 - 20.0) / 2.0);
            let at = |(x, y): (f64, f64)| ((cx + scale * x) as i32, (cy - scale * y) as i32);
            let caption = if back {
                "the far side (the die turned over, left to right)"
            } else {
                "seen from one side"
            };
            body.draw(&Text::new(
                caption,
                (panel as i32 + 20, 6),
                (FONT, 17).into_font(),
            ))
            .map_err(plot_err)?;
            for d in self.drawn.iter().filter(|d| d.back == back) {
                let pts: Vec<(i32, i32)> = d.outline.iter().map(|&p| at(p)).collect();
                let face = d.face.and_then(|k| self.faces.get(k));
                let fill = face.map_or(RGBColor(225, 225, 225), |f| shade(f.z));
                body.draw(&Polygon::new(pts.clone(), fill.filled()))
                    .map_err(plot_err)?;
                let mut ring = pts.clone();
                ring.push(pts[0]);
                body.draw(&PathElement::new(ring, BLACK.stroke_width(2)))
                    .map_err(plot_err)?;
                if let Some(f) = face {
                    let n = d.outline.len() as f64;
                    let c = d
                        .outline
                        .iter()
                        .fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
                    let (x, y) = at(c);
                    let style = |size: i32| {
                        (FONT, size)
                            .into_font()
                            .into_text_style(&body)
                            .pos(Pos::new(HPos::Center, VPos::Center))
                    };
                    body.draw(&Text::new(f.label.clone(), (x, y - 12), style(20)))
                        .map_err(plot_err)?;
                    body.draw(&Text::new(format!("{:+.1}σ", f.z), (x, y + 10), style(14)))
                        .map_err(plot_err)?;
                }
            }
        }
        Ok(())
    }
}

/// Writes the map of a die of any shape as `dir/<stem>.svg` and `.png`: its hull seen from
/// one side and from the other (a slanted view that sees every facet), each face shaded by how
/// much more (red) or less (blue) often the die came to rest on it than the null says (white
/// at 0, full at 5σ), with the label the die then shows and the departure in σ; a facet the
/// die cannot rest on is grey. Nothing is written for a die without flat facets (a coin: its
/// faces figure says it all).
pub fn shape_map(
    dir: &Path,
    stem: &str,
    title: &str,
    shape: &crate::model::shape::Shape,
    faces: &[ShapeFace],
) -> crate::Result<()> {
    let drawn = projected(shape);
    if drawn.is_empty() {
        return Ok(());
    }
    write_both(
        dir,
        stem,
        &ShapeMap {
            title,
            drawn,
            faces,
        },
    )
}

#[cfg(test)]
mod map_tests {
    use super::*;

    #[test]
    fn the_map_shows_every_facet_once_half_from_each_side_and_each_outcome_on_its_face() {
        for name in ["d4", "d6", "d8", "d10", "d12", "d20"] {
            let shape = crate::model::shape::named(name, None).unwrap();
            let drawn = projected(&shape);
            assert_eq!(drawn.len(), shape.facets().len(), "{name}");
            // Every outcome drawn exactly once, on the facet of its normal.
            for k in 0..shape.faces.len() {
                assert_eq!(
                    drawn.iter().filter(|d| d.face == Some(k)).count(),
                    1,
                    "{name} face {k}"
                );
            }
            // The view sees no facet edge-on, and each side shows some.
            let normals: Vec<_> = shape.facets().iter().map(|f| f.normal).collect();
            let v = view(&normals);
            assert!(normals.iter().all(|n| n.dot(&v).abs() > 0.05), "{name}");
            assert!(drawn.iter().any(|d| d.back) && drawn.iter().any(|d| !d.back));
            // A projection keeps a facet's area times |cos| of its slant: the front's facets
            // cover the hull's outline, as the back's do, so the two sides' areas are equal.
            let area = |back: bool| -> f64 {
                drawn
                    .iter()
                    .filter(|d| d.back == back)
                    .map(|d| {
                        let o = &d.outline;
                        (0..o.len())
                            .map(|i| {
                                let (a, b) = (o[i], o[(i + 1) % o.len()]);
                                a.0 * b.1 - b.0 * a.1
                            })
                            .sum::<f64>()
                            .abs()
                            / 2.0
                    })
                    .sum()
            };
            assert!(
                (area(false) - area(true)).abs() < 1e-9 * area(false),
                "{name}: {} {}",
                area(false),
                area(true)
            );
        }
        let coin = crate::model::shape::named("coin:24,2", None).unwrap();
        assert!(projected(&coin).is_empty());
    }
}
