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
