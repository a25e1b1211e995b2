//! `dicephys merge`: shards of one run (`roll --shard K/N --json`) combined into the result of
//! the unsharded run: the same exact counts, because every throw depends only on its index.

use super::roll::RollArgs;
use crate::batch::Tally;
use crate::error::{Error, Result};
use crate::summary::RunSummary;
use clap::{Args, Parser};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shards' `roll --json` outputs.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Parser)]
struct Replay {
    #[command(flatten)]
    roll: RollArgs,
}

/// Combines shard summaries; refuses shards of different runs, missing or repeated shards.
pub fn merge(parts: &[RunSummary]) -> Result<RunSummary> {
    let first = parts
        .first()
        .ok_or_else(|| Error::Usage("merge: no shards".into()))?;
    let n = first.shard.map(|s| s.n).unwrap_or(1);
    let mut seen = vec![false; n as usize];
    let mut tally = Tally::default();
    let (mut wall, mut cpu) = (0.0, 0.0);
    for p in parts {
        if p.args != first.args {
            return Err(Error::Usage(format!(
                "merge: shards of different runs ({} against {})",
                p.args.join(" "),
                first.args.join(" ")
            )));
        }
        if p.partial {
            return Err(Error::Usage(
                "merge: a shard is partial (interrupted); resume it first".into(),
            ));
        }
        let s = p
            .shard
            .ok_or_else(|| Error::Usage("merge: an input is not a shard (no --shard)".into()))?;
        if s.n != n || seen[s.k as usize] {
            return Err(Error::Usage(format!(
                "merge: shard {}/{} is repeated or of another split",
                s.k, s.n
            )));
        }
        seen[s.k as usize] = true;
        tally.merge(&p.tally);
        wall += p.wall_s;
        cpu += p.cpu_s;
    }
    if let Some(k) = seen.iter().position(|&x| !x) {
        return Err(Error::Usage(format!("merge: shard {k}/{n} is missing")));
    }
    // Rebuild the summary from the run's own arguments, as the unsharded run would.
    let mut argv = vec!["roll".to_string()];
    argv.extend(first.args.iter().cloned());
    let r = Replay::try_parse_from(&argv)
        .map_err(|e| Error::Usage(format!("merge: the shards' arguments do not parse ({e})")))?
        .roll;
    let scene = r.scene.scene()?;
    let settle = r.run.check_at(scene.dt)?;
    let mut out = RunSummary::new(
        r.engine,
        &scene,
        r.throw.seed,
        r.throw.throws,
        &r.throw.ranges()?,
        &settle,
        &tally,
        wall,
        cpu,
        first.threads,
    );
    out.args = first.args.clone();
    Ok(out)
}

pub fn run(a: &MergeArgs) -> Result<()> {
    let mut parts = Vec::new();
    for f in &a.files {
        let text = std::fs::read_to_string(f)
            .map_err(|e| Error::Usage(format!("merge: {}: {e}", f.display())))?;
        let s: RunSummary = serde_json::from_str(&text).map_err(|e| {
            Error::Usage(format!(
                "merge: {}: not a `roll --json` output ({e})",
                f.display()
            ))
        })?;
        parts.push(s);
    }
    let out = merge(&parts)?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        print!("{}", out.human());
    }
    Ok(())
}
