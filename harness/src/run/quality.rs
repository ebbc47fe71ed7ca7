//! Image quality of a technique against the CPU reference renderer, and the reference cache.
//!
//! `gibench run --quality` runs the technique once more over the same frames, untimed, reads
//! back its indirect irradiance and composed radiance at chosen frames (in consecutive pairs,
//! so that flicker can be measured), and compares them with the reference for the same frames:
//! RMSE, relative MSE and MAE of indirect irradiance, FLIP of the tonemapped composed images,
//! and temporal instability (see [`crate::measure::metrics`]). Beside the component its
//! technique computes, every run is scored against the one-bounce and the multi-bounce
//! component ([`errors_against`]), so runs of techniques that compute different components
//! compare on one.
//!
//! References are cached on disk by (scene descriptor, frame, resolution, spp, bounces, seed,
//! reference code version), so sweeps and repeated runs reuse them.

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::cpu::bvh::SceneTrees;
use crate::cpu::reference::{self, ReferenceImages, ReferenceSettings};
use crate::measure::metrics::{self, ComponentErrors, FrameQuality, QualitySummary};
use crate::measure::stats::Stats;
use crate::scene::anim::FrameState;
use crate::scene::Scene;
use crate::{Error, Result};

/// Re-exported: the component lives with the reference images it picks from.
pub use crate::cpu::reference::IndirectComponent;

/// Settings of the quality measurement.
#[derive(Clone, Debug)]
pub struct QualityConfig {
    /// Number of consecutive frame pairs compared (spread evenly over the measured frames).
    pub pairs: u32,
    /// Compare every measured frame instead (for per-frame error and lag plots).
    pub all: bool,
    pub reference: ReferenceSettings,
    /// The component to compare with; `None`: each technique's own
    /// ([`crate::kit::technique::TechniqueInfo::reference`]).
    pub component: Option<IndirectComponent>,
}

impl QualityConfig {
    /// This configuration with the component resolved for `info` with `params` (the one they
    /// compute unless overridden).
    pub fn for_technique(
        &self,
        info: &crate::kit::technique::TechniqueInfo,
        params: &crate::kit::technique::Params,
    ) -> QualityConfig {
        QualityConfig {
            component: Some(self.component.unwrap_or((info.reference)(params))),
            ..self.clone()
        }
    }

    /// The component compared with (one-bounce when neither the configuration nor a technique
    /// chose one).
    pub fn component(&self) -> IndirectComponent {
        self.component.unwrap_or(IndirectComponent::OneBounce)
    }

    /// The reference settings actually rendered: one bounce suffices for the one-bounce and
    /// direct components.
    pub fn reference_settings(&self) -> ReferenceSettings {
        let mut s = self.reference;
        if matches!(
            self.component(),
            IndirectComponent::OneBounce | IndirectComponent::Direct
        ) {
            s.bounces = 1;
        }
        s
    }

    /// Label stored in the results, e.g. "one-bounce, 256 spp, seed 1".
    /// The bounces are named only for the multi-bounce component (the others' names say it).
    pub fn label(&self) -> String {
        let s = self.reference_settings();
        let bounces = match self.component() {
            IndirectComponent::MultiBounce => format!("{} bounces, ", s.bounces),
            IndirectComponent::OneBounce | IndirectComponent::Direct => String::new(),
        };
        format!(
            "{}, {} spp, {bounces}seed {}",
            self.component().name(),
            s.spp,
            s.seed
        )
    }

    /// Animation frames to capture, as (frame, is_pair_end) in increasing order: for each of
    /// `pairs` target frames spread over the measured range, the target and the frame before it.
    pub fn capture_frames(&self, first_measured: u32, measured: u32) -> Vec<(u32, bool)> {
        let last = first_measured + measured - 1;
        if self.all {
            return (first_measured..=last)
                .map(|f| (f, f > first_measured))
                .collect();
        }
        if measured < 2 || self.pairs == 0 {
            return vec![(last, false)];
        }
        let mut out: Vec<(u32, bool)> = Vec::new();
        for k in 1..=self.pairs {
            let t =
                first_measured + 1 + ((measured - 2) as u64 * k as u64 / self.pairs as u64) as u32;
            for (f, end) in [(t - 1, false), (t, true)] {
                match out.iter_mut().find(|(g, _)| *g == f) {
                    Some(e) => e.1 |= end,
                    None => out.push((f, end)),
                }
            }
        }
        out.sort();
        out
    }
}

/// On-disk cache of reference images (`None` directory: no caching).
///
/// An entry's name hashes everything the reference depends on: the descriptor, the *loaded*
/// scene's content (every vertex, index and material of the static mesh and the movers, every
/// texel — so an edited glTF or another copy of an asset never reuses a stale entry), the frame,
/// resolution, spp, bounces, seed and the reference code's version. An entry is checked on
/// load (its size, its header and every value finite) and rendered again if bad. The cache
/// keeps at most [`MAX_CACHE_BYTES`], dropping the least recently used entries; temporary
/// files a killed run left are removed when the cache is used.
#[derive(Clone, Debug, Default)]
pub struct ReferenceCache {
    pub dir: Option<PathBuf>,
}

const MAGIC: &[u8; 8] = b"GIBREF1\n";

/// Most bytes of entries the reference cache keeps (4 GiB).
pub const MAX_CACHE_BYTES: u64 = 4 << 30;

/// A hash of the loaded scene's content the reference depends on (see [`ReferenceCache`]).
pub fn scene_content_hash(scene: &Scene) -> u64 {
    let mut h = 0xcbf29ce484222325;
    let mesh = |m: &crate::scene::Mesh, h: &mut u64| {
        *h = fnv1a(bytemuck::cast_slice(&m.positions), *h);
        *h = fnv1a(bytemuck::cast_slice(&m.normals), *h);
        *h = fnv1a(bytemuck::cast_slice(&m.uvs), *h);
        *h = fnv1a(bytemuck::cast_slice(&m.materials), *h);
        *h = fnv1a(bytemuck::cast_slice(&m.indices), *h);
    };
    mesh(&scene.mesh, &mut h);
    for m in &scene.movers {
        h = fnv1a(m.name.as_bytes(), h);
        mesh(&m.mesh, &mut h);
    }
    for m in &scene.materials {
        h = fnv1a(m.name.as_bytes(), h);
        h = fnv1a(bytemuck::bytes_of(&m.base_color), h);
        h = fnv1a(bytemuck::bytes_of(&m.average_color), h);
        h = fnv1a(&m.texture.map_or(u64::MAX, |t| t as u64).to_le_bytes(), h);
    }
    for t in &scene.textures {
        h = fnv1a(&t.width.to_le_bytes(), h);
        h = fnv1a(&t.height.to_le_bytes(), h);
        h = fnv1a(&t.rgba8, h);
    }
    h
}

pub(crate) fn fnv1a(bytes: &[u8], mut h: u64) -> u64 {
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    h
}

impl ReferenceCache {
    /// The cache key's file name for these inputs.
    pub fn file_name(
        scene: &Scene,
        frame: u32,
        resolution: [u32; 2],
        s: &ReferenceSettings,
    ) -> String {
        let desc = serde_json::to_vec(&scene.descriptor).unwrap_or_default();
        let mut h = fnv1a(&desc, 0xcbf29ce484222325);
        h = fnv1a(&scene_content_hash(scene).to_le_bytes(), h);
        let key = format!(
            "{frame}|{}x{}|{}|{}|{}|{}|{}|{}",
            resolution[0],
            resolution[1],
            s.spp,
            s.bounces,
            s.seed,
            reference::REFERENCE_VERSION,
            scene.mesh.triangle_count(),
            env!("CARGO_PKG_VERSION")
        );
        h = fnv1a(key.as_bytes(), h);
        format!(
            "{}-f{frame}-{}x{}-spp{}-b{}-s{}-{h:016x}.bin",
            scene.descriptor.name, resolution[0], resolution[1], s.spp, s.bounces, s.seed
        )
    }

    /// The reference for `frame`, from the cache or rendered (and then cached).
    pub fn get(
        &self,
        scene: &Scene,
        frame: &FrameState,
        resolution: [u32; 2],
        settings: &ReferenceSettings,
    ) -> Result<ReferenceImages> {
        Ok(self.get_timed(scene, frame, resolution, settings)?.0)
    }

    /// [`get`](Self::get), with the tracer's set-up cost when it rendered (`None` from the
    /// cache).
    pub fn get_timed(
        &self,
        scene: &Scene,
        frame: &FrameState,
        resolution: [u32; 2],
        settings: &ReferenceSettings,
    ) -> Result<(ReferenceImages, Option<reference::TracerSetup>)> {
        self.get_with(&SceneTrees::new(scene), frame, resolution, settings)
    }

    /// [`get_timed`](Self::get_timed) for a frame of `trees`' scene: a frame it renders uses
    /// the scene's static tree, built once for every frame asked of the same `trees`.
    pub fn get_with(
        &self,
        trees: &SceneTrees,
        frame: &FrameState,
        resolution: [u32; 2],
        settings: &ReferenceSettings,
    ) -> Result<(ReferenceImages, Option<reference::TracerSetup>)> {
        let scene = trees.scene();
        let path = self
            .dir
            .as_ref()
            .map(|d| d.join(Self::file_name(scene, frame.index, resolution, settings)));
        if let Some(dir) = &self.dir {
            crate::output::remove_stale_temporaries(dir);
        }
        if let Some(p) = &path {
            if let Some(r) = read_cached(p, resolution, settings) {
                // Recently used: kept longest when the cache is trimmed.
                if let Ok(f) = std::fs::File::options().append(true).open(p) {
                    let _ = f.set_modified(std::time::SystemTime::now());
                }
                return Ok((r, None));
            }
        }
        let (r, setup) = reference::render_reference_with(trees, frame, resolution, settings);
        if let (Some(p), Some(dir)) = (&path, &self.dir) {
            crate::output::write_atomic_direct(p, &encode(&r))?;
            trim(dir, MAX_CACHE_BYTES, p);
        }
        Ok((r, Some(setup)))
    }
}

fn encode(r: &ReferenceImages) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    for v in [r.size[0], r.size[1], r.spp, r.bounces] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&r.seed.to_le_bytes());
    out.extend(r.hit.iter().map(|h| *h as u8));
    for img in [
        &r.albedo,
        &r.direct,
        &r.one_bounce,
        &r.multi_bounce,
        &r.radiance,
    ] {
        for v in img.iter() {
            for c in v.to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    out
}

/// Whether `path` starts with a cache entry's header (only entries are ever trimmed).
fn is_entry(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && &head == MAGIC
}

/// Removes the least recently used entries (`*.bin` files that start with an entry's header, by
/// modification time) of the cache in `dir` until they total at most `max` bytes, never `keep`
/// (the entry just written). Other files in the folder are never touched.
fn trim(dir: &Path, max: u64, keep: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut files: Vec<(std::time::SystemTime, u64, PathBuf)> = entries
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "bin") && is_entry(&e.path()))
        .filter_map(|e| {
            let m = e.metadata().ok()?;
            Some((m.modified().ok()?, m.len(), e.path()))
        })
        .collect();
    let mut total: u64 = files.iter().map(|f| f.1).sum();
    files.sort();
    for (_, len, p) in files {
        if total <= max {
            break;
        }
        if p != keep && std::fs::remove_file(&p).is_ok() {
            total -= len;
        }
    }
}

/// A cached reference, or `None` if absent, not matching or damaged (a wrong size or header,
/// a non-finite value): it is then rendered again.
fn read_cached(path: &Path, size: [u32; 2], s: &ReferenceSettings) -> Option<ReferenceImages> {
    let n = (size[0] * size[1]) as usize;
    let expected = 8 + 24 + n + 5 * n * 12;
    if std::fs::metadata(path).ok()?.len() != expected as u64 {
        return None;
    }
    let bytes = crate::error::read_bounded(path, expected as u64).ok()?;
    if bytes.len() != expected || &bytes[..8] != MAGIC {
        return None;
    }
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let seed = u64::from_le_bytes(bytes[24..32].try_into().unwrap());
    if [u32_at(8), u32_at(12), u32_at(16), u32_at(20)] != [size[0], size[1], s.spp, s.bounces]
        || seed != s.seed
    {
        return None;
    }
    let hit: Vec<bool> = bytes[32..32 + n].iter().map(|b| *b != 0).collect();
    let mut o = 32 + n;
    let mut img = || {
        let v: Vec<Vec3> = (0..n)
            .map(|i| {
                let f = |c: usize| {
                    f32::from_le_bytes(
                        bytes[o + i * 12 + 4 * c..o + i * 12 + 4 * c + 4]
                            .try_into()
                            .unwrap(),
                    )
                };
                Vec3::new(f(0), f(1), f(2))
            })
            .collect();
        o += n * 12;
        v
    };
    let (albedo, direct, one_bounce, multi_bounce, radiance) = (img(), img(), img(), img(), img());
    if [&albedo, &direct, &one_bounce, &multi_bounce, &radiance]
        .iter()
        .any(|img| img.iter().any(|v| !v.is_finite()))
    {
        return None;
    }
    Some(ReferenceImages {
        size,
        spp: s.spp,
        bounces: s.bounces,
        seed: s.seed,
        hit,
        albedo,
        direct,
        one_bounce,
        multi_bounce,
        radiance,
    })
}

/// A technique's images at one frame.
pub struct CapturedFrame {
    pub frame: u32,
    pub pair_end: bool,
    pub indirect: Vec<Vec3>,
    pub radiance: Vec<Vec3>,
}

/// Images kept for a person to look at (sRGB RGBA8). Of the last compared frame: the
/// technique's composed image and the reference's at the scene's exposure, the FLIP map, and
/// the indirect light alone (ρ/π · E_indirect) of both at one exposure derived from the
/// reference ([`indirect_exposure`]), so every technique compared on the same frame shares it.
/// Of the compared frames (the last [`FilmStrip::MAX_FRAMES`]), in order: the indirect light
/// alone of the technique and of the reference at that same exposure, as film strips
/// ([`FilmStrip`]) that the HTML page plays.
pub struct QualityImages {
    pub size: [u32; 2],
    pub compared_display: Vec<u8>,
    pub reference_display: Vec<u8>,
    pub flip_map: Vec<u8>,
    pub indirect_display: Vec<u8>,
    pub reference_indirect_display: Vec<u8>,
    /// The compared frames' technique indirect images, tiled.
    pub indirect_strip: FilmStrip,
    /// The same frames' reference indirect images, tiled the same way.
    pub reference_indirect_strip: FilmStrip,
}

/// Frames of one size tiled into one image, left to right and then top to bottom, in
/// [`FilmStrip::columns`] columns: one file per run for the HTML page's frame player, which
/// shows one tile at a time.
pub struct FilmStrip {
    /// The whole image's size.
    pub size: [u32; 2],
    /// sRGB RGBA8, row-major.
    pub rgba: Vec<u8>,
}

impl FilmStrip {
    /// The widest a strip grows before it wraps (pixels): wide enough for a row of frames at
    /// the default resolutions, small enough for every browser and image viewer.
    pub const MAX_WIDTH: u32 = 8192;
    /// The most frames a strip holds: the last ones compared (consecutive ones with
    /// `--quality-all`, so the player still shows flicker and lag), which keeps a strip of a
    /// 60-frame run near a megabyte.
    pub const MAX_FRAMES: usize = 16;
    /// The widest tile (pixels): frames wider are shrunk by a whole factor (a box filter), the
    /// size the page shows them at.
    pub const MAX_TILE_WIDTH: u32 = 256;

    /// The indices, among `compared` frames, of those a strip holds ([`Self::MAX_FRAMES`]).
    pub fn shown(compared: usize) -> std::ops::Range<usize> {
        compared.saturating_sub(Self::MAX_FRAMES)..compared
    }

    /// The whole factor a frame of `size` is shrunk by, and the tile size that gives.
    pub fn shrink(size: [u32; 2]) -> (u32, [u32; 2]) {
        let f = size[0].div_ceil(Self::MAX_TILE_WIDTH).max(1);
        (f, [(size[0] / f).max(1), (size[1] / f).max(1)])
    }

    /// `rgba` (`size`, RGBA8) shrunk by [`Self::shrink`]'s factor: each tile pixel the mean of
    /// its f × f block.
    pub fn shrunk(size: [u32; 2], rgba: &[u8]) -> Vec<u8> {
        let (f, [w, h]) = Self::shrink(size);
        if f == 1 {
            return rgba.to_vec();
        }
        let mut out = vec![0u8; 4 * (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                for c in 0..4 {
                    let mut sum = 0u32;
                    for dy in 0..f {
                        for dx in 0..f {
                            let i = ((y * f + dy) * size[0] + x * f + dx) as usize * 4 + c;
                            sum += rgba[i] as u32;
                        }
                    }
                    out[(y * w + x) as usize * 4 + c] = ((sum + f * f / 2) / (f * f)) as u8;
                }
            }
        }
        out
    }

    /// The number of columns a strip of `frames` tiles `width` pixels wide is laid out in (the
    /// HTML page computes the same from the run's resolution and frame count).
    pub fn columns(width: u32, frames: usize) -> usize {
        (Self::MAX_WIDTH / width.max(1)).clamp(1, frames.max(1) as u32) as usize
    }

    /// `tiles` (each `tile` in size, RGBA8) tiled in [`FilmStrip::columns`] columns; unused
    /// cells of the last row are transparent.
    pub fn tile(tile: [u32; 2], tiles: &[Vec<u8>]) -> FilmStrip {
        let columns = Self::columns(tile[0], tiles.len());
        let rows = tiles.len().div_ceil(columns).max(1);
        let size = [tile[0] * columns as u32, tile[1] * rows as u32];
        let row_bytes = 4 * tile[0] as usize;
        let mut rgba = vec![0u8; 4 * size[0] as usize * size[1] as usize];
        for (i, t) in tiles.iter().enumerate() {
            let (cx, cy) = (i % columns, i / columns);
            for y in 0..tile[1] as usize {
                let dst =
                    ((cy * tile[1] as usize + y) * size[0] as usize + cx * tile[0] as usize) * 4;
                rgba[dst..dst + row_bytes].copy_from_slice(&t[y * row_bytes..(y + 1) * row_bytes]);
            }
        }
        FilmStrip { size, rgba }
    }
}

/// `rgb` (sRGB8 triples) with an opaque alpha channel.
fn opaque_rgba(rgb: &[u8]) -> Vec<u8> {
    rgb.chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect()
}

/// The indirect light alone, ρ/π · `e`, over the reference's hits (black elsewhere).
fn indirect_radiance(r: &ReferenceImages, e: &[Vec3]) -> Vec<Vec3> {
    r.hit
        .iter()
        .zip(&r.albedo)
        .zip(e)
        .map(|((h, a), e)| {
            if *h {
                *a * std::f32::consts::FRAC_1_PI * *e
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// The exposure that puts the 99th percentile of the reference's indirect radiance (the
/// brightest channel, over the pixels that hit geometry) at 0.9 before sRGB encoding; 1 where
/// there is no indirect light.
pub fn indirect_exposure(reference_indirect: &[Vec3], hit: &[bool]) -> f32 {
    let mut v: Vec<f32> = reference_indirect
        .iter()
        .zip(hit)
        .filter(|(_, h)| **h)
        .map(|(c, _)| c.max_element())
        .filter(|x| x.is_finite())
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    let i = ((v.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = v.select_nth_unstable_by(i, f32::total_cmp);
    if *p99 > 0.0 {
        0.9 / *p99
    } else {
        1.0
    }
}

/// The reference's flicker floor ([`metrics::flicker_floor`]) of a quality pass: over up to
/// three of its compared pairs (spread over them, the last included), each rendered again by
/// `again` (a frame's reference with the next seed), the mean; `None` when no pair was compared.
pub fn flicker_floor(
    captured: &[CapturedFrame],
    references: &[ReferenceImages],
    component: IndirectComponent,
    again: &mut dyn FnMut(u32) -> Result<ReferenceImages>,
) -> Result<Option<f64>> {
    let pairs: Vec<usize> = (1..captured.len())
        .filter(|&i| captured[i].pair_end && captured[i - 1].frame + 1 == captured[i].frame)
        .collect();
    let chosen = match pairs.len() {
        0..=3 => pairs,
        n => vec![pairs[0], pairs[n / 2], pairs[n - 1]],
    };
    let mut floors = Vec::new();
    for &i in &chosen {
        let (r1p, r1c) = (again(captured[i - 1].frame)?, again(captured[i].frame)?);
        let (r0p, r0c) = (&references[i - 1], &references[i]);
        let mask: Vec<bool> = r0p
            .hit
            .iter()
            .zip(&r0c.hit)
            .map(|(a, b)| *a && *b)
            .collect();
        floors.push(metrics::flicker_floor(
            component.of(&r1p),
            component.of(&r1c),
            component.of(r0p),
            component.of(r0c),
            &mask,
        ));
    }
    Ok((!floors.is_empty()).then(|| floors.iter().sum::<f64>() / floors.len() as f64))
}

/// The tonemapped composed images of a captured frame and of its reference (direct light plus
/// `component`), and the FLIP between them over the pixels that hit geometry.
fn composed_flip(
    c: &CapturedFrame,
    r: &ReferenceImages,
    component: IndirectComponent,
    exposure: f32,
) -> Result<(Vec<u8>, Vec<u8>, metrics::FlipResult)> {
    let test8 = metrics::tonemap_srgb8(&c.radiance, exposure);
    let ref8 = metrics::tonemap_srgb8(&r.radiance_with(component.of(r)), exposure);
    let flip = metrics::flip_masked(&test8, &ref8, r.size, &r.hit)?;
    Ok((test8, ref8, flip))
}

/// The captured frames' errors against `component` of their `references` (one per frame, in
/// order), labelled `reference` ([`QualityConfig::label`] of that component): what a run is
/// scored with beside its own component ([`ComponentErrors`]).
pub fn errors_against(
    captured: &[CapturedFrame],
    references: &[ReferenceImages],
    component: IndirectComponent,
    reference: String,
    exposure: f32,
) -> Result<ComponentErrors> {
    let (mut rel_mse, mut bias, mut flip) = (Vec::new(), Vec::new(), Vec::new());
    for (c, r) in captured.iter().zip(references) {
        let target = component.of(r);
        rel_mse.push(metrics::relative_mse(&c.indirect, target, &r.hit));
        bias.push(metrics::relative_bias(&c.indirect, target, &r.hit));
        flip.push(composed_flip(c, r, component, exposure)?.2.mean);
    }
    Ok(ComponentErrors {
        component: component.name().to_string(),
        reference,
        rel_mse: Stats::of(&rel_mse),
        bias: Stats::of(&bias),
        flip_mean: Stats::of(&flip),
    })
}

/// Compares captured frames with their references.
pub fn compare(
    captured: &[CapturedFrame],
    references: &[ReferenceImages],
    config: &QualityConfig,
    exposure: f32,
) -> Result<(QualitySummary, QualityImages)> {
    let mut frames = Vec::new();
    let mut images = None;
    for (i, (c, r)) in captured.iter().zip(references).enumerate() {
        let component = config.component().of(r);
        let size = r.size;
        let (test8, ref8, flip) = composed_flip(c, r, config.component(), exposure)?;
        let temporal = if c.pair_end && i > 0 && captured[i - 1].frame + 1 == c.frame {
            let (pc, pr) = (&captured[i - 1], &references[i - 1]);
            let mask: Vec<bool> = r.hit.iter().zip(&pr.hit).map(|(a, b)| *a && *b).collect();
            Some(metrics::temporal_instability(
                &pc.indirect,
                &c.indirect,
                config.component().of(pr),
                component,
                &mask,
            ))
        } else {
            None
        };
        frames.push(FrameQuality {
            frame: c.frame,
            rmse: metrics::rmse(&c.indirect, component, &r.hit),
            rel_mse: metrics::relative_mse(&c.indirect, component, &r.hit),
            mae: metrics::mae(&c.indirect, component, &r.hit),
            flip_mean: flip.mean,
            bias: metrics::relative_bias(&c.indirect, component, &r.hit),
            temporal,
        });
        if i + 1 == captured.len() {
            let (test_ind, ref_ind) = (
                indirect_radiance(r, &c.indirect),
                indirect_radiance(r, component),
            );
            let k = indirect_exposure(&ref_ind, &r.hit);
            // Every compared frame's indirect light at this frame's exposure, so that a change
            // of brightness from frame to frame shows.
            let strip = |image: &dyn Fn(usize) -> Vec<Vec3>| {
                let tiles: Vec<Vec<u8>> = FilmStrip::shown(captured.len())
                    .map(|j| {
                        let rgba = opaque_rgba(&metrics::tonemap_srgb8(&image(j), k));
                        FilmStrip::shrunk(size, &rgba)
                    })
                    .collect();
                FilmStrip::tile(FilmStrip::shrink(size).1, &tiles)
            };
            let component_of = config.component();
            images = Some(QualityImages {
                size,
                compared_display: opaque_rgba(&test8),
                reference_display: opaque_rgba(&ref8),
                flip_map: metrics::flip_error_png(&flip, size),
                indirect_display: opaque_rgba(&metrics::tonemap_srgb8(&test_ind, k)),
                reference_indirect_display: opaque_rgba(&metrics::tonemap_srgb8(&ref_ind, k)),
                indirect_strip: strip(&|j| {
                    indirect_radiance(&references[j], &captured[j].indirect)
                }),
                reference_indirect_strip: strip(&|j| {
                    indirect_radiance(&references[j], component_of.of(&references[j]))
                }),
            });
        }
    }
    let images = images
        .ok_or_else(|| Error::Invalid("no frames were compared with the reference".into()))?;
    Ok((metrics::summarize(config.label(), frames), images))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip holds the last 16 compared frames, each at most 256 pixels wide: a 512x8 frame
    /// becomes a 256x4 tile whose pixels are the means of 2x2 blocks.
    #[test]
    fn film_strips_keep_the_last_frames_and_shrink_wide_ones() {
        assert_eq!(FilmStrip::shown(4), 0..4);
        assert_eq!(FilmStrip::shown(60), 44..60);
        assert_eq!(FilmStrip::shrink([256, 192]), (1, [256, 192]));
        assert_eq!(FilmStrip::shrink([1024, 768]), (4, [256, 192]));
        let size = [512u32, 8];
        let rgba: Vec<u8> = (0..size[0] * size[1])
            .flat_map(|i| [if i % 2 == 0 { 10 } else { 20 }, 0, 255, 255])
            .collect();
        let tile = FilmStrip::shrunk(size, &rgba);
        assert_eq!(tile.len(), 4 * 256 * 4);
        assert!(
            tile.chunks_exact(4).all(|p| p == [15, 0, 255, 255]),
            "{:?}",
            &tile[..8]
        );
        let strip = FilmStrip::tile([2, 1], &[vec![1; 8], vec![2; 8], vec![3; 8]]);
        assert_eq!(strip.size, [6, 1]);
        assert_eq!(strip.rgba[..8], [1; 8]);
        assert_eq!(strip.rgba[16..], [3; 8]);
    }
    use crate::scene::assets::AssetPaths;

    fn tiny(value: f32) -> ReferenceImages {
        let n = 4;
        let img = vec![Vec3::splat(value); n];
        ReferenceImages {
            size: [2, 2],
            spp: 1,
            bounces: 1,
            seed: 0,
            hit: vec![true; n],
            albedo: img.clone(),
            direct: img.clone(),
            one_bounce: img.clone(),
            multi_bounce: img.clone(),
            radiance: img,
        }
    }

    /// The key follows the loaded content: a changed material colour or a moved vertex gives
    /// another entry; the same scene loaded twice the same one.
    #[test]
    fn the_cache_key_follows_the_scenes_content() {
        let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
        let frame = crate::scene::anim::FrameClock::new(&scene.descriptor).frame(0);
        let s = ReferenceSettings {
            spp: 4,
            bounces: 1,
            seed: 0,
        };
        let key = |sc: &Scene| ReferenceCache::file_name(sc, frame.index, [8, 8], &s);
        let again = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
        assert_eq!(key(&scene), key(&again));
        let mut recoloured = scene.clone();
        recoloured.materials[0].base_color *= 0.5;
        assert_ne!(key(&scene), key(&recoloured));
        let mut moved = scene.clone();
        moved.mesh.positions[0].x += 1.0;
        assert_ne!(key(&scene), key(&moved));
    }

    /// A damaged entry (a NaN, a truncated file) is not used; a good one is.
    #[test]
    fn damaged_entries_are_rendered_again() {
        let dir = tempfile::tempdir().unwrap();
        let s = ReferenceSettings {
            spp: 1,
            bounces: 1,
            seed: 0,
        };
        let good = dir.path().join("good.bin");
        std::fs::write(&good, encode(&tiny(1.0))).unwrap();
        assert!(read_cached(&good, [2, 2], &s).is_some());
        let nan = dir.path().join("nan.bin");
        std::fs::write(&nan, encode(&tiny(f32::NAN))).unwrap();
        assert!(read_cached(&nan, [2, 2], &s).is_none());
        let bytes = encode(&tiny(1.0));
        let cut = dir.path().join("cut.bin");
        std::fs::write(&cut, &bytes[..bytes.len() - 1]).unwrap();
        assert!(read_cached(&cut, [2, 2], &s).is_none());
    }

    /// Trimming drops the least recently used entries until the rest fit, never the new one.
    #[test]
    fn the_cache_is_trimmed_oldest_first() {
        let dir = tempfile::tempdir().unwrap();
        let t0 = std::time::SystemTime::now() - std::time::Duration::from_secs(100);
        let mut entry = MAGIC.to_vec();
        entry.resize(100, 0);
        // Not an entry, and the oldest file: never trimmed.
        let foreign = dir.path().join("mine.bin");
        std::fs::write(&foreign, vec![1u8; 1000]).unwrap();
        std::fs::File::options()
            .append(true)
            .open(&foreign)
            .unwrap()
            .set_modified(std::time::SystemTime::UNIX_EPOCH)
            .unwrap();
        for (i, name) in ["a.bin", "b.bin", "c.bin"].iter().enumerate() {
            let p = dir.path().join(name);
            std::fs::write(&p, &entry).unwrap();
            let f = std::fs::File::options().append(true).open(&p).unwrap();
            f.set_modified(t0 + std::time::Duration::from_secs(10 * i as u64))
                .unwrap();
        }
        let newest = dir.path().join("a.bin");
        trim(dir.path(), 200, &newest);
        let left: Vec<bool> = ["a.bin", "b.bin", "c.bin"]
            .iter()
            .map(|n| dir.path().join(n).exists())
            .collect();
        assert_eq!(left, [true, false, true]);
        assert!(foreign.exists());
    }
}
