//! A run, sweep or reference command as a target of `gibench reproduce`: parsed on its own (the
//! three subcommands a target may be, with the top-level command line's argument types, not
//! through it), checked before anything runs, then run into its `--out`.

use clap::Parser;
use gibench_harness::gpu::GpuContext;
use gibench_harness::run::session::RunSpec;
use gibench_harness::{Error, Result};

use crate::progress::Bars;
use crate::reference::{reference_plan, reference_planned, ReferenceArgs, ReferencePlan};
use crate::run::{plan_scenes, run_planned, Plan, RunArgs};
use crate::sweep::{sweep_plan, sweep_planned, SweepArgs, SweepPlan};

/// The commands a target may be, parsed as `gibench run|sweep|reference ...` is.
#[derive(Parser)]
#[command(name = "gibench")]
enum TargetCommand {
    Run(RunArgs),
    Sweep(SweepArgs),
    Reference(ReferenceArgs),
}

/// A gibench command run as a target of `gibench reproduce`, checked before anything runs.
pub enum Job {
    /// One plan per scene of its `--scene a,b`.
    Run(Vec<(RunArgs, Plan)>),
    Sweep(Box<SweepArgs>, Box<SweepPlan>),
    Reference(Box<ReferenceArgs>, Box<ReferencePlan>),
}

impl Job {
    /// Parses and checks `gibench ARGV...` (run, sweep or reference).
    pub fn plan(argv: &[String]) -> Result<Job> {
        if !matches!(
            argv.first().map(String::as_str),
            Some("run" | "sweep" | "reference")
        ) {
            return Err(Error::Invalid(format!(
                "`gibench {}` is not a run, sweep or reference command",
                argv.join(" ")
            )));
        }
        let command = TargetCommand::try_parse_from(
            std::iter::once("gibench").chain(argv.iter().map(String::as_str)),
        )
        .map_err(|e| Error::Invalid(e.to_string().trim().to_string()))?;
        match command {
            TargetCommand::Run(a) => Ok(Job::Run(plan_scenes(&a)?)),
            TargetCommand::Sweep(a) => {
                let p = sweep_plan(&a)?;
                Ok(Job::Sweep(Box::new(a), Box::new(p)))
            }
            TargetCommand::Reference(a) => {
                let p = reference_plan(&a)?;
                Ok(Job::Reference(Box::new(a), Box::new(p)))
            }
        }
    }

    /// Marks the tables a run or sweep writes as a smoke run's ([`gibench_harness::report::Table::mark_smoke`];
    /// a reference command writes no table of timings).
    pub fn mark_smoke(&mut self, note: String) {
        match self {
            Job::Run(plans) => plans
                .iter_mut()
                .for_each(|(a, _)| a.smoke = Some(note.clone())),
            Job::Sweep(a, _) => a.run.smoke = Some(note),
            Job::Reference(..) => {}
        }
    }

    pub fn needs_gpu(&self) -> bool {
        !matches!(self, Job::Reference(..))
    }

    /// (frames rendered, frames × pixels; reference: samples × pixels).
    pub fn work(&self) -> (u64, u64) {
        let of = |spec: &RunSpec| {
            let frames = spec.total_frames();
            let [w, h] = spec.config.resolution;
            (frames, frames * w as u64 * h as u64)
        };
        match self {
            Job::Run(plans) => (plans.iter())
                .map(|(a, p)| {
                    let (frames, units) = of(&p.spec(a));
                    // --equal-time's search: at most this many frames more per technique with
                    // a knob (an upper bound; the manifest's rate absorbs the difference).
                    let search = p.equal_time.map_or(0, |_| {
                        let tuned = p.techniques.iter().filter(|t| t.knob.is_some()).count();
                        tuned as u64 * crate::equal_time::search_frames()
                    });
                    let [w, h] = p.config.resolution;
                    (frames + search, units + search * w as u64 * h as u64)
                })
                .fold((0, 0), |(f, u), (g, v)| (f + g, u + v)),
            Job::Sweep(a, p) => of(&p.spec(a)),
            Job::Reference(a, p) => {
                let seeds = 1 + a.error_estimate as u64;
                let [w, h] = p.resolution;
                (0, seeds * p.settings.spp as u64 * w as u64 * h as u64)
            }
        }
    }

    /// Runs it into its `--out` (inside an open output set) on `gpu`; returns what it wrote.
    pub fn execute(&self, gpu: Option<&GpuContext>, bars: &Bars) -> Result<String> {
        let gpu =
            || gpu.ok_or_else(|| Error::Invalid("no adapter was opened for a GPU run".into()));
        match self {
            Job::Run(plans) => {
                let mut lines = Vec::new();
                for (a, p) in plans {
                    lines.push(run_planned(a, p, gpu()?, bars)?);
                }
                Ok(lines.join("\n"))
            }
            Job::Sweep(a, p) => sweep_planned(a, p, gpu()?, bars),
            Job::Reference(a, p) => reference_planned(a, p, bars),
        }
    }
}
