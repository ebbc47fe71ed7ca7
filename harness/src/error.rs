//! One error type for the whole harness. Every variant names what was wrong (a file, a field, a
//! parameter) and what was expected, so the CLI can print it as is and exit non-zero.

use std::path::PathBuf;

/// Errors reported to the user. Messages are complete sentences fragments meant to be printed
/// after `error: `.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An asset (glTF file) was not found anywhere on the search path.
    #[error("asset '{name}' not found; looked in: {searched}")]
    AssetNotFound { name: String, searched: String },
    /// A file exists but its content is not what was expected.
    #[error("{}: {message}", path.display())]
    BadFile { path: PathBuf, message: String },
    /// A command-line or technique parameter is wrong.
    #[error("parameter '{name}': {message}")]
    Param { name: String, message: String },
    /// Any other invalid input (unknown scene or technique name, bad resolution, ...).
    #[error("{0}")]
    Invalid(String),
    /// The GPU could not be set up or reported an error.
    #[error("GPU: {0}")]
    Gpu(String),
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// Result with the harness [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Shorthand for [`Error::BadFile`].
    pub fn bad_file(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::BadFile {
            path: path.into(),
            message: message.into(),
        }
    }
    /// Shorthand for [`Error::Param`].
    pub fn param(name: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Param {
            name: name.into(),
            message: message.into(),
        }
    }
    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, then a rename,
/// so a reader never sees a half-written file and a failed run leaves nothing behind. While an
/// [`crate::output::OutputSet`] is open on a folder holding `path`, the file is staged there and
/// appears at `path` when the set is published.
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    match crate::output::staged_path(path)? {
        Some(staged) => write_atomic_direct(&staged, bytes),
        None => write_atomic_direct(path, bytes),
    }
}

/// [`write_atomic`] straight to `path`, never staged (the reference cache). The temporary file is
/// named `.gibench-tmp-PID-…`, so one a killed process leaves can be found and removed
/// ([`crate::output::remove_stale_temporaries`]).
pub fn write_atomic_direct(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(
            "{}{}-",
            crate::output::TEMP_PREFIX,
            std::process::id()
        ))
        .tempfile_in(dir)
        .map_err(|e| Error::io(dir, e))?;
    tmp.write_all(bytes).map_err(|e| Error::io(path, e))?;
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    // Temporary files are created private; results are meant to be read by anyone.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(|e| Error::io(path, e))?;
    }
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}

/// Parses JSON `bytes` as `T`. A failure says where: the path of the field that failed
/// (`light.path.keys[1].position`) before serde's message (which gives the line and column).
pub fn from_json<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> std::result::Result<T, String> {
    let mut de = serde_json::Deserializer::from_slice(bytes);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        if path == "." || path.is_empty() {
            e.into_inner().to_string()
        } else {
            format!("{path}: {}", e.into_inner())
        }
    })
}

/// Reads the regular file `path` whole, refusing anything else (a device such as `/dev/zero`, a
/// pipe, a folder) and files over `max` bytes, so no input can make a read run without bound.
pub fn read_bounded(path: &std::path::Path, max: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(Error::bad_file(path, "not a regular file"));
    }
    if meta.len() > max {
        return Err(Error::bad_file(
            path,
            format!(
                "{} bytes, more than the {max} this input may have",
                meta.len()
            ),
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > max {
        return Err(Error::bad_file(
            path,
            format!("grew past the {max} bytes this input may have while being read"),
        ));
    }
    Ok(bytes)
}
