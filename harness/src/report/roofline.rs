//! The roofline table of one run ([`roofline_table`]): each GPU stage's achieved fraction of the
//! device's measured bandwidth and arithmetic rate (`gibench report --detailed`).

use super::runs::{run_label, stage_ms};
use super::table::{Cell, Table};
use crate::measure::results::{RunResult, StageKind};
use crate::measure::roofline::{roofline, Binding, BoundTimer};

/// One row per GPU stage: its time ("ms", the tables' median), its declared bytes read and
/// written ("MB") and operations ("Mop"), the achieved GB/s and Gop/s and their fractions of the
/// bounds ("% BW", "% ops"), the binding bound, time_min ("min ms") and the efficiency
/// ("eff %", time_min / time). A stage without a declared cost, or a run without measured
/// bounds, shows "–" where a number would need them. Notes give the bounds and how they were
/// measured.
pub fn roofline_table(result: &RunResult) -> Table {
    let columns = [
        "stage", "ms", "MB", "Mop", "GB/s", "% BW", "Gop/s", "% ops", "bound", "min ms", "eff %",
    ]
    .map(String::from)
    .to_vec();
    let bounds = result.device_bounds.as_ref();
    let rows = result
        .stages
        .iter()
        .filter(|s| s.kind == StageKind::Gpu)
        .map(|s| {
            let ms = stage_ms(s);
            let cost = result.stage_costs.get(&s.name);
            let per_s = |v: f64| ms.filter(|&t| t > 0.0).map(|t| v / (t * 1e-3) / 1e9);
            let roof = match (cost, bounds, ms) {
                (Some(c), Some(b), Some(t)) => roofline(c, b, t),
                _ => None,
            };
            vec![
                Cell::text(&s.name),
                Cell::Ms(ms),
                Cell::Num(cost.map(|c| c.bytes() / 1e6), 2),
                Cell::Num(cost.map(|c| c.ops / 1e6), 2),
                Cell::Num(cost.and_then(|c| per_s(c.bytes())), 2),
                Cell::Num(roof.map(|r| 100.0 * r.bandwidth_fraction), 1),
                Cell::Num(cost.and_then(|c| per_s(c.ops)), 2),
                Cell::Num(roof.map(|r| 100.0 * r.ops_fraction), 1),
                Cell::text(match roof.map(|r| r.binding) {
                    Some(Binding::Memory) => "memory",
                    Some(Binding::Arithmetic) => "arithmetic",
                    None => "–",
                }),
                Cell::Ms(roof.map(|r| r.time_min_ms)),
                Cell::Num(roof.map(|r| 100.0 * r.efficiency), 1),
            ]
        })
        .collect();
    let mut notes = vec![
        "Roofline: each GPU stage declares the fewest bytes it must read and write (MB) and the \
         operations it must do (Mop: floating point, an FMA counting two) per frame; % BW and % \
         ops: achieved GB/s and Gop/s over the bounds; min ms: time_min = max(bytes / bandwidth, \
         operations / rate); eff %: time_min / ms, with ms the median flushed wall time of the \
         tables. \"–\": the stage declares no cost."
            .to_string(),
    ];
    match bounds {
        Some(b) => notes.push(format!(
            "Bounds measured on this device before the first stage-timed run's frames ({:.0} ms in all): bandwidth {:.2} GB/s \
             (a copy reading and writing {:.1} MB in {:.3} ms), arithmetic rate {:.2} Gop/s ({:.1} \
             Mop of FMA chains in {:.3} ms); each the fastest of its runs, timed by {}.",
            b.measure_ms,
            b.bandwidth() / 1e9,
            b.copy_bytes / 1e6,
            b.copy_ms,
            b.ops_per_s() / 1e9,
            b.fma_ops / 1e6,
            b.fma_ms,
            match b.timer {
                BoundTimer::Timestamps => "GPU timestamps",
                BoundTimer::Wall => "flushed wall time (the adapter has no timestamp queries)",
            }
        )),
        None => notes.push(
            "This results file holds no measured bounds (written before gibench measured them, \
             or a frame-only run): no fractions."
                .to_string(),
        ),
    }
    Table {
        title: format!("{}: stage efficiency (roofline)", run_label(result)),
        columns,
        rows,
        notes,
    }
}
