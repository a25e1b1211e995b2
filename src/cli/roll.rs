//! `dicephys roll`: many throws of one block on one engine.

use super::args::{parse_engine, RunArgs, SceneArgs, ThrowArgs};
use crate::checkpoint;
use crate::cputime::process_cpu_seconds;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::roll::{Fate, RollRecord};
use crate::summary::{RunSummary, Shard};
use crate::throws::Throws;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct RollArgs {
    /// Physics engine: bullet, rapier (in 2D a true 2D body), rapier-locked (in 2D a locked 3D
    /// body, as DicePhys).
    #[arg(long, default_value = "bullet", value_parser = parse_engine)]
    pub engine: EngineKind,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub throw: ThrowArgs,
    #[command(flatten)]
    pub run: RunArgs,
    /// Print one JSON document instead of the human summary.
    #[arg(long)]
    pub json: bool,
    /// Write one CSV row per throw to this file.
    #[arg(long, value_name = "FILE.csv")]
    pub per_roll: Option<PathBuf>,
    /// Keep a checkpoint here as the run goes (chunks of 1,000 rolls, written atomically);
    /// `dicephys roll --resume DIR` continues it, bit for bit.
    #[arg(long, value_name = "DIR")]
    pub checkpoint: Option<PathBuf>,
    /// Continue the run checkpointed in DIR, with the configuration stored there.
    #[arg(long, value_name = "DIR")]
    pub resume: Option<PathBuf>,
    /// Roll only throws with index ≡ K (mod N); `dicephys merge` combines the shards' --json
    /// outputs into the unsharded result.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
}

fn parse_shard(s: &str) -> std::result::Result<Shard, String> {
    s.parse()
}

pub fn run(a: &RollArgs) -> Result<()> {
    let scene = a.scene.scene()?;
    let ranges = a.throw.ranges()?;
    let settle = a.run.check_at(scene.dt)?;
    if let Some(p) = &a.per_roll {
        super::check_writable(p)?;
    }
    let throws = Throws::new(a.throw.throws, a.throw.seed, ranges, a.run.rolls);
    let threads = if a.run.threads == 0 {
        rayon::current_num_threads()
    } else {
        a.run.threads
    };
    let indices = match a.shard {
        Some(Shard { k, n }) => checkpoint::Indices {
            k,
            n,
            end: a.run.rolls,
        },
        None => checkpoint::Indices::all(a.run.rolls),
    };
    let args = super::runargs::current();
    if let Some(dir) = &a.checkpoint {
        open_checkpoint(dir, &super::runargs::defining(&args))?;
    }
    // The per-roll CSV grows chunk by chunk in a temporary file, renamed into place at the end.
    let mut csv = match &a.per_roll {
        Some(p) => {
            let tmp = p.with_extension(format!("tmp-{}", std::process::id()));
            let mut f = std::io::BufWriter::new(
                std::fs::File::create(&tmp)
                    .map_err(|e| Error::Usage(format!("--per-roll {}: {e}", p.display())))?,
            );
            f.write_all(PER_ROLL_HEADER.as_bytes())?;
            Some((tmp, f))
        }
        None => None,
    };
    let dt = scene.dt;
    let mut sink = |recs: &[RollRecord]| -> std::result::Result<(), String> {
        if let Some((_, f)) = csv.as_mut() {
            f.write_all(per_roll_rows(recs, dt).as_bytes())
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    };
    let wall = Instant::now();
    let cpu = process_cpu_seconds();
    let done = checkpoint::run(
        a.engine,
        &scene,
        &throws,
        &settle,
        indices,
        threads,
        a.checkpoint.as_deref(),
        &|_| {},
        &mut sink,
    )
    .map_err(Error::Run)?;
    let cpu_s = process_cpu_seconds() - cpu;
    let wall_s = wall.elapsed().as_secs_f64();
    let tally = done.tally;
    if let (Some((tmp, f)), Some(p)) = (csv, &a.per_roll) {
        f.into_inner()
            .map_err(|e| Error::Run(e.to_string()))?
            .sync_all()?;
        std::fs::rename(&tmp, p)?;
    }
    let mut summary = RunSummary::new(
        a.engine,
        &scene,
        a.throw.seed,
        a.throw.throws,
        &ranges,
        &settle,
        &tally,
        wall_s,
        cpu_s,
        threads,
    );
    summary.args = super::runargs::defining_unsharded(&args);
    summary.shard = a.shard;
    summary.partial = !done.complete;
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| Error::Run(e.to_string()))?
        );
    } else {
        print!("{}", summary.human());
    }
    if !done.complete {
        return Err(Error::Interrupted(match &a.checkpoint {
            Some(d) => format!(
                "interrupted after {} of {} rolls; continue with: dicephys roll --resume {}",
                tally.rolls,
                indices.len(),
                d.display()
            ),
            None => format!(
                "interrupted after {} of {} rolls",
                tally.rolls,
                indices.len()
            ),
        }));
    }
    Ok(())
}

/// Creates the checkpoint directory with the run's arguments in it, or checks that an existing
/// one holds this very run.
fn open_checkpoint(dir: &std::path::Path, args: &[String]) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Error::Usage(format!(
            "--checkpoint {}: cannot create it ({e})",
            dir.display()
        ))
    })?;
    let file = dir.join("args.json");
    let want = serde_json::to_string(args).map_err(|e| Error::Run(e.to_string()))?;
    match std::fs::read_to_string(&file) {
        Ok(have) if have.trim() == want => Ok(()),
        Ok(_) => Err(Error::Usage(format!(
            "--checkpoint {}: it holds another run; resume that with --resume, or use a new directory",
            dir.display()
        ))),
        Err(_) => super::write_atomic(&file, want.as_bytes()).map_err(|e| {
            Error::Usage(format!("--checkpoint {}: cannot write there ({e})", dir.display()))
        }),
    }
}

/// The per-throw CSV's header.
pub const PER_ROLL_HEADER: &str =
    "index,drop_height_m,velocity_m_s,spin_rad_s,status,outcome,steps,sim_time_s,energy_gain,dip_steps,longest_dip_steps,penetration_m\n";

/// Per-throw CSV rows: index, initial conditions, status, outcome, steps, simulated time; then
/// the flags: energy gain (0/1), the steps at whose end the die's centre was below the
/// floor's top face, the longest run of them, and the deepest any point of the die went
/// below that face, m (`roll::Dip`).
pub fn per_roll_rows(records: &[RollRecord], dt: f64) -> String {
    let mut s = String::new();
    for r in records {
        let (status, outcome) = match r.fate {
            Fate::Settled(o) => ("settled", o.name()),
            Fate::Unconverged(o) => ("unconverged", o.name()),
            Fate::Failed(f) => (f.name(), ""),
        };
        let t = &r.throw;
        s += &format!(
            "{},{:?},{:?},{:?},{},{},{},{:?},{},{},{},{:?}\n",
            t.index,
            t.drop_height,
            t.velocity,
            t.spin,
            status,
            outcome,
            r.steps,
            r.sim_time(dt),
            r.energy_gain as u8,
            r.dip.steps,
            r.dip.longest,
            r.dip.penetration
        );
    }
    s
}
