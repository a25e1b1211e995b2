//! `dicephys merge`: shards of one run (`roll --shard K/N --json`) combined into the result of
//! the unsharded run: the same exact counts, because every throw depends only on its index.

use super::error::{Error, Result};
use super::{out, outln};
use clap::Args;
use dicephys::report::summary::{RunSummary, ShardResult};
use std::path::PathBuf;

/// `dicephys merge`'s arguments.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shards' `roll --json` outputs.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print one JSON document instead of the human summary.
    #[arg(long)]
    pub json: bool,
}

/// Runs `dicephys merge`.
pub fn run(a: &MergeArgs) -> Result<()> {
    let mut parts = Vec::new();
    for f in &a.files {
        let text = std::fs::read_to_string(f)
            .map_err(|e| Error::Usage(format!("merge: {}: {e}", f.display())))?;
        let s: ShardResult = dicephys::run::seal::open(&text).map_err(|e| {
            Error::Usage(format!(
                "merge: {}: not a whole `roll --json` output: {e}",
                f.display()
            ))
        })?;
        parts.push(s);
    }
    let out = RunSummary::merge(&parts)?;
    if a.json {
        outln!("{}", dicephys::run::seal::to_string(&out, true)?);
    } else {
        out!("{}", out.human());
    }
    Ok(())
}
