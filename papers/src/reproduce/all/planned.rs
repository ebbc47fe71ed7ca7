//! A target checked before any runs ([`Planned`]): its folder, its equivalent command line, the
//! work it does, and the run that makes its files.

use std::path::PathBuf;

use gibench_harness::gpu::GpuContext;
use gibench_harness::report;
use gibench_harness::{Error, Result};

use super::targets::{Kind, Target};
use crate::progress::Bars;
use crate::reproduce::job::Job;
use crate::reproduce::ReproduceArgs;

/// A target checked and ready to run into `out`.
pub(super) struct Planned {
    pub(super) target: &'static Target,
    pub(super) out: PathBuf,
    /// The equivalent command line (for the listing and the manifest).
    pub(super) command: String,
    pub(super) work: Work,
    /// `reproduce`'s arguments with `out` set (paper targets).
    pub(super) args: ReproduceArgs,
    pub(super) job: Option<Job>,
}

/// Frames rendered or stepped, and the work units estimates scale with.
#[derive(Clone, Copy, Default)]
pub(super) struct Work {
    pub(super) frames: u64,
    pub(super) units: u64,
}

impl Planned {
    pub(super) fn new(
        target: &'static Target,
        args: &ReproduceArgs,
        out: PathBuf,
    ) -> Result<Planned> {
        let mode = if args.quick { " --quick" } else { "" };
        let mut targs = args.clone();
        targs.out = Some(out.clone());
        match target.kind {
            Kind::Paper(m) => {
                (m.check)(target.name, &targs)?;
                let (frames, units) = (m.work)(target.name, &targs);
                let mut command = format!(
                    "gibench reproduce {}{mode} --out {}",
                    target.name,
                    out.display()
                );
                if let Some(f) = args.frames {
                    command.push_str(&format!(" --frames {f}"));
                }
                if !args.scenes.is_empty() {
                    command.push_str(&format!(" --scenes {}", args.scenes.join(",")));
                }
                if args.html {
                    command.push_str(" --html");
                }
                Ok(Planned {
                    target,
                    out,
                    command,
                    work: Work { frames, units },
                    args: targs,
                    job: None,
                })
            }
            Kind::Command { quick, paper } => {
                if !args.scenes.is_empty() {
                    return Err(Error::param(
                        "scenes",
                        format!(
                            "applies to the paper targets only; '{}' runs the scene its command names",
                            target.name
                        ),
                    ));
                }
                let mut argv: Vec<String> = (if args.quick { quick } else { paper })
                    .split_whitespace()
                    .map(String::from)
                    .collect();
                if let Some(f) = args.frames {
                    if argv[0] != "reference" {
                        set_option(&mut argv, "--frames", &f.to_string());
                    }
                }
                if args.tiny() {
                    // The test size: tiny images (the frames are set above).
                    set_option(&mut argv, "--resolution", "64x48");
                }
                if let Some(a) = &args.assets {
                    set_option(&mut argv, "--assets", &a.display().to_string());
                }
                if args.html && argv[0] != "reference" {
                    argv.push("--html".into());
                }
                set_option(&mut argv, "--out", &out.display().to_string());
                let mut job = Job::plan(&argv).map_err(|e| {
                    Error::Invalid(format!(
                        "target '{}' (gibench {}): {e}",
                        target.name,
                        argv.join(" ")
                    ))
                })?;
                if let Some(smoke) = smoke_marker(args) {
                    job.mark_smoke(smoke);
                }
                let (frames, units) = job.work();
                Ok(Planned {
                    target,
                    out,
                    command: format!("gibench {}", argv.join(" ")),
                    work: Work { frames, units },
                    args: targs,
                    job: Some(job),
                })
            }
        }
    }

    pub(super) fn needs_gpu(&self) -> bool {
        match (&self.job, &self.target.kind) {
            (Some(job), _) => job.needs_gpu(),
            (None, Kind::Paper(m)) => (m.needs_gpu)(self.target.name),
            (None, Kind::Command { .. }) => true,
        }
    }

    /// Runs the target; returns a line saying what it wrote. `GIBENCH_TEST_FAIL_TARGET=NAME`
    /// makes target NAME fail after it has written its files: how the tests try a failure
    /// within a budget (`reproduce all --budget` leaves it out and publishes the rest).
    pub(super) fn run(&self, gpu: Option<&GpuContext>, bars: &Bars) -> Result<String> {
        let done = self.run_target(gpu, bars)?;
        if std::env::var("GIBENCH_TEST_FAIL_TARGET").is_ok_and(|v| v == self.target.name) {
            return Err(Error::Invalid(format!(
                "GIBENCH_TEST_FAIL_TARGET: target '{}' failed on purpose after writing its files",
                self.target.name
            )));
        }
        Ok(done)
    }

    fn run_target(&self, gpu: Option<&GpuContext>, bars: &Bars) -> Result<String> {
        match (&self.job, &self.target.kind) {
            (Some(job), _) => job.execute(gpu, bars),
            (None, Kind::Command { .. }) => Err(Error::Invalid(format!(
                "target '{}' was not planned",
                self.target.name
            ))),
            (None, Kind::Paper(m)) => {
                let (mut tables, runs) = (m.reproduce)(self.target.name, &self.args, gpu, bars)?;
                if let Some(smoke) = smoke_marker(&self.args) {
                    for (table, _) in &mut tables {
                        table.mark_smoke(&smoke);
                    }
                }
                let mut written = Vec::new();
                for (table, stem) in &tables {
                    bars.table(table);
                    written.extend(report::write_tables(table, &self.out, stem)?);
                }
                let mut done = format!(
                    "wrote {}",
                    written
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
                if self.args.html {
                    let page = self.out.join(format!("{}.html", self.target.name));
                    let figures = (m.figures)(&self.out, self.target.name);
                    crate::page::write_page(
                        &page,
                        self.target.description(),
                        tables.into_iter().map(|(t, _)| t).collect(),
                        figures,
                        crate::page::with_folder(&(m.runs_folder)(&self.args), runs),
                    )?;
                    done.push_str(&crate::page::page_line(&page));
                }
                Ok(done)
            }
        }
    }
}

/// Sets `--name value` in a command's arguments (replacing a value it has).
fn set_option(argv: &mut Vec<String>, name: &str, value: &str) {
    match argv.iter().position(|a| a == name) {
        Some(i) if i + 1 < argv.len() => argv[i + 1] = value.to_string(),
        _ => argv.extend([name.to_string(), value.to_string()]),
    }
}

/// The note that marks a paper target's tables as a smoke run's (`--test-size tiny` or a
/// `--frames` override), so that they never pass for benchmark results; `None` for a real run.
fn smoke_marker(args: &crate::reproduce::ReproduceArgs) -> Option<String> {
    let what = match (args.tiny(), args.frames) {
        (true, _) => "--test-size tiny: every target cut to a few frames at tiny sizes".to_string(),
        (false, Some(n)) => format!("--frames {n}: every target's frame count overridden"),
        (false, None) => return None,
    };
    Some(format!("SMOKE RUN ({what}): not benchmark results."))
}
