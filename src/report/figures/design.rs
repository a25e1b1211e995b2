//! The design figure (`design.svg`, `.png`): per outcome, the target, the design's
//! simulated share at its check with its 2σ interval, and the same design's quasi-static
//! share, so that what the throws add to the rest's answer shows at a glance.

use super::*;

/// One outcome on the design figure.
#[derive(Clone, Debug, PartialEq)]
pub struct DesignBar {
    /// What the die shows (a label, `rest`, a class `2|12`).
    pub label: String,
    /// The target's probability.
    pub target: f64,
    /// The check's share.
    pub p: f64,
    /// Its one-standard error: the check's binomial error and the design's own together.
    pub err: f64,
    /// The design's quasi-static share, where there is one (3D).
    pub quasi_static: Option<f64>,
}

struct Design<'a> {
    title: &'a str,
    bars: &'a [DesignBar],
}

impl Figure for Design<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let mut ys = Span::new(0.0, f64::NEG_INFINITY);
        for b in self.bars {
            ys.add(b.p + 2.0 * bar(b.err));
            ys.add(b.target);
            if let Some(q) = b.quasi_static {
                ys.add(q);
            }
        }
        let labels: Vec<String> = self.bars.iter().map(|b| b.label.clone()).collect();
        let mut chart = labelled_chart(
            root,
            (self.title, 20),
            labels,
            ys.padded(0.0, 0.3),
            ("outcome (the label the die shows)", "probability"),
        )?;
        // The target: a black bar across each outcome's place.
        let black = BLACK.stroke_width(3);
        chart
            .draw_series(self.bars.iter().enumerate().map(|(k, b)| {
                let x = k as f64 + 1.0;
                PathElement::new(vec![(x - 0.35, b.target), (x + 0.35, b.target)], black)
            }))
            .map_err(plot_err)?
            .label("target")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], black));
        // The two answers side by side about the outcome's place, so that neither hides the
        // other: thrown on the left, at rest on the right.
        let thrown: Vec<Point> = self
            .bars
            .iter()
            .enumerate()
            .map(|(k, b)| Point {
                x: k as f64 + 0.9,
                y: b.p,
                y_err: 2.0 * b.err,
            })
            .collect();
        points(
            &mut chart,
            &thrown,
            MDF_RED,
            Marker::Circle,
            false,
            "the design thrown (its check), ± 2σ",
        )?;
        let rest: Vec<Point> = self
            .bars
            .iter()
            .enumerate()
            .filter_map(|(k, b)| {
                b.quasi_static.map(|q| Point {
                    x: k as f64 + 1.1,
                    y: q,
                    y_err: 0.0,
                })
            })
            .collect();
        if !rest.is_empty() {
            points(
                &mut chart,
                &rest,
                DARK_BLUE,
                Marker::Triangle,
                false,
                "the design at rest (quasi-static theory)",
            )?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Writes the design figure as `dir/<stem>.svg` and `.png`.
pub fn design(dir: &Path, stem: &str, title: &str, bars: &[DesignBar]) -> crate::Result<()> {
    write_both(dir, stem, &Design { title, bars })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_design_figure_draws_every_outcome_and_both_answers() {
        let dir = std::env::temp_dir().join(format!("dicephys-design-fig-{}", std::process::id()));
        let bars: Vec<DesignBar> = ["heads", "tails", "edge"]
            .iter()
            .map(|l| DesignBar {
                label: l.to_string(),
                target: 1.0 / 3.0,
                p: 0.33,
                err: 0.004,
                quasi_static: Some(0.3),
            })
            .collect();
        design(&dir, "design", "a coin", &bars).unwrap();
        let svg = std::fs::read_to_string(dir.join("design.svg")).unwrap();
        for text in ["heads", "tails", "edge", "target", "quasi-static"] {
            assert!(svg.contains(text), "{text}");
        }
        assert!(dir.join("design.png").is_file());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
