//! **Output sets**: a command's files appear in its output folder complete or not at all.
//!
//! A command that writes into a folder opens an [`OutputSet`] on it before any expensive work:
//!
//! * it refuses a folder below it that is a symbolic link, naming it, so that no file outside
//!   the folder is written, moved or removed through one;
//! * it takes the folder's lock: the operating system's exclusive lock on `.gibench.lock`
//!   (which also holds the process id, for messages). A second command into a folder in use is
//!   refused, naming `--out`; the lock of a killed run is released by the operating system
//!   when its process ends (a zombie too), and the next command finishes or undoes what that
//!   run left (below);
//! * while the set is open, every file written with [`write_atomic`] under the
//!   folder goes to a hidden staging folder (`.gibench-staging/`) instead;
//! * [`OutputSet::publish`] lists the staged files in a journal (`.gibench-publish`), moves them
//!   into place, then removes the journal, the staging folder and the lock. A run killed while
//!   moving is finished by the next command that opens the folder (the journal says what to
//!   move; every staged file is complete); a run that fails or is killed before publishing
//!   leaves only the staging folder, which the next command removes. Dropping an unpublished
//!   set (an error) removes the staging folder and the lock at once.
//!
//! A set can also **replace** subfolders ([`OutputSet::replace`]): at publication, files under
//! such a subfolder that this set did not write are removed, so a regenerated result holds only
//! what its command wrote (the journal lists the replaced subfolders too, so a killed
//! publication is finished the same way), and **file patterns** of the folder itself
//! ([`OutputSet::replace_files`]: `mesh-*.ply`), likewise.
//!
//! Files written with [`write_atomic_direct`] (the reference cache, whose entries
//! are shared across runs and read back within one) bypass the set.
//!
//! One set per process at a time.

use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;

use crate::{Error, Result};

const LOCK: &str = ".gibench.lock";
const STAGING: &str = ".gibench-staging";
const JOURNAL: &str = ".gibench-publish";
/// In the staging folder of a set opened with [`OutputSet::resume`].
const RESUMABLE: &str = ".gibench-resumable";

/// The open set's folder (absolute, lexically normalised), its staged files (relative), the
/// subfolders it replaces and the file patterns it replaces in the folder itself.
struct Active {
    dir: PathBuf,
    /// The folder as the command named it, made absolute lexically (links not resolved).
    given: PathBuf,
    staged: Vec<PathBuf>,
    replaced: Vec<PathBuf>,
    patterns: Vec<String>,
}

/// The journal's prefix for a replaced subfolder (no file gibench writes starts with it).
const REPLACE: &str = "replace:";
/// The journal's prefix for a replaced file pattern (`PREFIX*SUFFIX`).
const REPLACE_FILES: &str = "replace-files:";

static ACTIVE: Mutex<Option<Active>> = Mutex::new(None);

mod lock;
use lock::{FolderLock, LockError};

/// How far an open set had got ([`OutputSet::mark`]): the counts of its staged files, replaced
/// subfolders and replaced patterns.
#[derive(Clone, Copy, Debug, Default)]
pub struct Mark {
    staged: usize,
    replaced: usize,
    patterns: usize,
}

/// What [`OutputSet::resume`] asks: given the files staged there, which to take over.
pub type Keep<'a> = dyn FnMut(&[PathBuf]) -> Vec<PathBuf> + 'a;

/// An open output set (see the module docs). Publish it on success; dropping it unpublished
/// discards what was staged.
pub struct OutputSet {
    /// The folder, canonical (symlinks resolved): staging, lock and publication all use it.
    dir: PathBuf,
    option: String,
    published: bool,
    /// Closed by [`OutputSet::suspend`]: the staging folder stays for [`OutputSet::resume`].
    suspended: bool,
    /// The folders `begin` created, deepest first (an unpublished set removes them if empty).
    created: Vec<PathBuf>,
    /// Held until the set is closed.
    lock: Option<FolderLock>,
}

/// `path` made absolute against the working directory and with `.` and `..` resolved lexically.
/// `path` joined to the working directory when relative, nothing resolved.
fn joined_to_cwd(path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()
            .unwrap_or_else(|_| PathBuf::from("/"))
            .join(path)
    }
}

pub(crate) fn absolute(path: &Path) -> PathBuf {
    let joined = joined_to_cwd(path);
    let mut out = PathBuf::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `path` without its `.` components (`create_dir_all("new/.")` fails where `new` is missing).
pub fn without_cur_dirs(path: &Path) -> PathBuf {
    let p: PathBuf = path
        .components()
        .filter(|c| !matches!(c, Component::CurDir))
        .collect();
    if p.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        p
    }
}

/// Whether process `pid` is alive and runs the same program as this one (Linux: `/proc/PID`
/// and its `comm`, so a pid reused by another program is not taken for it; elsewhere every
/// process is taken as live): a temporary file of a live process is left alone.
fn alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        if pid == std::process::id() {
            return true;
        }
        let comm = |p: &str| std::fs::read_to_string(format!("/proc/{p}/comm")).ok();
        match (comm(&pid.to_string()), comm("self")) {
            (Some(theirs), Some(ours)) => theirs == ours,
            _ => false,
        }
    } else {
        true
    }
}

/// `path` with its longest existing ancestor canonicalised (symlinks and `..` resolved the way
/// the OS will resolve them) and the rest appended.
fn resolve(path: &Path) -> PathBuf {
    // `..` is left to the OS (after a link it leads to the link target's parent).
    let abs = joined_to_cwd(path);
    let mut existing = abs.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(c) = existing.canonicalize() {
            let mut out = c;
            for part in rest.iter().rev() {
                out.push(part);
            }
            return out;
        }
        match (existing.parent(), existing.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_os_string());
                existing = parent;
            }
            _ => return abs,
        }
    }
}

/// Refuses `dir` if a folder below it (not `dir` itself) is a symbolic link: a command writes,
/// replaces and removes files under `--out`, and through a link those would be another
/// folder's. The error names the link and `option`.
fn refuse_links_below(dir: &Path, option: &str) -> Result<()> {
    if let Some(link) = first_link_below(dir) {
        return Err(Error::param(
            option,
            format!(
                "{} is a symbolic link; gibench writes and replaces files below the output folder \
                 and does not follow links out of it (replace the link by a folder, or give its \
                 target as the output folder)",
                link.display()
            ),
        ));
    }
    Ok(())
}

/// The first symbolic link found below `dir` (links are not followed; the staging folder is
/// skipped), if any.
fn first_link_below(dir: &Path) -> Option<PathBuf> {
    let mut stack = vec![dir.to_path_buf()];
    let mut seen = 0usize;
    while let Some(d) = stack.pop() {
        // A huge tree (`--out` a home folder) is not walked whole: the writes and replacements
        // themselves refuse links too (`staged_path`, `replace`, publication).
        seen += 1;
        if seen > MAX_FOLDERS_WALKED {
            return None;
        }
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        let mut entries: Vec<_> = entries.flatten().collect();
        entries.sort_by_key(|e| e.file_name());
        for e in entries {
            if d == dir && e.file_name() == STAGING {
                continue;
            }
            let Ok(kind) = e.file_type() else { continue };
            if kind.is_symlink() {
                // A link to a file is replaced, not written through, by every write; a link to
                // a folder (or a dangling one, which a write would create a folder through) is
                // refused.
                if !e.path().is_file() {
                    return Some(e.path());
                }
            } else if kind.is_dir() {
                stack.push(e.path());
            }
        }
    }
    None
}

/// Folders [`first_link_below`] looks into at most.
const MAX_FOLDERS_WALKED: usize = 20_000;

/// Whether a component of `rel` below `dir` (`dir` itself excluded) is a symbolic link.
fn link_on_the_way(dir: &Path, rel: &Path) -> bool {
    let mut at = dir.to_path_buf();
    for c in rel.components() {
        at.push(c);
        if std::fs::symlink_metadata(&at).is_ok_and(|m| m.file_type().is_symlink()) {
            return true;
        }
    }
    false
}

impl OutputSet {
    /// Opens the set on `dir` (created if needed); `option` names the command-line option in
    /// errors (`out`).
    pub fn begin(option: &str, dir: &Path) -> Result<OutputSet> {
        Self::open(option, dir, None)
    }

    /// [`OutputSet::begin`], resuming a set that was killed or [suspended](OutputSet::suspend)
    /// before publishing: once the folder's lock is held, `keep` is given the files that set
    /// staged (relative to the folder) and says which to take over, as if this set had written
    /// them; the other staged files are removed. `keep` is not called when nothing is staged
    /// there.
    pub fn resume(option: &str, dir: &Path, keep: &mut Keep) -> Result<OutputSet> {
        Self::open(option, dir, Some(keep))
    }

    fn open(option: &str, dir: &Path, keep: Option<&mut Keep>) -> Result<OutputSet> {
        let fail = |what: String| Error::param(option, what);
        if ACTIVE.lock().map(|a| a.is_some()).unwrap_or(true) {
            return Err(fail("another output set is open in this process".into()));
        }
        let dir = &without_cur_dirs(dir);
        let given = dir.clone();
        let created: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        std::fs::create_dir_all(dir)
            .map_err(|e| fail(format!("{} is not a writable folder: {e}", dir.display())))?;
        let shown = dir.display().to_string();
        let dir = &dir
            .canonicalize()
            .map_err(|e| fail(format!("{shown} is not a writable folder: {e}")))?;
        refuse_links_below(dir, option)?;
        let lock = FolderLock::take(dir).map_err(|e| match e {
            LockError::InUse(pid) => fail(format!(
                "{shown} is in use by another gibench command ({}); wait for it or choose another folder",
                pid.map_or("process unknown".to_string(), |p| format!("process {p}"))
            )),
            LockError::Other(what) => fail(format!("{shown}: {what}")),
        })?;
        let set = OutputSet {
            dir: dir.to_path_buf(),
            option: option.to_string(),
            published: false,
            suspended: false,
            created,
            lock: Some(lock),
        };
        let resuming = keep.is_some();
        let kept = recover(dir, keep)?;
        let staging = dir.join(STAGING);
        std::fs::create_dir_all(&staging).map_err(|e| Error::io(&staging, e))?;
        if resuming {
            write_atomic_direct(&staging.join(RESUMABLE), b"staged by a resumable set\n")?;
        }
        let mut active = ACTIVE
            .lock()
            .map_err(|_| fail("output state poisoned".into()))?;
        *active = Some(Active {
            dir: dir.to_path_buf(),
            given: absolute(&given),
            staged: kept,
            replaced: Vec::new(),
            patterns: Vec::new(),
        });
        Ok(set)
    }

    /// Declares the files of the set's folder itself (not its subfolders) named
    /// `PREFIX*SUFFIX` replaced: at publication those this set did not write are removed — the
    /// numbered files of a kind a command writes a varying number of (`mesh-*.ply`). A pattern
    /// without `*` names one file.
    pub fn replace_files(&self, pattern: &str) -> Result<()> {
        if !add_pattern(pattern)? {
            return Err(Error::param(
                &self.option,
                format!("'{pattern}' is not a file name or a pattern PREFIX*SUFFIX"),
            ));
        }
        Ok(())
    }

    /// Declares `sub` (relative to the set's folder, plain names only) replaced: at publication
    /// the files under it that this set did not write are removed.
    pub fn replace(&self, sub: &Path) -> Result<()> {
        if sub.as_os_str().is_empty()
            || !sub.components().all(|c| matches!(c, Component::Normal(_)))
        {
            return Err(Error::param(
                &self.option,
                format!("{} is not a plain subfolder name", sub.display()),
            ));
        }
        if link_on_the_way(&self.dir, sub) {
            return Err(Error::param(
                &self.option,
                format!(
                    "{} is or lies under a symbolic link; gibench does not replace files through links",
                    self.dir.join(sub).display()
                ),
            ));
        }
        let mut active = ACTIVE
            .lock()
            .map_err(|_| Error::param(&self.option, "output state poisoned"))?;
        if let Some(a) = active.as_mut() {
            if !a.replaced.iter().any(|r| r == sub) {
                a.replaced.push(sub.to_path_buf());
            }
        }
        Ok(())
    }

    /// Where the set stands now, for [`OutputSet::rollback`].
    pub fn mark(&self) -> Mark {
        ACTIVE
            .lock()
            .ok()
            .and_then(|a| {
                a.as_ref().map(|a| Mark {
                    staged: a.staged.len(),
                    replaced: a.replaced.len(),
                    patterns: a.patterns.len(),
                })
            })
            .unwrap_or_default()
    }

    /// Drops what was staged, and the subfolders and patterns declared replaced, since `mark`:
    /// for a part of a command that failed while the rest is still published (a target of
    /// `reproduce all --budget`). A file first staged before the mark and written again after
    /// it keeps its newer content.
    pub fn rollback(&self, mark: Mark) -> Result<()> {
        let mut active = ACTIVE
            .lock()
            .map_err(|_| Error::param(&self.option, "output state poisoned"))?;
        if let Some(a) = active.as_mut() {
            for rel in a.staged.drain(mark.staged.min(a.staged.len())..) {
                let _ = std::fs::remove_file(a.dir.join(STAGING).join(rel));
            }
            a.replaced.truncate(mark.replaced);
            a.patterns.truncate(mark.patterns);
        }
        Ok(())
    }

    /// The files staged so far, relative to the set's folder, in the order first written.
    pub fn staged(&self) -> Vec<PathBuf> {
        ACTIVE
            .lock()
            .ok()
            .and_then(|a| a.as_ref().map(|a| a.staged.clone()))
            .unwrap_or_default()
    }

    /// Moves every staged file into place (see the module docs) and closes the set.
    pub fn publish(mut self) -> Result<()> {
        let (staged, replaced, patterns) = {
            let mut active = ACTIVE
                .lock()
                .map_err(|_| Error::param(&self.option, "output state poisoned"))?;
            active
                .take()
                .map(|a| (a.staged, a.replaced, a.patterns))
                .unwrap_or_default()
        };
        // Every destination must be free to take a file before any is moved, so a failure
        // cannot leave some files new and others old.
        for rel in &staged {
            let to = self.dir.join(rel);
            if to.is_dir() {
                return Err(Error::param(
                    &self.option,
                    format!(
                        "{} is a folder where this command writes a file; nothing was changed",
                        to.display()
                    ),
                ));
            }
        }
        let journal = self.dir.join(JOURNAL);
        let list: Vec<String> = (replaced.iter())
            .map(|p| format!("{REPLACE}{}", p.to_string_lossy()))
            .chain(patterns.iter().map(|p| format!("{REPLACE_FILES}{p}")))
            .chain(staged.iter().map(|p| p.to_string_lossy().into_owned()))
            .collect();
        write_atomic_direct(&journal, list.join("\n").as_bytes())?;
        move_staged(&self.dir)?;
        self.published = true;
        self.close();
        Ok(())
    }

    /// Closes the set unpublished but keeps what it staged, for a later
    /// [`OutputSet::resume`] (a command stopped by a signal). Until then the folder shows what
    /// it showed before; a later [`OutputSet::begin`] discards the staged files.
    pub fn suspend(mut self) {
        if let Ok(mut active) = ACTIVE.lock() {
            *active = None;
        }
        self.suspended = true;
        self.close();
    }

    /// Removes the staging folder (unless suspended), the journal and the lock (and,
    /// unpublished, the folder itself if this set created it and it is empty).
    fn close(&mut self) {
        if !self.suspended {
            let _ = std::fs::remove_dir_all(self.dir.join(STAGING));
        }
        let _ = std::fs::remove_file(self.dir.join(JOURNAL));
        if let Some(lock) = self.lock.take() {
            lock.release();
        }
        if !self.published {
            for d in &self.created {
                let _ = std::fs::remove_dir(d);
            }
        }
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        // Unwinding from a panic: what was staged stays for a resume, as after a kill (the
        // next command into the folder decides what to do with it).
        if std::thread::panicking() {
            self.suspended = true;
        }
        if !self.published && !self.suspended {
            if let Ok(mut active) = ACTIVE.lock() {
                *active = None;
            }
            self.close();
        }
    }
}

/// Removes, under the subfolders the journal in `dir` marks replaced, every file the journal
/// does not list, then moves the listed files from the staging folder into place (skipping any
/// already moved). Running it again after an interruption finishes the same work.
fn move_staged(dir: &Path) -> Result<()> {
    let journal = dir.join(JOURNAL);
    let text = std::fs::read_to_string(&journal).map_err(|e| Error::io(&journal, e))?;
    let lines: Vec<&str> = text.lines().filter(|l| !l.is_empty()).collect();
    // The directives' prefixes end in ':', which no file gibench writes has.
    let directive = |l: &&&str| l.starts_with(REPLACE) || l.starts_with(REPLACE_FILES);
    let listed: std::collections::HashSet<&Path> = lines
        .iter()
        .filter(|l| !directive(l))
        .map(Path::new)
        .collect();
    for sub in lines.iter().filter_map(|l| l.strip_prefix(REPLACE)) {
        let sub = Path::new(sub);
        if sub.components().all(|c| matches!(c, Component::Normal(_))) {
            remove_unlisted(dir, sub, &listed)?;
        }
    }
    for pattern in lines.iter().filter_map(|l| l.strip_prefix(REPLACE_FILES)) {
        remove_unlisted_matching(dir, pattern, &listed)?;
    }
    for rel in lines.iter().filter(|l| !directive(l)) {
        let rel = Path::new(rel);
        if !rel.components().all(|c| matches!(c, Component::Normal(_))) {
            // Not written by gibench: ignored.
            continue;
        }
        let from = dir.join(STAGING).join(rel);
        let to = dir.join(rel);
        if !from.exists() {
            continue;
        }
        if rel.parent().is_some_and(|p| link_on_the_way(dir, p)) {
            return Err(Error::Invalid(format!(
                "{} lies under a symbolic link; gibench does not write through links",
                to.display()
            )));
        }
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        }
        std::fs::rename(&from, &to).map_err(|e| Error::io(&to, e))?;
    }
    Ok(())
}

/// Removes the files under `dir/sub` (recursively; links themselves, never followed) whose
/// path relative to `dir` is not in `keep`, then the folders left empty.
fn remove_unlisted(dir: &Path, sub: &Path, keep: &std::collections::HashSet<&Path>) -> Result<()> {
    let folder = dir.join(sub);
    if link_on_the_way(dir, sub) {
        return Err(Error::Invalid(format!(
            "{} is or lies under a symbolic link; gibench does not remove files through links",
            folder.display()
        )));
    }
    let Ok(entries) = std::fs::read_dir(&folder) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let rel = sub.join(e.file_name());
        let kind = e.file_type().map_err(|err| Error::io(e.path(), err))?;
        if kind.is_dir() {
            remove_unlisted(dir, &rel, keep)?;
            let _ = std::fs::remove_dir(e.path());
        } else if !keep.contains(rel.as_path()) {
            std::fs::remove_file(e.path()).map_err(|err| Error::io(e.path(), err))?;
        }
    }
    Ok(())
}

/// Records `pattern` (a plain file name, or `PREFIX*SUFFIX`) as replaced in the open set:
/// `Ok(false)` if it is not such a pattern, `Ok(true)` otherwise (also with no set open).
fn add_pattern(pattern: &str) -> Result<bool> {
    let plain = pattern.matches('*').count() <= 1
        && !pattern.contains(['/', '\\'])
        && pattern.len() > 1
        && !pattern.starts_with('.');
    if !plain {
        return Ok(false);
    }
    let mut active = ACTIVE
        .lock()
        .map_err(|_| Error::Invalid("output state poisoned".into()))?;
    if let Some(a) = active.as_mut() {
        if !a.patterns.iter().any(|p| p == pattern) {
            a.patterns.push(pattern.to_string());
        }
    }
    Ok(true)
}

/// Declares `path` replaced in the open output set, if one is open on its folder: at
/// publication it is removed unless the set wrote it — a file a command writes only
/// sometimes (a run's images) does not outlive the run that no longer writes it.
pub fn replace_in_open_set(path: &Path) -> Result<()> {
    let dir = {
        let active = ACTIVE
            .lock()
            .map_err(|_| Error::Invalid("output state poisoned".into()))?;
        match active.as_ref() {
            Some(a) => a.dir.clone(),
            None => return Ok(()),
        }
    };
    let resolved = resolve(path);
    if resolved.parent() != Some(dir.as_path()) {
        return Ok(());
    }
    if let Some(name) = resolved.file_name().and_then(|n| n.to_str()) {
        add_pattern(name)?;
    }
    Ok(())
}

/// Removes the files (not folders) directly in `dir` named `PREFIX*SUFFIX` (`pattern`; a
/// pattern without `*` is one name) that are not in `keep`.
fn remove_unlisted_matching(
    dir: &Path,
    pattern: &str,
    keep: &std::collections::HashSet<&Path>,
) -> Result<()> {
    let (prefix, suffix) = pattern.split_once('*').unwrap_or((pattern, ""));
    let exact = !pattern.contains('*');
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(name) = name.to_str() else {
            continue;
        };
        let matches = if exact {
            name == pattern
        } else {
            name.len() >= prefix.len() + suffix.len()
                && name.starts_with(prefix)
                && name.ends_with(suffix)
        };
        let file = e.file_type().is_ok_and(|t| t.is_file());
        if matches && file && !keep.contains(Path::new(name)) {
            std::fs::remove_file(e.path()).map_err(|err| Error::io(e.path(), err))?;
        }
    }
    Ok(())
}

/// Finishes a publication a killed run left half done, then removes its staging folder and
/// journal — or, with `keep` and no publication to finish, keeps the staged files `keep`
/// names (those that are there) and removes the rest. Returns the files kept.
fn recover(dir: &Path, keep: Option<&mut Keep>) -> Result<Vec<PathBuf>> {
    let journal = dir.join(JOURNAL);
    let finishing = journal.exists();
    if finishing {
        move_staged(dir)?;
    }
    let staging = dir.join(STAGING);
    let mut kept = Vec::new();
    // Only a set opened with `resume` marks its staging folder resumable: files another
    // command staged there (and was killed before publishing) are never taken over.
    let resumable = staging.join(RESUMABLE).is_file();
    match keep {
        Some(keep) if !finishing && resumable && staging.is_dir() => {
            let mut present = Vec::new();
            files_below(&staging, Path::new(""), &mut present);
            present.retain(|p| p != Path::new(RESUMABLE));
            let wanted = keep(&present);
            for rel in &present {
                if !wanted.contains(rel) {
                    let f = staging.join(rel);
                    std::fs::remove_file(&f).map_err(|e| Error::io(&f, e))?;
                }
            }
            kept = (wanted.into_iter())
                .filter(|w| present.contains(w))
                .collect();
        }
        _ if staging.is_dir() => {
            std::fs::remove_dir_all(&staging).map_err(|e| Error::io(&staging, e))?
        }
        _ if staging.exists() => {
            std::fs::remove_file(&staging).map_err(|e| Error::io(&staging, e))?
        }
        _ => {}
    }
    if journal.exists() {
        std::fs::remove_file(&journal).map_err(|e| Error::io(&journal, e))?;
    }
    Ok(kept)
}

/// Every file below `root.join(rel)` (relative to `root`), links not followed.
fn files_below(root: &Path, rel: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(root.join(rel)) else {
        return;
    };
    for e in entries.flatten() {
        let r = rel.join(e.file_name());
        match e.file_type() {
            Ok(t) if t.is_dir() => files_below(root, &r, out),
            Ok(_) => out.push(r),
            Err(_) => {}
        }
    }
}

/// Where a write to `path` must go while a set is open: its staged path, recorded for
/// publication; `None` when `path` is outside the open set's folder (or none is open). A path
/// named below the folder that a symbolic link takes out of it is an error.
pub(crate) fn staged_path(path: &Path) -> Result<Option<PathBuf>> {
    let Ok(mut active) = ACTIVE.lock() else {
        return Ok(None);
    };
    let Some(a) = active.as_mut() else {
        return Ok(None);
    };
    let Ok(rel) = resolve(path).strip_prefix(&a.dir).map(Path::to_path_buf) else {
        if absolute(path).starts_with(&a.given) {
            return Err(Error::Invalid(format!(
                "{} lies under a symbolic link out of the output folder {}; gibench does not \
                 write through links",
                path.display(),
                a.given.display()
            )));
        }
        return Ok(None);
    };
    if rel.as_os_str().is_empty() || rel.starts_with(STAGING) {
        return Ok(None);
    }
    if rel.parent().is_some_and(|p| link_on_the_way(&a.dir, p)) {
        return Err(Error::Invalid(format!(
            "{} lies under a symbolic link; gibench does not write through links",
            path.display()
        )));
    }
    let staged = a.dir.join(STAGING).join(&rel);
    if !a.staged.contains(&rel) {
        a.staged.push(rel);
    }
    Ok(Some(staged))
}

/// Removes temporary files (`.gibench-tmp-PID-*`) in `dir` whose process is gone: what a killed
/// atomic write leaves behind.
pub fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(TEMP_PREFIX)) else {
            continue;
        };
        let pid = rest.split('-').next().and_then(|p| p.parse::<u32>().ok());
        if pid.is_some_and(|p| !alive(p)) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Prefix of every temporary file gibench writes (then `PID-`).
pub(crate) const TEMP_PREFIX: &str = ".gibench-tmp-";

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, then a rename,
/// so a reader never sees a half-written file and a failed run leaves nothing behind. While an
/// [`OutputSet`] is open on a folder holding `path`, the file is staged there and
/// appears at `path` when the set is published.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    match staged_path(path)? {
        Some(staged) => write_atomic_direct(&staged, bytes),
        None => write_atomic_direct(path, bytes),
    }
}

/// [`write_atomic`] straight to `path`, never staged (the reference cache). The temporary file is
/// named `.gibench-tmp-PID-…`, so one a killed process leaves can be found and removed
/// ([`remove_stale_temporaries`]).
pub fn write_atomic_direct(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!("{}{}-", TEMP_PREFIX, std::process::id()))
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

#[cfg(test)]
mod tests;
