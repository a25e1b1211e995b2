//! Every file dicephys writes goes through here, so that each one is written whole or not at
//! all, is checked before a run starts, and never replaces what is not a regular file.
//!
//! * A regular file (or a new one) is written to a temporary file beside it, synced to disk,
//!   then renamed over it: a reader, a crash or a full disk never sees half of it.
//! * A symbolic link is followed: its target is written, and the link stays a link.
//! * A character device or a FIFO (`/dev/stdout`, a pipe) is written in place: there is
//!   nothing to rename over, and replacing it would destroy it.
//! * A directory is refused when the output is checked, before anything runs.

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// An output path, checked: where the bytes will go and how.
#[derive(Clone, Debug)]
pub struct Output {
    /// The path as given (for messages).
    pub path: PathBuf,
    /// Where the bytes go: the path, or the end of its chain of links.
    target: PathBuf,
    /// Written in place (a device or a FIFO), not through a temporary file and a rename.
    in_place: bool,
}

impl Output {
    /// Checks that `path` can be written, before any work is done: its directory exists and
    /// takes a new file, and it is not a directory.
    pub fn check(path: &Path) -> Result<Output> {
        let bad = |why: String| Error::Invalid(format!("{}: {why}", path.display()));
        // Follow links to the file they name (which may not exist yet).
        let mut target = path.to_path_buf();
        for _ in 0..40 {
            match std::fs::symlink_metadata(&target) {
                Ok(m) if m.file_type().is_symlink() => {
                    let link = std::fs::read_link(&target).map_err(|e| bad(e.to_string()))?;
                    target = match target.parent() {
                        Some(dir) => dir.join(link),
                        None => link,
                    };
                }
                _ => break,
            }
        }
        match std::fs::metadata(&target) {
            Ok(m) if m.is_dir() => return Err(bad("is a directory".into())),
            Ok(m) if !m.is_file() => {
                // A device or a FIFO: it must be writable. Not opened to find out: opening a
                // FIFO waits for its reader, and closing it again ends the reader's input.
                if !writable(&target) {
                    return Err(bad("cannot write there (permission denied)".into()));
                }
                return Ok(Output {
                    path: path.to_path_buf(),
                    target,
                    in_place: true,
                });
            }
            _ => {}
        }
        let dir = parent(&target);
        if !dir.is_dir() {
            return Err(bad(format!("directory {} does not exist", dir.display())));
        }
        tempfile::Builder::new()
            .prefix(".dicephys-probe-")
            .tempfile_in(dir)
            .map_err(|e| bad(format!("cannot write there ({e})")))?;
        Ok(Output {
            path: path.to_path_buf(),
            target,
            in_place: false,
        })
    }

    /// Writes `bytes` as the whole file.
    pub fn write(&self, bytes: &[u8]) -> Result<()> {
        let mut w = self.writer()?;
        w.write_all(bytes).map_err(|e| Error::io(&self.path, e))?;
        w.commit()
    }

    /// A writer that grows the file and puts it in place at `commit`; dropped without a
    /// commit, it leaves the old file (and no temporary file) behind.
    pub fn writer(&self) -> Result<OutputWriter> {
        let inner = if self.in_place {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(&self.target)
                .map_err(|e| Error::io(&self.path, e))?;
            Inner::InPlace(BufWriter::new(f))
        } else {
            let tmp = tempfile::Builder::new()
                .prefix(&format!(".{}.", file_name(&self.target)))
                .suffix(".tmp")
                .tempfile_in(parent(&self.target))
                .map_err(|e| Error::io(&self.path, e))?;
            Inner::Temp(BufWriter::new(tmp))
        };
        Ok(OutputWriter {
            out: self.clone(),
            inner,
        })
    }
}

enum Inner {
    InPlace(BufWriter<File>),
    Temp(BufWriter<tempfile::NamedTempFile>),
}

/// A file being written (see [`Output::writer`]).
pub struct OutputWriter {
    out: Output,
    inner: Inner,
}

impl Write for OutputWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.inner {
            Inner::InPlace(w) => w.write(buf),
            Inner::Temp(w) => w.write(buf),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.inner {
            Inner::InPlace(w) => w.flush(),
            Inner::Temp(w) => w.flush(),
        }
    }
}

impl OutputWriter {
    /// Flushes, syncs to disk and puts the file in place.
    pub fn commit(self) -> Result<()> {
        let path = self.out.path.clone();
        let io = |e: std::io::Error| Error::io(&path, e);
        match self.inner {
            Inner::InPlace(w) => {
                w.into_inner().map_err(|e| io(e.into_error()))?;
                Ok(())
            }
            Inner::Temp(w) => {
                let tmp = w.into_inner().map_err(|e| io(e.into_error()))?;
                tmp.as_file().sync_all().map_err(io)?;
                tmp.persist(&self.out.target).map_err(|e| io(e.error))?;
                sync_dir(parent(&self.out.target));
                Ok(())
            }
        }
    }
}

/// Writes a whole file or nothing, for files dicephys owns (checkpoints, figures): a synced
/// temporary file beside it, renamed over it.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{}.", file_name(path)))
        .suffix(".tmp")
        .tempfile_in(parent(path))
        .map_err(|e| Error::io(path, e))?;
    tmp.write_all(bytes).map_err(|e| Error::io(path, e))?;
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    sync_dir(parent(path));
    Ok(())
}

/// Makes a rename in `dir` durable (best effort: not every file system syncs directories).
fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// access(2) with W_OK: may this process write to `path`?
fn writable(path: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
        return false;
    };
    // SAFETY: `c` is a valid NUL-terminated path that outlives the call.
    unsafe { libc::access(c.as_ptr(), libc::W_OK) == 0 }
}

fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into())
}
