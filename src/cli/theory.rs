//! `dicephys theory`: the paper's closed-form predictions for one block (`--block`), or its
//! whole experimental table set against the theory (`--table`). Text, or one JSON document with
//! `--json` (fields documented in docs/json.md).

use super::args::Json;
use clap::{ArgGroup, Args};
use serde::Serialize;
use std::io::Write;

use super::error::{Error, Result};
use dicephys::model::block::Block;
use dicephys::report::table::{block_report, table_report, write_block, write_table};

/// Default uncertainty of a measured side, mm.
pub const DEFAULT_TOLERANCE_MM: f64 = 0.1;

#[derive(Args, Debug, Clone)]
#[command(group(ArgGroup::new("input").required(true).args(["block", "table"])))]
pub struct TheoryArgs {
    /// The block, LENGTHxBREADTHxWIDTH in mm, e.g. 140x24x20.
    #[arg(
        long,
        value_name = "LxBxW",
        allow_hyphen_values = true,
        conflicts_with = "table"
    )]
    pub block: Option<Block>,

    /// Uncertainty of each measured side in mm (one standard error), carried into R and the
    /// predicted ratio. For --block only: the table uses each row's printed ±.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_TOLERANCE_MM,
          value_parser = parse_tolerance, conflicts_with = "table")]
    pub tolerance: f64,

    /// The paper's whole experimental table against the theory, with a check of its printed
    /// numbers and χ² per data set.
    #[arg(long)]
    pub table: bool,

    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
}

fn parse_tolerance(s: &str) -> std::result::Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "tolerance '{s}' must be a finite number of mm, 0 or more"
        )),
    }
}

/// Runs `dicephys theory`.
pub fn run(args: &TheoryArgs) -> Result<()> {
    if !(args.tolerance.is_finite() && args.tolerance >= 0.0) {
        return Err(Error::Usage(format!(
            "tolerance {} must be a finite number of mm, 0 or more",
            args.tolerance
        )));
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match (&args.block, args.table) {
        (Some(_), true) => Err(Error::Usage(
            "give either --block or --table, not both".to_string(),
        )),
        (Some(block), false) => {
            let report = block_report(block, args.tolerance);
            if *args.json {
                write_json(&mut out, &report)
            } else {
                Ok(write_block(&mut out, &report)?)
            }
        }
        (None, true) => {
            let report = table_report()?;
            if *args.json {
                write_json(&mut out, &report)
            } else {
                Ok(write_table(&mut out, &report)?)
            }
        }
        (None, false) => Err(Error::Usage(
            "give --block LxBxW (mm) or --table".to_string(),
        )),
    }
}

fn write_json<T: Serialize>(out: &mut impl Write, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| Error::Run(format!("cannot write JSON: {e}")))?;
    writeln!(out, "{text}")?;
    Ok(())
}
