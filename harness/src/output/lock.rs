//! The folder lock of an output set: the operating system's exclusive lock on `.gibench.lock`.

use std::path::{Path, PathBuf};

use super::LOCK;

/// Why the folder's lock could not be taken.
#[derive(Debug)]
pub(super) enum LockError {
    /// Another process holds it (its process id, if it has written it yet).
    InUse(Option<u32>),
    Other(String),
}

/// The operating system's exclusive lock on a folder's `.gibench.lock`, held while the file is
/// open and released by the operating system when the process ends, however it ends.
#[derive(Debug)]
pub(super) struct FolderLock {
    file: std::fs::File,
    path: PathBuf,
}

impl FolderLock {
    /// Takes the lock of `dir` (which exists), writing this process's id into the lock file.
    pub(super) fn take(dir: &Path) -> std::result::Result<FolderLock, LockError> {
        use std::io::Write;
        let path = dir.join(LOCK);
        if path.is_dir() {
            return Err(LockError::Other(format!(
                "{} is a folder, not gibench's lock file; remove it",
                path.display()
            )));
        }
        let other = |what: &str, e: std::io::Error| {
            LockError::Other(format!("cannot {what} {}: {e}", path.display()))
        };
        loop {
            let mut file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(|e| other("open", e))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let pid = std::fs::read_to_string(&path)
                        .ok()
                        .and_then(|s| s.trim().parse::<u32>().ok());
                    return Err(LockError::InUse(pid));
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(other("lock", e)),
            }
            // A command that finishes removes its lock file while holding the lock; one that
            // opened the file before that holds the lock of a removed file, and tries again.
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0).map_err(|e| other("write", e))?;
            file.write_all(std::process::id().to_string().as_bytes())
                .map_err(|e| other("write", e))?;
            return Ok(FolderLock { file, path });
        }
    }

    /// Removes the lock file (where the platform lets a lock's file be identified, so that a
    /// removed one is never mistaken for the current one), then releases the lock.
    pub(super) fn release(self) {
        if cfg!(unix) {
            let _ = std::fs::remove_file(&self.path);
        }
        drop(self.file);
    }
}

/// Whether the open `file` is the file now at `path`.
#[cfg(unix)]
fn same_file(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Elsewhere the lock file is never removed, so the open file is the one at `path`.
#[cfg(not(unix))]
fn same_file(_: &std::fs::File, path: &Path) -> bool {
    path.is_file()
}
