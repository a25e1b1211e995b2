//! What results say: a run's summary, the theory and the paper's table as reports, the paper's
//! Markdown and CSV, and the figures.

pub mod bench;
pub mod compare;
pub mod converge;
pub mod crosscheck;
pub mod fair;
pub mod figures;
pub mod fit;
pub mod html;
pub mod outcomes;
pub mod paper;
pub mod per_roll;
pub mod precision;
pub mod progress;
pub mod shape_outcomes;
pub mod stability;
pub mod summary;
pub mod table;
pub mod text;
pub mod trace;
pub mod tradeoff;
pub mod validate;
pub mod view;

/// A study's report, written the one way every study's is (`studies::outputs`): its figures
/// drawn into the output folder, then its Markdown showing them (`report.md`, or
/// `calibrated.md`). Its JSON is its results' own serialization, written beside it.
pub trait Report {
    /// Draws the figures into `dir`; returns their stems, in the order the report shows them.
    fn write_figures(&self, dir: &std::path::Path) -> crate::Result<Vec<String>>;
    /// The Markdown, showing the figures `stems` (a partial run's report names the figures
    /// of its last complete one).
    fn markdown(&self, stems: &[String]) -> String;
}

/// Figure stems as the reports' own functions take them.
fn stems(s: &[String]) -> Vec<&str> {
    s.iter().map(String::as_str).collect()
}

/// Figure stems as [`Report::write_figures`] returns them.
fn owned(s: Vec<&str>) -> Vec<String> {
    s.into_iter().map(String::from).collect()
}
