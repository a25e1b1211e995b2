//! What a fit says: its own report (`report.md`, its figures, its terminal lines), the
//! calibrated paper's report, and a prediction's.

mod calibrated;
mod fitted;
mod predictions;

pub use fitted::{
    bootstrap_line, discrepancy_text, first_pass_text, fixed_text, maxima_text, misfit_line,
    recovery_text, row_ratios,
};
pub use predictions::{
    dice_csv, prediction_text, predictions_csv, predictions_figure, predictions_markdown,
};
