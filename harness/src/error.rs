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
    /// The GPU device was lost (a driver reset, a GPU timeout, or destroyed): `what` is the
    /// driver's word, `at` the technique, stage and frame where gibench found it.
    #[error("the GPU device was lost ({what}){}", if at.is_empty() { String::new() } else { format!(" at {at}") })]
    DeviceLost { what: String, at: String },
    /// SIGTERM or SIGINT arrived ([`crate::interrupt`]): the command stopped at `at`.
    #[error("stopped by {signal} at {at}")]
    Interrupted { signal: &'static str, at: String },
}

/// Result with the harness [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Whether the error ends the whole command, not one run, value or target: a signal
    /// (SIGTERM, SIGINT) or a lost device, after which nothing more can run.
    pub fn stops_everything(&self) -> bool {
        matches!(self, Error::Interrupted { .. } | Error::DeviceLost { .. })
    }
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
