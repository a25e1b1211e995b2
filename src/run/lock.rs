//! A directory's lock: a file held with the system's advisory lock (flock) for as long as a
//! run uses the directory, with the holder's process id in it, so that a second run there is
//! refused with the first one named rather than left to write the same files at once.

use crate::error::{Error, Result};
use std::fs::File;
use std::path::Path;

/// Takes the lock file `path`, writing this process's id into it; if another process holds
/// it, says which, naming what it guards as `what` ("checkpoint DIR", a study's directory).
/// Held until the returned file is dropped (the process's end included: the system frees it).
pub fn lock(path: &Path, what: &str) -> Result<File> {
    use std::io::{Read, Seek, Write};
    let mut f = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .map_err(|e| Error::io(path, e))?;
    match f.try_lock() {
        Ok(()) => {
            f.set_len(0).map_err(|e| Error::io(path, e))?;
            f.rewind().map_err(|e| Error::io(path, e))?;
            writeln!(f, "pid {}", std::process::id()).map_err(|e| Error::io(path, e))?;
            Ok(f)
        }
        Err(std::fs::TryLockError::WouldBlock) => {
            // The holder writes its id just after taking the lock: give it a moment.
            let mut holder = String::new();
            for _ in 0..20 {
                holder.clear();
                let _ = f.rewind();
                let _ = f.read_to_string(&mut holder);
                if !holder.trim().is_empty() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(25));
            }
            let holder = match holder.trim() {
                "" => "a process that has not yet written its id".to_string(),
                h => h.to_string(),
            };
            Err(Error::Mismatch(format!(
                "{what}: in use by another run ({holder})"
            )))
        }
        Err(std::fs::TryLockError::Error(e)) => Err(Error::io(path, e)),
    }
}
