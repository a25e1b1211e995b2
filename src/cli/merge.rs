//! `dicephys merge`: shards of one run (`roll --shard K/N --json`) combined into the result of
//! the unsharded run: the same exact counts, because every throw depends only on its index.

use super::args::Json;
use super::error::{Error, Result};
use super::term::{out, outln};
use clap::Args;
use dicephys::report::summary::{RunSummary, ShardResult};
use dicephys::studies::roll::RollStudy;
use std::path::PathBuf;

/// `dicephys merge`'s arguments.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shards' `roll --json` outputs.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// JSON or text.
    #[command(flatten)]
    pub json: Json,
}

/// A shard's `fair --shard K/N --json` document: its roll's summary and the null it was
/// judged against (the whole document under its checksum).
#[derive(serde::Deserialize)]
struct FairShard {
    fairness: NullOnly,
    summary: ShardResult,
}

#[derive(serde::Deserialize)]
struct NullOnly {
    null: dicephys::studies::fair::Null,
}

/// Runs `dicephys merge`: shards of `roll --json`, or of `fair --json` (reliability round 5,
/// class M), combined into the unsharded run's result (a fair document judged again).
pub fn run(a: &MergeArgs) -> Result<()> {
    let mut parts = Vec::new();
    let mut nulls = Vec::new();
    for f in &a.files {
        let text = read_small(f)?;
        let value: serde_json::Value = dicephys::run::seal::open(&text).map_err(|e| {
            Error::Usage(format!(
                "merge: {}: not a whole `roll --json` or `fair --json` output: {e}",
                f.display()
            ))
        })?;
        let shape = |e: serde_json::Error| {
            Error::Usage(format!(
                "merge: {}: not a whole `roll --json` or `fair --json` output: {e}",
                f.display()
            ))
        };
        if value.get("fairness").is_some() {
            let s: FairShard = serde_json::from_value(value).map_err(shape)?;
            nulls.push(Some(s.fairness.null));
            parts.push(s.summary);
        } else {
            nulls.push(None);
            parts.push(serde_json::from_value(value).map_err(shape)?);
        }
    }
    if nulls.windows(2).any(|w| w[0] != w[1]) {
        return Err(Error::Usage(
            "merge: the shards are of different commands (roll and fair) or nulls: give one \
             run's shards"
                .into(),
        ));
    }
    let out = RunSummary::merge(&parts)?;
    // The one machine's `roll` (or `fair`) rendering of the merged run.
    let fair = nulls.into_iter().next().flatten();
    let (json, text) = RollStudy::new(out.spec.clone(), fair).render(&out)?;
    if *a.json {
        outln!("{json}");
    } else {
        out!("{text}");
    }
    Ok(())
}

const MAX_SHARD_BYTES: u64 = 16 << 20;

/// The text of `f`, read no further than [`MAX_SHARD_BYTES`] (a file larger than that is not
/// a shard, and is refused without being read whole).
fn read_small(f: &std::path::Path) -> Result<String> {
    use std::io::Read;
    let bad = |e: std::io::Error| Error::Usage(format!("merge: {}: {e}", f.display()));
    let mut bytes = Vec::new();
    std::fs::File::open(f)
        .map_err(bad)?
        .take(MAX_SHARD_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(bad)?;
    if bytes.len() as u64 > MAX_SHARD_BYTES {
        return Err(Error::Usage(format!(
            "merge: {}: larger than {} MiB, not a `roll --json` output",
            f.display(),
            MAX_SHARD_BYTES >> 20
        )));
    }
    String::from_utf8(bytes).map_err(|_| {
        Error::Usage(format!(
            "merge: {}: not UTF-8, not a `roll --json` output",
            f.display()
        ))
    })
}
