//! The validation's rows so far, each logged as it is measured and counted towards the
//! progress.

use crate::report::validate::{format_row, Row};
use crate::studies::study::Progress;

/// The rows so far, each logged as it is measured.
pub(crate) struct Rows<'a> {
    pub(super) rows: Vec<Row>,
    pub(super) log: &'a dyn Fn(&str),
    pub(super) progress: Progress<'a>,
    pub(super) total: usize,
}

impl Rows<'_> {
    pub(super) fn push(&mut self, r: Row) {
        (self.log)(&format_row(&r));
        self.rows.push(r);
        (self.progress)(self.rows.len() as f64, self.total as f64);
    }
}
