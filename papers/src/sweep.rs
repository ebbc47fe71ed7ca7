//! `gibench sweep`: one technique, one parameter over a list of values: its arguments, the
//! plan of every point checked before any runs, and the table, plots and page of the points.

use std::path::{Path, PathBuf};

use clap::Args;
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::technique::{Params, TechniqueInfo};
use gibench_harness::measure::results::RunResult;
use gibench_harness::output::OutputSet;
use gibench_harness::report;
use gibench_harness::run::session::{RunSpec, TechniqueRun};
use gibench_harness::{Error, Result};

use crate::page::{page_line, with_folder, write_page};
use crate::params::assign_params;
use crate::progress::{execute_skipping_with_bar, Bars};
use crate::registry;
use crate::run::{announcement, open_gpu, plan, settings, weigh_equally, Plan, RunArgs};
use crate::shard::{own_units, ShardRecord};

#[derive(Args)]
pub struct SweepArgs {
    /// The swept parameter and its values: name=v1,v2,...
    #[arg(long)]
    pub sweep: String,
    #[command(flatten)]
    pub run: RunArgs,
}

/// `gibench sweep`: one technique, one parameter over a list of values. With a shard
/// (`--shard`, or a job array's environment) only its part of the points runs, and a
/// [`ShardRecord`] beside the results says which, for `gibench merge`.
pub fn exec(args: &SweepArgs) -> Result<()> {
    let mut planned = sweep_plan(args)?;
    let shard = args.run.shard.resolve()?;
    let record = match &shard {
        Some(s) => {
            eprintln!("gibench sweep: shard {s} (0-based), from {}", s.source);
            let units = planned.values.clone();
            let mine = own_units(
                &weigh_equally(&units),
                s,
                &|_| "1 point".into(),
                "equal weights (every point runs the same size and frames), ties by value as text",
            );
            let mut settings = settings(&args.run, &planned.plans[0]);
            settings.insert(
                "technique".into(),
                planned.plans[0].techniques[0].name.into(),
            );
            settings.insert("sweep".into(), planned.name.clone());
            let mut k = mine.iter();
            planned.values.retain(|_| *k.next().unwrap_or(&false));
            let mut k = mine.iter();
            planned.plans.retain(|_| *k.next().unwrap_or(&false));
            Some(ShardRecord::new("sweep", s, units, settings))
        }
        None => None,
    };
    let set = OutputSet::begin("out", &args.run.out)?;
    let mut stale = Vec::new();
    // The folder's points of this scene, technique and parameter are this sweep's alone: an
    // earlier sweep's points at values this one does not run are removed when it publishes
    // (they would otherwise sit beside its table as if part of it).
    // Its page and error plot likewise: written only with --html / --quality, an earlier
    // sweep's would otherwise describe other points.
    if !planned.plans.is_empty() {
        for point in planned.earlier_points(&args.run.out) {
            gibench_harness::output::replace_in_open_set(&point)?;
        }
        let first = &planned.plans[0];
        let stem = summary_stem(&first.desc.name, first.techniques[0].name, &planned.name);
        stale = replace_sweep_files(&set, &args.run.out, &stem)?;
    }
    let mut lost = None;
    if let Some(mut record) = record {
        let mut done = "this shard has no points to run".to_string();
        if !planned.plans.is_empty() {
            let prefix = planned.point_prefix();
            let gpu = open_gpu(&args.run)?;
            let (line, completed, e) =
                sweep_planned_keeping(args, &planned, &gpu, &Bars::Own(args.run.quiet))?;
            (done, lost) = (line, e);
            record.ran = (planned.values.iter().enumerate())
                .map(|(i, v)| match i < completed {
                    true => (v.clone(), format!("{prefix}{v}.json")),
                    false => (
                        v.clone(),
                        "skipped: not completed: the GPU device was lost".into(),
                    ),
                })
                .collect();
        }
        record.write(&args.run.out)?;
        set.publish()?;
        eprintln!("{done}");
        if let Some(note) = crate::run::removed_note(&stale) {
            eprintln!("{note}");
        }
        return lost.map_or(Ok(()), Err);
    }
    let gpu = open_gpu(&args.run)?;
    let (done, _, lost) = sweep_planned_keeping(args, &planned, &gpu, &Bars::Own(args.run.quiet))?;
    set.publish()?;
    eprintln!("{done}");
    if let Some(note) = crate::run::removed_note(&stale) {
        eprintln!("{note}");
    }
    lost.map_or(Ok(()), Err)
}

/// A sweep checked before it runs: the parameter, its values and one plan per value.
pub struct SweepPlan {
    name: String,
    values: Vec<String>,
    plans: Vec<Plan>,
}

impl SweepPlan {
    /// The typed run of every point.
    pub fn spec(&self, args: &SweepArgs) -> RunSpec<'_> {
        let first = &self.plans[0];
        let info = first.techniques[0];
        let mut spec = first.spec(&args.run);
        spec.runs = self
            .values
            .iter()
            .zip(&self.plans)
            .map(|(v, p)| TechniqueRun {
                info,
                params: p.params[0].clone(),
                stem: format!("{}{v}", self.point_prefix()),
                settings: Default::default(),
            })
            .collect();
        spec
    }

    /// What every point's files are named after: `SCENE-TECHNIQUE-PARAMETER-` (the value
    /// follows).
    fn point_prefix(&self) -> String {
        let first = &self.plans[0];
        let info = first.techniques[0];
        format!("{}-{}-{}-", first.desc.name, info.name, self.name)
    }

    /// The files in `dir` named as points of a sweep of this scene, technique and parameter
    /// (any value) — not those of a parameter whose name extends this one's (`vpl-map-size`
    /// beside `vpl-map`).
    fn earlier_points(&self, dir: &Path) -> Vec<PathBuf> {
        let prefix = self.point_prefix();
        let first = &self.plans[0];
        let info = first.techniques[0];
        let bare = self.name.rsplit('.').next().unwrap_or(&self.name);
        let longer: Vec<String> = (info.params.iter().flat_map(|g| g.iter()))
            .filter(|p| p.name.starts_with(&format!("{bare}-")))
            .map(|p| format!("{}-{}-{}-", first.desc.name, info.name, p.name))
            .collect();
        let Ok(entries) = std::fs::read_dir(dir) else {
            return Vec::new();
        };
        entries
            .flatten()
            .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
            .filter(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.starts_with(&prefix) && !longer.iter().any(|l| name.starts_with(l))
            })
            .map(|e| e.path())
            .collect()
    }
}

/// Checks a sweep's arguments and plans every point before any runs.
pub fn sweep_plan(args: &SweepArgs) -> Result<SweepPlan> {
    if args.run.equal_time.is_some() {
        return Err(Error::param(
            "equal-time",
            "applies to gibench run (a sweep sets its swept parameter itself)",
        ));
    }
    let (name, values) = args
        .sweep
        .split_once('=')
        .map(|(n, v)| {
            (
                n.trim().to_string(),
                v.split(',')
                    .map(|x| x.trim().to_string())
                    .collect::<Vec<_>>(),
            )
        })
        .filter(|(n, v)| !n.is_empty() && !v.is_empty() && v.iter().all(|x| !x.is_empty()))
        .ok_or_else(|| {
            Error::param(
                "sweep",
                format!("expected name=v1,v2,... (got '{}')", args.sweep),
            )
        })?;
    if args.run.technique.len() != 1 {
        return Err(Error::param(
            "technique",
            "a sweep runs exactly one technique",
        ));
    }
    if args.run.scene.contains(',') {
        return Err(Error::param(
            "scene",
            format!(
                "a sweep runs on one scene (got '{}'); run one sweep per scene",
                args.run.scene
            ),
        ));
    }
    check_swept_not_given(&args.sweep, &name, &args.run.params)?;
    let info = TechniqueInfo::find(registry::all(), args.run.technique[0].trim())?;
    check_distinct_values(info, &name, &values)?;
    // Check every point before running any.
    let plans: Vec<Plan> = values
        .iter()
        .map(|v| plan(&args.run, &[format!("{name}={v}")]))
        .collect::<Result<_>>()?;
    let planned = SweepPlan {
        name,
        values,
        plans,
    };
    planned.spec(args).validate()?;
    Ok(planned)
}

/// Refuses a `--param` that sets the swept parameter `name` (with or without a `technique.`
/// prefix): every point would silently override it.
fn check_swept_not_given(sweep: &str, name: &str, params: &[String]) -> Result<()> {
    let bare = |key: &str| key.split_once('.').map_or(key, |(_, n)| n).to_string();
    let swept = bare(name);
    let given = params
        .iter()
        .find(|p| p.split_once('=').is_some_and(|(k, _)| bare(k) == swept));
    if let Some(p) = given {
        return Err(Error::param(
            swept,
            format!(
                "given both as --param ('{p}') and as the swept parameter (--sweep {sweep}); \
                 give it once"
            ),
        ));
    }
    Ok(())
}

/// Refuses a sweep value listed twice, compared as the technique reads them (`08` and `8`, `1`
/// and `1.0` are one setting): the second point would repeat the first's run, or overwrite its
/// files.
fn check_distinct_values(info: &TechniqueInfo, name: &str, values: &[String]) -> Result<()> {
    let parsed: Vec<Params> = values
        .iter()
        .map(|v| assign_params(&[info], &[format!("{name}={v}")]).map(|mut p| p.remove(0)))
        .collect::<Result<_>>()?;
    for (i, p) in parsed.iter().enumerate() {
        if let Some(j) = parsed[..i].iter().position(|q| q == p) {
            let (a, b) = (&values[j], &values[i]);
            let message = if a == b {
                format!("the value '{b}' is listed twice; its second run would overwrite the first's files")
            } else {
                format!(
                    "the values '{a}' and '{b}' are listed twice: {} reads both as the same \
                     {name}, so the second run would only repeat the first",
                    info.name
                )
            };
            return Err(Error::param("sweep", message));
        }
    }
    Ok(())
}

/// The work of `gibench sweep` once planned and its output set is open. Returns what it
/// wrote, as a line for the terminal; a lost device fails it (a target of `reproduce all` is
/// complete only with every point).
pub fn sweep_planned(
    args: &SweepArgs,
    planned: &SweepPlan,
    gpu: &GpuContext,
    bars: &Bars,
) -> Result<String> {
    let (done, _, lost) = sweep_planned_keeping(args, planned, gpu, bars)?;
    lost.map_or(Ok(done), Err)
}

/// [`sweep_planned`], keeping the points completed before a lost device: their files and a
/// table of them are written; returns the line, how many points completed (the first ones),
/// and the lost device's error for the command to fail with once it has published them.
pub fn sweep_planned_keeping(
    args: &SweepArgs,
    planned: &SweepPlan,
    gpu: &GpuContext,
    bars: &Bars,
) -> Result<(String, usize, Option<Error>)> {
    let SweepPlan {
        name,
        values,
        plans,
    } = planned;
    let (name, values) = (name.clone(), values.clone());
    let first = &plans[0];
    let info = first.techniques[0];
    let spec = planned.spec(args);
    bars.note(&announcement(first, gpu));
    let (runs, skipped) = execute_skipping_with_bar(bars, gpu, &spec, false)?;
    let lost = gibench_harness::run::session::device_lost(&skipped);
    if runs.is_empty() {
        if let Some(e) = lost {
            return Err(e);
        }
    }
    let completed = runs.len();
    let points: Vec<(String, RunResult)> = values.iter().cloned().zip(runs).collect();
    let (table, figures, stem) = write_summary(
        &points,
        info.name,
        &first.desc.name,
        &name,
        &args.run.out,
        first.quality.is_some(),
        args.run.smoke.as_deref(),
    )?;
    bars.table(&table);
    let results: Vec<RunResult> = points.iter().map(|(_, r)| r.clone()).collect();
    let mut done = format!(
        "wrote {} points and {stem}.md/.csv/.tex/.svg{} to {}",
        points.len(),
        if figures.len() > 1 {
            ", -time-vs-error.svg"
        } else {
            ""
        },
        args.run.out.display()
    );
    if args.run.html {
        let page = args.run.out.join(format!("{stem}.html"));
        write_page(
            &page,
            table.title.clone(),
            vec![table],
            figures,
            with_folder(&args.run.out, results),
        )?;
        done.push_str(&page_line(&page));
    }
    if let Some(e) = &lost {
        done.push_str(&format!(
            "\nnot completed: {name}={} ({e}); the table holds the points before it",
            values[completed..].join(",")
        ));
    }
    Ok((done, completed, lost))
}

/// The table and plots of a sweep of `technique` on `scene` over `name` from its `points`
/// (value, results): `{scene}-{technique}-sweep-{name}.md/.csv/.tex/.svg` and with `quality`
/// the time-versus-error plot, into `out`, the table marked with `smoke`'s note for a smoke
/// run. `gibench sweep` and `gibench merge` (pooling shards) both write them here. Returns
/// the table, the figures and the stem.
pub fn write_summary(
    points: &[(String, RunResult)],
    technique: &str,
    scene: &str,
    name: &str,
    out: &Path,
    quality: bool,
    smoke: Option<&str>,
) -> Result<(report::Table, Vec<PathBuf>, String)> {
    let results: Vec<RunResult> = points.iter().map(|(_, r)| r.clone()).collect();
    let mut table = report::stage_table(&results);
    table.title = format!("{technique} on {scene}: per-stage time (median ms) against {name}");
    // The swept value leads each row; a setting column would only repeat it.
    if let Some(c) = table.columns.iter().position(|c| c == "setting") {
        table.columns.remove(c);
        table.rows.iter_mut().for_each(|r| {
            r.remove(c);
        });
    }
    table.columns.insert(0, name.to_string());
    for (row, (v, _)) in table.rows.iter_mut().zip(points) {
        row.insert(0, report::Cell::text(v));
    }
    if let Some(note) = smoke {
        table.mark_smoke(note);
    }
    let stem = summary_stem(scene, technique, name);
    report::write_tables(&table, out, &stem)?;
    report::sweep_plot_svg(
        points,
        &out.join(format!("{stem}.svg")),
        &format!("{technique} on {scene}: stage times against {name}"),
        name,
    )?;
    let mut figures = vec![out.join(format!("{stem}.svg"))];
    if quality {
        let svg = out.join(format!("{stem}-time-vs-error.svg"));
        report::time_vs_error_svg(
            &results,
            &svg,
            &format!("{technique} on {scene}: time versus error over {name}"),
        )?;
        figures.push(svg);
    }
    Ok((table, figures, stem))
}

/// The stem of a sweep's tables, plots and page: `{scene}-{technique}-sweep-{name}`.
pub(crate) fn summary_stem(scene: &str, technique: &str, name: &str) -> String {
    format!("{scene}-{technique}-sweep-{name}")
}

/// A sweep's page and time-versus-error plot (`{stem}.html`, `{stem}-time-vs-error.svg`),
/// written only with `--html` / `--quality`, declared replaced in `set` (`sweep` and `merge`
/// of a sweep's shards): an earlier command's would describe other points. Returns those
/// present now ([`crate::run::removed_note`]).
pub(crate) fn replace_sweep_files(set: &OutputSet, out: &Path, stem: &str) -> Result<Vec<PathBuf>> {
    let names = [format!("{stem}.html"), format!("{stem}-time-vs-error.svg")];
    crate::run::replace_listing_present(set, out, &names)
}
