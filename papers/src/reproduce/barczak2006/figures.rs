//! Barczak 2006's figures from our runs: Figures 5-2 to 5-6 (an SVG and the table of the numbers
//! behind each, with the thesis' words on it beside ours) and the quality table.

use std::path::Path;

use gibench_barczak::{STAGES, STAGE_SHADOW_MAPS, STAGE_VISIBILITY};
use gibench_harness::measure::results::RunResult;
use gibench_harness::report::{self, Cell, Table};
use gibench_harness::Result;

use super::super::{device_note, ms, sum_ms};
use super::{CASES, FIGURES, ROOMS};

fn param<'r>(r: &'r RunResult, name: &str) -> Option<&'r str> {
    r.parameters.get(name).and_then(|v| v.as_str())
}

fn int_param(r: &RunResult, name: &str) -> Option<f64> {
    r.parameters.get(name).and_then(|v| v.as_f64())
}

fn frame_ms(r: &RunResult) -> Option<f64> {
    r.frame.as_ref().map(|f| f.frame_ms.median)
}

fn fps(r: &RunResult) -> Option<f64> {
    frame_ms(r).map(|m| 1000.0 / m)
}

fn counter(r: &RunResult, name: &str) -> Option<f64> {
    r.counters.get(name).map(|s| s.mean)
}

/// The thesis' words on figure `key`, and its setting.
fn thesis(paper: &serde_json::Value, key: &str) -> String {
    format!(
        "The thesis ({}, {}, {}, {}): \"{}\" — {}",
        paper["hardware"].as_str().unwrap_or("?"),
        paper["resolution"].as_str().unwrap_or("?"),
        paper["api"].as_str().unwrap_or("?"),
        paper["year"],
        paper["figures"][key]["caption"].as_str().unwrap_or("?"),
        paper["figures"][key]["shows"].as_str().unwrap_or("?"),
    )
}

fn timing_note(runs: &[&RunResult]) -> String {
    let (frames, warmup, res) = runs
        .first()
        .map(|r| (r.frames.measured, r.frames.warmup, r.resolution))
        .unwrap_or_default();
    format!(
        "gibench: `barczak` at {}x{}, {} measured frames after {} warm-up frames (the first frame, which renders every shadow map, is the warm-up's); \
         frame: median time between frame starts without added synchronisation (FPS = 1000 / it); stages: medians with the queue flushed \
         before and after each. Light draws: mean per frame, the low-resolution pass counting its two renderings.",
        res[0], res[1], frames, warmup
    )
}

/// Least-squares line y = a + b x and its R².
fn fit(points: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let b = sxy / sxx;
    let r2 = if syy == 0.0 {
        1.0
    } else {
        sxy * sxy / (sxx * syy)
    };
    Some((my - b * mx, b, r2))
}

fn lights_runs<'r>(
    runs: &'r [RunResult],
    scene: &str,
    set: &str,
    level: &str,
) -> Vec<&'r RunResult> {
    let mut v: Vec<&RunResult> = runs
        .iter()
        .filter(|r| {
            r.quality.is_none()
                && r.scene == scene
                && param(r, "set") == Some(set)
                && param(r, "level") == Some(level)
        })
        .collect();
    v.sort_by(|a, b| {
        int_param(a, "vpls")
            .unwrap_or(0.0)
            .total_cmp(&int_param(b, "vpls").unwrap_or(0.0))
    });
    v
}

fn svg(
    out: &Path,
    file: &str,
    lines: Vec<(String, Vec<(f64, f64)>)>,
    title: &str,
    x: &str,
    y: &str,
) -> Result<()> {
    report::lines_svg(&lines, &out.join(file), title, x, y)
}

pub(super) fn fig5_2(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut shows = Vec::new();
    let mut all = Vec::new();
    for room in ROOMS {
        let scene = still_name(room);
        let rs = lights_runs(runs, &scene, "indirect", "full");
        let mut points = Vec::new();
        for r in &rs {
            rows.push(vec![
                Cell::text(&r.scene),
                Cell::Num(int_param(r, "vpls"), 0),
                Cell::Ms(frame_ms(r)),
                Cell::Num(fps(r), 1),
                Cell::Ms(sum_ms(r, &present(r))),
                Cell::Num(counter(r, "light-draws"), 0),
            ]);
            if let (Some(n), Some(m)) = (int_param(r, "vpls"), frame_ms(r)) {
                points.push((n, m));
            }
            all.push(*r);
        }
        if let Some((a, b, r2)) = fit(&points) {
            shows.push(format!(
                "{scene}: frame time ≈ {a:.1} ms + {b:.3} ms per light (R² = {r2:.3})"
            ));
        }
        lines.push((
            scene.clone(),
            points.iter().map(|(n, m)| (*n, 1000.0 / m)).collect(),
        ));
    }
    svg(
        out,
        FIGURES[0].0,
        lines,
        "Figure 5-2: frame rate against lights, static views (barczak, Full)",
        "light samples",
        "frames per second",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-2: rendering performance for fixed views of each test scene"
            .into(),
        columns: cols(&["scene", "lights", "frame", "FPS", "Σ stages", "light draws"]),
        rows,
        notes: vec![
            thesis(paper, "5-2"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "{} Level Full, indirect light samples (5 bounces), movers held at their first pose.",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// The static view's scene name of `room`.
fn still_name(room: &str) -> String {
    if room == "barczak-area" {
        room.to_string()
    } else {
        format!("{room}-static")
    }
}

/// The stages `r` has (the low-resolution ones only at its levels).
fn present(r: &RunResult) -> Vec<&'static str> {
    STAGES
        .iter()
        .map(|s| s.name)
        .filter(|s| r.stage(s).is_some())
        .collect()
}

fn cols(names: &[&str]) -> Vec<String> {
    names.iter().map(|s| s.to_string()).collect()
}

pub(super) fn fig5_3(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut shows = Vec::new();
    let mut all = Vec::new();
    for set in ["indirect", "direct"] {
        let mut at_max = Vec::new();
        for level in ["full", "vd-lp", "vd", "naive"] {
            let rs = lights_runs(runs, "barczak-area", set, level);
            let mut points = Vec::new();
            for r in &rs {
                rows.push(vec![
                    Cell::text(set),
                    Cell::text(level),
                    Cell::Num(int_param(r, "vpls"), 0),
                    Cell::Ms(frame_ms(r)),
                    Cell::Num(fps(r), 1),
                    Cell::Num(counter(r, "light-draws"), 0),
                    Cell::Num(counter(r, "elements"), 0),
                ]);
                if let (Some(n), Some(f)) = (int_param(r, "vpls"), fps(r)) {
                    points.push((n, f));
                }
                all.push(*r);
            }
            if let Some(r) = rs.last() {
                at_max.push((level, int_param(r, "vpls"), frame_ms(r)));
            }
            lines.push((format!("{level} ({set})"), points));
        }
        let get = |l: &str| at_max.iter().find(|(n, _, _)| *n == l).and_then(|x| x.2);
        if let (Some(full), Some(naive)) = (get("full"), get("naive")) {
            let n = at_max.first().and_then(|x| x.1).unwrap_or(0.0);
            let ratio = naive / full;
            let line = format!(
                "{set} samples at {n:.0} lights: Full {full:.1} ms, Naive {naive:.1} ms per frame — Full is {ratio:.2}x {} than Naive",
                if ratio >= 1.0 { "faster" } else { "slower" }
            );
            println!("barczak2006: {line}");
            let mut order: Vec<(&str, f64)> = at_max
                .iter()
                .filter_map(|(l, _, m)| m.map(|m| (*l, m)))
                .collect();
            order.sort_by(|a, b| a.1.total_cmp(&b.1));
            shows.push(format!(
                "{line}; fastest to slowest: {}",
                order
                    .iter()
                    .map(|(l, m)| format!("{l} {m:.1} ms"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    svg(
        out,
        FIGURES[1].0,
        lines,
        "Figure 5-3: frame rate against lights per optimisation level, area-light room",
        "light samples",
        "frames per second",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-3: effect of each optimisation on rendering performance (area-light room)".into(),
        columns: cols(&["samples", "level", "lights", "frame", "FPS", "light draws", "elements"]),
        rows,
        notes: vec![
            thesis(paper, "5-3"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "{} full: light maps minus the occluded partial lights, drawn at low resolution (factor 2, edges redrawn), elements merged by the pass optimiser (K = 7 lights per draw); \
                 vd-lp: visibility determination and the low-resolution pass; vd: visibility determination at full resolution; naive: every light with a shadow-map lookup on every patch. \
                 indirect: random-walk samples (5 bounces); direct: points on the area light (the thesis' room has two area lights, ours one).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// The update runs of a case, sorted by updates, and its static run.
/// Whether run `r` drew its shadow maps without face culling (`face-cull=off`).
fn unculled(r: &RunResult) -> bool {
    r.parameters.get("face-cull").and_then(|v| v.as_str()) == Some("off")
}

/// Case `case`'s run without face culling, if any.
fn unculled_run<'r>(runs: &'r [RunResult], case: &str) -> Option<&'r RunResult> {
    let scene = format!("barczak-{case}");
    runs.iter().find(|r| r.scene == scene && unculled(r))
}

/// Case `case`'s moving runs with face culling (by updates) and its static view.
fn case_runs<'r>(runs: &'r [RunResult], case: &str) -> (Vec<&'r RunResult>, Option<&'r RunResult>) {
    let scene = format!("barczak-{case}");
    let mut moving: Vec<&RunResult> = (runs.iter())
        .filter(|r| r.scene == scene && !unculled(r))
        .collect();
    moving.sort_by(|a, b| {
        int_param(a, "updates")
            .unwrap_or(0.0)
            .total_cmp(&int_param(b, "updates").unwrap_or(0.0))
    });
    let still = runs.iter().find(|r| r.scene == format!("{scene}-static"));
    (moving, still)
}

pub(super) fn fig5_4(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut shows = Vec::new();
    let mut all = Vec::new();
    for (name, _, _) in CASES {
        let (moving, still) = case_runs(runs, name);
        if let Some(s) = still {
            rows.push(vec![
                Cell::text(name),
                Cell::text("static"),
                Cell::Num(int_param(s, "vpls"), 0),
                Cell::Ms(frame_ms(s)),
                Cell::Num(fps(s), 1),
                Cell::Num(counter(s, "maps-rendered"), 1),
                Cell::Num(faces_per_map(s), 2),
                Cell::Num(counter(s, "light-map-changes"), 1),
            ]);
            all.push(s);
        }
        let mut points = Vec::new();
        for r in &moving {
            rows.push(vec![
                Cell::text(name),
                Cell::Num(int_param(r, "updates"), 0),
                Cell::Num(int_param(r, "vpls"), 0),
                Cell::Ms(frame_ms(r)),
                Cell::Num(fps(r), 1),
                Cell::Num(counter(r, "maps-rendered"), 1),
                Cell::Num(faces_per_map(r), 2),
                Cell::Num(counter(r, "light-map-changes"), 1),
            ]);
            if let (Some(u), Some(f)) = (int_param(r, "updates"), fps(r)) {
                points.push((u, f));
            }
            all.push(*r);
        }
        if let (Some(s), Some(last)) = (still.and_then(fps), points.last()) {
            let faces = moving.last().and_then(|r| faces_per_map(r));
            shows.push(format!(
                "{name}: {s:.1} FPS static, {:.1} FPS at {:.0} updates per frame ({:.0} % of static), {} octahedral faces drawn per map",
                last.1,
                last.0,
                100.0 * last.1 / s,
                faces.map_or("–".to_string(), |f| format!("{f:.2}"))
            ));
            let (x0, x1) = (points[0].0, last.0);
            lines.push((format!("{name} static"), vec![(x0, s), (x1, s)]));
        }
        lines.push((name.to_string(), points));
    }
    svg(
        out,
        FIGURES[2].0,
        lines,
        "Figure 5-4: frame rate against shadow-map updates per frame, moving objects",
        "shadow maps updated per frame",
        "frames per second",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-4: rendering performance in dynamic scenes against visibility updates per frame".into(),
        columns: cols(&["case", "updates", "lights", "frame", "FPS", "maps rendered", "faces per map", "light-map changes"]),
        rows,
        notes: vec![
            thesis(paper, "5-4"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "{} The mover follows its path (the thesis: a fixed path, 200 frames, fixed camera); updates: the shadow maps re-rendered per frame at \
                 most, brightest and longest out of date first; maps rendered: the mean actually rendered (only out-of-date maps are); faces per map: the octahedral faces drawn into per map rendered, of \
                 four (§4.2.2: a face holding no shadow caster is not drawn; the room's shell casts none). Level Full, \
                 indirect samples. Cases: the rooms as built (bunny on the table, torus among the pillars) and swapped (the torus at 0.6 scale on the \
                 table's loop, the bunny on the floor under the pillar room's circle).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// Octahedral faces drawn into per shadow map rendered (`map-faces` / `maps-rendered`).
fn faces_per_map(r: &RunResult) -> Option<f64> {
    let maps = counter(r, "maps-rendered")?;
    (maps > 0.0).then(|| counter(r, "map-faces").map(|f| f / maps))?
}

pub(super) fn fig5_5(
    out: &Path,
    runs: &[RunResult],
    paper: &serde_json::Value,
    movers: &[(String, usize)],
) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut all = Vec::new();
    let mut at_max = Vec::new();
    let mut culling = Vec::new();
    for (name, _, _) in CASES {
        let (moving, _) = case_runs(runs, name);
        let vertices = movers
            .iter()
            .find(|(s, _)| *s == format!("barczak-{name}"))
            .map(|m| m.1 as f64);
        let mut points = Vec::new();
        for r in &moving {
            let sm = ms(r, STAGE_SHADOW_MAPS);
            let maps = counter(r, "maps-rendered");
            rows.push(vec![
                Cell::text(name),
                Cell::Num(vertices, 0),
                Cell::Num(int_param(r, "updates"), 0),
                Cell::Num(maps, 1),
                Cell::Ms(sm),
                Cell::Ms(sm.zip(maps).map(|(t, m)| t / m.max(1.0))),
            ]);
            if let (Some(u), Some(t)) = (int_param(r, "updates"), sm) {
                points.push((u, t));
            }
            all.push(*r);
        }
        if let (Some(last), Some(v)) = (
            moving.last().and_then(|r| ms(r, STAGE_SHADOW_MAPS)),
            vertices,
        ) {
            at_max.push((name, v, last));
        }
        let per_map = |r: &RunResult| {
            let maps = counter(r, "maps-rendered").filter(|m| *m > 0.0)?;
            Some(ms(r, STAGE_SHADOW_MAPS)? / maps)
        };
        if let (Some(off), Some(on)) = (
            unculled_run(runs, name).and_then(per_map),
            moving.last().and_then(|r| per_map(r)),
        ) {
            culling.push(format!(
                "{name} {on:.2} ms per map with face culling against {off:.2} without ({:.2}x)",
                off / on
            ));
        }
        lines.push((name.to_string(), points));
    }
    let mut shows = Vec::new();
    for room in ["table", "pillars"] {
        let get = |m: &str| at_max.iter().find(|c| c.0 == format!("{m}-{room}"));
        if let (Some(b), Some(t)) = (get("bunny"), get("torus")) {
            shows.push(format!(
                "in the {room} room, bunny/torus shadow-map time {:.2} at the most updates against a vertex ratio of {:.2}",
                b.2 / t.2,
                b.1 / t.1
            ));
        }
    }
    svg(
        out,
        FIGURES[3].0,
        lines,
        "Figure 5-5: shadow-map rendering time against updates per frame",
        "shadow maps updated per frame",
        "shadow-map stage (ms)",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-5: shadow-map rendering times for each test case".into(),
        columns: cols(&["case", "mover vertices", "updates", "maps rendered", "shadow maps", "per map"]),
        rows,
        notes: vec![
            thesis(paper, "5-5"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "Face culling (§4.2.2) at the most updates, the same case run again with face-cull=off: {}.",
                culling.join("; ")
            ),
            format!(
                "{} Shadow maps: the stage rendering the out-of-date octahedral maps, each only into the faces that hold a shadow caster \
                 (§4.2.2), the room's casters (not its shell) and the mover in each (the kit's atlas rasteriser; the thesis re-rendered the \
                 occluders of each map).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

pub(super) fn fig5_6(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let (moving, _) = case_runs(runs, "bunny-pillars");
    let mut rows = Vec::new();
    let (mut vis, mut maps) = (Vec::new(), Vec::new());
    for r in &moving {
        let total = sum_ms(r, &present(r));
        let v = ms(r, STAGE_VISIBILITY);
        let s = ms(r, STAGE_SHADOW_MAPS);
        let frac = |x: Option<f64>| x.zip(total).map(|(x, t)| x / t);
        rows.push(vec![
            Cell::Num(int_param(r, "updates"), 0),
            Cell::Ms(v),
            Cell::Ms(s),
            Cell::Ms(total),
            Cell::Num(frac(v).map(|f| 100.0 * f), 1),
            Cell::Num(frac(s).map(|f| 100.0 * f), 1),
            Cell::Num(frac(v.zip(s).map(|(a, b)| a + b)).map(|f| 100.0 * f), 1),
        ]);
        if let Some(u) = int_param(r, "updates") {
            if let Some(f) = frac(v) {
                vis.push((u, 100.0 * f));
            }
            if let Some(f) = frac(s) {
                maps.push((u, 100.0 * f));
            }
        }
    }
    let shows = match (maps.first(), maps.last(), vis.first(), vis.last()) {
        (Some(m0), Some(m1), Some(v0), Some(v1)) => format!(
            "shadow maps take {:.0} % of the frame at {:.0} updates and {:.0} % at {:.0}; visibility determination {:.1} % and {:.1} %",
            m0.1, m0.0, m1.1, m1.0, v0.1, v1.1
        ),
        _ => "no runs".into(),
    };
    svg(
        out,
        FIGURES[4].0,
        vec![
            ("shadow maps (% of Σ stages)".into(), maps),
            ("visibility determination (% of Σ stages)".into(), vis),
        ],
        "Figure 5-6: fraction of the frame in updates, bunny in the pillar room",
        "shadow maps updated per frame",
        "% of the frame",
    )?;
    let all: Vec<&RunResult> = moving.to_vec();
    Ok(Table {
        title: "Barczak 2006, Figure 5-6: fraction of rendering time taken by visibility updates (bunny, pillar room)".into(),
        columns: cols(&["updates", "visibility", "shadow maps", "Σ stages", "visibility %", "shadow maps %", "updates %"]),
        rows,
        notes: vec![
            thesis(paper, "5-6"),
            format!("Ours shows: {shows}."),
            format!(
                "{} Visibility: the CPU stage moving the mover in the visibility database (Table 4-1), updating light maps and planning the draws; \
                 shadow maps: the GPU stage; both as fractions of the sum of every stage of the frame (G-buffer, direct light and compose included).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// Each light-sample set against its reference component (§4.1's two sets; the quality
/// check): the indirect samples against the multi-bounce reference, the direct ones against the
/// reference's direct light (soft shadows).
pub(super) fn quality_table(runs: &[RunResult]) -> Result<Table> {
    let mut rows = Vec::new();
    let mut all = Vec::new();
    for r in runs.iter().filter(|r| r.quality.is_some()) {
        let q = r.quality.as_ref().expect("filtered");
        rows.push(vec![
            Cell::text(param(r, "set").unwrap_or("?")),
            Cell::text(&q.reference),
            Cell::Num(int_param(r, "vpls"), 0),
            Cell::Num(Some(q.rel_mse.mean), 4),
            Cell::Num(Some(q.rmse.mean), 4),
            Cell::Num(Some(q.bias.mean), 3),
            Cell::Num(Some(q.flip_mean.mean), 4),
        ]);
        all.push(r);
    }
    let res = all.first().map(|r| r.resolution).unwrap_or_default();
    Ok(Table {
        title: "Barczak 2006: the light-sample sets against the reference (area-light room)".into(),
        columns: cols(&["samples", "reference", "lights", "relMSE", "RMSE", "bias", "FLIP"]),
        rows,
        notes: vec![
            format!(
                "gibench: `barczak` level Full at {}x{}, one pair of consecutive frames. indirect: the random-walk samples (5 bounces) \
                 against the reference's multi-bounce indirect irradiance; direct: points on the area light against the reference's \
                 direct irradiance (stratified points on the light at every pixel). relMSE: relative MSE (Rousselle et al. 2011); bias: \
                 signed relative error of the mean. No clamp (the thesis has none): samples near a surface make hot spots.",
                res[0], res[1]
            ),
            device_note(&all),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_line() {
        let (a, b, r2) = fit(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]).unwrap();
        assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12 && (r2 - 1.0).abs() < 1e-12);
        assert!(fit(&[(1.0, 1.0)]).is_none());
    }
}
