//! Tests of the tables, their renderings, the plots and the Pareto front.

use std::collections::BTreeMap;

use super::latex::latex_escape;
use super::*;
use crate::measure::results::{
    DeviceInfo, FrameRange, FrameResult, RunResult, StageKind, StageResult, SCHEMA_VERSION,
};
use crate::measure::stats::Stats;
use crate::Error;

/// The front keeps exactly the points nothing beats in both time and error.
#[test]
fn pareto_front_keeps_the_unbeaten_points() {
    let p = |t: f64, e: f64| (String::new(), t, e);
    let points = vec![
        p(10.0, 0.5),
        p(5.0, 0.9),
        p(20.0, 0.1),
        p(12.0, 0.6),
        p(5.0, 1.0),
    ];
    // (12, 0.6) is beaten by (10, 0.5); (5, 1.0) by (5, 0.9).
    assert_eq!(pareto_front(&points), vec![1, 0, 2]);
}

/// Stats of 100 frames with the given median.
fn stats(median: f64) -> Stats {
    Stats {
        count: 100,
        mean: median * 1.01,
        median,
        p5: median * 0.9,
        p95: median * 1.2,
        p99: median * 1.4,
        min: median * 0.8,
        max: median * 1.5,
    }
}

fn stage(name: &str, kind: StageKind, gpu: Option<f64>, wall: Option<f64>) -> StageResult {
    StageResult {
        name: name.into(),
        kind,
        gpu_ms: gpu.map(stats),
        wall_ms: wall.map(stats),
        cpu_ms: None,
    }
}

fn run(scene: &str, technique: &str, stages: Vec<StageResult>, frame_median: f64) -> RunResult {
    RunResult {
        schema_version: SCHEMA_VERSION,
        gibench_version: "0.1.0".into(),
        git_commit: "abc1234".into(),
        timestamp: 1_700_000_000,
        scene: scene.into(),
        technique: technique.into(),
        parameters: BTreeMap::from([("vpls".to_string(), serde_json::json!(256))]),
        settings: BTreeMap::from([("shadow_map_size".to_string(), serde_json::json!(1024))]),
        resolution: [1280, 720],
        frames: FrameRange {
            warmup: 10,
            measured: 100,
            first: 10,
        },
        seed: 7,
        timing_mode: "both".into(),
        device: DeviceInfo {
            adapter: "Test GPU".into(),
            backend: "Vulkan".into(),
            device_type: "DiscreteGpu".into(),
            driver: "testdrv".into(),
            driver_info: "1.2.3".into(),
            timestamp_queries: true,
            timestamp_period_ns: 1.0,
            driver_env: Default::default(),
        },
        stages,
        frame: Some(FrameResult {
            frame_ms: stats(frame_median),
            fps: 1000.0 / (frame_median * 1.01),
            frames_in_flight: 2,
            samples_ms: vec![frame_median],
            gpu_span_ms: None,
            gpu_spans: Vec::new(),
        }),
        counters: BTreeMap::from([("shadow maps".to_string(), stats(1.0))]),
        prepare_ms: None,
        first_frame_ms: None,
        quality: None,
        images: vec!["frame.png".into()],
        warnings: Vec::new(),
        calibration_ms: None,
        peak_memory_mb: None,
        device_bounds: None,
        stage_costs: BTreeMap::new(),
    }
}

/// Run A: three GPU stages (GPU timestamps a little above the wall times), the last one
/// without GPU timestamps (wall time 0.75 ms).
/// Run B: a name with a comma and quotes, a scene with `_` and `%`, an extra CPU stage.
fn two_runs() -> Vec<RunResult> {
    let a = run(
        "sponza",
        "direct",
        vec![
            stage("g-buffer", StageKind::Gpu, Some(0.6), Some(0.5)),
            stage("shadow map", StageKind::Gpu, Some(1.5), Some(1.234)),
            stage("compose", StageKind::Gpu, None, Some(0.75)),
        ],
        3.0,
    );
    let b = run(
        "cornell_box 100%",
        "ism, \"imperfect\"",
        vec![
            stage("g-buffer", StageKind::Gpu, Some(0.3), Some(0.25)),
            stage("vpl trace", StageKind::Cpu, None, Some(2.0)),
            stage("compose", StageKind::Gpu, Some(0.1), Some(0.05)),
        ],
        4.5,
    );
    vec![a, b]
}

/// Runs from two devices pooled into one table get a device column naming each row's;
/// runs from one device do not.
#[test]
fn pooled_devices_get_a_device_column() {
    let mut runs = two_runs();
    assert!(!stage_table(&runs).columns.contains(&"device".to_string()));
    runs[1].device.adapter = "NVIDIA H200".into();
    let t = stage_table(&runs);
    assert_eq!(t.columns[0], "device");
    let cell = |r: usize| match &t.rows[r][0] {
        Cell::Text(s) => s.clone(),
        other => panic!("{other:?}"),
    };
    assert!(cell(1).starts_with("NVIDIA H200") && !cell(0).starts_with("NVIDIA"));
}

/// A software rasteriser's thread setting tells runs apart like another device: the second
/// run made with `LP_NUM_THREADS=0` gets the device column and the notes name the setting.
/// Catches a table that pools the two settings' timings as one device's.
#[test]
fn a_thread_setting_is_named_as_another_device() {
    let mut runs = two_runs();
    runs[1].device.driver_env = [("LP_NUM_THREADS".to_string(), "0".to_string())].into();
    let t = stage_table(&runs);
    assert_eq!(t.columns[0], "device");
    assert!(
        t.notes.iter().any(|n| n.contains("LP_NUM_THREADS=0")),
        "{:?}",
        t.notes
    );
}

#[test]
fn stage_union_keeps_execution_order() {
    let t = stage_table(&two_runs());
    let expected = [
        "scene",
        "technique",
        "resolution",
        "g-buffer",
        "shadow map",
        "vpl trace",
        "compose",
        "Σ stages",
        "frame (median ms)",
        "frame p95",
        "frame p99",
        "GPU frame span",
        "FPS",
    ];
    assert_eq!(t.columns, expected);
    assert_eq!(t.rows.len(), 2);
}

#[test]
fn markdown_has_header_separator_and_one_row_per_result() {
    let md = stage_table(&two_runs()).to_markdown();
    let lines: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
    assert_eq!(lines.len(), 4, "header, separator, two rows:\n{md}");
    assert!(
        lines[0].contains("| g-buffer | shadow map | vpl trace | compose | Σ stages |"),
        "{md}"
    );
    assert_eq!(
        lines[1],
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    // Run A: medians 0.50, 1.23 (1.234), no vpl trace, 0.75 (wall); sum 2.484; frame 3.00.
    assert_eq!(
        lines[2],
        "| sponza | direct | 1280x720 | 0.50 | 1.23 | – | 0.75 | 2.48 | 3.00 | 3.60 | 4.20 | – | 330.0 |"
    );
    // Run B: 0.05 ms shows three decimals.
    assert!(
        lines[3].contains("| 0.25 | – | 2.00 | 0.050 | 2.30 | 4.50 |"),
        "{}",
        lines[3]
    );
    assert!(md.starts_with("### "));
    assert!(md.contains("\nTimes in milliseconds, median over 100 measured frames (10 warm-up frames dropped); GPU stages: CPU wall time with the queue flushed before and after"), "{md}");
    assert!(
        md.contains("Device: Test GPU (Vulkan, DiscreteGpu; driver testdrv 1.2.3)."),
        "{md}"
    );
}

#[test]
fn tables_use_flushed_wall_time() {
    let runs = two_runs();
    let t = stage_table(&runs);
    let compose = t.columns.iter().position(|c| c == "compose").unwrap();
    assert_eq!(t.rows[0][compose], Cell::Ms(Some(0.75)));
    // The flushed wall time wins over a GPU timestamp (Laine's per-task method).
    let gbuffer = t.columns.iter().position(|c| c == "g-buffer").unwrap();
    assert_eq!(t.rows[1][gbuffer], Cell::Ms(Some(0.25)));
    // No stage lacks a wall time here: no fallback note.
    assert!(!t.notes.iter().any(|n| n.contains("GPU timestamps only")));
}

#[test]
fn differing_devices_are_each_listed() {
    let mut runs = two_runs();
    runs[1].device.adapter = "Other GPU".into();
    runs[1].frames.measured = 50;
    let notes = stage_table(&runs).notes.join("\n");
    assert!(notes.contains("Devices: Test GPU (Vulkan, DiscreteGpu; driver testdrv 1.2.3) for direct @ sponza; Other GPU"), "{notes}");
    assert!(
        notes.contains(
            "100 measured frames (10 warm-up frames dropped) for direct @ sponza; 50 measured"
        ),
        "{notes}"
    );
}

/// A huge value (a results file may say 1e308 ms) is written with an exponent, not as a
/// cell of 300 digits; ordinary values keep their decimals.
#[test]
fn huge_values_are_written_with_an_exponent() {
    for cell in [Cell::Ms(Some(1e308)), Cell::Num(Some(-1e308), 1)] {
        assert!(cell.display().len() <= 12, "{}", cell.display());
        assert!(cell.csv().len() <= 12, "{}", cell.csv());
        assert!(cell.display().contains("e308"), "{}", cell.display());
    }
    assert_eq!(Cell::Ms(Some(12.345)).display(), "12.35");
    assert_eq!(Cell::Num(Some(123456.0), 1).display(), "123456.0");
}

/// A table wider than the terminal is folded into blocks no wider than it, each repeating
/// scene, technique and resolution and listing only the rows with values in its columns;
/// every value is still shown once; notes are wrapped. (Before, the default run printed
/// one line of over 300 characters per technique.)
#[test]
fn wide_tables_fold_to_the_terminal_width() {
    let mut t = Table {
        title: "wide".into(),
        columns: ["scene", "technique", "resolution"]
            .map(String::from)
            .into(),
        rows: Vec::new(),
        notes: vec![format!("{} end", "word ".repeat(60))],
    };
    t.columns
        .extend((0..30).map(|k| format!("stage-number-{k}")));
    for (name, range) in [("alpha", 0..16), ("beta", 16..30)] {
        let mut row = vec![Cell::text("sibenik"), Cell::text(name), Cell::text("64x48")];
        row.extend(
            (0..30).map(|k| Cell::Ms(range.contains(&k).then_some(1000.0 + k as f64 + 0.25))),
        );
        t.rows.push(row);
    }
    let out = t.to_terminal();
    assert!(
        out.lines().all(|l| l.chars().count() <= TERMINAL_WIDTH),
        "{out}"
    );
    for k in 0..30 {
        let v = format!("{:.2}", 1000.0 + k as f64 + 0.25);
        assert_eq!(out.matches(&v).count(), 1, "{v} in\n{out}");
    }
    // Every row a block lists has a value in that block (alpha's and beta's own stages
    // are apart).
    for block in out.split("\n\n").filter(|b| b.contains("stage-number")) {
        let rows = block.lines().skip_while(|l| !l.starts_with("---")).skip(1);
        for l in rows {
            assert!(l.contains("10"), "a row without values: {l}");
        }
    }
    assert!(out.contains("word end"));
    // A narrow table is unchanged: one block, every row.
    let narrow = two_runs();
    let out = stage_table(&narrow[..1]).to_terminal();
    assert!(out.lines().all(|l| l.chars().count() <= TERMINAL_WIDTH));
}

#[test]
fn csv_quotes_commas_and_quotes() {
    let csv = stage_table(&two_runs()).to_csv();
    let records: Vec<&str> = csv.split("\r\n").collect();
    assert_eq!(
        records.len(),
        4,
        "header, two rows, trailing empty: {csv:?}"
    );
    assert_eq!(records[3], "");
    assert!(records[0].starts_with("scene,technique,resolution,g-buffer,shadow map,"));
    assert_eq!(
        records[1],
        "sponza,direct,1280x720,0.5000,1.2340,,0.7500,2.4840,3.0000,3.6000,4.2000,,330.0"
    );
    assert!(
        records[2].starts_with("cornell_box 100%,\"ism, \"\"imperfect\"\"\",1280x720,"),
        "{}",
        records[2]
    );
    assert!(!csv.contains("Times in milliseconds"), "no notes in CSV");
}

#[test]
fn latex_escapes_specials() {
    let tex = stage_table(&two_runs()).to_latex();
    assert!(tex.contains("\\begin{tabular}{lllrrrrrrrrrr}"), "{tex}");
    assert!(tex.contains("\\toprule") && tex.contains("\\midrule") && tex.contains("\\bottomrule"));
    assert!(
        tex.contains("cornell\\_box 100\\% & ism, \"imperfect\" & 1280x720"),
        "{tex}"
    );
    assert!(tex.contains("$\\Sigma$ stages"), "{tex}");
    assert!(tex.contains("{\\footnotesize\n"), "{tex}");
    assert_eq!(
        latex_escape("a&b%c$d#e_f{g}h~i^j\\k"),
        "a\\&b\\%c\\$d\\#e\\_f\\{g\\}h\\textasciitilde{}i\\textasciicircum{}j\\textbackslash{}k"
    );
    // Missing values are en dashes.
    assert!(tex.contains("& -- &"), "{tex}");
}

#[test]
fn terminal_columns_align() {
    let out = stage_table(&two_runs()).to_terminal();
    let lines: Vec<&str> = out.lines().collect();
    assert!(lines[0].starts_with("Per-stage"));
    let header = lines[1];
    let dashes = lines[2];
    assert!(dashes.starts_with("------"));
    // Right-aligned numeric columns: every data row ends where the header ends.
    let width = |s: &str| s.chars().count();
    assert_eq!(width(lines[3]), width(header), "{out}");
    assert_eq!(width(lines[4]), width(header), "{out}");
    assert_eq!(width(dashes), width(header), "{out}");
    assert!(out.contains("\nDevice: Test GPU"));
}

#[test]
fn detailed_table_has_one_row_per_stage_and_frame() {
    let runs = two_runs();
    let t = stage_table_detailed(&runs[0]);
    assert_eq!(t.columns.len(), 14);
    assert_eq!(t.columns[2], "GPU median");
    assert_eq!(t.columns[13], "wall max");
    assert_eq!(t.rows.len(), 4);
    assert_eq!(t.rows[1][0], Cell::text("shadow map"));
    assert_eq!(t.rows[1][2].display(), "1.50");
    assert_eq!(t.rows[1][8].display(), "1.23");
    assert_eq!(t.rows[2][2], Cell::Ms(None));
    assert_eq!(t.rows[3][0], Cell::text("frame"));
    assert_eq!(t.rows[3][8].display(), "3.00");
    assert!(t.title.starts_with("direct @ sponza (1280x720)"));
    assert!(t.to_markdown().contains("| compose | GPU | – | – |"));
}

#[test]
fn write_tables_writes_three_files() {
    let dir = tempfile::tempdir().unwrap();
    let table = stage_table(&two_runs());
    let paths = write_tables(&table, &dir.path().join("tables"), "stages").unwrap();
    let names: Vec<String> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["stages.md", "stages.csv", "stages.tex"]);
    assert_eq!(
        std::fs::read_to_string(&paths[0]).unwrap(),
        table.to_markdown()
    );
    assert_eq!(std::fs::read_to_string(&paths[1]).unwrap(), table.to_csv());
    assert_eq!(
        std::fs::read_to_string(&paths[2]).unwrap(),
        table.to_latex()
    );
    assert!(write_tables(&table, dir.path(), "").is_err());
}

/// The text content of every `<text>` element.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .map(|t| {
            t[t.find('>').unwrap() + 1..t.find("</text>").unwrap()]
                .trim()
                .to_string()
        })
        .collect()
}

#[test]
fn stacked_bar_svg_has_bars_labels_and_legend() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bars.svg");
    stacked_bar_svg(&two_runs(), &path, "Stage times").unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    // The same figure as a PDF beside it, its text set in an embedded font (a PDF without one
    // has lost every label: the fonts come with Chromium, which the HTML tests need too).
    let pdf = std::fs::read(pdf_path(&path)).unwrap();
    assert!(pdf.starts_with(b"%PDF-"), "not a PDF");
    assert!(
        pdf.windows(10).any(|w| w == b"/FontFile2"),
        "the PDF embeds no font: install DejaVu Sans or Liberation Sans"
    );
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{svg}"
    );
    let texts = svg_texts(&svg);
    for name in [
        "g-buffer",
        "shadow map",
        "vpl trace",
        "compose",
        "Stage times",
        "milliseconds (median)",
        "direct @ sponza",
    ] {
        assert!(
            texts.iter().any(|t| t == name),
            "no <text> '{name}' in {texts:?}"
        );
    }
    // The quotes of run B's name are escaped, not raw.
    assert!(
        texts
            .iter()
            .any(|t| t.contains("ism, &quot;imperfect&quot; @ cornell_box 100%")),
        "{texts:?}"
    );
    assert!(texts.iter().any(|t| t == "2.48 ms"), "{texts:?}");
    // Six segments (three stages per run) in the stage colours plus the legend swatches.
    let blue = format!("fill=\"#{:02X}{:02X}{:02X}\"", 78, 121, 167);
    assert_eq!(
        svg.matches(&blue).count(),
        3,
        "two g-buffer segments and a legend swatch"
    );
}

#[test]
fn zero_and_missing_stage_times_do_not_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut runs = two_runs();
    runs[0].stages[0].gpu_ms = Some(stats(0.0));
    runs[0].stages[1].gpu_ms = None;
    runs[0].stages[1].wall_ms = None;
    let mut zero = runs[0].clone();
    for s in &mut zero.stages {
        s.gpu_ms = Some(stats(0.0));
    }
    zero.frame = None;
    let mut none = runs[1].clone();
    none.stages.clear();
    runs.extend([zero, none]);
    stacked_bar_svg(&runs, &dir.path().join("bars.svg"), "zeros").unwrap();
    stacked_bar_svg(&runs[2..], &dir.path().join("bars0.svg"), "all zero").unwrap();
    let points: Vec<(String, RunResult)> = runs
        .iter()
        .enumerate()
        .map(|(i, r)| (i.to_string(), r.clone()))
        .collect();
    sweep_plot_svg(&points, &dir.path().join("sweep.svg"), "zeros", "n").unwrap();
    sweep_plot_svg(
        &points[2..],
        &dir.path().join("sweep0.svg"),
        "all zero",
        "n",
    )
    .unwrap();
    let t = stage_table(&runs);
    assert_eq!(
        t.rows[3].iter().filter(|c| **c == Cell::Ms(None)).count(),
        6,
        "{:?}",
        t.rows[3]
    );
    let _ = (t.to_markdown(), t.to_csv(), t.to_latex(), t.to_terminal());
}

#[test]
fn sweep_plot_svg_has_stage_lines_and_total() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sweep.svg");
    let runs = two_runs();
    let points: Vec<(String, RunResult)> = ["64", "256", "1024"]
        .iter()
        .zip([runs[0].clone(), runs[1].clone(), runs[0].clone()])
        .map(|(x, r)| (x.to_string(), r))
        .collect();
    sweep_plot_svg(&points, &path, "VPL count sweep", "VPLs").unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"));
    let texts = svg_texts(&svg);
    for name in [
        "g-buffer",
        "shadow map",
        "vpl trace",
        "compose",
        "total (Σ stages)",
        "VPLs",
        "64",
        "256",
        "1024",
    ] {
        assert!(
            texts.iter().any(|t| t == name),
            "no <text> '{name}' in {texts:?}"
        );
    }
    assert!(svg.contains("<polyline"), "lines are drawn");
}

#[test]
fn empty_input_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.svg");
    assert!(matches!(
        stacked_bar_svg(&[], &path, "empty"),
        Err(Error::Invalid(_))
    ));
    assert!(matches!(
        sweep_plot_svg(&[], &path, "empty", "x"),
        Err(Error::Invalid(_))
    ));
    assert!(!path.exists());
    let t = stage_table(&[]);
    assert!(t.rows.is_empty());
    assert_eq!(
        t.to_markdown()
            .lines()
            .filter(|l| l.starts_with('|'))
            .count(),
        2
    );
    let _ = (t.to_csv(), t.to_latex(), t.to_terminal());
}

/// A run with quality data: `rel_mse` against `component`, frame median `frame_ms`.
fn scored(technique: &str, frame_ms: f64, rel_mse: f64, component: &str) -> RunResult {
    let mut r = run("cornell", technique, vec![], frame_ms);
    let frame = crate::measure::metrics::FrameQuality {
        frame: 1,
        rmse: rel_mse.sqrt(),
        rel_mse,
        mae: 0.1,
        flip_mean: 0.05,
        bias: 0.0,
        temporal: None,
    };
    r.quality = Some(crate::measure::metrics::summarize(
        format!("{component}, 256 spp, seed 0"),
        vec![frame],
    ));
    r
}

/// Ranks peel the front off: the front is rank 1, the front of the rest rank 2. Catches ranks
/// taken by time or by error alone, and a point beaten by one of rank 2 given rank 2.
#[test]
fn pareto_ranks_peel_fronts() {
    let p = |t: f64, e: f64| (String::new(), t, e);
    let points = vec![
        p(10.0, 0.5),
        p(5.0, 0.9),
        p(20.0, 0.1),
        p(12.0, 0.6),
        p(13.0, 0.7),
    ];
    assert_eq!(pareto_ranks(&points), vec![1, 1, 1, 2, 3]);
}

/// The glance lists the runs fastest first with their component and rank, and the Pareto line
/// joins the front fastest first; runs from files that hold only their own errors, against
/// different components, are said not to be comparable in the glance, the line, the stage
/// table (its reference column) and the plot's legend; one component says nothing of it. Catches a glance in run order, a rank
/// put on the wrong row once sorted, and mixed references left unsaid.
#[test]
fn glance_and_pareto_line_name_the_components() {
    let runs = vec![
        scored("laine", 8.0, 0.2, "one-bounce"),
        scored("direct", 2.0, 1.0, "one-bounce"),
        scored("ism", 9.0, 0.5, "one-bounce"),
    ];
    let g = glance_table(&runs).unwrap();
    let col = |name: &str| g.columns.iter().position(|c| c == name).unwrap();
    let cells: Vec<(String, String)> = g
        .rows
        .iter()
        .map(|r| (r[0].display(), r[col("Pareto rank")].display()))
        .collect();
    let want = [("direct", "1"), ("laine", "1"), ("ism", "2")];
    assert_eq!(
        cells,
        want.map(|(a, b)| (a.to_string(), b.to_string())),
        "{cells:?}"
    );
    assert_eq!(g.rows[0][col("reference")].display(), "one-bounce");
    assert!(!g.notes.iter().any(|n| n.contains("not comparable")));
    let line = pareto_line(&runs).unwrap();
    assert!(
        line.contains("direct 2.00 ms 1.0000 → laine 8.00 ms 0.2000.")
            && !line.contains("not comparable"),
        "{line}"
    );
    let stage = stage_table(&runs);
    assert_eq!(stage.notes.last(), Some(&line));
    let mut mixed = runs.clone();
    mixed.push(scored("gaitatzes", 3.0, 0.6, "multi-bounce"));
    let g = glance_table(&mixed).unwrap();
    assert!(
        g.notes
            .iter()
            .any(|n| n.contains("not comparable") && n.contains("multi-bounce: gaitatzes")),
        "{:?}",
        g.notes
    );
    assert!(pareto_line(&mixed).unwrap().contains("not comparable"));
    let stage = stage_table(&mixed);
    let reference = stage.columns.iter().position(|c| c == "reference").unwrap();
    let of: Vec<String> = stage.rows.iter().map(|r| r[reference].display()).collect();
    assert_eq!(
        of,
        ["one-bounce", "one-bounce", "one-bounce", "multi-bounce"]
    );
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("t.svg");
    time_vs_error_svg(&mixed, &svg, "t").unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("gaitatzes vs multi-bounce"), "{text}");
    time_vs_error_svg(&runs, &svg, "t").unwrap();
    assert!(!std::fs::read_to_string(&svg).unwrap().contains(" vs "));
}

/// Ranks and fronts are taken per scene (and resolution and device): a run on another scene,
/// faster and more accurate than every Cornell run, leaves their ranks as they were, gets rank
/// 1 of its own, and the line gives one front per scene. Catches one front over scenes that
/// cannot be compared.
#[test]
fn pareto_ranks_are_per_scene() {
    let mut other = scored("laine", 1.0, 0.01, "one-bounce");
    other.scene = "sibenik".into();
    let runs = vec![
        scored("laine", 8.0, 0.2, "one-bounce"),
        scored("ism", 9.0, 0.5, "one-bounce"),
        other,
    ];
    let g = glance_table(&runs).unwrap();
    let rank = g.columns.iter().position(|c| c == "Pareto rank").unwrap();
    let cells: Vec<(String, String)> = g
        .rows
        .iter()
        .map(|r| (r[0].display(), r[rank].display()))
        .collect();
    let want = [
        ("laine @ sibenik", "1"),
        ("laine @ cornell", "1"),
        ("ism @ cornell", "2"),
    ];
    assert_eq!(cells, want.map(|(a, b)| (a.to_string(), b.to_string())));
    let line = pareto_line(&runs).unwrap();
    assert!(
        line.contains(" on cornell 1280x720 (") && line.contains(" on sibenik 1280x720 ("),
        "{line}"
    );
}

/// A run scored against both components: relMSE `one` and `multi`, its own `own`.
fn scored_both(technique: &str, frame_ms: f64, one: f64, multi: f64, own: &str) -> RunResult {
    let own_error = if own == "one-bounce" { one } else { multi };
    let mut r = scored(technique, frame_ms, own_error, own);
    let q = r.quality.as_mut().unwrap();
    q.components = (crate::measure::metrics::ComponentErrors::NAMES.iter())
        .zip([one, multi])
        .map(|(c, e)| crate::measure::metrics::ComponentErrors {
            component: c.to_string(),
            reference: format!("{c}, 256 spp, seed 0"),
            rel_mse: Stats::of(&[e]),
            bias: Stats::of(&[-0.1]),
            flip_mean: Stats::of(&[0.05]),
        })
        .collect();
    r
}

/// Runs of techniques that compute different components, each scored against both: every
/// table format shows both errors with the run's own marked (CSV bare, its reference column
/// naming the own), and ranks, the Pareto line and the plot are on multi-bounce, which they
/// name. Catches ranks on each run's own error (laine's 0.2 one-bounce would put it on the
/// front), an unmarked or wrongly marked own cell, and a mark that breaks CSV numbers.
#[test]
fn errors_against_both_components_with_the_own_marked() {
    let runs = vec![
        scored_both("laine", 8.0, 0.2, 0.9, "one-bounce"),
        scored_both("gaitatzes", 3.0, 2.0, 0.6, "multi-bounce"),
    ];
    let g = glance_table(&runs).unwrap();
    let col = |t: &Table, name: &str| t.columns.iter().position(|c| c == name).unwrap();
    let row = |t: &Table, technique: &str, name: &str| {
        let r = (t.rows.iter())
            .find(|r| r.iter().any(|c| c.display() == technique))
            .unwrap();
        r[col(t, name)].display()
    };
    for t in [&g, &stage_table(&runs)] {
        assert_eq!(row(t, "laine", "relMSE one-bounce"), "0.2000*");
        assert_eq!(row(t, "laine", "relMSE multi-bounce"), "0.9000");
        assert_eq!(row(t, "gaitatzes", "relMSE one-bounce"), "2.0000");
        assert_eq!(row(t, "gaitatzes", "relMSE multi-bounce"), "0.6000*");
        assert_eq!(row(t, "gaitatzes", "FLIP multi-bounce"), "0.0500*");
        assert!(
            (t.notes.iter()).any(|n| n.contains("taken on the errors against multi-bounce")),
            "{:?}",
            t.notes
        );
    }
    assert_eq!(row(&g, "gaitatzes", "Pareto rank"), "1");
    assert_eq!(row(&g, "laine", "Pareto rank"), "2");
    let stage = stage_table(&runs);
    assert_eq!(row(&stage, "laine", "bias multi-bounce"), "-0.1000");
    for text in [stage.to_markdown(), stage.to_latex(), stage.to_terminal()] {
        assert!(
            text.contains("0.2000*") && text.contains("0.6000*") && text.contains("0.9000 "),
            "{text}"
        );
    }
    let csv = stage.to_csv();
    let header = csv.lines().next().unwrap();
    assert!(
        header.contains(",reference,RMSE,relMSE one-bounce,relMSE multi-bounce,"),
        "{header}"
    );
    assert!(
        !csv.contains('*') && csv.contains(",0.2000,0.9000,"),
        "{csv}"
    );
    let picked = stage
        .select_columns("--columns", &["relmse".to_string()])
        .unwrap();
    assert_eq!(
        picked.columns[picked.columns.len() - 2..],
        ["relMSE one-bounce", "relMSE multi-bounce"]
    );
    let line = pareto_line(&runs).unwrap();
    assert!(
        line.contains("relMSE against multi-bounce")
            && line.contains(": gaitatzes 3.00 ms 0.6000.")
            && !line.contains("not comparable"),
        "{line}"
    );
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("t.svg");
    time_vs_error_svg(&runs, &svg, "t").unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("against the multi-bounce reference") && !text.contains(" vs "),
        "{text}"
    );
}

/// The equal-time table: a header for every cell of a row (the steps column last, not cut),
/// the setting with its range end, the own error marked, the search's thresholds from its
/// record, and a run over the budget in its own measurement said in a note (not the one at its
/// range's end, nor one within). Catches a column missing from the header, which shifted every
/// heading and dropped the steps (it happened).
#[test]
fn equal_time_table_heads_every_cell() {
    let mut laine = scored_both("laine", 140.0, 0.2, 0.9, "one-bounce");
    laine.settings.insert(
        "equal_time".into(),
        serde_json::json!({"budget_ms": 150.0, "knob": "vpls", "value": 300, "frame_ms": 135.0,
            "end": null, "fit": 0.95, "low": 0.89,
            "steps": [{"value": 64, "frame_ms": 40.0}, {"value": 300, "frame_ms": 135.0}]}),
    );
    let mut ism = scored_both("ism", 152.5, 0.2, 0.9, "one-bounce");
    ism.settings.insert(
        "equal_time".into(),
        serde_json::json!({"budget_ms": 150.0, "knob": "vpls", "value": 400, "frame_ms": 141.0,
            "end": null, "steps": [{"value": 400, "frame_ms": 141.0}],
            "runs": [{"value": 420, "frame_ms": 161.5}]}),
    );
    let mut gaitatzes = scored_both("gaitatzes", 240.0, 2.0, 0.6, "multi-bounce");
    gaitatzes.settings.insert(
        "equal_time".into(),
        serde_json::json!({"budget_ms": 150.0, "knob": "iterations", "value": 0, "frame_ms": 240.0,
            "end": "min", "steps": [{"value": 0, "frame_ms": 240.0}]}),
    );
    let t = equal_time_table(&[laine, gaitatzes, ism]).unwrap();
    let notes = t.notes.join("\n");
    assert!(
        notes.contains("within 95 % of it") && notes.contains("reached 89 %"),
        "{notes}"
    );
    assert!(
        notes.contains("cornell ism: the run measured 152.50 ms, over the 150 ms budget (its search: 141.00 ms)")
            && !notes.contains("cornell laine:")
            && !notes.contains("cornell gaitatzes:"),
        "{notes}"
    );
    assert!(
        notes.contains("went on): cornell ism: 420 at 161.50 ms."),
        "{notes}"
    );
    assert!(
        t.rows.iter().all(|r| r.len() == t.columns.len()),
        "{:?}",
        t.columns
    );
    let cell = |row: usize, name: &str| {
        t.rows[row][t.columns.iter().position(|c| c == name).unwrap()].display()
    };
    assert_eq!(cell(0, "reference"), "one-bounce");
    assert_eq!(cell(0, "setting"), "vpls=300");
    assert_eq!(cell(0, "search ms"), "135.00");
    assert_eq!(cell(0, "relMSE one-bounce"), "0.2000*");
    assert_eq!(cell(0, "search (value ms → …)"), "64 40.0 → 300 135.0");
    assert_eq!(
        cell(1, "setting"),
        "iterations=0 (its smallest: over budget)"
    );
    assert_eq!(cell(1, "relMSE multi-bounce"), "0.6000*");
}
