//! **HTML report**: one static page per run, sweep or reproduction, built from results files
//! and the images and plots written beside them. It opens from disk with no server and no
//! network: the page is one file with its styles and scripts inline, and its images are the
//! PNG and SVG files next to the results, referenced by relative paths.
//!
//! Reads: [`RunResult`]s (and the folder each was read from), tables, SVG figures.
//! Writes: the page.
//!
//! Sections: the glance (below), the summary table and any further tables (a paper's rows beside ours), sortable
//! by any column; per scene, an image viewer flipping or sliding between any two of the
//! reference's and every technique's images (composed, and indirect light alone at one
//! exposure), with the FLIP error maps, and a frame player stepping through the (last 16) compared
//! frame's indirect light beside the reference's; time versus error; the figures (per-stage bars,
//! per-frame error and flicker, sweep plots); the device, driver, commit, command line and each
//! run's settings.
//!
//! The page checks itself when it loads: every image must decode and no script error or
//! `console.error` may occur; it records the outcome on its root element
//! (`data-selfcheck="ok N"` for N images, else `fail …`), and whether every frame player
//! advances to another tile of strips of the expected size (`data-players="ok N"`), which
//! `tests/it/html.rs` reads from headless Chromium. A failed check also shows a warning at the top
//! of the page (a checkout keeps only some of the images: `results/.gitignore`).
//!
//! A page of runs with quality data opens on the glance table ([`report::glance_table`]: per
//! run frame ms, FPS, its reference component, relMSE and FLIP against each component and
//! Pareto rank) with the
//! time-versus-error plot beside it; the page records whether every glance row's frame time
//! and error lie within the window it was opened in (`data-first-screen="ok N"`). A table's
//! leading identifying columns (device, scene, technique, resolution, setting, run) stay in
//! view when it scrolls sideways.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::measure::results::RunResult;
use crate::output::absolute;
use crate::report::{self, Table};
use crate::run::quality::FilmStrip;
use crate::run::session::QUALITY_IMAGES;
use crate::Result;

/// What a page shows.
pub struct Page {
    pub title: String,
    /// The command line that produced it.
    pub command: String,
    /// Tables, in order (the first is the summary).
    pub tables: Vec<Table>,
    /// SVG figures (paths as written; shown in order).
    pub figures: Vec<PathBuf>,
    /// The runs, each with the folder its results file and images are in.
    pub runs: Vec<(PathBuf, RunResult)>,
}

/// `text` with HTML's special characters escaped.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// The relative URL of `target` from a page in `from_dir` (segments percent-encoded where
/// needed).
pub fn relative_url(from_dir: &Path, target: &Path) -> String {
    let (a, b) = (absolute(from_dir), absolute(target));
    let (ac, bc): (Vec<_>, Vec<_>) = (a.components().collect(), b.components().collect());
    let common = ac.iter().zip(&bc).take_while(|(x, y)| x == y).count();
    let mut parts: Vec<String> = vec!["..".into(); ac.len() - common];
    parts.extend(
        bc[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts
        .iter()
        .map(|p| {
            p.bytes()
                .map(|b| match b {
                    b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => {
                        (b as char).to_string()
                    }
                    _ => format!("%{b:02X}"),
                })
                .collect::<String>()
        })
        .collect::<Vec<_>>()
        .join("/")
}

/// A table as sortable HTML (numbers sort numerically; click a header).
fn table_html(t: &Table, class: &str) -> String {
    let mut h = format!(
        "<h3>{}</h3>\n<div class=\"scroll\"><table class=\"sortable {class}\"><thead><tr>",
        esc(&t.title)
    );
    // The identifying columns (the leading text columns: scene, technique, resolution, ...)
    // stay in view while the table scrolls sideways.
    let ids = t.identifying_columns();
    let id = |c: usize| if c < ids { " class=\"id\"" } else { "" };
    for (i, c) in t.columns.iter().enumerate() {
        let _ = write!(h, "<th{}>{}</th>", id(i), esc(c));
    }
    h.push_str("</tr></thead><tbody>\n");
    for row in &t.rows {
        // A row whose first cell names another source than gibench is a paper's: marked.
        let paper = row
            .first()
            .map(|c| {
                let s = c.display();
                !s.is_empty() && s != "gibench" && t.columns.first().is_some_and(|c| c == "source")
            })
            .unwrap_or(false);
        h.push_str(if paper {
            "<tr class=\"paper\">"
        } else {
            "<tr>"
        });
        for (i, c) in row.iter().enumerate() {
            let _ = write!(h, "<td{}>{}</td>", id(i), esc(&c.display()));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table></div>\n");
    for n in &t.notes {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", esc(n));
    }
    h
}

/// One frame player of a scene: the runs compared on the same frames at the same size.
struct Player {
    frames: Vec<u32>,
    size: [u32; 2],
    /// (label, film strip URL): the references first met, then each technique, in run order.
    rows: Vec<(String, String)>,
    /// The reference components shown.
    references: Vec<String>,
}

/// One image of a scene's viewer: its label and URL.
struct Shot {
    label: String,
    url: String,
}

impl Page {
    /// Renders the page as HTML for a file in `dir`.
    pub fn render(&self, dir: &Path) -> String {
        let mut body = String::new();
        let _ = writeln!(body, "<h1>{}</h1>", esc(&self.title));
        let shown = self.glance(dir, &mut body);
        body.push_str(&self.provenance());
        for t in &self.tables {
            body.push_str(&table_html(t, ""));
        }
        body.push_str(&self.viewers(dir));
        let figures: Vec<&PathBuf> = (self.figures.iter())
            .filter(|f| Some(*f) != shown)
            .collect();
        if !figures.is_empty() {
            body.push_str("<h2>Figures</h2>\n");
            for f in figures {
                let _ = writeln!(
                    body,
                    "<figure><img class=\"plot\" src=\"{}\" alt=\"{}\"></figure>",
                    esc(&relative_url(dir, f)),
                    esc(&f.file_name().unwrap_or_default().to_string_lossy())
                );
            }
        }
        body.push_str(&self.settings());
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\" data-selfcheck=\"pending\">\n<head>\n<meta charset=\"utf-8\">\n\
             <title>{}</title>\n<style>{STYLE}</style>\n<script>{CHECK_SCRIPT}</script>\n</head>\n<body>\n{body}\
             <script>{UI_SCRIPT}</script>\n</body>\n</html>\n",
            esc(&self.title)
        )
    }

    /// The first screen, where a run has quality data: the glance table
    /// ([`report::glance_table`]) with the time-versus-error plot beside it (if among the
    /// figures), appended to `body`. Returns the plot shown, which the figures then leave out.
    fn glance(&self, dir: &Path, body: &mut String) -> Option<&PathBuf> {
        let runs: Vec<RunResult> = self.runs.iter().map(|(_, r)| r.clone()).collect();
        let table = report::glance_table(&runs)?;
        let plot =
            (self.figures.iter()).find(|f| f.to_string_lossy().ends_with("-time-vs-error.svg"));
        body.push_str("<section class=\"glance\"><div>");
        body.push_str(&table_html(&table, "glance"));
        body.push_str("</div>");
        if let Some(f) = plot {
            let _ = write!(
                body,
                "<figure><img class=\"plot\" src=\"{}\" alt=\"time versus error\"></figure>",
                esc(&relative_url(dir, f))
            );
        }
        body.push_str("</section>\n");
        plot
    }

    /// Writes the page to `path` (atomically; staged inside an open output set).
    pub fn write(&self, path: &Path) -> Result<()> {
        let dir = path.parent().unwrap_or(Path::new("."));
        crate::output::write_atomic(path, self.render(dir).as_bytes())
    }

    /// Device, driver, commit and command line.
    fn provenance(&self) -> String {
        let mut devices: Vec<String> = self
            .runs
            .iter()
            .map(|(_, r)| {
                // GL reports no driver name; its version string is the driver's description.
                let d = &r.device;
                let driver = [d.driver.as_str(), d.driver_info.as_str()]
                    .into_iter()
                    .filter(|s| !s.is_empty())
                    .collect::<Vec<_>>()
                    .join(" ");
                let env = d.env_text();
                if driver.is_empty() {
                    format!("{} ({}{env})", d.adapter, d.backend)
                } else {
                    format!("{} ({}, driver {driver}{env})", d.adapter, d.backend)
                }
            })
            .collect();
        devices.sort();
        devices.dedup();
        let mut commits: Vec<&str> = self
            .runs
            .iter()
            .map(|(_, r)| r.git_commit.as_str())
            .collect();
        commits.sort();
        commits.dedup();
        format!(
            "<dl class=\"provenance\"><dt>command</dt><dd><code>{}</code></dd><dt>device</dt><dd>{}</dd>\
             <dt>git commit</dt><dd>{}</dd><dt>gibench</dt><dd>{}</dd></dl>\n",
            esc(&self.command),
            esc(&if devices.is_empty() { "—".to_string() } else { devices.join("; ") }),
            esc(&if commits.is_empty() { "—".to_string() } else { commits.join(", ") }),
            env!("CARGO_PKG_VERSION"),
        )
    }

    /// Per scene: the image viewer and the FLIP maps.
    fn viewers(&self, dir: &Path) -> String {
        let mut scenes: Vec<&str> = self.runs.iter().map(|(_, r)| r.scene.as_str()).collect();
        scenes.dedup();
        let all: Vec<RunResult> = self.runs.iter().map(|(_, r)| r.clone()).collect();
        let mut h = String::new();
        for (v, scene) in scenes.iter().enumerate() {
            let runs: Vec<&(PathBuf, RunResult)> = self
                .runs
                .iter()
                .filter(|(_, r)| r.scene == *scene)
                .collect();
            let url = |folder: &Path, name: &str| relative_url(dir, &folder.join(name));
            let has = |r: &RunResult, name: &str| r.images.iter().any(|i| i == name);
            let mut shots: Vec<Shot> = Vec::new();
            let mut flips: Vec<(String, String, f64)> = Vec::new();
            // The references shown, by component (techniques may compare with different ones).
            let mut references: Vec<String> = Vec::new();
            for (folder, r) in &runs {
                let label = report::distinct_label(&all, r);
                // The quality pass's images (same frame as the reference), else the last frame.
                let stem = r
                    .images
                    .iter()
                    .find_map(|i| i.strip_suffix(QUALITY_IMAGES[0]))
                    .map(String::from);
                match stem {
                    Some(stem) => {
                        let img = |suffix: &str| format!("{stem}{suffix}");
                        let component = r
                            .quality
                            .as_ref()
                            .and_then(|q| q.reference.split(',').next())
                            .unwrap_or("")
                            .trim()
                            .to_string();
                        // The reference's images are shared by the run set
                        // (`reference_image_name`), listed in each run's images.
                        let reference = |suffix: &str| {
                            r.images
                                .iter()
                                .find(|i| i.ends_with(suffix) && !i.starts_with(&stem))
                                .or_else(|| r.images.iter().find(|i| **i == img(suffix)))
                        };
                        if let Some(shown) = reference(QUALITY_IMAGES[1])
                            .filter(|_| !references.contains(&component))
                        {
                            shots.push(Shot {
                                label: format!("reference ({component})"),
                                url: url(folder, shown),
                            });
                            if let Some(indirect) = reference(QUALITY_IMAGES[4]) {
                                shots.push(Shot {
                                    label: format!("reference ({component}), indirect only"),
                                    url: url(folder, indirect),
                                });
                            }
                            references.push(component);
                        }
                        shots.push(Shot {
                            label: label.clone(),
                            url: url(folder, &img(QUALITY_IMAGES[0])),
                        });
                        if has(r, &img(QUALITY_IMAGES[3])) {
                            shots.push(Shot {
                                label: format!("{label}, indirect only"),
                                url: url(folder, &img(QUALITY_IMAGES[3])),
                            });
                        }
                        if has(r, &img(QUALITY_IMAGES[2])) {
                            let mean = r
                                .quality
                                .as_ref()
                                .map(|q| q.flip_mean.mean)
                                .unwrap_or(f64::NAN);
                            flips.push((label, url(folder, &img(QUALITY_IMAGES[2])), mean));
                        }
                    }
                    None => {
                        if let Some(png) = r
                            .images
                            .iter()
                            .find(|i| i.ends_with(".png") && !i.ends_with("-indirect.png"))
                        {
                            shots.push(Shot {
                                label,
                                url: url(folder, png),
                            });
                        }
                    }
                }
            }
            if shots.is_empty() {
                continue;
            }
            let _ = writeln!(h, "<h2>Images: {}</h2>", esc(scene));
            if !references.is_empty() {
                h.push_str(
                    "<p class=\"note\">The last frame compared with the CPU reference. Composed images at the scene's \
                     exposure; \"indirect only\" images (ρ/π · indirect irradiance) share one exposure, set from the \
                     reference.</p>\n",
                );
            } else {
                h.push_str("<p class=\"note\">The last measured frame (run with --quality to compare with the reference).</p>\n");
            }
            h.push_str(&viewer(v, &shots));
            if !flips.is_empty() {
                let _ = writeln!(
                    h,
                    "<h3>FLIP error against the reference ({})</h3>\n<div class=\"strip\">",
                    esc(scene)
                );
                for (label, u, mean) in &flips {
                    let _ = writeln!(
                        h,
                        "<figure><img class=\"thumb\" src=\"{}\" alt=\"FLIP {}\"><figcaption>{} — mean FLIP {:.4}</figcaption></figure>",
                        esc(u),
                        esc(label),
                        esc(label),
                        mean
                    );
                }
                h.push_str("</div>\n");
            }
            h.push_str(&self.players(dir, scene, &all));
        }
        h
    }

    /// Per scene, the frame player: every compared frame's indirect light of each technique
    /// beside the reference's (the quality pass's film strips), stepped or played, so that lag
    /// and flicker can be seen. Runs compared on different frames get a player each.
    fn players(&self, dir: &Path, scene: &str, all: &[RunResult]) -> String {
        let mut groups: Vec<Player> = Vec::new();
        for (folder, r) in self.runs.iter().filter(|(_, r)| r.scene == scene) {
            let Some(q) = &r.quality else { continue };
            let Some(stem) = r
                .images
                .iter()
                .filter_map(|i| i.strip_suffix(QUALITY_IMAGES[5]))
                .find(|s| !s.ends_with("-reference"))
            else {
                continue;
            };
            let frames: Vec<u32> = q.frames[FilmStrip::shown(q.frames.len())]
                .iter()
                .map(|f| f.frame)
                .collect();
            // Shared by the run set (`reference_image_name`); a run written before that
            // names it after its own stem.
            let Some(reference_strip) = r
                .images
                .iter()
                .find(|i| i.ends_with(QUALITY_IMAGES[6]) && !i.starts_with(stem))
                .or_else(|| {
                    r.images
                        .iter()
                        .find(|i| **i == format!("{stem}{}", QUALITY_IMAGES[6]))
                })
                .cloned()
            else {
                continue;
            };
            if frames.len() < 2 {
                continue;
            }
            let url = |name: &str| relative_url(dir, &folder.join(name));
            let i = match groups
                .iter()
                .position(|g| g.frames == frames && g.size == r.resolution)
            {
                Some(i) => i,
                None => {
                    groups.push(Player {
                        frames,
                        size: r.resolution,
                        rows: Vec::new(),
                        references: Vec::new(),
                    });
                    groups.len() - 1
                }
            };
            let g = &mut groups[i];
            let component = q
                .reference
                .split(',')
                .next()
                .unwrap_or("")
                .trim()
                .to_string();
            if !g.references.contains(&component) {
                g.rows
                    .push((format!("reference ({component})"), url(&reference_strip)));
                g.references.push(component);
            }
            g.rows.push((
                report::distinct_label(all, r),
                url(&format!("{stem}{}", QUALITY_IMAGES[5])),
            ));
        }
        let mut h = String::new();
        for Player {
            frames, size, rows, ..
        } in &groups
        {
            let n = frames.len();
            let tile = FilmStrip::shrink(*size).1;
            let columns = FilmStrip::columns(tile[0], n);
            // Shown 256 pixels wide, whatever the resolution.
            let (w, hgt) = (256.0, 256.0 * tile[1] as f64 / tile[0].max(1) as f64);
            let _ = writeln!(
                h,
                "<h3>Frames: {} (indirect light alone, every compared frame at the last one's exposure)</h3>\n\
                 <div class=\"player\" data-frames=\"{}\" data-columns=\"{columns}\" data-tile-width=\"{w}\" \
                 data-tile-height=\"{hgt:.3}\" data-strip-width=\"{}\" data-strip-height=\"{}\">\n\
                 <div class=\"controls\"><button class=\"play\">play</button> <button class=\"step\">next frame</button> \
                 <input class=\"scrub\" type=\"range\" min=\"0\" max=\"{}\" value=\"0\" aria-label=\"frame\"> \
                 <span class=\"frame-label\">frame {} (1 of {n})</span></div>\n<div class=\"strip\">",
                esc(scene),
                frames.iter().map(|f| f.to_string()).collect::<Vec<_>>().join(","),
                tile[0] as usize * columns,
                tile[1] as usize * n.div_ceil(columns),
                n - 1,
                frames[0],
            );
            for (label, u) in rows {
                let _ = write!(
                    h,
                    "<figure><div class=\"tile\" style=\"width:{w}px;height:{hgt:.3}px\"><img class=\"film\" src=\"{}\" \
                     alt=\"{} frames\" style=\"width:{}px\"></div><figcaption>{}</figcaption></figure>",
                    esc(u),
                    esc(label),
                    w * columns as f64,
                    esc(label)
                );
            }
            h.push_str("</div>\n</div>\n");
        }
        h
    }

    /// Each run's parameters and settings.
    fn settings(&self) -> String {
        let mut h = String::from("<h2>Runs and settings</h2>\n");
        for (folder, r) in &self.runs {
            let params = serde_json::to_string_pretty(&serde_json::json!({
                "folder": folder, "technique": r.technique, "scene": r.scene,
                "resolution": r.resolution, "frames": r.frames, "seed": r.seed,
                "timing_mode": r.timing_mode, "parameters": r.parameters, "settings": r.settings,
                "reference": r.quality.as_ref().map(|q| q.reference.clone()),
                "device": r.device, "git_commit": r.git_commit, "warnings": r.warnings,
            }))
            .unwrap_or_default();
            let _ = writeln!(
                h,
                "<details><summary>{} on {}, {}x{}</summary><pre>{}</pre></details>",
                esc(&r.technique),
                esc(&r.scene),
                r.resolution[0],
                r.resolution[1],
                esc(&params)
            );
        }
        h
    }
}

/// One entry of an index page: a target, what it shows, and its files (relative to the page).
pub struct IndexEntry {
    pub name: String,
    pub what: String,
    /// How long it took, as shown.
    pub time: String,
    pub files: Vec<String>,
}

/// An index page over several outputs (`gibench reproduce all --html`): per entry its
/// description, links to its pages and tables, and its SVG figures shown inline (as images).
pub fn write_index(path: &Path, title: &str, command: &str, entries: &[IndexEntry]) -> Result<()> {
    let mut body = format!(
        "<h1>{}</h1>\n<dl class=\"provenance\"><dt>command</dt><dd><code>{}</code></dd><dt>gibench</dt><dd>{}</dd></dl>\n",
        esc(title),
        esc(command),
        env!("CARGO_PKG_VERSION")
    );
    for e in entries {
        let link = |f: &String| format!("<a href=\"{}\">{}</a>", esc(&url_of(f)), esc(f));
        let pages: Vec<String> = e
            .files
            .iter()
            .filter(|f| f.ends_with(".html"))
            .map(link)
            .collect();
        let tables: Vec<String> = e
            .files
            .iter()
            .filter(|f| f.ends_with(".md"))
            .map(link)
            .collect();
        let _ = writeln!(
            body,
            "<h2 id=\"{}\">{}</h2>\n<p>{} <span class=\"note\">({})</span></p>",
            esc(&e.name),
            esc(&e.name),
            esc(&e.what),
            esc(&e.time)
        );
        if !pages.is_empty() {
            let _ = writeln!(body, "<p>page: {}</p>", pages.join(", "));
        }
        if !tables.is_empty() {
            let _ = writeln!(body, "<p>tables: {}</p>", tables.join(", "));
        }
        for f in e.files.iter().filter(|f| f.ends_with(".svg")) {
            let _ = writeln!(
                body,
                "<figure><img class=\"plot\" src=\"{}\" alt=\"{}\"></figure>",
                esc(&url_of(f)),
                esc(f)
            );
        }
    }
    let html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\" data-selfcheck=\"pending\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n<script>{CHECK_SCRIPT}</script>\n</head>\n<body>\n{body}</body>\n</html>\n",
        esc(title)
    );
    crate::output::write_atomic(path, html.as_bytes())
}

/// The A/B image viewer `v` of a scene over `shots` (A: the first image, the reference where
/// there is one; B: the first technique's), with every image as a thumbnail.
fn viewer(v: usize, shots: &[Shot]) -> String {
    // A: the first image (the reference where there is one); B: the first technique's.
    let a = 0;
    let b = shots
        .iter()
        .position(|s| !s.label.starts_with("reference"))
        .filter(|&i| i != a)
        .unwrap_or(if shots.len() > 1 { 1 } else { 0 });
    let options = |sel: usize| {
        shots
            .iter()
            .enumerate()
            .map(|(i, s)| {
                format!(
                    "<option value=\"{}\"{}>{}</option>",
                    esc(&s.url),
                    if i == sel { " selected" } else { "" },
                    esc(&s.label)
                )
            })
            .collect::<String>()
    };
    let mut h = String::new();
    let _ = writeln!(
                h,
                "<div class=\"viewer\" id=\"viewer{v}\">\n<div class=\"controls\">A <select class=\"pick-a\">{}</select> \
                 B <select class=\"pick-b\">{}</select> <button class=\"swap\">flip A/B</button> \
                 <input class=\"slider\" type=\"range\" min=\"0\" max=\"100\" value=\"50\" aria-label=\"A/B split\"></div>\n\
                 <div class=\"stack\"><img class=\"img-a\" src=\"{}\" alt=\"A\"><img class=\"img-b\" src=\"{}\" alt=\"B\"></div>\n\
                 <div class=\"strip\">{}</div>\n</div>",
                options(a),
                options(b),
                esc(&shots[a].url),
                esc(&shots[b].url),
                shots
                    .iter()
                    .map(|s| format!(
                        "<figure><img class=\"thumb\" src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                        esc(&s.url),
                        esc(&s.label),
                        esc(&s.label)
                    ))
                    .collect::<String>()
            );
    h
}

/// A relative path (with `/` separators) as a URL, each segment percent-encoded.
fn url_of(relative: &str) -> String {
    relative
        .split('/')
        .map(|seg| relative_url(Path::new("/"), &Path::new("/").join(seg)))
        .collect::<Vec<_>>()
        .join("/")
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;max-width:1400px;color:#222}\
.selfcheck-fail{background:#fde8e8;border:1px solid #c00;padding:.5em 1em;font-weight:bold}\
table{border-collapse:collapse;margin:.5em 0;font-size:14px}th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}\
th{background:#eee;cursor:pointer;user-select:none}td:first-child,th:first-child{text-align:left}\
tr.paper td{background:#fff7e0;font-style:italic}.note{font-size:13px;color:#555;max-width:1100px}\
.viewer{margin:1em 0}.stack{position:relative;display:inline-block;line-height:0}\
.stack img{width:768px;image-rendering:pixelated}.img-b{position:absolute;left:0;top:0;clip-path:inset(0 0 0 50%)}\
.strip{display:flex;flex-wrap:wrap;gap:8px}.strip figure{margin:0;font-size:12px;max-width:260px}\
.thumb{width:256px;image-rendering:pixelated;cursor:pointer}img.plot{max-width:100%}.scroll{overflow-x:auto}\
.tile{overflow:hidden;line-height:0}.tile img.film{max-width:none;image-rendering:pixelated}\
dl.provenance{display:grid;grid-template-columns:max-content auto;gap:2px 12px;font-size:14px}dt{font-weight:bold}\
th.id,td.id{position:sticky;z-index:1;background:#fff}th.id{background:#eee}\
section.glance{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}section.glance>div{max-width:720px}\
section.glance figure{margin:0}section.glance img.plot{width:600px}";

/// Runs first: records script errors, `console.error` calls and images that fail to decode,
/// and on load writes the verdict on the root element.
const CHECK_SCRIPT: &str = "(function(){var errors=[];\
window.addEventListener('error',function(e){var t=e.target;errors.push(t&&t.tagName?('resource '+(t.getAttribute('src')||t.tagName)):String(e.message));},true);\
var ce=console.error;console.error=function(){errors.push(Array.prototype.join.call(arguments,' '));return ce.apply(console,arguments);};\
window.addEventListener('load',function(){var imgs=Array.prototype.slice.call(document.images);\
var bad=imgs.filter(function(i){return !(i.complete&&i.naturalWidth>0);}).map(function(i){return i.getAttribute('src');});\
document.documentElement.setAttribute('data-selfcheck',(bad.length||errors.length)?('fail '+JSON.stringify({images:bad,errors:errors})):('ok '+imgs.length));\
if(bad.length||errors.length){var w=document.createElement('p');w.className='selfcheck-fail';w.setAttribute('role','alert');\
w.textContent='This page is incomplete: '+bad.length+' image(s) did not load'+(errors.length?(' and '+errors.length+' error(s) were raised'):'')+'. '\
+'A checkout keeps only the composed images of committed results; the command on this page (or bash results/regenerate.sh) writes the rest.';\
document.body.insertBefore(w,document.body.firstChild);}});})();";

/// Sortable tables and the A/B image viewers.
const UI_SCRIPT: &str = "document.querySelectorAll('table.sortable').forEach(function(t){\
t.querySelectorAll('th').forEach(function(th,col){var asc=true;th.addEventListener('click',function(){\
var body=t.tBodies[0];var rows=Array.prototype.slice.call(body.rows);\
var key=function(r){var s=r.cells[col]?r.cells[col].textContent.trim():'';var n=parseFloat(s.replace(/[^0-9eE+.\\-]/g,''));return isNaN(n)?s:n;};\
rows.sort(function(a,b){var x=key(a),y=key(b);var c=(typeof x==='number'&&typeof y==='number')?x-y:String(x).localeCompare(String(y));return asc?c:-c;});\
asc=!asc;rows.forEach(function(r){body.appendChild(r);});});});});\
document.querySelectorAll('.viewer').forEach(function(v){var a=v.querySelector('.img-a'),b=v.querySelector('.img-b');\
var pa=v.querySelector('.pick-a'),pb=v.querySelector('.pick-b'),s=v.querySelector('.slider');\
pa.addEventListener('change',function(){a.src=pa.value;});pb.addEventListener('change',function(){b.src=pb.value;});\
s.addEventListener('input',function(){b.style.clipPath='inset(0 0 0 '+s.value+'%)';});\
v.querySelector('.swap').addEventListener('click',function(){var t=pa.value;pa.value=pb.value;pb.value=t;a.src=pa.value;b.src=pb.value;});\
v.querySelectorAll('.thumb').forEach(function(th){th.addEventListener('click',function(){pa.value=th.getAttribute('src');a.src=pa.value;});});});\
var players=[];document.querySelectorAll('.player').forEach(function(p){var frames=p.dataset.frames.split(',');var n=frames.length;\
var cols=+p.dataset.columns,w=+p.dataset.tileWidth,h=+p.dataset.tileHeight;var scrub=p.querySelector('.scrub'),label=p.querySelector('.frame-label');\
var films=Array.prototype.slice.call(p.querySelectorAll('img.film'));var timer=null;\
function show(i){i=((i%n)+n)%n;p.dataset.frame=i;scrub.value=i;label.textContent='frame '+frames[i]+' ('+(i+1)+' of '+n+')';\
films.forEach(function(f){f.style.transform='translate('+(-(i%cols)*w)+'px,'+(-Math.floor(i/cols)*h)+'px)';});}\
p.querySelector('.step').addEventListener('click',function(){show(+p.dataset.frame+1);});\
scrub.addEventListener('input',function(){show(+scrub.value);});\
p.querySelector('.play').addEventListener('click',function(e){if(timer){clearInterval(timer);timer=null;e.target.textContent='play';}\
else{timer=setInterval(function(){show(+p.dataset.frame+1);},400);e.target.textContent='pause';}});\
show(0);players.push({p:p,films:films,show:show,n:n,cols:cols});});\
window.addEventListener('load',function(){var bad=[];players.forEach(function(q,k){\
q.films.forEach(function(f){if(f.naturalWidth!=+q.p.dataset.stripWidth||f.naturalHeight!=+q.p.dataset.stripHeight)bad.push('player '+k+': '+f.getAttribute('src')+' is '+f.naturalWidth+'x'+f.naturalHeight);});\
var before=q.films.map(function(f){return f.style.transform;});q.p.querySelector('.step').click();\
var after=q.films.map(function(f){return f.style.transform;});\
if(+q.p.dataset.frame!==1||before.some(function(t,j){return t===after[j];}))bad.push('player '+k+': the next frame shows the same tile');q.show(0);});\
document.documentElement.setAttribute('data-players',bad.length?('fail '+JSON.stringify(bad)):('ok '+players.length));});\
window.addEventListener('load',function(){document.querySelectorAll('table.sortable').forEach(function(t){\
Array.prototype.forEach.call(t.rows,function(row){var left=0;for(var c=0;c<row.cells.length&&row.cells[c].classList.contains('id');c++){\
row.cells[c].style.left=left+'px';left+=row.cells[c].offsetWidth;}});});\
var g=document.querySelector('table.glance');if(!g)return;var cols=[];\
Array.prototype.forEach.call(g.tHead.rows[0].cells,function(th,i){var n=th.textContent.trim();if(n==='frame ms'||n.indexOf('relMSE')===0)cols.push(i);});\
var off=[],n=0;Array.prototype.forEach.call(g.tBodies[0].rows,function(r){var ok=cols.length===3&&cols.every(function(i){\
var b=r.cells[i].getBoundingClientRect();return b.width>0&&b.bottom<=window.innerHeight&&b.right<=window.innerWidth;});\
if(ok)n++;else off.push(r.cells[0].textContent);});\
document.documentElement.setAttribute('data-first-screen',off.length?('fail '+JSON.stringify(off)):('ok '+n));});";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_urls_walk_up_and_encode() {
        assert_eq!(
            relative_url(Path::new("/a/b"), Path::new("/a/b/c.png")),
            "c.png"
        );
        assert_eq!(
            relative_url(Path::new("/a/b"), Path::new("/a/x y/c#1.png")),
            "../x%20y/c%231.png"
        );
        assert_eq!(
            relative_url(Path::new("/a/b/"), Path::new("/a/b/d/e.svg")),
            "d/e.svg"
        );
    }

    #[test]
    fn escapes_markup() {
        assert_eq!(
            esc("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
    }
}
