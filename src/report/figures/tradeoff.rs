//! The trade-off figure: CPU per 1,000 rolls (log) against |departure| from the reference (log),
//! one panel per block (small multiples on shared axes), every point numbered and the numbers
//! keyed to the methods' names in a column beside the panels. Labels are placed so that no two
//! overlap and none covers a marker ([`place_labels`]); the y range is fitted to the points and
//! their 2σ bars and the precision ([`y_range`]), never to the yardstick bands.

use super::sweeps::{log_tick, pct};
use super::*;

/// One method's point in a panel.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodPoint {
    /// Its short label, drawn beside the marker (a number, keyed in the figure's key).
    pub key: String,
    /// CPU seconds per 1,000 rolls.
    pub cost: f64,
    /// |departure| from the reference, per cent.
    pub error: f64,
    /// Its one-standard-error, per cent (the bar drawn is 2σ).
    pub error_err: f64,
    /// A 2D method (circle), else 3D (triangle).
    pub two_d: bool,
    /// 2σ of the departure is within the precision: drawn filled, else hollow and grey.
    pub resolved: bool,
    /// On its mode's Pareto front (over resolved methods): joined by the front's line.
    pub on_front: bool,
    /// The cheapest method within the precision: ringed.
    pub cheapest: bool,
}

/// A yardstick drawn across a panel: |departure| from `lo` to `hi`, per cent.
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    /// Its lower edge, per cent (0 or less: the foot of the panel).
    pub lo: f64,
    /// Its upper edge, per cent.
    pub hi: f64,
    /// Drawn in the 2D methods' colour, else the 3D ones'; `None`: grey, both modes.
    pub two_d: Option<bool>,
}

/// One block's panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Its caption (the block, and what is cheapest there).
    pub title: String,
    /// Its methods.
    pub methods: Vec<MethodPoint>,
    /// Its yardsticks.
    pub bands: Vec<Band>,
}

/// The whole figure: the panels, and the key (each short label with its method's name) and the
/// bands' meaning written beside them.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// The figure's title.
    pub title: String,
    /// One panel per block.
    pub panels: Vec<Panel>,
    /// (short label, method name), in the order listed.
    pub key: Vec<(String, String)>,
    /// What the bands are, one line each (grey first, then 3D, then 2D).
    pub band_notes: Vec<String>,
    /// The precision asked, per cent (2σ): a dashed line.
    pub precision: f64,
}

const MODE_COLORS: [(bool, RGBColor, &str); 2] = [
    (false, RGBColor(128, 0, 128), "3D"),
    (true, RGBColor(0, 140, 120), "2D"),
];
const KEY_WIDTH: u32 = 330;
const PANEL_SIZE: (u32, u32) = (560, 440);
const LABEL_FONT: u32 = 13;
/// Half the size of a marker's box, px (a triangle of size 7 or a circle of radius 5).
const MARKER: i32 = 7;

/// Draws `fig` into `dir/<stem>.svg` and `.png`.
pub fn write(dir: &Path, stem: &str, fig: &Figure) -> crate::Result<()> {
    write_both(dir, stem, fig)
}

/// Columns of the small multiples: 1, 2 or 3.
fn columns(n: usize) -> usize {
    match n {
        0 | 1 => 1,
        2 | 4 => 2,
        _ => 3,
    }
}

/// Whether a point is drawn: a positive finite cost and a finite departure.
fn drawn(m: &MethodPoint) -> bool {
    m.cost > 0.0 && m.cost.is_finite() && m.error.is_finite()
}

/// The y range, log10 of per cent: from the smallest |departure| (a departure below a twentieth
/// of the precision is drawn at that floor, its bar showing how small) to the largest
/// |departure| + 2σ, always holding the precision, with a little room each side.
pub fn y_range<'a>(
    points: impl IntoIterator<Item = &'a MethodPoint>,
    precision: f64,
) -> std::ops::Range<f64> {
    let floor = (precision / 20.0).max(1e-6);
    let mut s = Span::new(precision.log10(), precision.log10());
    for m in points.into_iter().filter(|m| drawn(m)) {
        s.add(m.error.max(floor).log10());
        s.add((m.error + 2.0 * bar(m.error_err)).max(floor).log10());
    }
    s.padded(0.04, 0.06)
}

/// The x range, log10 of CPU seconds per 1,000 rolls, with room for the labels.
fn x_range<'a>(points: impl IntoIterator<Item = &'a MethodPoint>) -> std::ops::Range<f64> {
    let mut s = Span::new(f64::INFINITY, f64::NEG_INFINITY);
    for m in points.into_iter().filter(|m| drawn(m)) {
        s.add(m.cost.log10());
    }
    if !s.lo.is_finite() {
        s = Span::new(0.0, 1.0);
    }
    s.padded(0.06, 0.1)
}

/// A box in pixels: x0..x1, y0..y1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PxBox {
    /// Left.
    pub x0: i32,
    /// Top.
    pub y0: i32,
    /// Right.
    pub x1: i32,
    /// Bottom.
    pub y1: i32,
}

impl PxBox {
    fn around((x, y): (i32, i32), r: i32) -> PxBox {
        PxBox {
            x0: x - r,
            y0: y - r,
            x1: x + r,
            y1: y + r,
        }
    }

    /// The boxes share some area (touching edges do not count).
    pub fn overlaps(&self, o: &PxBox) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    fn inside(&self, o: &PxBox) -> bool {
        self.x0 >= o.x0 && self.x1 <= o.x1 && self.y0 >= o.y0 && self.y1 <= o.y1
    }
}

/// Places a label of `sizes[i]` (w, h, px) beside each anchor (a marker's centre) within
/// `bounds`: the box of each label, chosen so that no label overlaps another, any marker (a
/// box of `marker` px either side of each anchor) or any of `obstacles`. Candidates are tried close first, in 16
/// directions on rings 3 px apart out to 160 px; the crowded anchors (most neighbours within
/// 40 px) are placed first. `None`: no free place (the caller leaves that label out).
pub fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(u32, u32)],
    bounds: PxBox,
    marker: i32,
    obstacles: &[PxBox],
) -> Vec<Option<PxBox>> {
    let mut markers: Vec<PxBox> = anchors.iter().map(|&a| PxBox::around(a, marker)).collect();
    markers.extend_from_slice(obstacles);
    let crowd = |a: (i32, i32)| {
        anchors
            .iter()
            .filter(|b| (b.0 - a.0).abs() < 40 && (b.1 - a.1).abs() < 40)
            .count()
    };
    let mut order: Vec<usize> = (0..anchors.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(crowd(anchors[i])), i));
    let mut placed: Vec<Option<PxBox>> = vec![None; anchors.len()];
    let mut taken: Vec<PxBox> = Vec::new();
    for i in order {
        let (ax, ay) = anchors[i];
        let (w, h) = (sizes[i].0 as i32, sizes[i].1 as i32);
        'search: for ring in 0..=53 {
            let d = marker + 2 + 3 * ring;
            for k in 0..16 {
                let t = std::f64::consts::PI * k as f64 / 8.0;
                let (c, s) = (t.cos(), -t.sin());
                // The label's box touches the ring at its side facing the anchor.
                let cx = ax + (d as f64 * c) as i32 + ((w as f64 / 2.0) * c).round() as i32;
                let cy = ay + (d as f64 * s) as i32 + ((h as f64 / 2.0) * s).round() as i32;
                let b = PxBox {
                    x0: cx - w / 2,
                    y0: cy - h / 2,
                    x1: cx - w / 2 + w,
                    y1: cy - h / 2 + h,
                };
                if b.inside(&bounds)
                    && !markers.iter().any(|m| m.overlaps(&b))
                    && !taken.iter().any(|t| t.overlaps(&b))
                {
                    taken.push(b);
                    placed[i] = Some(b);
                    break 'search;
                }
            }
        }
    }
    placed
}

impl super::Figure for Figure {
    fn size(&self) -> (u32, u32) {
        let n = self.panels.len().max(1);
        let cols = columns(n) as u32;
        let rows = n.div_ceil(cols as usize) as u32;
        let (pw, ph) = if n == 1 { (900, 680) } else { PANEL_SIZE };
        // The key needs its height whatever the panels.
        let key_h = 120 + 18 * (9 + self.key.len() + self.band_notes.len()) as u32;
        (cols * pw + KEY_WIDTH, (50 + rows * ph).max(key_h))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(plot_err)?;
        let root = root.titled(&self.title, (FONT, 24)).map_err(plot_err)?;
        let (w, _) = root.dim_in_pixel();
        let (plots, key) = root.split_horizontally(w.saturating_sub(KEY_WIDTH));
        let n = self.panels.len().max(1);
        let cols = columns(n);
        let areas = plots.split_evenly((n.div_ceil(cols), cols));
        let all = || self.panels.iter().flat_map(|p| &p.methods);
        let x = x_range(all());
        let y = y_range(all(), self.precision);
        for (p, area) in self.panels.iter().zip(areas.iter()) {
            self.panel(p, area, x.clone(), y.clone())?;
        }
        self.key(&key)
    }
}

/// A panel's chart: log10 CPU against log10 |departure|.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

impl Figure {
    fn panel<DB: DrawingBackend>(
        &self,
        p: &Panel,
        area: &DrawingArea<DB, Shift>,
        x: std::ops::Range<f64>,
        y: std::ops::Range<f64>,
    ) -> Result<(), String> {
        let small = self.panels.len() > 1;
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, (FONT, if small { 17 } else { 20 }))
            .margin(10)
            .x_label_area_size(if small { 40 } else { 50 })
            .y_label_area_size(if small { 55 } else { 70 })
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("CPU s per 1,000 rolls (log)")
            .y_desc("|departure|, % (log), 2σ bars")
            .axis_desc_style((FONT, if small { 14 } else { 17 }))
            .label_style((FONT, if small { 12 } else { 15 }))
            .x_labels(6)
            .y_labels(8)
            .x_label_formatter(&log_tick)
            .y_label_formatter(&log_tick)
            .light_line_style(RGBColor(243, 243, 243))
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()
            .map_err(plot_err)?;
        let ly = |v: f64| {
            if v > 0.0 {
                v.log10().clamp(y.start, y.end)
            } else {
                y.start
            }
        };
        draw_bands(&mut chart, &p.bands, &x, &ly)?;
        let prec = ly(self.precision);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x.start, prec), (x.end, prec)],
                9,
                6,
                GREY.stroke_width(1),
            ))
            .map_err(plot_err)?;
        let pts: Vec<&MethodPoint> = p.methods.iter().filter(|m| drawn(m)).collect();
        draw_points(&mut chart, &pts, &ly)?;
        let (anchors, boxes) = place_numbers(&chart, area, &pts, &ly)?;
        draw_numbers(&mut chart, &pts, &anchors, &boxes, &ly)
    }

    /// The key: what the marks mean, then each number's method.
    fn key<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let f = |s: u32| (FONT, s).into_font();
        let line = 18;
        let mut y = 16;
        let text = |s: String, x: i32, y: i32, style: TextStyle| {
            area.draw(&Text::new(s, (x, y), style)).map_err(plot_err)
        };
        let mark = |y: i32, what: &str, two_d: bool, resolved: bool| {
            key_mark(area, y, what, two_d, resolved)
        };
        // Only the modes the figure draws.
        let has = |two_d: bool| {
            self.panels
                .iter()
                .any(|p| p.methods.iter().any(|m| m.two_d == two_d))
        };
        let (three, two) = (has(false), has(true));
        if three {
            mark(y, "3D method, resolved (2σ ≤ precision)", false, true)?;
            y += line;
        }
        if two {
            mark(y, "2D method, resolved", true, true)?;
            y += line;
        }
        mark(y, "unresolved within its budget (hollow)", two, false)?;
        y += line;
        for (two_d, color, mode) in MODE_COLORS {
            if !has(two_d) {
                continue;
            }
            area.draw(&PathElement::new(
                vec![(6, y + 7), (26, y + 7)],
                color.stroke_width(2),
            ))
            .map_err(plot_err)?;
            text(
                format!("{mode} Pareto front"),
                32,
                y,
                f(13).into_text_style(area),
            )?;
            y += line;
        }
        area.draw(&Circle::new((16, y + 7), 9, BLACK.stroke_width(2)))
            .map_err(plot_err)?;
        text(
            format!("ringed: cheapest within ±{}", pct(self.precision)),
            32,
            y,
            f(13).into_text_style(area),
        )?;
        y += line;
        area.draw(&PathElement::new(
            vec![(6, y + 7), (14, y + 7)],
            GREY.stroke_width(1),
        ))
        .map_err(plot_err)?;
        area.draw(&PathElement::new(
            vec![(19, y + 7), (27, y + 7)],
            GREY.stroke_width(1),
        ))
        .map_err(plot_err)?;
        text(
            format!("the precision, {}", pct(self.precision)),
            32,
            y,
            f(13).into_text_style(area),
        )?;
        y += line;
        for note in &self.band_notes {
            text(note.clone(), 6, y, f(12).into_text_style(area))?;
            y += line;
        }
        y += line / 2;
        text(
            "Methods (the number by each point):".into(),
            6,
            y,
            f(14).into_text_style(area),
        )?;
        y += line + 2;
        for (k, name) in &self.key {
            text(format!("{k:>3}"), 6, y, f(13).into_text_style(area))?;
            text(name.clone(), 36, y, f(13).into_text_style(area))?;
            y += line;
        }
        Ok(())
    }
}

/// The yardsticks, as bands across the panel.
fn draw_bands<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    bands: &[Band],
    x: &std::ops::Range<f64>,
    ly: &impl Fn(f64) -> f64,
) -> Result<(), String> {
    for b in bands {
        let color = match b.two_d {
            Some(t) => MODE_COLORS[t as usize].1,
            None => GREY,
        };
        let (lo, hi) = (ly(b.lo), ly(b.hi));
        if hi > lo {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x.start, lo), (x.end, hi)],
                    color.mix(0.13).filled(),
                )))
                .map_err(plot_err)?;
        }
    }
    Ok(())
}

/// The methods: each mode's Pareto front, the 2σ bars, the markers (filled where resolved,
/// hollow and grey where not) and the rings around the cheapest.
fn draw_points<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    pts: &[&MethodPoint],
    ly: &impl Fn(f64) -> f64,
) -> Result<(), String> {
    for (two_d, color, _) in MODE_COLORS {
        let mut front: Vec<(f64, f64)> = pts
            .iter()
            .filter(|m| m.two_d == two_d && m.on_front)
            .map(|m| (m.cost.log10(), ly(m.error)))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front, color.mix(0.7).stroke_width(2)))
            .map_err(plot_err)?;
    }
    for m in pts {
        let color = MODE_COLORS[m.two_d as usize].1;
        let c = if m.resolved { color } else { GREY };
        let (cx, e) = (m.cost.log10(), 2.0 * bar(m.error_err));
        chart
            .draw_series(std::iter::once(ErrorBar::new_vertical(
                cx,
                ly(m.error - e),
                ly(m.error),
                ly(m.error + e),
                c.mix(0.6).stroke_width(1),
                6,
            )))
            .map_err(plot_err)?;
    }
    for m in pts {
        let color = MODE_COLORS[m.two_d as usize].1;
        let at = (m.cost.log10(), ly(m.error));
        let style = if m.resolved {
            color.filled()
        } else {
            GREY.stroke_width(1)
        };
        if m.two_d {
            chart
                .draw_series(std::iter::once(Circle::new(at, 5, style)))
                .map_err(plot_err)?;
        } else if m.resolved {
            chart
                .draw_series(std::iter::once(TriangleMarker::new(at, 6, style)))
                .map_err(plot_err)?;
        } else {
            chart
                .draw_series(std::iter::once(EmptyElement::at(at) + hollow_triangle(6)))
                .map_err(plot_err)?;
        }
        if m.cheapest {
            chart
                .draw_series(std::iter::once(Circle::new(at, 10, color.stroke_width(2))))
                .map_err(plot_err)?;
        }
    }
    Ok(())
}

/// Each number's anchor (its marker's centre) and its label's box, in pixels.
type Placed = (Vec<(i32, i32)>, Vec<Option<PxBox>>);

/// Where each method's number goes, in pixels: its marker's centre, and its label's box
/// (`place_labels`, the rings around the cheapest in the way too; `None`: left out).
fn place_numbers<DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    area: &DrawingArea<DB, Shift>,
    pts: &[&MethodPoint],
    ly: &impl Fn(f64) -> f64,
) -> Result<Placed, String> {
    let font = (FONT, LABEL_FONT).into_font();
    let anchors: Vec<(i32, i32)> = pts
        .iter()
        .map(|m| chart.backend_coord(&(m.cost.log10(), ly(m.error))))
        .collect();
    let mut sizes = Vec::new();
    for m in pts {
        let (w, h) = area
            .estimate_text_size(&m.key, &font.clone().into_text_style(area))
            .map_err(plot_err)?;
        sizes.push((w + 2, h));
    }
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let bounds = PxBox {
        x0: xr.start,
        y0: yr.start,
        x1: xr.end,
        y1: yr.end,
    };
    let rings: Vec<PxBox> = pts
        .iter()
        .zip(&anchors)
        .filter(|(m, _)| m.cheapest)
        .map(|(_, &a)| PxBox::around(a, 12))
        .collect();
    let boxes = place_labels(&anchors, &sizes, bounds, MARKER, &rings);
    Ok((anchors, boxes))
}

/// Draws each placed number as an offset from its point, with a leader from the marker's
/// edge where it sits far from it.
fn draw_numbers<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    pts: &[&MethodPoint],
    anchors: &[(i32, i32)],
    boxes: &[Option<PxBox>],
    ly: &impl Fn(f64) -> f64,
) -> Result<(), String> {
    let font = (FONT, LABEL_FONT).into_font();
    for ((m, &a), b) in pts.iter().zip(anchors).zip(boxes) {
        let Some(b) = b else { continue };
        let color = if m.resolved {
            MODE_COLORS[m.two_d as usize].1
        } else {
            GREY
        };
        let at = (m.cost.log10(), ly(m.error));
        let (dx, dy) = (b.x0 - a.0 + 1, b.y0 - a.1);
        let far = (b.x0 + b.x1) / 2 - a.0;
        let far = far.abs().max(((b.y0 + b.y1) / 2 - a.1).abs()) > 2 * MARKER + 8;
        let text = Text::new(m.key.clone(), (dx, dy), font.clone().color(&color));
        if far {
            // A leader from the marker's edge to the label's nearest side.
            let tx = (b.x0 + b.x1) / 2 - a.0;
            let ty = (b.y0 + b.y1) / 2 - a.1;
            let len = ((tx * tx + ty * ty) as f64).sqrt().max(1.0);
            let s = (
                (tx as f64 * MARKER as f64 / len) as i32,
                (ty as f64 * MARKER as f64 / len) as i32,
            );
            let end = (
                tx.clamp(dx, dx + b.x1 - b.x0),
                ty.clamp(dy, dy + b.y1 - b.y0),
            );
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(at)
                        + PathElement::new(vec![s, end], GREY.mix(0.8).stroke_width(1))
                        + text,
                ))
                .map_err(plot_err)?;
        } else {
            chart
                .draw_series(std::iter::once(EmptyElement::at(at) + text))
                .map_err(plot_err)?;
        }
    }
    Ok(())
}

/// One line of the key: a method's marker at `y`, and what it means.
fn key_mark<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    y: i32,
    what: &str,
    two_d: bool,
    resolved: bool,
) -> Result<(), String> {
    let c = MODE_COLORS[two_d as usize].1;
    let at = (16, y + 7);
    let style = if resolved {
        c.filled()
    } else {
        GREY.stroke_width(1)
    };
    if two_d {
        area.draw(&Circle::new(at, 5, style)).map_err(plot_err)?;
    } else if resolved {
        area.draw(&TriangleMarker::new(at, 6, style))
            .map_err(plot_err)?;
    } else {
        area.draw(&(EmptyElement::at(at) + hollow_triangle(6)))
            .map_err(plot_err)?;
    }
    area.draw(&Text::new(
        what.to_string(),
        (32, y),
        (FONT, 13).into_font().into_text_style(area),
    ))
    .map_err(plot_err)
}

/// An unresolved 3D method's marker: plotters' `TriangleMarker` is always filled, so the hollow
/// triangle is its outline, in pixels about the point (the same size and shape).
fn hollow_triangle(size: i32) -> PathElement<(i32, i32)> {
    let (h, w) = (size / 2, size * 866 / 1000);
    PathElement::new(
        vec![(0, -size), (w, h), (-w, h), (0, -size)],
        GREY.stroke_width(1),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(cost: f64, error: f64, error_err: f64) -> MethodPoint {
        MethodPoint {
            key: "1".into(),
            cost,
            error,
            error_err,
            two_d: false,
            resolved: true,
            on_front: false,
            cheapest: false,
        }
    }

    #[test]
    fn the_y_range_is_the_points_and_their_bars_not_a_decade_more() {
        let pts = [point(0.1, 1.5, 0.5), point(1.0, 40.0, 2.0)];
        let y = y_range(&pts, 2.0);
        // From 1.5 % to 44 %, padded by a few per cent of the span on each side.
        let span = 44f64.log10() - 1.5f64.log10();
        assert!(
            (y.start - (1.5f64.log10() - 0.04 * span)).abs() < 1e-12,
            "{y:?}"
        );
        assert!(
            (y.end - (44f64.log10() + 0.06 * span)).abs() < 1e-12,
            "{y:?}"
        );
        // All within the precision: the range reaches the precision, and no higher.
        let y = y_range(&[point(0.1, 0.5, 0.2)], 2.0);
        assert!(y.end < 2f64.log10() + 0.1 && y.end >= 2f64.log10(), "{y:?}");
        // A departure of 0 sits on the floor, a twentieth of the precision.
        let y = y_range(&[point(0.1, 0.0, 0.0)], 2.0);
        assert!(
            y.start < 0.1f64.log10() && y.start > 0.1f64.log10() - 0.2,
            "{y:?}"
        );
        // A point not drawn (NaN departure) does not stretch it.
        let y = y_range(&[point(0.1, 1.0, 0.1), point(0.1, f64::NAN, 1e9)], 2.0);
        assert!(y.end < 1.0, "{y:?}");
    }

    /// 48 labels, a tight cluster and a loose line: every one placed, inside the plot, none
    /// overlapping another or any marker.
    #[test]
    fn labels_never_overlap_each_other_or_a_marker() {
        let bounds = PxBox {
            x0: 0,
            y0: 0,
            x1: 500,
            y1: 400,
        };
        let mut anchors: Vec<(i32, i32)> = (0..24)
            .map(|i| (200 + i % 5 * 9, 180 + i / 5 * 8))
            .collect();
        anchors.extend((0..24).map(|i| (20 + i * 19, 380 - i * 3)));
        anchors.push((2, 2)); // in a corner
        let sizes: Vec<(u32, u32)> = (0..anchors.len())
            .map(|i| (if i < 9 { 9 } else { 16 }, 13))
            .collect();
        // A ring around one point of the cluster is in the way too.
        let ring = PxBox::around(anchors[7], 12);
        let boxes = place_labels(&anchors, &sizes, bounds, MARKER, &[ring]);
        let mut markers: Vec<PxBox> = anchors.iter().map(|&a| PxBox::around(a, MARKER)).collect();
        markers.push(ring);
        for (i, b) in boxes.iter().enumerate() {
            let b = b.unwrap_or_else(|| panic!("label {i} not placed"));
            assert!(b.inside(&bounds), "{i}: {b:?}");
            assert_eq!(
                (b.x1 - b.x0, b.y1 - b.y0),
                (sizes[i].0 as i32, sizes[i].1 as i32)
            );
            assert!(
                !markers.iter().any(|m| m.overlaps(&b)),
                "{i} covers a marker"
            );
            for (j, c) in boxes.iter().enumerate().skip(i + 1) {
                assert!(!b.overlaps(&c.unwrap()), "labels {i} and {j} overlap");
            }
        }
        // A lone point's label sits right beside it (the first candidate, to its right).
        let one = place_labels(&[(100, 100)], &[(10, 12)], bounds, MARKER, &[]);
        assert_eq!(
            one[0],
            Some(PxBox {
                x0: 109,
                y0: 94,
                x1: 119,
                y1: 106
            })
        );
    }

    #[test]
    fn a_label_with_no_room_is_left_out_not_overlapped() {
        // The plot is the marker itself: nowhere to put a label.
        let bounds = PxBox {
            x0: 0,
            y0: 0,
            x1: 14,
            y1: 14,
        };
        assert_eq!(
            place_labels(&[(7, 7)], &[(10, 12)], bounds, MARKER, &[]),
            [None]
        );
    }
}
