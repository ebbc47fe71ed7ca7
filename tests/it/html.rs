//! The HTML report, checked in a real browser: headless Chromium opens the page from disk and
//! the page's own check (every image decoded, no script error, no `console.error`) must say
//! "ok" for as many images as the page has; a page with a broken image reference or a console
//! error must say "fail". Needs Chromium (Debian's `chromium`; `.ci/run` installs it): without
//! it these tests fail and say so, unless `GIBENCH_NO_BROWSER=1` asks to skip them knowingly.
//! A screenshot of the run page is kept in the target folder (`html-report/screenshot.png`).

use crate::support;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `gibench ARGS`, which must succeed.
fn gibench<S: AsRef<std::ffi::OsStr> + std::fmt::Debug>(args: &[S]) -> std::process::Output {
    support::GIBENCH.run_ok(args)
}

/// The Chromium binary (`GIBENCH_CHROMIUM`, else `chromium` or `chromium-browser` on PATH);
/// `None` only when the user skips browser checks with `GIBENCH_NO_BROWSER=1`.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("GIBENCH_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let found = std::env::var_os("PATH").and_then(|path| {
        std::env::split_paths(&path)
            .flat_map(|d| ["chromium", "chromium-browser"].map(|n| d.join(n)))
            .find(|p| p.is_file())
    });
    if found.is_none() && std::env::var_os("GIBENCH_NO_BROWSER").is_some_and(|v| v == "1") {
        eprintln!("SKIPPED: Chromium is missing and GIBENCH_NO_BROWSER=1: the HTML page was not checked in a browser");
        return None;
    }
    Some(found.expect(
        "Chromium is missing: the HTML report is checked in headless Chromium. Install it \
         (Debian: apt-get install chromium) or set GIBENCH_CHROMIUM to its path; \
         GIBENCH_NO_BROWSER=1 skips these checks knowingly",
    ))
}

const FLAGS: &[&str] = &[
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--virtual-time-budget=10000",
];

fn url(page: &Path) -> String {
    format!("file://{}", page.canonicalize().unwrap().display())
}

/// The page's self-check verdict after loading it in Chromium.
fn verdict(browser: &Path, page: &Path) -> String {
    attribute(browser, page, "data-selfcheck")
}

/// The value of attribute `name` (written by the page's scripts) in the DOM Chromium dumps.
fn attribute(browser: &Path, page: &Path, name: &str) -> String {
    attribute_in(browser, page, name, None)
}

/// [`attribute`] with the page opened in a window of `size` ("W,H"; else Chromium's default).
fn attribute_in(browser: &Path, page: &Path, name: &str, size: Option<&str>) -> String {
    let profile = tempfile::tempdir().unwrap();
    let o = Command::new(browser)
        .args(FLAGS)
        .args(size.map(|s| format!("--window-size={s}")))
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg("--dump-dom")
        .arg(url(page))
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&o.stdout);
    let key = format!("{name}=\"");
    let start = dom.find(&key).unwrap_or_else(|| {
        panic!(
            "no {name} in the DOM Chromium dumped:\n{dom}\n{}",
            String::from_utf8_lossy(&o.stderr)
        )
    }) + key.len();
    let end = dom[start..].find('"').unwrap() + start;
    dom[start..end].replace("&quot;", "\"")
}

/// Asserts the page loads clean: "ok N" with N the number of images in its source.
fn assert_clean(browser: &Path, page: &Path) {
    let images = std::fs::read_to_string(page)
        .unwrap()
        .matches("<img ")
        .count();
    assert!(images > 0);
    let v = verdict(browser, page);
    assert_eq!(v, format!("ok {images}"), "{}", page.display());
}

fn screenshot(browser: &Path, page: &Path, png: &Path) {
    screenshot_in(browser, page, png, "1400,2600");
}

/// [`screenshot`] of a window of `size` ("W,H").
fn screenshot_in(browser: &Path, page: &Path, png: &Path, size: &str) {
    let profile = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(png.parent().unwrap()).unwrap();
    let o = Command::new(browser)
        .args(FLAGS)
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("--window-size={size}"))
        .arg(format!("--screenshot={}", png.display()))
        .arg(url(page))
        .output()
        .unwrap();
    assert!(
        png.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A run with --quality --html: the page shows every technique's image beside the reference's,
/// their FLIP maps and the time-versus-error plot, and loads clean; the same page with one
/// image removed, or with a console error, fails the check.
#[test]
fn run_page_loads_clean_and_fails_on_a_broken_image_or_console_error() {
    let Some(browser) = chromium() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let cache = tmp.path().join("cache");
    let o = gibench(&[
        "run",
        "--technique",
        "direct,keller-full,laine",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--timing",
        "stages",
        "--resolution",
        "64x48",
        "--quality",
        "--quality-pairs",
        "1",
        "--spp",
        "8",
        "--html",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--cache",
        cache.to_str().unwrap(),
    ]);
    let page = out.join("cornell-report.html");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains(&format!(
            "report: {}",
            std::env::current_dir().unwrap().join(&page).display()
        )),
        "{stderr}"
    );
    let html = std::fs::read_to_string(&page).unwrap();
    for t in ["direct", "keller-full", "laine"] {
        for suffix in ["-compared.png", "-flip.png", "-indirect.png"] {
            assert!(
                html.contains(&format!("src=\"cornell-{t}{suffix}\"")),
                "{t}{suffix}"
            );
        }
    }
    assert!(html.contains("reference (multi-bounce)") || html.contains("reference (one-bounce)"));
    assert!(html.contains("src=\"cornell-time-vs-error.svg\""));
    // The command as typed, not this machine's path to the executable; a driver only if named.
    assert!(html.contains("<code>gibench run --technique direct,keller-full,laine"));
    assert!(!html.contains(env!("CARGO_BIN_EXE_gibench")));
    assert!(!html.contains("driver )") && !html.contains("driver ;"));
    assert_clean(&browser, &page);
    // The frame player: each technique's film strip of the compared frames (two here) beside
    // the reference's; advancing shows the next tile of every strip, and the strip's tiles are
    // really different frames (the light moves between them).
    for t in ["keller-full", "laine"] {
        assert!(
            html.contains(&format!("class=\"film\" src=\"cornell-{t}-frames.png\"")),
            "{t}"
        );
        let strip = image::open(out.join(format!("cornell-{t}-frames.png")))
            .unwrap()
            .to_rgba8();
        assert_eq!(
            strip.dimensions(),
            (2 * 64, 48),
            "{t}: two 64x48 frames side by side"
        );
        let tile = |i: u32| image::imageops::crop_imm(&strip, 64 * i, 0, 64, 48).to_image();
        assert_ne!(
            tile(0),
            tile(1),
            "{t}: the strip's two frames are the same image"
        );
    }
    assert!(html.contains("-reference-frames.png\""));
    // The reference's images are written once per run set (issue 51), not once per technique:
    // the three techniques compare with one component (one-bounce), so one file of each kind,
    // which every run lists.
    for suffix in [
        "-reference.png",
        "-reference-indirect.png",
        "-reference-frames.png",
    ] {
        let shared: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(suffix))
            .collect();
        assert_eq!(shared.len(), 1, "{suffix}: {shared:?}");
        for t in ["direct", "keller-full", "laine"] {
            let json = std::fs::read_to_string(out.join(format!("cornell-{t}.json"))).unwrap();
            assert!(
                json.contains(&format!("\"{}\"", shared[0])),
                "{t}: {suffix}"
            );
        }
    }
    assert_eq!(attribute(&browser, &page, "data-players"), "ok 1");
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("html-report/screenshot.png");
    screenshot(&browser, &page, &shot);

    // One image gone: the check fails and names it.
    let broken = tmp.path().join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    for e in std::fs::read_dir(&out).unwrap().flatten() {
        if e.path().is_file() {
            std::fs::copy(e.path(), broken.join(e.file_name())).unwrap();
        }
    }
    std::fs::remove_file(broken.join("cornell-laine-flip.png")).unwrap();
    let v = verdict(&browser, &broken.join("cornell-report.html"));
    assert!(
        v.starts_with("fail") && v.contains("cornell-laine-flip.png"),
        "{v}"
    );
    // ... and says so at the top of the page, where a reader of a checkout (which keeps only
    // some of the images: results/.gitignore) sees it.
    assert_eq!(
        attribute(
            &browser,
            &broken.join("cornell-report.html"),
            "class=\"selfcheck-fail\" role"
        ),
        "alert"
    );

    // A player whose step does not advance: its check fails.
    let stuck = broken.join("stuck.html");
    let text = html.replace("show(+p.dataset.frame+1)", "show(+p.dataset.frame)");
    assert_ne!(
        text, html,
        "the player's step is where this test expects it"
    );
    std::fs::write(&stuck, text).unwrap();
    let v = attribute(&browser, &stuck, "data-players");
    assert!(v.starts_with("fail") && v.contains("same tile"), "{v}");

    // A console error: the check fails and quotes it.
    let noisy = broken.join("noisy.html");
    std::fs::copy(&page, &noisy).unwrap();
    let text = std::fs::read_to_string(&page).unwrap().replace(
        "</body>",
        "<script>console.error('boom from the test')</script></body>",
    );
    std::fs::write(&noisy, text).unwrap();
    let v = verdict(&browser, &noisy);
    assert!(
        v.starts_with("fail") && v.contains("boom from the test"),
        "{v}"
    );
}

/// `reproduce laine-table1 --quick --html`: the page has the paper's rows beside ours, marked
/// as the paper's, and loads clean.
#[test]
fn reproduce_page_has_the_papers_rows() {
    let Some(browser) = chromium() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("laine");
    gibench(&[
        "reproduce",
        "laine-table1",
        "--quick",
        "--scenes",
        "cornell",
        "--frames",
        "2",
        "--html",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let page = out.join("laine-table1.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("<tr class=\"paper\"><td>Laine et al. 2007, Table 1 (GeForce 8800 GTX)</td>")
    );
    assert!(html.contains("<tr><td>gibench</td>"));
    // No images in a table-only page: the check still runs (and must find no errors).
    let v = verdict(&browser, &page);
    assert_eq!(v, "ok 0");
}

/// `reproduce all --html`'s index page (`reproduce-all.html`) shows the figures of the targets
/// it ran and loads clean — from the repository root too, where the committed
/// `results/reproduce-all.json` gives estimates but its targets' files are not in the output
/// folder (so none of them may be listed there).
#[test]
fn reproduce_all_index_page_loads_clean() {
    let Some(browser) = chromium() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("all");
    gibench(&[
        "reproduce",
        "all",
        "--quick",
        "--only",
        "laine-dispersion",
        "--html",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let page = out.join("reproduce-all.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("src=\"laine/laine-dispersion.svg\""));
    assert!(html.contains("href=\"laine/laine-dispersion.html\""));
    assert!(
        !html.contains("keller/"),
        "a target that did not run is listed"
    );
    assert_clean(&browser, &page);
}

/// The default run's page (every technique with `--quality --html`, as the README's first
/// command, at a small size) answers on its first screen: opened in a 1400x900 window, every
/// technique's frame time and error in the glance lie within it (the page's own measure,
/// `data-first-screen`); a screenshot of that screen is kept in the target folder
/// (`html-report/first-screen.png`). The glance comes before the stage table, the
/// time-versus-error plot beside it. Catches the page that opened on the 42-column stage table
/// with the errors off-screen to the right and the plot 4,900 pixels down (issue 56), and a
/// glance missing a technique.
#[test]
fn default_page_shows_every_techniques_time_and_error_on_its_first_screen() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let cache = tmp.path().join("cache");
    #[rustfmt::skip]
    gibench(&[
        "run", "--quality", "--html", "--resolution", "64x48", "--frames", "2", "--warmup", "3",
        "--quality-pairs", "1", "--spp", "8", "--quiet",
        "--out", out.to_str().unwrap(), "--cache", cache.to_str().unwrap(),
    ]);
    let runs = std::fs::read_dir(&out)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            let name = name.to_string_lossy();
            name.starts_with("cornell-") && name.ends_with(".json") && !name.contains("skipped")
        })
        .count();
    assert!(runs >= 7, "{runs} techniques ran");
    errors_against_both_components_in_every_format(&out, runs);
    let Some(browser) = chromium() else { return };
    let page = out.join("cornell-report.html");
    let html = std::fs::read_to_string(&page).unwrap();
    let glance = html
        .find("<table class=\"sortable glance\">")
        .expect("a glance table");
    let stages = html.find("Per-stage GPU/CPU time").unwrap();
    let plot = html.find("src=\"cornell-time-vs-error.svg\"").unwrap();
    assert!(
        glance < plot && plot < stages,
        "glance, plot, then the stage table"
    );
    let v = attribute_in(&browser, &page, "data-first-screen", Some("1400,900"));
    assert_eq!(v, format!("ok {runs}"));
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("html-report/first-screen.png");
    screenshot_in(&browser, &page, &shot, "1400,900");
    assert_clean(&browser, &page);
}

/// In the default run's Markdown, LaTeX and CSV summaries, every run's row has its relMSE
/// against both components, the own one marked with `*` (CSV: bare numbers, the reference
/// column naming the own); the time-versus-error plot names the component it plots (issue 56).
/// Catches a run scored against its own component only ("–" in the other column) and an own
/// error unmarked or marked in the wrong column.
fn errors_against_both_components_in_every_format(out: &Path, runs: usize) {
    let csv = std::fs::read_to_string(out.join("cornell-summary.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).expect(name);
    let (reference, one, multi) = (
        col("reference"),
        col("relMSE one-bounce"),
        col("relMSE multi-bounce"),
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), runs);
    for r in &rows {
        for c in [one, multi] {
            assert!(
                r[c].parse::<f64>().is_ok(),
                "{} in {}: {r:?}",
                r[c],
                header[c]
            );
        }
    }
    // Each row's own, as the Markdown and LaTeX show it: "0.1234*" in its component's column.
    let own: Vec<String> = (rows.iter())
        .map(|r| {
            let c = match r[reference] {
                "one-bounce" => one,
                "multi-bounce" => multi,
                other => panic!("reference {other}"),
            };
            format!("{}*", r[c])
        })
        .collect();
    for file in ["cornell-summary.md", "cornell-summary.tex"] {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        assert!(text.contains("relMSE multi-bounce"), "{file}");
        for (r, own) in rows.iter().zip(&own) {
            let line = (text.lines())
                .find(|l| l.contains(&format!(" {} ", r[1].replace('_', "\\_"))))
                .unwrap_or_else(|| panic!("{file}: no row of {}", r[1]));
            assert!(line.contains(own.as_str()), "{file}: {own} not in {line}");
            let other = if own == &format!("{}*", r[one]) {
                r[multi]
            } else {
                r[one]
            };
            assert!(line.contains(other), "{file}: {other} not in {line}");
        }
    }
    let svg = std::fs::read_to_string(out.join("cornell-time-vs-error.svg")).unwrap();
    assert!(svg.contains("relative MSE against the multi-bounce reference"));
}
