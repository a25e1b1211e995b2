//! Which run a directory belongs to. A study's output directory (`paper --out`, the sweeps',
//! `validate`'s, a Slurm study's `--dir`, `crosscheck --checkpoint`) records its owner in
//! `dicephys-run.json`: the command and its configuration, with a key over the configuration.
//! Another command, or the same command with other flags, is refused there before it writes
//! or removes anything, as `roll --checkpoint` refuses another run's checkpoint. The same
//! command with the same flags continues the run; flags that only add rounds to a study
//! rolled to a precision (`--precision`, `--budget`, `--plan`, `--preroll`) do not count.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::Path;

/// The file in a directory that names its owner.
pub const FILE: &str = "dicephys-run.json";

/// The lock a run here holds on its directory while it runs ([`hold`]).
pub const LOCK: &str = "lock";

/// Holds `dir` for this process while the returned lock lives (its file removed as it ends): a second run of the same
/// study there (its claim passes: it is the same run) is refused, naming the first's process,
/// rather than rolling and writing the same cells and outputs at once. A cluster's tasks,
/// which share a directory by design, do not take it.
pub fn hold(dir: &Path) -> Result<crate::run::lock::Held> {
    crate::run::lock::lock_removed(&dir.join(LOCK), &dir.display().to_string())
}

/// A directory's owner.
#[derive(Serialize, Deserialize)]
struct Owner {
    command: String,
    key: String,
    config: Value,
}

/// The key of a run's identity, `config` (a checksum of it, canonical).
pub fn key(config: &Value) -> String {
    let sum = crate::run::seal::checksum(config);
    sum.rsplit(':').next().unwrap_or(&sum).to_string()
}

/// Claims `dir` for the run of `command` whose identity is `config`: records it in a
/// directory that has no owner yet (making the directory), or checks that the recorded owner
/// is this very run. Refuses a directory another command or another run owns, and one that
/// holds a `roll` checkpoint or a Slurm run of `roll`.
pub fn claim(dir: &Path, command: &str, config: &Value) -> Result<()> {
    let file = dir.join(FILE);
    let want = key(config);
    match std::fs::read_to_string(&file) {
        Ok(text) => {
            let owner: Owner = serde_json::from_str(&text).map_err(|e| {
                Error::Mismatch(format!(
                    "{}: damaged ({e}); it names the run that owns {}: remove it only if \
                     that directory is yours to reuse",
                    file.display(),
                    dir.display()
                ))
            })?;
            if owner.command != command {
                return Err(Error::Mismatch(format!(
                    "{}: it holds the outputs of a `{}` run ({}); give `{command}` a new \
                     directory",
                    dir.display(),
                    owner.command,
                    file.display()
                )));
            }
            if owner.key != want {
                return Err(Error::Mismatch(format!(
                    "{}: it holds another `{command}` run, with other flags ({}); run that \
                     one again to continue it, or use a new directory",
                    dir.display(),
                    file.display()
                )));
            }
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            for (f, what) in [
                ("spec.json", "a `roll` checkpoint"),
                ("slurm.json", "a Slurm run"),
            ] {
                if dir.join(f).exists() {
                    return Err(Error::Mismatch(format!(
                        "{}: it holds {what} ({}); give `{command}` a new directory",
                        dir.display(),
                        dir.join(f).display()
                    )));
                }
            }
            std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
            let owner = Owner {
                command: command.to_string(),
                key: want,
                config: config.clone(),
            };
            let json =
                serde_json::to_string_pretty(&owner).map_err(|e| Error::failed(e.to_string()))?;
            // Put in place only if still absent (a hard link fails on an existing name), so
            // that of two runs claiming one directory at the same moment one wins, and the
            // other reads the winner's claim and is refused unless it is the same run.
            // 0666 less the umask, as every other output (tempfile's own default is 0600).
            let mut tmp = tempfile::Builder::new()
                .prefix(".dicephys-run.")
                .permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666))
                .tempfile_in(dir)
                .map_err(|e| Error::io(dir, e))?;
            std::io::Write::write_all(&mut tmp, format!("{json}\n").as_bytes())
                .and_then(|()| tmp.as_file().sync_all())
                .map_err(|e| Error::io(tmp.path(), e))?;
            match std::fs::hard_link(tmp.path(), &file) {
                Ok(()) => Ok(()),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    claim(dir, command, config)
                }
                Err(e) => Err(Error::io(&file, e)),
            }
        }
        Err(e) => Err(Error::io(&file, e)),
    }
}

/// Refuses `dir` for a run on this machine if a Slurm run lives there (its `slurm.json`):
/// its tasks and finishing job write there.
pub fn refuse_cluster_run(dir: &Path) -> Result<()> {
    let file = dir.join("slurm.json");
    if file.exists() {
        return Err(Error::Mismatch(format!(
            "{}: it holds a Slurm run ({}); give a run on this machine a directory of its own",
            dir.display(),
            file.display()
        )));
    }
    Ok(())
}

/// Refuses `dir` as a checkpoint of `roll` if a study owns it.
pub fn check_unowned(dir: &Path) -> Result<()> {
    let file = dir.join(FILE);
    if file.exists() {
        return Err(Error::Mismatch(format!(
            "checkpoint {}: it holds a study's outputs ({}); use a new directory",
            dir.display(),
            file.display()
        )));
    }
    Ok(())
}
