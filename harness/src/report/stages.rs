//! The stage tables: one row per run ([`stage_table`]) or one row per stage of one run
//! ([`stage_table_detailed`]), with the notes that say how the times were taken.

use super::glance::{error_cell, error_columns};
use super::runs::{run_label, stage_ms, stage_names, stage_sum};
use super::table::{Cell, Table};
use crate::measure::metrics::ComponentErrors;
use crate::measure::results::{RunResult, StageKind};
use crate::measure::stats::Stats;

/// The device as one phrase: "adapter (backend, device type; driver ...)".
fn device_text(r: &RunResult) -> String {
    let d = &r.device;
    let driver = [d.driver.trim(), d.driver_info.trim()]
        .iter()
        .filter(|s| !s.is_empty())
        .copied()
        .collect::<Vec<_>>();
    let driver = if driver.is_empty() {
        "unknown".to_string()
    } else {
        driver.join(" ")
    };
    let adapter = if d.adapter.trim().is_empty() {
        "unknown adapter"
    } else {
        d.adapter.trim()
    };
    let mut kind: Vec<&str> = vec![d.backend.trim(), d.device_type.trim()];
    kind.retain(|s| !s.is_empty());
    let env = d.env_text();
    if kind.is_empty() {
        format!("{adapter} (driver {driver}{env})")
    } else {
        format!("{adapter} ({}; driver {driver}{env})", kind.join(", "))
    }
}

/// Groups runs by `key`, in first-seen order; each group lists its runs' labels.
fn group_runs<K: PartialEq>(
    results: &[&RunResult],
    key: impl Fn(&RunResult) -> K,
) -> Vec<(K, Vec<String>)> {
    let mut groups: Vec<(K, Vec<String>)> = Vec::new();
    for r in results {
        let k = key(r);
        match groups.iter_mut().find(|(g, _)| *g == k) {
            Some((_, labels)) => labels.push(run_label(r)),
            None => groups.push((k, vec![run_label(r)])),
        }
    }
    groups
}

/// The notes shared by both stage tables: frame counts and timing method, wall-time fallbacks,
/// device(s).
fn timing_notes(results: &[&RunResult]) -> Vec<String> {
    let frames_text =
        |&(m, w): &(u32, u32)| format!("{m} measured frames ({w} warm-up frames dropped)");
    let frames = group_runs(results, |r| (r.frames.measured, r.frames.warmup));
    let frames = match frames.as_slice() {
        [] => "the measured frames".to_string(),
        [(k, _)] => frames_text(k),
        groups => groups
            .iter()
            .map(|(k, runs)| format!("{} for {}", frames_text(k), runs.join(", ")))
            .collect::<Vec<_>>()
            .join("; "),
    };
    let mut notes = vec![format!(
        "Times in milliseconds, median over {frames}; GPU stages: CPU wall time with the queue flushed before and \
         after (Laine et al. 2007's per-task method; GPU timestamps are in the results files and in \
         `gibench report --detailed`); frame: no added synchronisation (time between frame starts); CPU stages: \
         wall time; frame p95 / p99: the 95th and 99th percentiles of the frame times (stutters); GPU frame span: \
         median over the frames of GPU timestamps from the first stage's start to the last stage's end, whole \
         frames submitted at once (the stages' own intervals would count twice what a GPU overlaps); FPS: \
         1000 / mean frame time."
    )];

    let fallbacks: Vec<String> = results
        .iter()
        .filter_map(|r| {
            let stages: Vec<&str> = r
                .stages
                .iter()
                .filter(|s| s.kind == StageKind::Gpu && s.wall_ms.is_none() && s.gpu_ms.is_some())
                .map(|s| s.name.as_str())
                .collect();
            (!stages.is_empty()).then(|| format!("{} ({})", run_label(r), stages.join(", ")))
        })
        .collect();
    if !fallbacks.is_empty() {
        notes.push(format!(
            "GPU stages timed by GPU timestamps only (no flushed wall time): {}.",
            fallbacks.join("; ")
        ));
    }

    let devices = group_runs(results, device_text);
    match devices.as_slice() {
        [] => {}
        [(d, _)] => notes.push(format!("Device: {d}.")),
        groups => notes.push(format!(
            "Devices: {}.",
            groups
                .iter()
                .map(|(d, runs)| format!("{d} for {}", runs.join(", ")))
                .collect::<Vec<_>>()
                .join("; ")
        )),
    }
    notes
}

/// "mean / min" of the VPLs lighting each measured frame (the `vpls` counter), if counted.
pub fn vpl_count_cell(r: &RunResult) -> Cell {
    match r.counters.get("vpls") {
        Some(c) => Cell::text(format!("{:.1} / {}", c.mean, c.min)),
        None => Cell::text("–"),
    }
}

/// "adapter (backend)" ([`crate::measure::results::DeviceInfo::label`]: with a software
/// rasteriser's thread setting): what a run ran on, for tables that pool several devices.
pub fn device_label(r: &RunResult) -> String {
    r.device.label()
}

/// "fewest / most" VPLs any interleaving tile got in any measured frame (the `tile-vpls-min`
/// and `tile-vpls-max` counters), if counted.
pub fn tile_balance_cell(r: &RunResult) -> Cell {
    match (
        r.counters.get("tile-vpls-min"),
        r.counters.get("tile-vpls-max"),
    ) {
        (Some(lo), Some(hi)) => Cell::text(format!("{} / {}", lo.min, hi.max)),
        _ => Cell::text("–"),
    }
}

/// One row per run: scene, technique, resolution "WxH", "setting" (the parameters that tell
/// runs of one technique apart, where any do), "VPLs (mean / min)" and "tile VPLs
/// (fewest / most)" when any run counts them, one column per stage (median ms: flushed wall time, else GPU timestamps),
/// "Σ stages", "frame (median ms)", "frame p95", "frame p99", "GPU frame span" (median ms),
/// "FPS". Notes say how the times were taken and on which
/// device(s).
pub fn stage_table(results: &[RunResult]) -> Table {
    let stages = stage_names(results);
    let vpls = results.iter().any(|r| r.counters.contains_key("vpls"));
    let mut columns: Vec<String> = ["scene", "technique", "resolution"]
        .map(String::from)
        .into();
    // Runs of one technique that differ in parameters: a column says how (a sweep's points
    // read the same otherwise).
    let settings: Vec<String> = (results.iter())
        .map(|r| super::pareto::distinct_setting(results, r))
        .collect();
    let setting = settings.iter().any(|s| !s.is_empty());
    if setting {
        columns.push("setting".into());
    }
    // Results pooled from several devices: one column says which each row ran on.
    let mut adapters: Vec<String> = results.iter().map(device_label).collect();
    adapters.sort();
    adapters.dedup();
    let pooled = adapters.len() > 1;
    if pooled {
        columns.insert(0, "device".into());
    }
    if vpls {
        columns.push("VPLs (mean / min)".into());
    }
    let tiles = results
        .iter()
        .any(|r| r.counters.contains_key("tile-vpls-min"));
    if tiles {
        columns.push("tile VPLs (fewest / most)".into());
    }
    columns.extend(stages.iter().cloned());
    columns.extend(
        [
            "Σ stages",
            "frame (median ms)",
            "frame p95",
            "frame p99",
            "GPU frame span",
            "FPS",
        ]
        .map(String::from),
    );
    let quality = results.iter().any(|r| r.quality.is_some());
    if quality {
        columns.extend(["reference".to_string(), "RMSE".to_string()]);
        columns.extend(error_columns("relMSE"));
        columns.extend(error_columns("bias"));
        columns.extend(error_columns("FLIP"));
        columns.extend(["flicker".to_string(), "flicker floor".to_string()]);
    }

    let rows = results
        .iter()
        .zip(&settings)
        .map(|(r, s)| {
            let mut row = vec![
                Cell::text(&r.scene),
                Cell::text(&r.technique),
                Cell::text(format!("{}x{}", r.resolution[0], r.resolution[1])),
            ];
            if setting {
                row.push(Cell::text(if s.is_empty() { "–" } else { s }));
            }
            if pooled {
                row.insert(0, Cell::text(device_label(r)));
            }
            if vpls {
                row.push(vpl_count_cell(r));
            }
            if tiles {
                row.push(tile_balance_cell(r));
            }
            row.extend(
                stages
                    .iter()
                    .map(|name| Cell::Ms(r.stage(name).and_then(stage_ms))),
            );
            row.push(Cell::Ms(stage_sum(r)));
            let frame = r.frame.as_ref();
            row.push(Cell::Ms(frame.map(|f| f.frame_ms.median)));
            row.push(Cell::Ms(frame.map(|f| f.frame_ms.p95)));
            row.push(Cell::Ms(frame.map(|f| f.frame_ms.p99)));
            row.push(Cell::Ms(
                frame.and_then(|f| f.gpu_span_ms).map(|s| s.median),
            ));
            row.push(Cell::Num(frame.map(|f| f.fps), 1));
            if quality {
                let q = r.quality.as_ref();
                row.push(Cell::text(super::glance::component_of(r).unwrap_or("–")));
                row.push(Cell::Num(q.map(|q| q.rmse.mean), 4));
                for metric in [
                    (|e| e.rel_mse.mean) as fn(&ComponentErrors) -> f64,
                    |e| e.bias.mean,
                    |e| e.flip_mean.mean,
                ] {
                    row.extend(ComponentErrors::NAMES.map(|c| error_cell(r, c, metric, 4)));
                }
                row.push(Cell::Num(q.and_then(|q| q.temporal.map(|t| t.mean)), 4));
                row.push(Cell::Num(q.and_then(|q| q.flicker_floor), 4));
            }
            row
        })
        .collect();

    let mut notes = timing_notes(&results.iter().collect::<Vec<_>>());
    if quality {
        let mut refs: Vec<&str> = Vec::new();
        for q in results.iter().filter_map(|r| r.quality.as_ref()) {
            let labels =
                std::iter::once(&q.reference).chain(q.components.iter().map(|c| &c.reference));
            for label in labels {
                if !refs.contains(&label.as_str()) {
                    refs.push(label);
                }
            }
        }
        notes.push(format!(
            "Quality: means over the compared frames against the CPU reference ({}). RMSE, relMSE \
             (relative MSE, Rousselle et al. 2011) and bias (signed relative error of the mean) of indirect \
             irradiance; FLIP (LDR-FLIP, mean) of the \
             tonemapped composed images; flicker: RMS of the frame-to-frame change of indirect irradiance \
             beyond the reference's change; flicker floor: the reference's own frame-to-frame noise \
             (up to three compared pairs rendered again with the next seed), which every flicker \
             includes: a flicker at or below it is at the floor. RMSE and flicker are against the \
             run's own component, in column reference (the one its technique computes unless \
             --quality-reference named another).",
            refs.join("; ")
        ));
        notes.push(super::glance::errors_note(results));
        notes.extend(super::glance::pareto_line(results));
    }
    Table {
        title: "Per-stage GPU/CPU time (median ms)".to_string(),
        columns,
        rows,
        notes,
    }
}

/// One run in detail: one row per stage (kind GPU/CPU) with median, mean, p5, p95, min and max
/// of the GPU timestamp times and of the wall-clock times, plus a "frame" row holding the
/// unsynchronised frame times in the wall columns.
pub fn stage_table_detailed(result: &RunResult) -> Table {
    const STATS: [&str; 6] = ["median", "mean", "p5", "p95", "min", "max"];
    let mut columns: Vec<String> = vec!["stage".into(), "kind".into()];
    columns.extend(STATS.iter().map(|s| format!("GPU {s}")));
    columns.extend(STATS.iter().map(|s| format!("wall {s}")));

    let cells = |s: Option<&Stats>| -> Vec<Cell> {
        match s {
            Some(s) => [s.median, s.mean, s.p5, s.p95, s.min, s.max]
                .map(|v| Cell::Ms(Some(v)))
                .into(),
            None => vec![Cell::Ms(None); STATS.len()],
        }
    };
    let mut rows: Vec<Vec<Cell>> = result
        .stages
        .iter()
        .map(|s| {
            let kind = match s.kind {
                StageKind::Gpu => "GPU",
                StageKind::Cpu => "CPU",
            };
            let mut row = vec![Cell::text(&s.name), Cell::text(kind)];
            row.extend(cells(s.gpu_ms.as_ref()));
            row.extend(cells(s.wall_ms.as_ref()));
            row
        })
        .collect();

    let mut notes = timing_notes(&[result]);
    if let Some(f) = &result.frame {
        let mut row = vec![Cell::text("frame"), Cell::text("frame")];
        row.extend(cells(None));
        row.extend(cells(Some(&f.frame_ms)));
        rows.push(row);
        notes.push(format!(
            "The frame row is the time between consecutive frame starts with at most {} frame(s) in flight \
             ({:.1} FPS).",
            f.frames_in_flight, f.fps
        ));
    }

    Table {
        title: format!(
            "{} ({}x{}): per-stage times (ms)",
            run_label(result),
            result.resolution[0],
            result.resolution[1]
        ),
        columns,
        rows,
        notes,
    }
}
