//! Fixed-width text tables, for the rows the bench and the sweeps print as they go: one place
//! says each column's title and width, so a header and its rows cannot drift apart. And a time
//! step as people write it.

/// One column: its title, its width in characters, and its alignment.
#[derive(Clone, Copy, Debug)]
pub struct Col {
    /// The title in the header.
    pub title: &'static str,
    /// The width, in characters; a longer cell widens its row rather than being cut.
    pub width: usize,
    /// Left-aligned (names) rather than right-aligned (numbers).
    pub left: bool,
}

/// A left-aligned column.
pub const fn left(title: &'static str, width: usize) -> Col {
    Col {
        title,
        width,
        left: true,
    }
}

/// A right-aligned column.
pub const fn right(title: &'static str, width: usize) -> Col {
    Col {
        title,
        width,
        left: false,
    }
}

/// A table's columns.
#[derive(Clone, Copy, Debug)]
pub struct Columns(pub &'static [Col]);

impl Columns {
    /// The header line.
    pub fn header(&self) -> String {
        let titles: Vec<String> = self.0.iter().map(|c| c.title.to_string()).collect();
        self.row(&titles)
    }

    /// One row of already formatted cells, one per column, padded to the columns' widths.
    pub fn row(&self, cells: &[String]) -> String {
        let padded: Vec<String> = self
            .0
            .iter()
            .zip(cells)
            .map(|(c, s)| {
                let pad = " ".repeat(c.width.saturating_sub(s.chars().count()));
                if c.left {
                    format!("{s}{pad}")
                } else {
                    format!("{pad}{s}")
                }
            })
            .collect();
        padded.join(" ").trim_end().to_string()
    }
}

/// A time step as people write it: 1/1000 for 0.001.
pub fn dt_label(dt: f64) -> String {
    let n = 1.0 / dt;
    if (n - n.round()).abs() < 1e-6 * n {
        format!("1/{}", n.round())
    } else {
        format!("{dt}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_rows_share_the_widths() {
        const T: Columns = Columns(&[left("name", 6), right("ratio", 15), right("σ", 4)]);
        assert_eq!(T.header(), "name             ratio    σ");
        let row = T.row(&["ab".into(), "0.5000 ± 0.0100".into(), "+1.0".into()]);
        assert_eq!(row, "ab     0.5000 ± 0.0100 +1.0");
        assert_eq!(row.chars().count(), T.header().chars().count());
    }
}
