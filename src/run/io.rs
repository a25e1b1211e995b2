//! Every file dicephys writes goes through here, so that each one is written whole or not at
//! all, is checked before a run starts, and never replaces what is not a regular file.
//!
//! * A regular file (or a new one) is written to a temporary file beside it, synced to disk,
//!   then renamed over it: a reader, a crash or a full disk never sees half of it. The new
//!   file has the mode a new file gets here (0666 less the umask), or the mode of the file it
//!   replaces.
//! * A symbolic link is followed: its target is written, and the link stays a link. A loop of
//!   links is refused.
//! * A character device or a FIFO (`/dev/null`, a pipe) is written in place: there is nothing
//!   to rename over, and replacing it would destroy it. The process's own standard output or
//!   error (`/dev/stdout`, whether a terminal, a pipe or a redirected file) is written through
//!   the stream itself, so that what the command prints there after it follows it.
//! * A directory is refused when the output is checked, before anything runs.
//!
//! A temporary file is named `.STEM.RANDOM.dicephys.tmp` (the stem cut short, so that the name
//! fits in 255 bytes however long the output's), and locked while it is written. One that a
//! killed run left behind is removed by the next run that checks an output, or opens a
//! checkpoint, in that directory.

use crate::error::{Error, Field, Result};
use std::ffi::OsStr;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How every temporary file of ours ends.
pub const TEMP_SUFFIX: &str = ".dicephys.tmp";

/// A leftover temporary file is removed once it is unlocked and this old: a file is locked
/// within moments of its creation, so a younger one may be another run's, just made.
const TEMP_STALE: Duration = Duration::from_secs(60);

/// An output path, checked: where the bytes will go and how.
#[derive(Clone, Debug)]
pub struct Output {
    /// The path as given (for messages).
    pub path: PathBuf,
    /// Where the bytes go: the path, or the end of its chain of links.
    target: PathBuf,
    /// How they go there.
    how: How,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum How {
    /// A temporary file beside the target, renamed over it.
    Replace,
    /// Opened and written in place (a device or a FIFO).
    InPlace,
    /// Through this process's standard output (1) or error (2), which the path names.
    Stream(i32),
}

impl Output {
    /// Checks that `path` can be written, before any work is done: its directory exists and
    /// takes a new file, it is not a directory, and links lead somewhere. Removes the
    /// temporary files a killed run left in its directory.
    pub fn check(path: &Path) -> Result<Output> {
        let bad = |why: String| Error::Invalid(format!("{}: {why}", path.display()));
        let out = |target: PathBuf, how| Output {
            path: path.to_path_buf(),
            target,
            how,
        };
        // What the path names, links followed by the system (so `/dev/stdout` is found to be
        // this process's pipe, terminal or file).
        match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => return Err(bad("is a directory".into())),
            Ok(m) => {
                if let Some(fd) = standard_stream(&m) {
                    return Ok(out(path.to_path_buf(), How::Stream(fd)));
                }
                if !m.is_file() {
                    // A device or a FIFO: it must be writable. Not opened to find out: opening
                    // a FIFO waits for its reader, and closing it again ends the reader's input.
                    if !access(path, libc::W_OK) {
                        return Err(bad("cannot write there (permission denied)".into()));
                    }
                    return Ok(out(path.to_path_buf(), How::InPlace));
                }
            }
            Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
                return Err(bad("a loop of symbolic links".into()))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(bad(e.to_string())),
        }
        let target = end_of_links(path).map_err(bad)?;
        let dir = parent(&target);
        if !dir.is_dir() {
            return Err(bad(format!("directory {} does not exist", dir.display())));
        }
        if !access(dir, libc::W_OK | libc::X_OK) {
            return Err(bad(format!(
                "cannot write there ({}: {})",
                dir.display(),
                std::io::Error::last_os_error()
            )));
        }
        clean_temporaries(dir);
        Ok(out(target, How::Replace))
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
        let io = |e| Error::io(&self.path, e);
        let inner = match self.how {
            How::Stream(fd) => {
                use std::os::fd::AsFd;
                let dup = match fd {
                    1 => std::io::stdout().as_fd().try_clone_to_owned(),
                    _ => std::io::stderr().as_fd().try_clone_to_owned(),
                };
                Inner::InPlace(BufWriter::new(File::from(dup.map_err(io)?)))
            }
            How::InPlace => {
                let f = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&self.target)
                    .map_err(io)?;
                Inner::InPlace(BufWriter::new(f))
            }
            How::Replace => Inner::Temp(BufWriter::new(temporary(&self.target).map_err(io)?)),
        };
        Ok(OutputWriter {
            out: self.clone(),
            inner,
        })
    }
}

/// The standard stream (1 or 2) that is the very file `m` describes, if any.
fn standard_stream(m: &std::fs::Metadata) -> Option<i32> {
    use std::os::fd::AsFd;
    let same = |f: std::os::fd::BorrowedFd| {
        File::from(f.try_clone_to_owned().ok()?)
            .metadata()
            .ok()
            .filter(|s| s.dev() == m.dev() && s.ino() == m.ino())
    };
    if same(std::io::stdout().as_fd()).is_some() {
        Some(1)
    } else if same(std::io::stderr().as_fd()).is_some() {
        Some(2)
    } else {
        None
    }
}

/// Where a path's chain of symbolic links ends (a file that may not exist yet).
fn end_of_links(path: &Path) -> std::result::Result<PathBuf, String> {
    let mut target = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&target).map_err(|e| e.to_string())?;
                target = parent(&target).join(link);
            }
            _ => return Ok(target),
        }
    }
    Err("a loop of symbolic links".into())
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
                put_in_place(tmp, &self.out.target).map_err(io)
            }
        }
    }
}

/// Writes a whole file or nothing, for files dicephys owns (checkpoints, figures): a synced
/// temporary file beside it, renamed over it.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |e| Error::io(path, e);
    let mut tmp = temporary(path).map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    put_in_place(tmp, path).map_err(io)
}

/// A new temporary file beside `target`, locked, with the mode `target` will have: its
/// current one if it exists, else 0666 less the umask.
fn temporary(target: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let name = target.file_name().map_or(&b"out"[..], OsStr::as_bytes);
    let stem = &name[..name.len().min(40)];
    let mut prefix = b".".to_vec();
    prefix.extend_from_slice(stem);
    prefix.push(b'.');
    let tmp = tempfile::Builder::new()
        .prefix(OsStr::from_bytes(&prefix))
        .suffix(TEMP_SUFFIX)
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(parent(target))?;
    // Held until the file is renamed or removed; a file system without locks leaves it
    // unlocked, and then no later run removes it (see `clean_temporaries`).
    let _ = tmp.as_file().try_lock();
    if let Ok(m) = std::fs::metadata(target) {
        if m.is_file() {
            let mode = m.permissions().mode() & 0o7777;
            tmp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(mode))?;
        }
    }
    Ok(tmp)
}

/// Syncs `tmp` and renames it over `target`.
fn put_in_place(tmp: tempfile::NamedTempFile, target: &Path) -> std::io::Result<()> {
    tmp.as_file().sync_all()?;
    tmp.persist(target).map_err(|e| e.error)?;
    sync_dir(parent(target));
    Ok(())
}

/// Removes the temporary files of ours in `dir` that a killed run left: those no process
/// holds locked, older than `TEMP_STALE`. Best effort: what cannot be read is left.
pub fn clean_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let name = name.as_bytes();
        if !(name.starts_with(b".") && name.ends_with(TEMP_SUFFIX.as_bytes())) {
            continue;
        }
        let path = e.path();
        let Ok(f) = File::open(&path) else { continue };
        let old = f
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age >= TEMP_STALE);
        if old && f.try_lock().is_ok() {
            let _ = std::fs::remove_file(&path);
        }
    }
}

/// Makes a rename in `dir` durable (best effort: not every file system syncs directories).
fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// access(2): may this process do `mode` (W_OK, X_OK) to `path`?
fn access(path: &Path, mode: i32) -> bool {
    let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
        return false;
    };
    // SAFETY: `c` is a valid NUL-terminated path that outlives the call.
    unsafe { libc::access(c.as_ptr(), mode) == 0 }
}

fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The bytes of `path`, read no further than `max` (a larger file is refused without being
/// read whole: `/dev/zero` is not a data file). Read on a thread of its own, so that a stop
/// request is honoured within a tenth of a second even while the read blocks (a named pipe
/// with no writer blocks in `open`); the blocked thread ends with the process.
pub fn read_capped(path: &Path, max: u64, stop: &crate::run::stop::Stop) -> Result<Vec<u8>> {
    use std::io::Read;
    let (tx, rx) = std::sync::mpsc::channel();
    let file = path.to_path_buf();
    std::thread::spawn(move || {
        let read = || -> std::io::Result<Vec<u8>> {
            let mut bytes = Vec::new();
            std::fs::File::open(&file)?
                .take(max + 1)
                .read_to_end(&mut bytes)?;
            Ok(bytes)
        };
        let _ = tx.send(read());
    });
    let bytes = loop {
        match rx.recv_timeout(std::time::Duration::from_millis(100)) {
            Ok(r) => break r.map_err(|e| Error::Invalid(format!("{}: {e}", path.display())))?,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) if stop.requested() => {
                return Err(Error::Stopped)
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(Error::failed(format!("{}: the read ended", path.display())))
            }
        }
    };
    if bytes.len() as u64 > max {
        return Err(Error::Invalid(format!(
            "{}: larger than {} MiB; refused without reading it whole",
            path.display(),
            max >> 20
        )));
    }
    Ok(bytes)
}

/// A die file's bytes (a TOML die file, a mesh), at most `max`, through the capped reader;
/// any failure names `--die`. What the model is given to read a die's files with
/// (`model::mass::ReadFile`).
pub fn read_die_bytes(path: &std::path::Path, max: u64) -> Result<Vec<u8>> {
    if path.is_dir() {
        return Err(Error::field(Field::Die, path.display(), "is a directory"));
    }
    read_capped(path, max, crate::run::stop::Stop::global()).map_err(|e| match e {
        Error::Stopped => Error::Stopped,
        Error::Invalid(m) => Error::field(
            Field::Die,
            path.display(),
            m.strip_prefix(&format!("{}: ", path.display()))
                .unwrap_or(&m)
                .to_string(),
        ),
        e => e,
    })
}
