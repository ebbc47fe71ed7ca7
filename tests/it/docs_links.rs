//! Every link in the README, in `docs/` and in each `results/**/README.md` (but `results/local/`
//! and `results/cache/`, which git ignores) leads somewhere, and the README fits a screen.
//!
//! Inline links and images (`[text](target)`, `![alt](target)`), reference-style links
//! (`[text][label]`, `[label][]`, and `[label]` where `label` is defined) and their definitions
//! (`[label]: target`) and autolinks (`<https://...>`) are found outside fenced code blocks and
//! code spans. A relative target must name a file or folder that exists, resolved from the
//! linking file's folder, inside the repository; an `#anchor` (on the same file or on another
//! `.md` file) must be the GitHub-style slug of one of that file's headings (lowercased,
//! punctuation but `-` and `_` dropped, spaces turned into `-`, a repeated heading's slug
//! suffixed `-1`, `-2`, ...); an anchor on another file must be a line (`#L12`, `#L12-L20`) that
//! the file has. `http://` and `https://` links are NOT fetched (CI runs offline): they are only
//! checked to parse as URLs (a scheme, `://`, a host, no whitespace), as `mailto:` links are
//! checked to hold an address; any other scheme is an error. A failure names the file, the line
//! and the link.

use std::collections::{HashMap, HashSet};
use std::path::{Component, Path, PathBuf};

/// The README's length limit, in lines (issue 38: the README fits a screen or two).
const README_MAX_LINES: usize = 250;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One link found in a Markdown file.
#[derive(Debug, Clone, PartialEq)]
struct Link {
    /// 1-based line of its opening bracket (or of its definition).
    line: usize,
    /// The link as written, for messages.
    written: String,
    /// Where it points: a URL, a path with an optional `#anchor`, or only an anchor.
    target: Target,
}

#[derive(Debug, Clone, PartialEq)]
enum Target {
    /// An inline link's or a definition's destination.
    Dest(String),
    /// A reference to a label that must be defined in the same file.
    Label(String),
}

/// The lines of `text` with fenced code blocks blanked (kept as empty lines, so that line
/// numbers stay right).
fn without_fences(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut fence: Option<(char, usize)> = None;
    for line in text.lines() {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let run = |c: char| trimmed.chars().take_while(|&x| x == c).count();
        match fence {
            None => {
                let opener = ['`', '~'].into_iter().find(|&c| run(c) >= 3);
                match opener {
                    // Up to three spaces of indent, or any inside a list item.
                    Some(c) if indent <= 3 || line[..indent].chars().all(|x| x == ' ') => {
                        fence = Some((c, run(c)));
                        out.push("");
                    }
                    _ => out.push(line),
                }
            }
            Some((c, n)) => {
                if run(c) >= n && trimmed.trim_start_matches(c).trim().is_empty() {
                    fence = None;
                }
                out.push("");
            }
        }
    }
    out
}

/// `line` with every code span's content replaced by `x` (same number of characters), so that
/// brackets inside code are not read as links.
fn mask_code_spans(line: &str) -> String {
    let chars: Vec<char> = line.chars().collect();
    let mut out = chars.clone();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' || (i > 0 && chars[i - 1] == '\\') {
            i += 1;
            continue;
        }
        let n = chars[i..].iter().take_while(|&&c| c == '`').count();
        // The closing run: the next run of exactly n backticks.
        let mut j = i + n;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '`' {
                let m = chars[j..].iter().take_while(|&&c| c == '`').count();
                if m == n {
                    close = Some(j);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(j) => {
                for c in &mut out[i + n..j] {
                    *c = 'x';
                }
                i = j + n;
            }
            None => i += n,
        }
    }
    out.into_iter().collect()
}

/// Normalised reference label: lowercase, whitespace collapsed.
fn label_key(label: &str) -> String {
    label
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_lowercase()
}

/// A reference definition `[label]: target` (up to three spaces of indent), if `line` is one.
fn definition(line: &str) -> Option<(String, String)> {
    let indent = line.len() - line.trim_start_matches(' ').len();
    if indent > 3 {
        return None;
    }
    let rest = line.trim_start().strip_prefix('[')?;
    let end = rest.find("]:")?;
    let label = &rest[..end];
    if label.is_empty() || label.starts_with('^') || label.contains('[') {
        return None;
    }
    let after = rest[end + 2..].trim_start();
    let dest = match after.strip_prefix('<') {
        Some(inside) => inside.split('>').next()?,
        None => after.split_whitespace().next()?,
    };
    Some((label_key(label), dest.to_string()))
}

/// Every link of a Markdown text, and its reference definitions (label → (line, target)).
fn links(text: &str) -> (Vec<Link>, HashMap<String, (usize, String)>) {
    let lines = without_fences(text);
    let mut definitions = HashMap::new();
    // The text as written, and the same with code spans masked (character for character).
    let mut plain = String::new();
    let mut masked = String::new();
    for (i, line) in lines.iter().enumerate() {
        match definition(line) {
            Some((label, dest)) => {
                definitions.entry(label).or_insert((i + 1, dest));
                plain.push('\n');
                masked.push('\n');
            }
            None => {
                plain.push_str(line);
                plain.push('\n');
                masked.push_str(&mask_code_spans(line));
                masked.push('\n');
            }
        }
    }
    let c: Vec<char> = masked.chars().collect();
    let p: Vec<char> = plain.chars().collect();
    assert_eq!(c.len(), p.len(), "masking changed the text's length");
    let line_of = |at: usize| 1 + c[..at].iter().filter(|&&x| x == '\n').count();
    let escaped = |at: usize| at > 0 && c[at - 1] == '\\';
    // The index of the bracket closing the one at `open`, within one paragraph.
    let closing = |open: usize, (o, cl): (char, char)| {
        let mut depth = 0;
        let mut k = open;
        while k < c.len() {
            if c[k] == '\n' && c.get(k + 1) == Some(&'\n') {
                return None;
            }
            if !escaped(k) {
                if c[k] == o {
                    depth += 1;
                } else if c[k] == cl {
                    depth -= 1;
                    if depth == 0 {
                        return Some(k);
                    }
                }
            }
            k += 1;
        }
        None
    };
    let mut found = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if c[i] == '<' && !escaped(i) {
            // An autolink: <scheme:...> with no space inside.
            if let Some(end) = c[i + 1..]
                .iter()
                .position(|&x| x == '>' || x == ' ' || x == '\n')
            {
                let inner: String = p[i + 1..i + 1 + end].iter().collect();
                if c[i + 1 + end] == '>' && inner.contains("://") {
                    found.push(Link {
                        line: line_of(i),
                        written: format!("<{inner}>"),
                        target: Target::Dest(inner),
                    });
                }
            }
            i += 1;
            continue;
        }
        if c[i] != '[' || escaped(i) {
            i += 1;
            continue;
        }
        let Some(j) = closing(i, ('[', ']')) else {
            i += 1;
            continue;
        };
        let text: String = p[i + 1..j].iter().collect();
        let image = i > 0 && c[i - 1] == '!' && !escaped(i - 1);
        let start = if image { i - 1 } else { i };
        let written_to = |end: usize| p[start..=end].iter().collect::<String>();
        match c.get(j + 1) {
            Some('(') => {
                if let Some(k) = closing(j + 1, ('(', ')')) {
                    let inside: String = p[j + 2..k].iter().collect();
                    let inside = inside.trim();
                    let dest = match inside.strip_prefix('<') {
                        Some(rest) => rest.split('>').next().unwrap_or("").to_string(),
                        None => inside.split_whitespace().next().unwrap_or("").to_string(),
                    };
                    found.push(Link {
                        line: line_of(i),
                        written: written_to(k),
                        target: Target::Dest(dest),
                    });
                }
            }
            Some('[') => {
                if let Some(k) = closing(j + 1, ('[', ']')) {
                    let label: String = p[j + 2..k].iter().collect();
                    let label = if label.trim().is_empty() { text } else { label };
                    found.push(Link {
                        line: line_of(i),
                        written: written_to(k),
                        target: Target::Label(label_key(&label)),
                    });
                    // Its label's brackets are not a link of their own.
                    i = k + 1;
                    continue;
                }
            }
            _ => {
                // A shortcut reference is a link only where its label is defined.
                if definitions.contains_key(&label_key(&text)) {
                    found.push(Link {
                        line: line_of(i),
                        written: written_to(j),
                        target: Target::Label(label_key(&text)),
                    });
                }
            }
        }
        i += 1;
    }
    (found, definitions)
}

/// The text a heading shows: code spans' content kept, emphasis markers and link syntax gone.
fn heading_text(raw: &str) -> String {
    let chars: Vec<char> = raw.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    let word = |c: Option<&char>| c.is_some_and(|c| c.is_alphanumeric());
    while i < chars.len() {
        let ch = chars[i];
        if ch == '`' {
            let n = chars[i..].iter().take_while(|&&c| c == '`').count();
            let rest: String = chars[i + n..].iter().collect();
            let fence: String = "`".repeat(n);
            if let Some(end) = rest.find(&fence) {
                out.push_str(&rest[..end]);
                i += n + rest[..end].chars().count() + n;
                continue;
            }
            i += n;
            continue;
        }
        if ch == '\\' && i + 1 < chars.len() {
            out.push(chars[i + 1]);
            i += 2;
            continue;
        }
        if ch == '*' {
            i += 1;
            continue;
        }
        // `_` is emphasis only at a word's edge; inside a word it is a character.
        if ch == '_'
            && !(word(i.checked_sub(1).and_then(|p| chars.get(p))) && word(chars.get(i + 1)))
        {
            i += 1;
            continue;
        }
        if ch == ']' && chars.get(i + 1) == Some(&'(') {
            // Drop a link's destination, keep its text.
            let close = chars[i..].iter().position(|&c| c == ')').map(|p| i + p);
            i = close.map_or(i + 1, |p| p + 1);
            continue;
        }
        if ch == '[' || ch == ']' {
            i += 1;
            continue;
        }
        out.push(ch);
        i += 1;
    }
    out
}

/// GitHub's anchor for a heading's text (before de-duplication).
fn slug(text: &str) -> String {
    text.trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            '-' | '_' => Some(c),
            c if c.is_alphanumeric() => Some(c),
            _ => None,
        })
        .collect()
}

/// Every anchor the headings of a Markdown text define, duplicates suffixed as GitHub does.
fn anchors(text: &str) -> HashSet<String> {
    let lines = without_fences(text);
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = HashSet::new();
    let mut add = |raw: &str| {
        let base = slug(&heading_text(raw));
        let mut s = base.clone();
        let n = seen.entry(base.clone()).or_insert(0);
        if *n > 0 {
            s = format!("{base}-{n}");
        }
        *n += 1;
        out.insert(s);
    };
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let indent = line.len() - t.len();
        let hashes = t.chars().take_while(|&c| c == '#').count();
        if indent <= 3 && (1..=6).contains(&hashes) {
            let rest = &t[hashes..];
            if rest.is_empty() || rest.starts_with(' ') || rest.starts_with('\t') {
                // A closing run of `#`s (after a space) is not part of the heading.
                let rest = rest.trim();
                let open = rest.trim_end_matches('#');
                let shown = if open.is_empty() {
                    ""
                } else if open.ends_with(' ') {
                    open.trim_end()
                } else {
                    rest
                };
                add(shown);
                continue;
            }
        }
        // A setext heading: a paragraph line underlined by `=` or `-`.
        let under = t.trim_end();
        let setext = !under.is_empty()
            && indent <= 3
            && (under.chars().all(|c| c == '=') || under.chars().all(|c| c == '-'));
        if setext && i > 0 {
            let prev = lines[i - 1].trim();
            let paragraph = !prev.is_empty()
                && !prev.starts_with('#')
                && !prev.starts_with('|')
                && !prev.starts_with("- ")
                && !prev.starts_with("* ")
                && !prev.starts_with('>');
            if paragraph {
                add(prev);
            }
        }
    }
    out
}

/// `%XX` escapes decoded.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).unwrap_or("");
            if let Ok(b) = u8::from_str_radix(hex, 16) {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `path` with `.` and `..` resolved lexically; `None` when it climbs above its start.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::Normal(p) => out.push(p),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

/// Whether `url` parses as an absolute http(s) URL: scheme, `://`, a host, no whitespace.
fn parses_as_web_url(url: &str) -> bool {
    let Some((scheme, rest)) = url.split_once("://") else {
        return false;
    };
    if !matches!(scheme, "http" | "https") || url.chars().any(char::is_whitespace) {
        return false;
    }
    let authority = rest.split(['/', '?', '#']).next().unwrap_or("");
    let host_port = authority.rsplit('@').next().unwrap_or("");
    let (host, port) = match host_port.rsplit_once(':') {
        Some((h, p)) if !h.ends_with(']') || h.starts_with('[') => (h, Some(p)),
        _ => (host_port, None),
    };
    let host_ok = !host.is_empty()
        && !host.starts_with('.')
        && !host.ends_with('.')
        && !host.contains("..")
        && host
            .chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '.' | '-' | '[' | ']' | ':'));
    let port_ok = port.is_none_or(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_digit()));
    host_ok && port_ok
}

/// The scheme of `dest` (`https` in `https://...`, `mailto` in `mailto:...`), if it has one.
fn scheme(dest: &str) -> Option<&str> {
    let (s, _) = dest.split_once(':')?;
    let ok = s.len() > 1
        && s.starts_with(|c: char| c.is_ascii_alphabetic())
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    ok.then_some(s)
}

/// Checks of the links of the Markdown files, reading files through `read` (paths relative
/// to `root`). Returns one message per broken link, and the external links seen.
struct Checker<'a> {
    root: &'a Path,
    anchors: HashMap<PathBuf, HashSet<String>>,
    /// Destinations checked so far.
    checked: usize,
}

impl<'a> Checker<'a> {
    fn new(root: &'a Path) -> Self {
        Checker {
            root,
            anchors: HashMap::new(),
            checked: 0,
        }
    }

    fn anchors_of(&mut self, rel: &Path) -> &HashSet<String> {
        let root = self.root;
        self.anchors.entry(rel.to_path_buf()).or_insert_with(|| {
            anchors(&std::fs::read_to_string(root.join(rel)).unwrap_or_default())
        })
    }

    /// Every problem with the links of the Markdown file `rel` (relative to the root).
    fn check_file(&mut self, rel: &Path, external: &mut Vec<String>) -> Vec<String> {
        let text = std::fs::read_to_string(self.root.join(rel))
            .unwrap_or_else(|e| panic!("{}: {e}", rel.display()));
        let (found, definitions) = links(&text);
        let mut problems = Vec::new();
        // (line, the link as written, its destination), definitions included.
        let mut dests = Vec::new();
        for link in &found {
            match &link.target {
                Target::Dest(dest) => dests.push((link.line, link.written.clone(), dest.clone())),
                Target::Label(label) if !definitions.contains_key(label) => {
                    problems.push(format!(
                        "{}:{}: {}: no definition `[{label}]: ...` in the file",
                        rel.display(),
                        link.line,
                        link.written
                    ));
                }
                Target::Label(_) => {}
            }
        }
        for (label, (line, dest)) in &definitions {
            dests.push((*line, format!("[{label}]: {dest}"), dest.clone()));
        }
        dests.sort_by_key(|d| d.0);
        for (line, written, dest) in dests {
            if let Err(why) = self.check_dest(rel, &dest, external) {
                problems.push(format!("{}:{line}: {written}: {why}", rel.display()));
            }
        }
        problems
    }

    /// Whether the destination `dest` written in `from` (relative to the root) leads
    /// somewhere; `Err` says why not.
    fn check_dest(
        &mut self,
        from: &Path,
        dest: &str,
        external: &mut Vec<String>,
    ) -> Result<(), String> {
        self.checked += 1;
        if dest.is_empty() {
            return Err("empty target".into());
        }
        if let Some(s) = scheme(dest) {
            return match s {
                "http" | "https" if parses_as_web_url(dest) => {
                    external.push(format!("{}: {dest}", from.display()));
                    Ok(())
                }
                "http" | "https" => Err("does not parse as a URL".into()),
                "mailto" if dest[7..].contains('@') => Ok(()),
                _ => Err(format!("unexpected scheme `{s}:`")),
            };
        }
        let (path, anchor) = match dest.split_once('#') {
            Some((p, a)) => (p, Some(percent_decode(a))),
            None => (dest, None),
        };
        let path = percent_decode(path.split('?').next().unwrap_or(""));
        let target = if path.is_empty() {
            from.to_path_buf()
        } else {
            let joined = if let Some(abs) = path.strip_prefix('/') {
                PathBuf::from(abs)
            } else {
                from.parent().unwrap_or(Path::new("")).join(&path)
            };
            normalise(&joined).ok_or("leads outside the repository")?
        };
        let full = self.root.join(&target);
        if !full.exists() {
            return Err(format!("{} does not exist", target.display()));
        }
        let Some(anchor) = anchor else {
            return Ok(());
        };
        if full.is_dir() {
            return Err(format!("an anchor on the folder {}", target.display()));
        }
        if target.extension().is_some_and(|e| e == "md") {
            if self.anchors_of(&target).contains(&anchor) {
                return Ok(());
            }
            return Err(format!(
                "{} has no heading whose anchor is #{anchor}",
                target.display()
            ));
        }
        // A source file's line anchor: #L12 or #L12-L20.
        let lines = std::fs::read_to_string(&full)
            .map(|t| t.lines().count())
            .unwrap_or(0);
        let line_no = |s: &str| s.strip_prefix('L').and_then(|n| n.parse::<usize>().ok());
        let (a, b) = anchor.split_once('-').unwrap_or((&anchor, &anchor));
        match (line_no(a), line_no(b)) {
            (Some(a), Some(b)) if 1 <= a && a <= b && b <= lines => Ok(()),
            _ => Err(format!(
                "#{anchor} is not a line of {} ({lines} lines)",
                target.display()
            )),
        }
    }
}

/// `dir` (relative to the root) and every folder below it, but hidden ones and `skip`.
fn walk(root: &Path, dir: &Path, skip: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
        return;
    };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let rel = dir.join(e.file_name());
        let name = e.file_name().to_string_lossy().into_owned();
        let is_dir = e.file_type().is_ok_and(|t| t.is_dir());
        if name.starts_with('.') || skip.iter().any(|s| Path::new(s) == rel) {
            continue;
        }
        if is_dir {
            walk(root, &rel, skip, out);
        } else {
            out.push(rel);
        }
    }
}

/// The README, every Markdown page under `docs/` and every README under `results/` (but
/// `results/local/` and `results/cache/`), relative to the root.
fn pages(root: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    walk(root, Path::new("docs"), &[], &mut files);
    walk(
        root,
        Path::new("results"),
        &["results/local", "results/cache"],
        &mut files,
    );
    let mut out = vec![PathBuf::from("README.md")];
    out.extend(files.into_iter().filter(|f| {
        (f.starts_with("docs") && f.extension().is_some_and(|e| e == "md"))
            || (f.starts_with("results") && f.file_name().is_some_and(|n| n == "README.md"))
    }));
    out
}

#[test]
fn the_readme_fits_in_250_lines() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines, more than {README_MAX_LINES}: move detail to docs/ or to a \
         results/<folder>/README.md and link it"
    );
}

/// The tracked tree's limit in bytes (issue 51): a GPU slot copies the working tree (at most 64
/// MiB, with the prebuilt bundle of `scripts/gpu-bundle.sh` beside it), so the checkout keeps
/// half of that. `results/.gitignore` keeps the images that regenerate out.
const TRACKED_TREE_MAX_BYTES: u64 = 32 << 20;

/// The size of the files git tracks under `root` (apparent sizes, as `du -b` adds them), or
/// `None` outside a git checkout.
fn tracked_bytes(root: &Path) -> Option<(u64, Vec<(u64, String)>)> {
    let o = std::process::Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    let mut files: Vec<(u64, String)> = o
        .stdout
        .split(|b| *b == 0)
        .filter(|n| !n.is_empty())
        .map(|n| String::from_utf8_lossy(n).into_owned())
        // A file deleted but not yet staged is not in the tree a copy takes.
        .filter_map(|n| Some((std::fs::metadata(root.join(&n)).ok()?.len(), n)))
        .collect();
    files.sort();
    Some((files.iter().map(|f| f.0).sum(), files))
}

#[test]
fn the_tracked_tree_stays_under_32_mib() {
    let root = root();
    let Some((total, files)) = tracked_bytes(&root) else {
        eprintln!("not a git checkout (or no git): the tracked tree's size was not checked");
        return;
    };
    let largest: Vec<String> = files
        .iter()
        .rev()
        .take(10)
        .map(|(n, f)| format!("{f} ({n} bytes)"))
        .collect();
    assert!(
        total < TRACKED_TREE_MAX_BYTES,
        "the tracked tree is {total} bytes, over {TRACKED_TREE_MAX_BYTES} (32 MiB): keep \
         regenerable images out (results/.gitignore); the largest files: {largest:#?}"
    );
}

/// The house's limit on a source file, in lines (docs/architecture.md): past it a file is split
/// by concern.
const SOURCE_MAX_LINES: usize = 900;

/// Every Rust source file of the repository (but `target/` and hidden folders), relative.
fn rust_sources(root: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    walk(root, Path::new(""), &["target", "results"], &mut files);
    files.retain(|f| f.extension().is_some_and(|e| e == "rs"));
    files
}

#[test]
fn no_source_file_passes_900_lines() {
    let root = root();
    let sources = rust_sources(&root);
    assert!(
        sources.iter().any(|f| f.ends_with("src/main.rs")) && sources.len() > 100,
        "the walk found too few sources: {sources:?}"
    );
    let long: Vec<String> = sources
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(root.join(f)).ok()?.lines().count();
            (n > SOURCE_MAX_LINES).then(|| format!("{} ({n} lines)", f.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "source files over {SOURCE_MAX_LINES} lines (split them by concern): {long:?}"
    );
}

/// Catches: the README's technique table, docs/running.md's parameter table or
/// docs/techniques.md's stage table drifting from the registry's declarations (a technique,
/// parameter or stage added or renamed, a default, doc, paper, summary or conformance bound
/// changed in the code and not in the docs): each table between its markers must equal its
/// part of `gibench list --markdown` (techniques, parameters, stages, a blank line between).
#[test]
fn the_generated_tables_in_the_docs_match_gibench_list_markdown() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_gibench"))
        .args(["list", "--markdown"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let generated = String::from_utf8(o.stdout).unwrap();
    let tables: Vec<&str> = generated.split("\n\n").collect();
    let [techniques, parameters, stages] = tables[..] else {
        panic!("three tables, a blank line between each two:\n{generated}");
    };
    assert!(parameters.lines().count() > 20, "{generated}");
    for (file, part, table) in [
        ("README.md", "techniques", format!("{techniques}\n")),
        ("docs/running.md", "parameters", format!("{parameters}\n")),
        ("docs/techniques.md", "stages", stages.to_string()),
    ] {
        let doc = std::fs::read_to_string(root().join(file)).unwrap();
        let start = format!("<!-- gibench list --markdown: {part} -->\n");
        let end = format!("<!-- end of gibench list --markdown: {part} -->");
        let from = doc
            .find(&start)
            .unwrap_or_else(|| panic!("{file}: no marker {start}"))
            + start.len();
        let to = doc[from..]
            .find(&end)
            .unwrap_or_else(|| panic!("{file}: no marker {end}"))
            + from;
        assert!(
            doc[from..to] == table,
            "{file}'s {part} table differs from `gibench list --markdown`: paste its output \
             between the markers.\nGenerated:\n{table}"
        );
    }
}

#[test]
fn every_link_in_the_readme_docs_and_results_readmes_is_alive() {
    let root = root();
    let pages = pages(&root);
    assert!(
        pages.iter().any(|p| p.starts_with("docs")),
        "no Markdown page under docs/"
    );
    let mut checker = Checker::new(&root);
    let mut external = Vec::new();
    let mut problems = Vec::new();
    for page in &pages {
        problems.extend(checker.check_file(page, &mut external));
    }
    eprintln!(
        "docs_links: {} links checked in {} files",
        checker.checked,
        pages.len()
    );
    if !external.is_empty() {
        eprintln!(
            "docs_links: {} http(s) links parsed, not fetched:",
            external.len()
        );
        for e in &external {
            eprintln!("  {e}");
        }
    }
    assert!(
        problems.is_empty(),
        "{} broken links:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn the_readme_links_every_docs_page_and_results_readme() {
    let root = root();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let (found, definitions) = links(&readme);
    let linked: HashSet<PathBuf> = found
        .iter()
        .filter_map(|l| match &l.target {
            Target::Dest(d) => Some(d.clone()),
            Target::Label(label) => definitions.get(label).map(|(_, d)| d.clone()),
        })
        .filter_map(|d| normalise(Path::new(d.split('#').next().unwrap_or(""))))
        .collect();
    let unlinked: Vec<String> = pages(&root)
        .into_iter()
        .skip(1)
        .filter(|p| !linked.contains(p))
        .map(|p| p.display().to_string())
        .collect();
    assert!(
        unlinked.is_empty(),
        "README.md links no page of these (its contents list should): {}",
        unlinked.join(", ")
    );
}

/// The checker itself, on texts whose links are known.
#[test]
fn the_checker_finds_links_anchors_and_breakages() {
    let text = "# Title\n\nSee [a](b.md#x) and ![i](img.png \"t\"), [r][lab], [lab], [lab][]\n\
                and [no link] and `[not](code)`.\n\n```sh\n[in](fence)\n```\n\n\
                [lab]: <c d.md>\n\n## Title\n\n### `a_b` *c* (d/e.f)\n\nSetext\n---\n";
    let (found, defs) = links(text);
    let dests: Vec<_> = found.iter().map(|l| (l.line, l.target.clone())).collect();
    assert_eq!(
        dests,
        vec![
            (3, Target::Dest("b.md#x".into())),
            (3, Target::Dest("img.png".into())),
            (3, Target::Label("lab".into())),
            (3, Target::Label("lab".into())),
            (3, Target::Label("lab".into())),
        ]
    );
    assert_eq!(defs.get("lab"), Some(&(10, "c d.md".to_string())));
    let a = anchors(text);
    for s in ["title", "title-1", "a_b-c-def", "setext"] {
        assert!(a.contains(s), "{s} not in {a:?}");
    }
    assert_eq!(
        slug(&heading_text(
            "The reference against Mitsuba 3 (`scripts/compare_mitsuba.py`)"
        )),
        "the-reference-against-mitsuba-3-scriptscompare_mitsubapy"
    );
    assert_eq!(
        slug(&heading_text(
            "Laine et al. 2007: Tables 1 and 2 regenerated"
        )),
        "laine-et-al-2007-tables-1-and-2-regenerated"
    );
    assert!(parses_as_web_url("https://example.org/a?b#c"));
    assert!(parses_as_web_url("http://localhost:8080/"));
    assert!(!parses_as_web_url("https:///nohost"));
    assert!(!parses_as_web_url("https://exa mple.org"));

    // A broken link is reported with its file and line.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("docs")).unwrap();
    std::fs::write(
        dir.path().join("docs/a.md"),
        "# A\n\n## Part two\n\n[ok](#part-two) [ok](../README.md#top)\n\
         [bad](#part-three)\n[gone](missing.md) [out](../../x.md) [web](https:/x)\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("README.md"), "# Top\n").unwrap();
    let mut checker = Checker::new(dir.path());
    let mut external = Vec::new();
    let problems = checker.check_file(Path::new("docs/a.md"), &mut external);
    assert_eq!(problems.len(), 4, "{problems:#?}");
    assert!(problems[0].starts_with("docs/a.md:6: [bad](#part-three): "));
    assert!(problems[1].starts_with("docs/a.md:7: [gone](missing.md): docs/missing.md"));
    assert!(problems[2].contains("outside the repository"));
    assert!(problems[3].contains("does not parse as a URL"));
}
