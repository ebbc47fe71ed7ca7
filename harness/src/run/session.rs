//! The typed run API: a [`RunSpec`] in (a loaded scene, techniques with parsed parameters,
//! frame settings, optional quality, where the files go), [`RunResult`]s out. The CLI's `run`
//! and `sweep` and every paper reproduction go through [`execute`]; nothing round-trips through
//! command-line strings.
//!
//! Per technique: its preparation once ([`Harness::prepare`], timed as `prepare_ms`), the
//! timing passes ([`Harness::run`]), the quality pass if asked ([`Harness::measure_quality`]),
//! then its files in `out`: `{stem}.json` (written last, atomically), and unless `images` is off
//! `{stem}.png`, `{stem}-indirect.exr`, `{stem}-direct.exr` (and with quality the images of
//! [`QUALITY_IMAGES`]).

use std::path::{Path, PathBuf};

use crate::gpu::image_io::{write_exr, write_png};
use crate::gpu::GpuContext;
use crate::kit::technique::{Params, TechniqueInfo};
use crate::measure::results::RunResult;
use crate::run::quality::{QualityConfig, ReferenceCache};
use crate::run::runner::{Harness, PreparedTechnique, RunConfig, TimingMode};
use crate::scene::Scene;
use crate::{Error, Result};

/// The quality pass's images, by file-name suffix. Of the last compared frame: the technique's
/// composed image, the reference's, the FLIP error map, and the indirect light alone of the
/// technique and of the reference at one shared exposure. Then the film strips of every
/// compared frame's indirect light, the technique's and the reference's, which the HTML page's
/// player shows.
///
/// The technique's images are named after its run's stem (`cornell-laine-compared.png`). The
/// reference's three (indices 1, 4 and 6) are the same for every technique of a run set that
/// compares with the same reference component on the same frames, so they are written once
/// per set, named after the scene and a key of their contents ([`reference_image_name`]:
/// `cornell-3f9a2c1d-reference-frames.png`); each run's `images` lists the ones it was
/// compared with.
pub const QUALITY_IMAGES: [&str; 7] = [
    "-compared.png",
    "-reference.png",
    "-flip.png",
    "-indirect.png",
    "-reference-indirect.png",
    "-frames.png",
    "-reference-frames.png",
];

/// The name of a reference image shared by a run set: `{scene}-{key}{suffix}`, the key being
/// eight hex digits of a hash of the three reference images' pixels and sizes, so that runs
/// compared with the same reference share the files and runs compared with another do not.
pub fn reference_image_name(scene: &str, key: u32, suffix: &str) -> String {
    format!("{scene}-{key:08x}{suffix}")
}

/// The key of [`reference_image_name`] for a quality pass's reference images.
fn reference_key(q: &crate::run::quality::QualityImages) -> u32 {
    use crate::run::quality::fnv1a;
    let mut h = 0xcbf2_9ce4_8422_2325;
    for (size, bytes) in [
        (q.size, &q.reference_display),
        (q.size, &q.reference_indirect_display),
        (
            q.reference_indirect_strip.size,
            &q.reference_indirect_strip.rgba,
        ),
    ] {
        h = fnv1a(&size[0].to_le_bytes(), h);
        h = fnv1a(&size[1].to_le_bytes(), h);
        h = fnv1a(bytes, h);
    }
    (h >> 32) as u32 ^ h as u32
}

/// The run's own images, by file-name suffix after its stem: the composed image, the indirect
/// and the direct light (HDR).
pub const RUN_IMAGES: [&str; 3] = [".png", "-indirect.exr", "-direct.exr"];

/// One technique of a run.
pub struct TechniqueRun {
    pub info: &'static TechniqueInfo,
    pub params: Params,
    /// File name stem of its outputs (unique within the run).
    pub stem: String,
    /// Recorded in its results beside the run's settings (`gibench run --equal-time`'s search).
    pub settings: std::collections::BTreeMap<String, serde_json::Value>,
}

impl TechniqueRun {
    /// `info` with `params` given as (name, value) pairs (defaults for the rest), its files
    /// named `stem`.
    pub fn new(
        info: &'static TechniqueInfo,
        params: &[(&str, &str)],
        stem: impl Into<String>,
    ) -> Result<TechniqueRun> {
        let given: Vec<(String, String)> = params
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Ok(TechniqueRun {
            info,
            params: info.parse_params(&given)?,
            stem: stem.into(),
            settings: Default::default(),
        })
    }
}

/// Everything a run needs (see the module docs).
pub struct RunSpec<'s> {
    pub scene: &'s Scene,
    pub runs: Vec<TechniqueRun>,
    pub config: RunConfig,
    pub quality: Option<QualityConfig>,
    pub cache: ReferenceCache,
    /// Where results and images go.
    pub out: PathBuf,
    /// Write images (PNG, EXR) beside the results.
    pub images: bool,
}

/// What [`execute`] reports as it goes.
pub enum Progress<'a> {
    /// A technique's once-per-scene preparation starts (`TechniqueInfo::prepare` and a first
    /// build: charts, visibility databases, PRT transfer …).
    Preparing(&'a str),
    /// It ended, after this many seconds (the frames that follow make no progress until then).
    Prepared(&'a str, f64),
    /// A technique's pass starts (its name, and "(quality)" for the quality pass).
    Technique(&'a str),
    /// One frame was rendered.
    Frame,
}

impl RunSpec<'_> {
    /// Checks what needs no GPU: the settings and unique stems.
    pub fn validate(&self) -> Result<()> {
        self.config.validate()?;
        for (i, r) in self.runs.iter().enumerate() {
            if self.runs[..i].iter().any(|o| o.stem == r.stem) {
                return Err(Error::Invalid(format!(
                    "two runs would write the same files '{}'",
                    r.stem
                )));
            }
        }
        Ok(())
    }

    /// Frames [`execute`] renders in all (for progress bars).
    pub fn total_frames(&self) -> u64 {
        let passes = if self.config.timing == TimingMode::Both {
            2
        } else {
            1
        } + self.quality.is_some() as u64;
        self.runs.len() as u64 * passes * (self.config.frames + self.config.warmup) as u64
    }
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A technique left out of a run over every technique: it cannot take the scene or does not
/// fit the device (what its preparation said).
#[derive(Clone, Debug)]
pub struct Skipped {
    pub technique: String,
    pub reason: String,
    /// Not completed, or not run, because the GPU device was lost (the driver's word and
    /// where it was found): the command writes the runs completed before it, lists this one,
    /// and fails with [`Skipped::lost`].
    pub device_lost: Option<(String, String)>,
}

impl Skipped {
    /// The lost device's error, for a skipped run the device's loss ended.
    pub fn lost(&self) -> Option<Error> {
        (self.device_lost.clone()).map(|(what, at)| Error::DeviceLost { what, at })
    }
}

/// The first lost-device error among `skipped`.
pub fn device_lost(skipped: &[Skipped]) -> Option<Error> {
    skipped.iter().find_map(Skipped::lost)
}

/// Runs every technique of `spec` on `gpu` and writes its files; returns the results in order.
/// A technique that cannot be prepared fails the run before any frame.
pub fn execute(
    gpu: &GpuContext,
    spec: &RunSpec,
    progress: &mut dyn FnMut(Progress),
) -> Result<Vec<RunResult>> {
    let (results, skipped) = execute_skipping(gpu, spec, false, progress)?;
    match device_lost(&skipped) {
        Some(e) => Err(e),
        None => Ok(results),
    }
}

/// [`execute`], except that with `skip_unfit` a technique whose preparation fails is left out
/// (with its reason) instead of failing the run: for a run over every technique, which should
/// not die for one that cannot take the scene. Skipped or not, it is found out before any
/// frame runs.
pub fn execute_skipping(
    gpu: &GpuContext,
    spec: &RunSpec,
    skip_unfit: bool,
    progress: &mut dyn FnMut(Progress),
) -> Result<(Vec<RunResult>, Vec<Skipped>)> {
    spec.validate()?;
    let harness = Harness::new(gpu, spec.scene, &spec.config)?;
    // Every technique is prepared and built once before any frame runs, so that what does not
    // fit the device (a VPL atlas, a buffer) is reported before the first technique's work.
    let mut prepared = Vec::with_capacity(spec.runs.len());
    let mut skipped = Vec::new();
    for run in &spec.runs {
        progress(Progress::Preparing(run.info.name));
        let started = std::time::Instant::now();
        let ready = harness
            .prepare(run.info, &run.params, &spec.config)
            .and_then(|p| {
                drop(harness.build(run.info, &run.params, &spec.config, &p)?);
                Ok(p)
            });
        progress(Progress::Prepared(
            run.info.name,
            started.elapsed().as_secs_f64(),
        ));
        match ready {
            Ok(p) => prepared.push((run, p)),
            // A lost device is not a technique that does not fit: nothing more can run.
            Err(e @ Error::DeviceLost { .. }) => return Err(e),
            Err(e) if skip_unfit => skipped.push(Skipped {
                technique: run.info.name.to_string(),
                reason: e.to_string(),
                device_lost: None,
            }),
            Err(e) => return Err(e),
        }
    }
    let mut results = Vec::with_capacity(prepared.len());
    // The shared reference images written so far (each once per set).
    let mut references_written = std::collections::HashSet::new();
    for (i, (run, p)) in prepared.iter().enumerate() {
        match execute_one(&harness, spec, run, p, &mut references_written, progress) {
            Ok(r) => results.push(r),
            // A lost device ends the runs; those completed stay, this one and the rest are
            // listed with why (a technique's files are written only once it completes).
            Err(e @ Error::DeviceLost { .. }) => {
                let reason = format!("not completed: {e}");
                let Error::DeviceLost { what, at } = e else {
                    unreachable!("matched above")
                };
                let lost = Some((what, at));
                skipped.push(Skipped {
                    technique: run.info.name.to_string(),
                    reason,
                    device_lost: lost.clone(),
                });
                for (rest, _) in &prepared[i + 1..] {
                    skipped.push(Skipped {
                        technique: rest.info.name.to_string(),
                        reason: "not run: the GPU device was lost before it".into(),
                        device_lost: lost.clone(),
                    });
                }
                break;
            }
            Err(e) => return Err(e),
        }
    }
    Ok((results, skipped))
}

fn execute_one(
    harness: &Harness,
    spec: &RunSpec,
    run: &TechniqueRun,
    prepared: &PreparedTechnique,
    references_written: &mut std::collections::HashSet<String>,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunResult> {
    let (info, params, config) = (run.info, &run.params, &spec.config);
    let out = |suffix: &str| spec.out.join(format!("{}{suffix}", run.stem));
    // Every image a run of this stem may write is replaced: one this run does not write
    // (--no-images, no --quality) is not left from an earlier run beside this run's results.
    for suffix in RUN_IMAGES.iter().chain(&QUALITY_IMAGES) {
        crate::output::replace_in_open_set(&out(suffix))?;
    }
    progress(Progress::Technique(info.name));
    let (mut result, images) = harness.run(info, params, config, prepared, &mut || {
        progress(Progress::Frame)
    })?;
    result.settings.extend(run.settings.clone());
    let mut extra_images = Vec::new();
    if let Some(q) = &spec.quality {
        let label = format!("{} (quality)", info.name);
        progress(Progress::Technique(&label));
        let (summary, qimages) =
            harness.measure_quality(info, params, config, prepared, q, &spec.cache, &mut || {
                progress(Progress::Frame)
            })?;
        result.quality = Some(summary);
        if spec.images {
            let key = reference_key(&qimages);
            let scene = &spec.scene.descriptor.name;
            for (suffix, size, rgba, shared) in [
                (
                    QUALITY_IMAGES[0],
                    qimages.size,
                    &qimages.compared_display,
                    false,
                ),
                (
                    QUALITY_IMAGES[1],
                    qimages.size,
                    &qimages.reference_display,
                    true,
                ),
                (QUALITY_IMAGES[2], qimages.size, &qimages.flip_map, false),
                (
                    QUALITY_IMAGES[3],
                    qimages.size,
                    &qimages.indirect_display,
                    false,
                ),
                (
                    QUALITY_IMAGES[4],
                    qimages.size,
                    &qimages.reference_indirect_display,
                    true,
                ),
                (
                    QUALITY_IMAGES[5],
                    qimages.indirect_strip.size,
                    &qimages.indirect_strip.rgba,
                    false,
                ),
                (
                    QUALITY_IMAGES[6],
                    qimages.reference_indirect_strip.size,
                    &qimages.reference_indirect_strip.rgba,
                    true,
                ),
            ] {
                let name = if shared {
                    reference_image_name(scene, key, suffix)
                } else {
                    format!("{}{suffix}", run.stem)
                };
                if !shared || references_written.insert(name.clone()) {
                    write_png(&spec.out.join(&name), size, rgba)?;
                }
                extra_images.push(name);
            }
        }
    }
    if spec.images {
        let png = out(RUN_IMAGES[0]);
        write_png(&png, images.size, &images.display)?;
        let exr = out(RUN_IMAGES[1]);
        write_exr(&exr, images.size, &images.indirect)?;
        let direct = out(RUN_IMAGES[2]);
        write_exr(&direct, images.size, &images.direct)?;
        result.images = vec![file_name(&png), file_name(&exr), file_name(&direct)];
        result.images.extend(extra_images);
    }
    result.write(&out(".json"))?;
    Ok(result)
}
