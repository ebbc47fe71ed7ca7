//! The frame loop every technique runs through: the same frames, the same shared passes and
//! the same profiler.
//!
//! Per frame: upload uniforms → `gbuffer` → `direct-shadow-map` → `direct-light` → the
//! technique's own stages → `compose`. With [`TimingMode::Both`] the whole animation is run
//! twice with a freshly built technique: once timing every stage (flushes between stages), once
//! timing whole frames with no added synchronisation.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde_json::Value;

use crate::cpu::bvh::{SceneBvh, SceneTrees};
use crate::gpu::profiler::{ProfileMode, Profiler};
use crate::gpu::GpuContext;
use crate::kit::passes::{Compose, DirectLight, DrawSet, FrameUniforms, GBuffer, GpuScene};
use crate::kit::technique::{
    FrameContext, Params, PrepareContext, Prepared, SceneContext, Technique, TechniqueInfo,
};
use crate::measure::metrics::{ComponentErrors, QualitySummary, ReferenceWork};
use crate::measure::results::{FrameRange, RunResult, StageKind, SCHEMA_VERSION};
use crate::measure::roofline::{DeviceBounds, StageCost};
use crate::run::bounds::measure_bounds;
use crate::run::quality::{
    CapturedFrame, IndirectComponent, QualityConfig, QualityImages, ReferenceCache,
};
use crate::scene::anim::{FrameClock, FrameState};
use crate::scene::Scene;
use crate::{Error, Result};

/// Stage: the camera's G-buffer.
pub const STAGE_GBUFFER: &str = "gbuffer";
/// Stage: the primary light's shadow map.
pub const STAGE_DIRECT_SHADOW_MAP: &str = "direct-shadow-map";
/// Stage: direct irradiance with PCF.
pub const STAGE_DIRECT_LIGHT: &str = "direct-light";
/// Stage: composing radiance and its display image.
pub const STAGE_COMPOSE: &str = "compose";
/// The stages every run times around the technique's, in frame order (all on the GPU).
pub const RUN_STAGES: [&str; 4] = [
    STAGE_GBUFFER,
    STAGE_DIRECT_SHADOW_MAP,
    STAGE_DIRECT_LIGHT,
    STAGE_COMPOSE,
];

/// The shared GPU stages' declared minimum costs ([`crate::measure::roofline`]), computed once per
/// harness.
struct SharedCosts {
    gbuffer: StageCost,
    /// One face of the direct light's shadow map (times the faces a frame draws).
    direct_shadow_face: StageCost,
    direct_light: StageCost,
}

impl SharedCosts {
    fn new(resolution: [u32; 2], shadow_size: u32, scene: &GpuScene) -> SharedCosts {
        let pixels = resolution[0] as u64 * resolution[1] as u64;
        // `gbuffer`: the scene drawn once ([`crate::kit::passes::GpuScene::draw_cost`]) and every
        // pixel's depth (4 bytes), normal (Rgba16Float, 8) and albedo (4) written once.
        // Fragments hidden behind others and texture reads are not counted: the minimum
        // renders each pixel once.
        let gbuffer = scene
            .draw_cost()
            .plus(StageCost::per_element(pixels, 0, 16, 0));
        // `direct-light`: per pixel the G-buffer's depth (4 bytes) and normal (8) read and the
        // irradiance (Rgba16Float, 8) written; the position rebuilt from depth and moved into
        // the light's map (two 4×4 matrix-vector products, 64 operations) and the 16 PCF taps
        // summed (16). The taps' texels are not counted as bytes: neighbouring pixels share
        // them, so the minimum reads the map's texels once, fewer than the pixels here.
        let direct_light = StageCost::per_element(pixels, 12, 8, 80);
        // `direct-shadow-map`, per face the light needs (the faces a spot light cannot reach are
        // not drawn; the frame's count multiplies this): the scene's positions and indices read
        // once and every vertex moved into the face's view
        // ([`crate::kit::passes::GpuScene::depth_draw_cost`]), and the face's size² depth
        // texels (Depth32Float, 4 bytes) written once. Fragments hidden behind nearer ones are
        // not counted: the minimum writes each texel once.
        let face = shadow_size as u64 * shadow_size as u64;
        let direct_shadow_face = scene
            .depth_draw_cost(DrawSet::StaticAndMovers)
            .plus(StageCost::per_element(face, 0, 4, 0));
        SharedCosts {
            gbuffer,
            direct_shadow_face,
            direct_light,
        }
    }
}

/// A technique's once-per-scene preparation and how long it took.
pub struct PreparedTechnique {
    pub prepared: Prepared,
    /// Wall time of `prepare`, milliseconds.
    pub ms: f64,
}

pub use super::config::{check_resolution, RunConfig, TimingMode, MAX_FRAMES, MAX_RESOLUTION};

/// The last frame's images.
pub struct FrameImages {
    pub size: [u32; 2],
    /// sRGB RGBA8 of the composed image.
    pub display: Vec<u8>,
    /// The technique's irradiance, negative values set to 0 (see [`non_negative`]).
    pub indirect: Vec<[f32; 3]>,
    pub direct: Vec<[f32; 3]>,
    /// The technique's output's negative pixels before [`non_negative`].
    pub negative_indirect: Negatives,
}

/// What [`non_negative`] found below zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Negatives {
    /// Pixels with a negative channel.
    pub pixels: usize,
    /// Of those, the pixels whose negative part (the sum of their negative channels, what is
    /// set to 0) lies below −1 % of the image's mean RGB sum. Half floats keep 11 significant
    /// bits (rounding ≤ 2⁻¹¹ ≈ 0.05 % of a value), so estimates that cancel to about zero
    /// leave less than that unless they are 20 times the mean: a pixel beyond it is the
    /// technique's estimates disagreeing, not rounding.
    pub beyond_rounding: usize,
    /// The lowest negative part relative to the image's mean RGB sum (−1.0: minus the mean).
    pub lowest: f32,
}

/// Sets negative irradiance to 0 and says what was negative. A technique that adds and
/// subtracts estimates (`barczak`'s interpolated light map minus its occluded lights' exact
/// contributions, in half floats) undershoots by rounding where they cancel to about zero and
/// further where the two disagree; no irradiance is negative, the compose pass clamps the same
/// way, and the run warns with the counts. NaN is left for its own warning.
pub fn non_negative(img: &mut [[f32; 3]]) -> Negatives {
    let mean = img.iter().flatten().map(|c| *c as f64).sum::<f64>() / img.len().max(1) as f64;
    let mut found = Negatives::default();
    for p in img.iter_mut() {
        if p.iter().any(|c| *c < 0.0) {
            let negative: f32 = p.iter().map(|c| c.min(0.0)).sum();
            let relative = (negative as f64 / mean) as f32;
            found.pixels += 1;
            found.beyond_rounding += usize::from(relative < -0.01);
            found.lowest = found.lowest.min(relative);
            for c in p.iter_mut() {
                *c = c.max(0.0);
            }
        }
    }
    found
}

/// A memory figure of this process from `/proc/self/status` (`VmRSS`: resident now; `VmHWM`:
/// the peak resident set so far), in MB; `None` where there is no such file (not Linux).
pub fn process_memory_mb(field: &str) -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| {
        l.strip_prefix(field)
            .is_some_and(|rest| rest.starts_with(':'))
    })?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Resets this process's peak resident memory (`VmHWM`) to what is resident now (Linux 4.0 and
/// later: `5` written to `/proc/self/clear_refs`); nothing elsewhere, where the peak then keeps
/// what came before.
fn reset_peak_memory() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The warning for the negative indirect irradiance `neg` found in an image of `pixels` pixels:
/// the pixels past −1 % of the image's mean (the technique's estimates disagreeing) and those
/// within it (half-float rounding) told apart.
fn negative_warning(neg: &Negatives, pixels: usize) -> String {
    let rounding = neg.pixels - neg.beyond_rounding;
    let lowest = 100.0 * neg.lowest;
    let found = format!(
        "indirect irradiance was negative in {} of {pixels} pixels of the last frame",
        neg.pixels
    );
    let cause = if neg.beyond_rounding == 0 {
        format!(
            "all within 1 % of the image's mean below zero (the lowest {lowest:.2} %): half-float \
             rounding where the technique's estimates cancel to about zero"
        )
    } else {
        format!(
            "{} of them beyond -1 % of the image's mean (the lowest {lowest:.1} %), where the \
             technique's estimates undershoot; {rounding} within 1 % of it (half-float rounding \
             where estimates cancel to about zero)",
            neg.beyond_rounding
        )
    };
    format!("{found}: {cause}; set to 0 in the images and the error metrics")
}

/// Largest finite half float: the irradiance buffers (Rgba16Float) clamp above it.
pub const HALF_MAX: f32 = 65504.0;

impl FrameImages {
    /// A warning for each irradiance image (indirect, direct) with pixels at or past
    /// [`HALF_MAX`], where the stored value is clamped, and for each with pixels that are not
    /// numbers (an overflow inside the technique): their error metrics are then not numbers
    /// either.
    pub fn saturation_warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        let neg = self.negative_indirect;
        if neg.pixels > 0 {
            out.push(negative_warning(&neg, self.indirect.len()));
        }
        for (what, img) in [("indirect", &self.indirect), ("direct", &self.direct)] {
            let nan = img.iter().filter(|p| p.iter().any(|c| c.is_nan())).count();
            if nan > 0 {
                out.push(format!(
                    "{what} irradiance is not a number in {nan} pixels of the last frame (an overflow in the technique): lower the light's power or use larger scene units"
                ));
            }
            let n = img
                .iter()
                .filter(|p| p.iter().any(|c| c.abs() >= HALF_MAX))
                .count();
            if n > 0 {
                out.push(format!(
                    "{what} irradiance reached the half-float limit ({HALF_MAX}) in {n} pixels of the last frame, where it is clamped: lower the light's power or use larger scene units"
                ));
            }
        }
        out
    }
}

/// Everything that is shared by all techniques on one scene.
pub struct Harness<'a> {
    pub gpu: &'a GpuContext,
    pub scene: &'a Scene,
    /// The static mesh's tree ([`SceneTrees::static_tree`] of `trees`): built once, shared by
    /// the techniques' CPU rays and the reference.
    pub bvh: Arc<SceneBvh>,
    /// The scene's trees for the reference (its static tree is `bvh`).
    pub trees: SceneTrees<'a>,
    pub gpu_scene: GpuScene,
    pub uniforms: FrameUniforms,
    pub gbuffer: GBuffer,
    pub direct: DirectLight,
    pub clock: FrameClock,
    /// The device's bounds, measured on the first timed run ([`Harness::device_bounds`]).
    bounds: std::sync::OnceLock<DeviceBounds>,
    /// The shared stages' declared costs: G-buffer, direct light.
    shared_costs: SharedCosts,
}

impl<'a> Harness<'a> {
    /// Uploads the scene and builds the shared passes for `config`.
    pub fn new(gpu: &'a GpuContext, scene: &'a Scene, config: &RunConfig) -> Result<Harness<'a>> {
        config.validate()?;
        let max = gpu.max_texture_2d();
        let [w, h] = config.resolution;
        if w > max || h > max {
            return Err(Error::param(
                "resolution",
                format!("{w}x{h} exceeds the adapter's limit of {max} per side"),
            ));
        }
        // The direct light's cube map is a 3x2 atlas of faces.
        if config.shadow_size as u64 * 3 > max as u64 {
            return Err(Error::param(
                "shadow-size",
                format!(
                    "{} needs a {}-texel-wide cube-map atlas (3 faces); the adapter's limit is {max}, so at most {}",
                    config.shadow_size,
                    config.shadow_size as u64 * 3,
                    max / 3
                ),
            ));
        }
        // Images are read back through one buffer (rows padded to 256 bytes, at most 16 bytes a
        // texel).
        let readback = (w as u64 * 16).next_multiple_of(256) * h as u64;
        let max_buffer = gpu.device.limits().max_buffer_size;
        if readback > max_buffer {
            return Err(Error::param(
                "resolution",
                format!(
                    "{w}x{h} needs a {readback}-byte readback buffer; the adapter allows {max_buffer}"
                ),
            ));
        }
        let gpu_scene = GpuScene::new(&gpu.device, &gpu.queue, scene)?;
        let uniforms = FrameUniforms::new(
            &gpu.device,
            &gpu_scene,
            config.resolution,
            config.shadow_size,
            scene.descriptor.settings.shadow_bias,
        );
        let gbuffer = GBuffer::new(gpu, &gpu_scene, &uniforms);
        let direct = DirectLight::new(gpu, &gpu_scene, &uniforms, &gbuffer);
        gpu.check_errors()?;
        let shared_costs = SharedCosts::new(config.resolution, config.shadow_size, &gpu_scene);
        let trees = SceneTrees::new(scene);
        Ok(Harness {
            gpu,
            scene,
            bvh: trees.static_tree().clone(),
            trees,
            gpu_scene,
            uniforms,
            gbuffer,
            direct,
            clock: FrameClock::new(&scene.descriptor),
            bounds: std::sync::OnceLock::new(),
            shared_costs,
        })
    }

    /// The device's bounds ([`crate::measure::roofline`]), measured the first time they are asked for
    /// (never inside a frame) and kept for every later run of this harness.
    pub fn device_bounds(&self) -> Result<DeviceBounds> {
        if let Some(b) = self.bounds.get() {
            return Ok(b.clone());
        }
        let b = measure_bounds(self.gpu)?;
        Ok(self.bounds.get_or_init(|| b).clone())
    }

    /// The fields every technique call sees.
    pub fn scene_context(&self) -> SceneContext<'_> {
        SceneContext {
            gpu: self.gpu,
            scene: self.scene,
            bvh: &self.bvh,
            gpu_scene: &self.gpu_scene,
            gbuffer: &self.gbuffer,
            uniforms: &self.uniforms,
            direct: &self.direct,
        }
    }

    fn prepare_context(&self, config: &RunConfig) -> PrepareContext<'_> {
        PrepareContext {
            base: self.scene_context(),
            resolution: config.resolution,
            seed: config.seed,
            first_frame: self.clock.frame(config.first_frame),
        }
    }

    /// Runs `info`'s once-per-scene preparation (after checking the adapter meets its needs) and
    /// times it; pass the result to every [`Harness::build`], [`Harness::run`] and
    /// [`Harness::measure_quality`] of the same technique, parameters and scene.
    pub fn prepare(
        &self,
        info: &TechniqueInfo,
        params: &Params,
        config: &RunConfig,
    ) -> Result<PreparedTechnique> {
        self.gpu.check_requirements(
            &format!("technique '{}'", info.name),
            info.required_features,
            &(info.required_limits)(),
        )?;
        let start = std::time::Instant::now();
        let prepared = (info.prepare)(params, &self.prepare_context(config))?;
        Ok(PreparedTechnique {
            prepared,
            ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// A profiler for `info`'s frames that records any stage it times beyond the run's own
    /// ([`RUN_STAGES`]) and the ones it declares ([`TechniqueInfo::stages`]) as undeclared
    /// ([`Profiler::undeclared`]), which [`Harness::run`] refuses.
    pub fn profiler(&self, info: &TechniqueInfo, mode: ProfileMode) -> Profiler {
        let mut profiler = Profiler::new(self.gpu, mode);
        profiler.declare_stages(
            RUN_STAGES
                .iter()
                .map(|&n| (n, StageKind::Gpu))
                .chain(info.stages().map(|s| (s.name, s.kind)))
                .collect(),
        );
        profiler
    }

    /// Records one frame: shared passes, the technique's stages, compose.
    pub fn render_frame(
        &self,
        technique: &mut dyn Technique,
        compose: &Compose,
        profiler: &mut Profiler,
        frame: &FrameState,
        measured: bool,
    ) -> Result<()> {
        let gpu = self.gpu;
        profiler.begin_frame(measured);
        self.uniforms.write(&gpu.queue, frame);
        profiler.gpu_stage(gpu, STAGE_GBUFFER, |enc| {
            self.gbuffer.encode(enc, &self.gpu_scene, &self.uniforms)
        })?;
        profiler.stage_cost(STAGE_GBUFFER, self.shared_costs.gbuffer);
        let faces = profiler.gpu_stage(gpu, STAGE_DIRECT_SHADOW_MAP, |enc| {
            self.direct
                .encode_shadow_map(enc, &self.gpu_scene, &self.uniforms, &frame.light)
        })?;
        profiler.stage_cost(
            STAGE_DIRECT_SHADOW_MAP,
            self.shared_costs.direct_shadow_face.scaled(faces as f64),
        );
        profiler.count("direct-shadow-faces", faces as f64);
        profiler.gpu_stage(gpu, STAGE_DIRECT_LIGHT, |enc| {
            self.direct.encode_lighting(enc, &self.gbuffer)
        })?;
        profiler.stage_cost(STAGE_DIRECT_LIGHT, self.shared_costs.direct_light);
        technique.render(&mut FrameContext {
            base: self.scene_context(),
            frame,
            profiler,
        })?;
        profiler.gpu_stage(gpu, STAGE_COMPOSE, |enc| compose.encode(enc, &self.gbuffer))?;
        profiler.stage_cost(STAGE_COMPOSE, compose.cost);
        profiler.end_frame(gpu)
    }

    /// Builds a fresh technique from its preparation and the compose pass bound to its output.
    pub fn build(
        &self,
        info: &TechniqueInfo,
        params: &Params,
        config: &RunConfig,
        prepared: &PreparedTechnique,
    ) -> Result<(Box<dyn Technique>, Compose)> {
        let technique = (info.create)(params, &self.prepare_context(config), &prepared.prepared)?;
        let compose = Compose::new(
            self.gpu,
            &self.gbuffer,
            &self.direct.irradiance_view,
            technique.output(),
            self.scene.descriptor.settings.exposure,
        );
        self.gpu.check_errors()?;
        Ok((technique, compose))
    }

    /// Runs `info` with `params` over the configured frames and returns its result (without
    /// image paths) and the last frame's images. `progress` is called after every frame.
    pub fn run(
        &self,
        info: &TechniqueInfo,
        params: &Params,
        config: &RunConfig,
        prepared: &PreparedTechnique,
        progress: &mut dyn FnMut(),
    ) -> Result<(RunResult, FrameImages)> {
        // Timed before the frames, in the same session: what `gibench compare` divides by.
        let calibration = crate::measure::calibrate::calibration_ms();
        // The device's bounds, once per harness, before any frame of a run that times stages.
        // Their buffers (64 MiB on a CPU adapter) are not the technique's: the peak resident
        // memory so far is kept, and the peak is reset after them where Linux allows it.
        let peak_before_bounds = process_memory_mb("VmHWM");
        let device_bounds = match config.timing {
            TimingMode::Frame => None,
            _ => {
                let measured = self.bounds.get().is_none();
                let b = self.device_bounds()?;
                if measured {
                    reset_peak_memory();
                }
                Some(b)
            }
        };
        let mut stage_costs = BTreeMap::new();
        let mut stages = Vec::new();
        let mut counters = BTreeMap::new();
        let mut frame_result = None;
        let mut first_frame_ms = None;
        let mut images = None;
        let mut hook_warning = None;
        for &mode in config.timing.passes() {
            let (mut technique, compose) = self.build(info, params, config, prepared)?;
            let mut profiler = self.profiler(info, mode);
            let total = config.warmup + config.frames;
            for i in 0..total {
                let f = config.first_frame + i;
                crate::interrupt::check(|| format!("{}'s frame {f}", info.name))?;
                self.gpu.test_lose_device(info.name, f);
                let frame = self.clock.frame(f);
                self.render_frame(
                    technique.as_mut(),
                    &compose,
                    &mut profiler,
                    &frame,
                    i >= config.warmup,
                )
                .map_err(|e| located(e, info.name, profiler.last_stage(), f))?;
                progress();
            }
            let last = config.first_frame + total.saturating_sub(1);
            (profiler.finish(self.gpu))
                .map_err(|e| located(e, info.name, profiler.last_stage(), last))?;
            if !profiler.undeclared().is_empty() {
                return Err(Error::Invalid(format!(
                    "technique '{}' timed stage(s) {} that its TechniqueInfo.stages does not \
                     declare (declared: {})",
                    info.name,
                    profiler.undeclared().join(", "),
                    info.stages().map(|s| s.name).collect::<Vec<_>>().join(", ")
                )));
            }
            hook_warning = profiler.test_hook_warning();
            match mode {
                ProfileMode::Stages => {
                    stages = profiler.stage_results();
                    counters = profiler.counter_results();
                    first_frame_ms = profiler.first_frame_ms();
                    stage_costs = profiler.stage_costs();
                }
                ProfileMode::Frame => {
                    frame_result = profiler.frame_result();
                    if stages.is_empty() {
                        // Frame-only runs still report CPU stages and counters.
                        stages = profiler.stage_results();
                        counters = profiler.counter_results();
                    }
                }
            }
            let (indirect, negative_indirect) = self.read_technique_output(technique.as_ref())?;
            images = Some(FrameImages {
                size: config.resolution,
                display: crate::gpu::image_io::read_texture(self.gpu, &compose.display)?,
                indirect,
                direct: crate::gpu::image_io::read_rgb_f32(self.gpu, &self.direct.irradiance)?,
                negative_indirect,
            });
        }
        let peak_memory_mb = match (peak_before_bounds, process_memory_mb("VmHWM")) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        let result = RunResult {
            schema_version: SCHEMA_VERSION,
            gibench_version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: git_commit(),
            timestamp: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0),
            scene: self.scene.descriptor.name.clone(),
            technique: info.name.to_string(),
            parameters: params.to_map(),
            settings: {
                let mut s = config.settings();
                s.insert(
                    "scene_triangles".into(),
                    Value::from(self.scene.mesh.triangle_count()),
                );
                s.insert(
                    "scene_surface_area".into(),
                    Value::from(self.scene.extent.surface_area as f64),
                );
                s.insert(
                    "shadow_mesh_triangles".into(),
                    Value::from(self.scene.shadow_caster_mesh().triangle_count()),
                );
                s
            },
            resolution: config.resolution,
            frames: FrameRange {
                warmup: config.warmup,
                measured: config.frames,
                first: config.first_frame + config.warmup,
            },
            seed: config.seed,
            timing_mode: config.timing.name().to_string(),
            device: self.gpu.info.clone(),
            stages,
            frame: frame_result,
            counters,
            prepare_ms: Some(prepared.ms),
            first_frame_ms,
            quality: None,
            images: Vec::new(),
            warnings: Vec::new(),
            calibration_ms: Some(calibration),
            peak_memory_mb,
            device_bounds,
            stage_costs,
        };
        let images = images.expect("at least one timing pass");
        let mut result = result;
        result.warnings = images.saturation_warnings();
        result.warnings.extend(hook_warning);
        Ok((result, images))
    }

    /// Runs the technique once more over the frames, untimed, capturing its images at the
    /// frames `quality` chooses, and compares them with the (cached) reference's component
    /// that `quality` names, or else the one the technique declares.
    #[allow(clippy::too_many_arguments)]
    pub fn measure_quality(
        &self,
        info: &TechniqueInfo,
        params: &Params,
        config: &RunConfig,
        prepared: &PreparedTechnique,
        quality: &QualityConfig,
        cache: &ReferenceCache,
        progress: &mut dyn FnMut(),
    ) -> Result<(QualitySummary, QualityImages)> {
        let quality = &quality.for_technique(info, params);
        let (mut technique, compose) = self.build(info, params, config, prepared)?;
        let mut profiler = Profiler::new(self.gpu, ProfileMode::Frame);
        let targets = quality.capture_frames(config.first_frame + config.warmup, config.frames);
        let last = targets.last().map(|t| t.0).unwrap_or(config.first_frame);
        let to_vec3 = |v: Vec<[f32; 3]>| v.into_iter().map(glam::Vec3::from).collect::<Vec<_>>();
        let mut captured = Vec::new();
        for f in config.first_frame..=last {
            crate::interrupt::check(|| format!("{}'s quality frame {f}", info.name))?;
            let frame = self.clock.frame(f);
            self.render_frame(technique.as_mut(), &compose, &mut profiler, &frame, false)
                .map_err(|e| located(e, info.name, profiler.last_stage(), f))?;
            if let Some(&(_, pair_end)) = targets.iter().find(|(g, _)| *g == f) {
                profiler.finish(self.gpu)?;
                captured.push(CapturedFrame {
                    frame: f,
                    pair_end,
                    indirect: to_vec3(self.read_technique_output(technique.as_ref())?.0),
                    radiance: to_vec3(crate::gpu::image_io::read_rgb_f32(
                        self.gpu,
                        &compose.radiance,
                    )?),
                });
            }
            progress();
        }
        profiler.finish(self.gpu)?;
        let settings = quality.reference_settings();
        let mut work = ReferenceWork::default();
        // A frame's reference with `settings`, from the cache or rendered, counted in `work`.
        let mut fetch = |f: u32, settings: &crate::cpu::reference::ReferenceSettings| {
            crate::interrupt::check(|| format!("the reference of frame {f}"))?;
            let frame = self.clock.frame(f);
            let (r, setup) = cache.get_with(&self.trees, &frame, config.resolution, settings)?;
            *(if setup.is_some() {
                &mut work.rendered
            } else {
                &mut work.cached
            }) += 1;
            Ok(r)
        };
        let references = (captured.iter())
            .map(|c| fetch(c.frame, &settings))
            .collect::<Result<Vec<_>>>()?;
        // The reference's flicker floor, from pairs rendered again with the next seed.
        let reseeded = crate::cpu::reference::ReferenceSettings {
            seed: settings.seed.wrapping_add(1),
            ..settings
        };
        let floor = crate::run::quality::flicker_floor(
            &captured,
            &references,
            quality.component(),
            &mut |f| fetch(f, &reseeded),
        )?;
        let exposure = self.scene.descriptor.settings.exposure;
        let (mut summary, images) =
            crate::run::quality::compare(&captured, &references, quality, exposure)?;
        // Every component beside its own, each from the references rendered for it (the same
        // images every technique's column of that component is scored with).
        for component in [IndirectComponent::OneBounce, IndirectComponent::MultiBounce] {
            if component == quality.component() {
                summary.components.push(ComponentErrors::own(&summary));
                continue;
            }
            let other = QualityConfig {
                component: Some(component),
                ..quality.clone()
            };
            let other_settings = other.reference_settings();
            let fetched;
            let refs = if other_settings == settings {
                &references
            } else {
                fetched = (captured.iter())
                    .map(|c| fetch(c.frame, &other_settings))
                    .collect::<Result<Vec<_>>>()?;
                &fetched
            };
            summary.components.push(crate::run::quality::errors_against(
                &captured,
                refs,
                component,
                other.label(),
                exposure,
            )?);
        }
        let builds = self.trees.builds();
        work.static_tree_builds = builds.static_tree;
        work.mover_tree_builds = builds.mover_trees;
        summary.reference_work = Some(work);
        summary.flicker_floor = floor;
        Ok((summary, images))
    }

    /// The technique's irradiance, made [`non_negative`], and what was negative.
    fn read_technique_output(
        &self,
        technique: &dyn Technique,
    ) -> Result<(Vec<[f32; 3]>, Negatives)> {
        let tex = technique.output().texture();
        let mut img = crate::gpu::image_io::read_rgb_f32(self.gpu, tex)?;
        let negative = non_negative(&mut img);
        Ok((img, negative))
    }
}

/// The commit the `gibench` binary was built from, when it said so at start
/// ([`set_build_commit`]); a copied binary (a before/after comparison, a GPU slot's bundle)
/// then records its own build, not the checkout it runs beside.
static BUILD_COMMIT: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Records the commit this process's binary was built from (the root crate's build script
/// stamps it; see [`super::commit`]). "unknown" is ignored: the run-time look-up may do better.
/// A lost device found while rendering `technique`'s frame `frame` (`stage` the GPU stage
/// recorded last), said where; other errors unchanged.
fn located(e: Error, technique: &str, stage: Option<&str>, frame: u32) -> Error {
    match e {
        Error::DeviceLost { what, at } if at.is_empty() => Error::DeviceLost {
            what,
            at: format!(
                "{technique}'s frame {frame}{}",
                stage.map(|s| format!(", stage '{s}'")).unwrap_or_default()
            ),
        },
        e => e,
    }
}

pub fn set_build_commit(commit: &str) {
    if commit != "unknown" {
        let _ = BUILD_COMMIT.set(commit.to_string());
    }
}

/// The commit results record: the binary's own ([`set_build_commit`]), else the source
/// checkout's at run time ([`super::commit::describe`]: tests, benches and examples).
pub fn git_commit() -> String {
    if let Some(commit) = BUILD_COMMIT.get() {
        return commit.clone();
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap_or(std::path::Path::new("."));
    super::commit::describe(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negatives_are_told_apart_from_rounding() {
        // Mean RGB sum: (3 + 3 + 3 - 0.003 - 0.6) / 5 = 1.6794.
        let mut img = vec![
            [1.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-0.001, -0.001, -0.001],
            [0.2, -0.4, -0.4],
        ];
        let n = non_negative(&mut img);
        assert_eq!(n.pixels, 2);
        // -0.003 is 0.18 % of the mean (rounding); the last pixel's negative part, -0.8, is
        // 48 % (its sum, -0.6, would hide part of it).
        assert_eq!(n.beyond_rounding, 1);
        assert!((n.lowest - (-0.8 / 1.6794)).abs() < 1e-4, "{}", n.lowest);
        assert_eq!(img[3], [0.0; 3]);
        assert_eq!(img[4], [0.2, 0.0, 0.0]);
        assert_eq!(non_negative(&mut img), Negatives::default());
    }

    /// The warning names the pixels past -1 % apart from the rounding ones, and says rounding
    /// alone only when nothing is past it. Caught by: one sentence for both (it read "3 below
    /// -1 % ... the lowest -43 % ... (within 1 %: rounding)").
    #[test]
    fn the_negative_warning_tells_undershoot_from_rounding() {
        let both = Negatives {
            pixels: 1000,
            beyond_rounding: 80,
            lowest: -1.22,
        };
        let w = negative_warning(&both, 12288);
        assert!(w.starts_with("indirect irradiance was negative in 1000 of 12288 pixels"));
        assert!(w.contains("80 of them beyond -1 % of the image's mean (the lowest -122.0 %)"));
        assert!(w.contains("undershoot; 920 within 1 % of it (half-float rounding"));
        let rounding = Negatives {
            pixels: 7,
            beyond_rounding: 0,
            lowest: -0.0004,
        };
        let w = negative_warning(&rounding, 3072);
        assert!(w.contains("all within 1 % of the image's mean below zero (the lowest -0.04 %)"));
        assert!(!w.contains("undershoot"), "{w}");
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn the_peak_resident_set_is_read_and_grows_with_use() {
        // Resident first: the peak read after it is at least that (other threads may allocate).
        let now = process_memory_mb("VmRSS").expect("VmRSS on Linux");
        let peak = process_memory_mb("VmHWM").expect("VmHWM on Linux");
        assert!(
            now > 1.0 && peak >= now,
            "peak {peak} MB, resident {now} MB"
        );
        // 64 MB touched page by page raises the peak by about that much.
        let mut block = vec![0u8; 64 << 20];
        for i in (0..block.len()).step_by(4096) {
            block[i] = 1;
        }
        let after = process_memory_mb("VmHWM").unwrap();
        assert!(
            after - now >= 60.0,
            "peak {after} MB after touching 64 MB at {now} MB"
        );
        std::hint::black_box(&block);
        assert_eq!(process_memory_mb("NoSuchField"), None);
    }
}
