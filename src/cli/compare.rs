//! `dicephys compare`: two fits of the same counts by different models (`fit --free …`), set
//! side by side by how well each predicts the rows it did not see ([`dicephys::calibration::compare`]).

use super::args::Json;
use super::error::{Error, Result};
use super::term::{out, outln};
use clap::Args;
use std::path::{Path, PathBuf};

/// `dicephys compare`'s arguments.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// One model's fit: its fit.json, or the `fit --out` directory that holds it.
    pub first: PathBuf,
    /// The other model's fit of the same counts.
    pub second: PathBuf,
    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
}

/// A fit read from its fit.json or its directory; bad input names the file.
fn read(path: &Path) -> Result<dicephys::calibration::FitResult> {
    let file = if path.is_dir() {
        path.join("fit.json")
    } else {
        path.to_path_buf()
    };
    dicephys::calibration::read_fit(&file, super::term::stop()).map_err(|e| match e {
        dicephys::Error::Stopped => Error::Interrupted(super::fit::nothing_read()),
        e => Error::Usage(format!("compare: {e}")),
    })
}

/// Runs `dicephys compare`.
pub fn run(a: &CompareArgs) -> Result<()> {
    let (x, y) = (read(&a.first)?, read(&a.second)?);
    let names = [
        a.first.display().to_string(),
        a.second.display().to_string(),
    ];
    let c = dicephys::calibration::compare::compare(&x, &y, [&names[0], &names[1]])
        .map_err(|e| Error::Usage(format!("compare: {e}")))?;
    if *a.json {
        outln!("{}", dicephys::run::seal::to_string(&c, true)?);
    } else {
        out!("{}", dicephys::report::compare::comparison_text(&c));
    }
    Ok(())
}
