//! The asset search path. Large meshes are never committed; they are found, in this order, in
//! `--assets DIR` (if given), `$GIBENCH_ASSETS` (colon-separated), `scenes/assets/` and
//! `../shared/scenes/` (both relative to the current directory and to the workspace root).

use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// Ordered list of directories searched for asset files.
#[derive(Clone, Debug, Default)]
pub struct AssetPaths {
    pub dirs: Vec<PathBuf>,
}

impl AssetPaths {
    /// The standard search path; `extra` (the `--assets` flag) comes first.
    pub fn standard(extra: Option<&Path>) -> Self {
        let mut dirs = Vec::new();
        if let Some(d) = extra {
            dirs.push(d.to_path_buf());
        }
        if let Ok(v) = std::env::var("GIBENCH_ASSETS") {
            dirs.extend(std::env::split_paths(&v).filter(|p| !p.as_os_str().is_empty()));
        }
        let root = Path::new(env!("CARGO_MANIFEST_DIR"))
            .parent()
            .unwrap_or(Path::new("."))
            .to_path_buf();
        for base in [PathBuf::from("."), root] {
            for rel in ["scenes/assets", "../shared/scenes"] {
                let d = base.join(rel);
                if !dirs.contains(&d) {
                    dirs.push(d);
                }
            }
        }
        AssetPaths { dirs }
    }

    /// Finds `name`. An absolute path or one that exists relative to the current directory is
    /// used as is. Otherwise the first directory holding it wins; none → [`Error::AssetNotFound`]
    /// naming every directory looked in.
    pub fn find(&self, name: &str) -> Result<PathBuf> {
        let direct = Path::new(name);
        if direct.is_absolute() || (direct.components().count() > 1 && direct.is_file()) {
            return if direct.is_file() {
                Ok(direct.to_path_buf())
            } else {
                Err(Error::AssetNotFound {
                    name: name.into(),
                    searched: direct.display().to_string(),
                })
            };
        }
        for d in &self.dirs {
            let p = d.join(name);
            if p.is_file() {
                return Ok(p);
            }
        }
        Err(Error::AssetNotFound {
            name: name.into(),
            searched: self
                .dirs
                .iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        })
    }
}
