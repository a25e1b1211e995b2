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
    // A lock file is removed by its holder as it ends ([`Held`]): a lock taken on a file no
    // longer under its name guards nothing, so it is let go and the name opened again.
    let mut tries = 0;
    let (mut f, taken) = loop {
        let f = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        match f.try_lock() {
            Ok(()) if !is_named(&f, path) && tries < 100 => tries += 1,
            taken => break (f, taken),
        }
    };
    match taken {
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

/// True if `path` names the open file `f` (the same file, not one since put in its place).
fn is_named(f: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (f.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// A lock taken by [`lock_removed`]: held while it lives, and its file removed as it ends, so
/// that a finished run leaves no lock behind.
#[derive(Debug)]
pub struct Held {
    file: File,
    path: std::path::PathBuf,
}

impl Drop for Held {
    fn drop(&mut self) {
        // Removed while still held (the file closes after), and only if the name is still
        // this lock's: a run that opens the name meanwhile finds its lock gone and opens anew.
        if is_named(&self.file, &self.path) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// [`lock`], its file removed when the returned lock is dropped (a run's end, an error or a
/// stop; a killed process leaves it, unheld, for the next run to take).
pub fn lock_removed(path: &Path, what: &str) -> Result<Held> {
    Ok(Held {
        file: lock(path, what)?,
        path: path.to_path_buf(),
    })
}
