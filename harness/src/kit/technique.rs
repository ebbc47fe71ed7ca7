//! The technique interface: plain structs built from named, typed parameters (in the spirit of
//! Mitsuba's plugin properties: a parameter nobody declared is an error that names it; each
//! technique reads them once into its own typed settings struct), that declare the GPU
//! features and limits they need, the reference component they approximate and their
//! conformance bounds, prepare once per scene, and then each frame record named stages and
//! return the indirect irradiance texture.

use std::collections::BTreeMap;

use serde_json::Value;

use crate::cpu::bvh::SceneBvh;
pub use crate::cpu::reference::IndirectComponent;
use crate::gpu::profiler::Profiler;
use crate::gpu::GpuContext;
use crate::kit::passes::{DirectLight, FrameUniforms, GBuffer, GpuScene};
use crate::measure::results::StageKind;
use crate::scene::anim::FrameState;
use crate::scene::Scene;
use crate::{Error, Result};

/// The type of a parameter, with its valid range.
#[derive(Clone, Copy, Debug)]
pub enum ParamKind {
    /// An integer in `[min, max]`.
    Int { min: i64, max: i64 },
    /// A finite number in `[min, max]`.
    Float { min: f64, max: f64 },
    /// `true` / `false`.
    Bool,
    /// A tile layout `NxM`, each in `[1, 64]`.
    Tiles,
    /// One of the given words.
    Choice(&'static [&'static str]),
}

/// One declared parameter.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    pub name: &'static str,
    pub kind: ParamKind,
    /// The default, written as on the command line.
    pub default: &'static str,
    pub doc: &'static str,
}

/// Parsed parameter values (defaults applied), keyed by name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Params {
    values: BTreeMap<String, Value>,
}

fn parse_value(technique: &str, spec: &ParamSpec, raw: &str) -> Result<Value> {
    let bad = |what: String| {
        Error::param(
            format!("{technique}.{}", spec.name),
            format!("{what} (got '{raw}')"),
        )
    };
    let raw = raw.trim();
    Ok(match spec.kind {
        ParamKind::Int { min, max } => {
            let v: i64 = raw.parse().map_err(|_| bad("expected an integer".into()))?;
            if v < min || v > max {
                return Err(bad(format!("expected an integer in [{min}, {max}]")));
            }
            Value::from(v)
        }
        ParamKind::Float { min, max } => {
            let v: f64 = raw.parse().map_err(|_| bad("expected a number".into()))?;
            if !v.is_finite() || v < min || v > max {
                return Err(bad(format!("expected a number in [{min}, {max}]")));
            }
            Value::from(v)
        }
        ParamKind::Bool => Value::from(match raw {
            "true" | "1" | "yes" | "on" => true,
            "false" | "0" | "no" | "off" => false,
            _ => return Err(bad("expected true or false".into())),
        }),
        ParamKind::Tiles => {
            let (n, m) = parse_tiles(raw)
                .ok_or_else(|| bad("expected tiles as NxM with N, M in [1, 64]".into()))?;
            Value::from(format!("{n}x{m}"))
        }
        ParamKind::Choice(words) => {
            if !words.contains(&raw) {
                return Err(bad(format!("expected one of {}", words.join(", "))));
            }
            Value::from(raw)
        }
    })
}

/// Parses `NxM` (N, M in 1..=64).
pub fn parse_tiles(s: &str) -> Option<(u32, u32)> {
    let (a, b) = s.split_once(['x', 'X'])?;
    let (n, m): (u32, u32) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
    ((1..=64).contains(&n) && (1..=64).contains(&m)).then_some((n, m))
}

impl Params {
    /// Parses `key=value` pairs for `technique` against its declared `specs`. Every key must be
    /// declared (otherwise the error names the key and lists the declared ones); missing keys
    /// take their defaults.
    pub fn parse(
        technique: &str,
        specs: &[ParamSpec],
        given: &[(String, String)],
    ) -> Result<Params> {
        let mut values = BTreeMap::new();
        for spec in specs {
            values.insert(
                spec.name.to_string(),
                parse_value(technique, spec, spec.default)?,
            );
        }
        for (k, v) in given {
            let spec = specs.iter().find(|s| s.name == k).ok_or_else(|| {
                let known: Vec<&str> = specs.iter().map(|s| s.name).collect();
                Error::param(
                    k.clone(),
                    format!(
                        "technique '{technique}' has no such parameter; it has: {}",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                )
            })?;
            values.insert(k.clone(), parse_value(technique, spec, v)?);
        }
        Ok(Params { values })
    }

    /// All values, for the results file.
    pub fn to_map(&self) -> BTreeMap<String, Value> {
        self.values.clone()
    }

    /// Whether `name` was declared.
    pub fn has(&self, name: &str) -> bool {
        self.values.contains_key(name)
    }

    fn get(&self, name: &str) -> &Value {
        self.values
            .get(name)
            .unwrap_or_else(|| panic!("parameter '{name}' was not declared by the technique"))
    }
    /// An integer parameter (declared with [`ParamKind::Int`]).
    pub fn int(&self, name: &str) -> i64 {
        self.get(name).as_i64().expect("declared as Int")
    }
    /// A number parameter (declared with [`ParamKind::Float`]).
    pub fn float(&self, name: &str) -> f64 {
        self.get(name).as_f64().expect("declared as Float")
    }
    /// A boolean parameter.
    pub fn bool(&self, name: &str) -> bool {
        self.get(name).as_bool().expect("declared as Bool")
    }
    /// A tiles parameter as (columns, rows).
    pub fn tiles(&self, name: &str) -> (u32, u32) {
        parse_tiles(self.get(name).as_str().expect("declared as Tiles")).expect("validated")
    }
    /// A choice parameter.
    pub fn choice(&self, name: &str) -> &str {
        self.get(name).as_str().expect("declared as Choice")
    }
}

/// What every technique call sees of the scene and the shared passes (the fields
/// [`PrepareContext`] and [`FrameContext`] share; both deref to it).
#[derive(Clone, Copy)]
pub struct SceneContext<'a> {
    pub gpu: &'a GpuContext,
    /// The scene, with its per-scene constants in [`Scene::extent`].
    pub scene: &'a Scene,
    /// CPU ray casts over the static mesh.
    pub bvh: &'a SceneBvh,
    pub gpu_scene: &'a GpuScene,
    pub gbuffer: &'a GBuffer,
    pub uniforms: &'a FrameUniforms,
    /// The primary light's shadow map and direct irradiance ([`DirectLight::wgsl`] and
    /// [`DirectLight::light_group`] give technique shaders the same lookup).
    pub direct: &'a DirectLight,
}

/// What a technique gets once per scene and when it is built.
pub struct PrepareContext<'a> {
    pub base: SceneContext<'a>,
    pub resolution: [u32; 2],
    pub seed: u64,
    /// The first animation frame the technique will render (warm-up included).
    pub first_frame: FrameState,
}

impl<'a> std::ops::Deref for PrepareContext<'a> {
    type Target = SceneContext<'a>;
    fn deref(&self) -> &SceneContext<'a> {
        &self.base
    }
}

/// What a technique gets every frame.
pub struct FrameContext<'a> {
    pub base: SceneContext<'a>,
    pub frame: &'a FrameState,
    /// Record stages through this: `profiler.gpu_stage(gpu, "name", |encoder| ...)` and
    /// `profiler.cpu_stage("name", || ...)`.
    pub profiler: &'a mut Profiler,
}

impl<'a> std::ops::Deref for FrameContext<'a> {
    type Target = SceneContext<'a>;
    fn deref(&self) -> &SceneContext<'a> {
        &self.base
    }
}

/// A real-time indirect-illumination technique.
pub trait Technique {
    /// Records this frame's stages. The indirect irradiance (see the harness's radiometric
    /// convention) must be in [`Technique::output`] once the recorded stages have run.
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()>;
    /// Full-resolution `Rgba16Float` indirect irradiance.
    fn output(&self) -> &wgpu::TextureView;
}

/// What a technique prepares once per scene (PRT transfer, point sets, voxel tables, …): made
/// by [`TechniqueInfo::prepare`], shared by both timing passes and the quality pass, and timed
/// as its own figure (`prepare_ms` in the results).
pub type Prepared = Box<dyn std::any::Any + Send + Sync>;

/// A technique whose output approximates one bounce of indirect light whatever its parameters.
pub fn one_bounce(_: &Params) -> IndirectComponent {
    IndirectComponent::OneBounce
}

/// A technique whose output approximates every bounce of indirect light whatever its parameters.
pub fn multi_bounce(_: &Params) -> IndirectComponent {
    IndirectComponent::MultiBounce
}

/// A technique's quality knob: the integer parameter whose larger values cost more time per
/// frame and give less error (VPLs, propagation iterations), searched over its declared range
/// by `gibench run --equal-time` for the largest value whose frame fits a budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knob {
    /// The parameter (an integer one of the technique's).
    pub param: &'static str,
    /// Why time and error follow it ("each VPL adds a shadow map and a gather term").
    pub why: &'static str,
}

impl Knob {
    /// The VPL count of an instant-radiosity technique.
    pub const VPLS: Knob = Knob {
        param: "vpls",
        why: "each VPL adds a shadow map and a term to every pixel's gather; more VPLs, less noise",
    };
}

/// The `prepare` of a technique that prepares nothing.
pub fn prepare_nothing(_: &Params, _: &PrepareContext) -> Result<Prepared> {
    Ok(Box::new(()))
}

/// What the conformance test (`tests/it/conformance.rs`) demands of a technique (96x72, after
/// three frames), beyond finite output, zero where no geometry is hit and identical output from
/// two builds: on each scene an entry names, its indirect irradiance against its
/// [`TechniqueInfo::reference`] component within a band around the [`KnownBias`] it declares
/// there, at its published defaults and at a converged setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conformance {
    /// At the published defaults, one entry per scene (every technique: the four Cornell boxes;
    /// a technique may add others, which the test then runs it on). Held within
    /// [`KnownBias::FACTOR`].
    pub defaults: &'static [KnownBias],
    /// At a setting where the technique's own approximations are small.
    pub converged: Converged,
}

impl Conformance {
    /// The published-defaults entry for `scene`.
    pub fn on(&self, scene: &str) -> Option<&KnownBias> {
        self.defaults.iter().find(|k| k.scene == scene)
    }
}

/// A technique's converged conformance: a parameter setting at which what it approximates by
/// design (too few VPLs, too few propagation iterations, a single bounce of albedo) becomes
/// small, and its residual bias there per Cornell box, measured like the defaults' entries. The
/// residual is the method's own (clamping, a finite grid, a tiled subset of VPLs) and stays
/// within [`Converged::MAX_RESIDUAL`] of the reference; the band around it,
/// [`Converged::FACTOR`], only admits the reference's noise and backends' last bits, so a
/// uniform ×1.1 or ×0.9 of the output fails every entry (the test checks both).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Converged {
    /// The parameters that differ from the defaults, as `name=value`.
    pub params: &'static [&'static str],
    /// Why these values converge and what residual is left.
    pub why: &'static str,
    /// One entry per Cornell box (spot, area, omni, sun).
    pub boxes: &'static [KnownBias],
}

impl Converged {
    /// How far the mean ratio may move around the stated residual, as a factor. The reference's
    /// mean at 256 samples per pixel over the 96x72 view moves by well under 1 % between seeds,
    /// the technique is deterministic for its seed, and GL and Vulkan agree to four decimals:
    /// ×1.05 holds all three with room, and a uniform ×1.1 or ×0.9 fails.
    pub const FACTOR: f64 = 1.05;
    /// How far the relative L1 error may grow (absolute).
    pub const L1_SLACK: f64 = 0.05;
    /// The largest residual a converged entry may state: its mean ratio within 1 ± this of the
    /// reference, or the setting is not converged.
    pub const MAX_RESIDUAL: f64 = 0.1;

    /// The parameters as `(name, value)` pairs, for [`TechniqueInfo::parse_params`].
    pub fn given(&self) -> Vec<(String, String)> {
        (self.params.iter())
            .map(|p| {
                let (k, v) = p.split_once('=').unwrap_or((p, ""));
                (k.to_string(), v.to_string())
            })
            .collect()
    }

    /// The entry for `scene`.
    pub fn on(&self, scene: &str) -> Option<&KnownBias> {
        self.boxes.iter().find(|k| k.scene == scene)
    }

    /// Why a measurement fails `known` (one of [`Converged::boxes`]), if it does.
    pub fn check(known: &KnownBias, mean_ratio: f64, relative_l1: f64) -> Option<String> {
        known.check_within(Self::FACTOR, Self::L1_SLACK, mean_ratio, relative_l1)
    }
}

/// A technique's bias at its published defaults on one scene, as the conformance test measures
/// it (`cargo test --release --test it conformance -- --nocapture` prints the figures): stated,
/// not hidden, in `gibench list` and docs/techniques.md. The test holds the technique to it
/// within [`KnownBias::FACTOR`], so that a change to the technique's output shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnownBias {
    pub scene: &'static str,
    /// The mean indirect irradiance relative to the reference's (Σt / Σr over the pixels that
    /// hit geometry, RGB summed): 1 is unbiased; halving the VPLs' intensities halves it.
    pub mean_ratio: f64,
    /// The relative L1 error Σ|t − r| / Σr over those pixels (an all-zero output scores 1; less
    /// dominated by VPL hot spots and dark pixels than a relative MSE).
    pub relative_l1: f64,
}

impl KnownBias {
    /// The entry for `scene`.
    pub const fn new(scene: &'static str, mean_ratio: f64, relative_l1: f64) -> KnownBias {
        KnownBias {
            scene,
            mean_ratio,
            relative_l1,
        }
    }

    /// How far the mean ratio may move either way, as a factor. A technique's output is
    /// deterministic for its seed and the reference's mean at 256 samples per pixel moves by
    /// well under 1 % between seeds, so this admits backends' last bits and a reordered sum, and
    /// nothing a user would see: a uniform ×1.15 or ×0.87 of the output fails (the test checks
    /// both on every entry).
    pub const FACTOR: f64 = 1.1;
    /// How far the relative L1 error may grow (absolute): a change in where the light lands
    /// with the same mean (a shifted or blurred image).
    pub const L1_SLACK: f64 = 0.1;

    /// The mean ratios that pass.
    pub fn mean_ratio_bounds(&self) -> (f64, f64) {
        self.bounds_within(Self::FACTOR)
    }

    /// The largest relative L1 error that passes.
    pub fn max_relative_l1(&self) -> f64 {
        self.relative_l1 + Self::L1_SLACK
    }

    /// Why `mean_ratio` and `relative_l1` (a measurement) fail the entry, if they do.
    pub fn check(&self, mean_ratio: f64, relative_l1: f64) -> Option<String> {
        self.check_within(Self::FACTOR, Self::L1_SLACK, mean_ratio, relative_l1)
    }

    /// The mean ratios that pass within `factor`.
    pub fn bounds_within(&self, factor: f64) -> (f64, f64) {
        (self.mean_ratio / factor, self.mean_ratio * factor)
    }

    /// Why a measurement fails the entry held within `factor` (mean ratio) and `slack`
    /// (relative L1), if it does.
    pub fn check_within(
        &self,
        factor: f64,
        slack: f64,
        mean_ratio: f64,
        relative_l1: f64,
    ) -> Option<String> {
        let (lo, hi) = self.bounds_within(factor);
        let max_l1 = self.relative_l1 + slack;
        if relative_l1.is_nan() || relative_l1 > max_l1 {
            Some(format!(
                "relative L1 error {relative_l1:.4} above {max_l1:.4} (known {} + {slack})",
                self.relative_l1
            ))
        } else if !(lo..=hi).contains(&mean_ratio) {
            Some(format!(
                "mean ratio {mean_ratio:.4} outside {lo:.4}-{hi:.4} (known {} within ×{factor})",
                self.mean_ratio
            ))
        } else {
            None
        }
    }
}

/// [`KnownBias`] entries for the four Cornell boxes, `(mean ratio, relative L1)` in the order
/// spot (`cornell`), area, omni, sun.
pub const fn cornell_boxes(m: [(f64, f64); 4]) -> [KnownBias; 4] {
    [
        KnownBias::new("cornell", m[0].0, m[0].1),
        KnownBias::new("cornell-area", m[1].0, m[1].1),
        KnownBias::new("cornell-omni", m[2].0, m[2].1),
        KnownBias::new("cornell-sun", m[3].0, m[3].1),
    ]
}

/// A stage a technique times (the name its `gpu_stage` / `cpu_stage` calls give, as the tables
/// print it) and where it runs. Declared in [`TechniqueInfo::stages`]: a run refuses a stage
/// that is not declared, `gibench list` prints them, and the conformance test checks that every
/// declared GPU stage that runs has a declared cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stage {
    pub name: &'static str,
    pub kind: StageKind,
}

impl Stage {
    pub const fn gpu(name: &'static str) -> Stage {
        Stage {
            name,
            kind: StageKind::Gpu,
        }
    }
    pub const fn cpu(name: &'static str) -> Stage {
        Stage {
            name,
            kind: StageKind::Cpu,
        }
    }
}

/// A registry entry: how to list and build a technique.
pub struct TechniqueInfo {
    pub name: &'static str,
    /// The paper it implements, as the README's table names it (`Laine et al. 2007`; `—` for a
    /// baseline).
    pub paper: &'static str,
    /// What it is, in a few words (the README's table; `gibench list --markdown`).
    pub summary: &'static str,
    pub description: &'static str,
    /// The stages it times, in frame order, composed from shared sets (the kit's
    /// [`crate::kit::ir::gather::GATHER_STAGES`]) and its own: every name its `render` passes to
    /// the profiler, some only under some parameters.
    pub stages: &'static [&'static [Stage]],
    /// Declared parameters, composed from shared sets (e.g. the kit's gather parameters) and
    /// the technique's own; names are unique across the groups.
    pub params: &'static [&'static [ParamSpec]],
    /// GPU features the technique cannot run without.
    pub required_features: wgpu::Features,
    /// Limits the technique needs (checked before it is built).
    pub required_limits: fn() -> wgpu::Limits,
    /// The reference component its indirect irradiance approximates with these parameters
    /// (`keller-full bounces=3` computes several bounces, `barczak set=direct` the direct
    /// light): `--quality` compares with it unless `--quality-reference` overrides.
    pub reference: fn(&Params) -> IndirectComponent,
    /// Its conformance bounds.
    pub conformance: Conformance,
    /// The parameter that trades time for error (`gibench run --equal-time`), if any.
    pub knob: Option<Knob>,
    /// Per-scene preparation, once per scene and parameter set ([`prepare_nothing`] if none).
    pub prepare: fn(&Params, &PrepareContext) -> Result<Prepared>,
    /// Builds the technique for one scene from what `prepare` made.
    pub create: fn(&Params, &PrepareContext, &Prepared) -> Result<Box<dyn Technique>>,
}

impl TechniqueInfo {
    /// Finds `name` in `registry`; the error lists the known names.
    pub fn find<'r>(registry: &'r [TechniqueInfo], name: &str) -> Result<&'r TechniqueInfo> {
        registry.iter().find(|t| t.name == name).ok_or_else(|| {
            let known: Vec<&str> = registry.iter().map(|t| t.name).collect();
            Error::Invalid(format!(
                "unknown technique '{name}'; known techniques: {}",
                known.join(", ")
            ))
        })
    }

    /// Every declared parameter, in declaration order.
    pub fn stages(&self) -> impl Iterator<Item = &'static Stage> + '_ {
        self.stages.iter().flat_map(|g| g.iter())
    }

    pub fn param_specs(&self) -> impl Iterator<Item = &'static ParamSpec> + '_ {
        self.params.iter().flat_map(|g| g.iter())
    }

    /// Parses `key=value` pairs against this technique's parameters (see [`Params::parse`]).
    pub fn parse_params(&self, given: &[(String, String)]) -> Result<Params> {
        let specs: Vec<ParamSpec> = self.param_specs().copied().collect();
        Params::parse(self.name, &specs, given)
    }

    /// The reference component with its default parameters (what `gibench list` shows).
    pub fn default_reference(&self) -> IndirectComponent {
        let defaults = self
            .parse_params(&[])
            .expect("a technique's defaults parse (tested for every registered technique)");
        (self.reference)(&defaults)
    }

    /// Whether it declares a parameter `name`.
    pub fn has_param(&self, name: &str) -> bool {
        self.param_specs().any(|p| p.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPECS: &[ParamSpec] = &[
        ParamSpec {
            name: "vpls",
            kind: ParamKind::Int { min: 1, max: 4096 },
            default: "256",
            doc: "",
        },
        ParamSpec {
            name: "tiles",
            kind: ParamKind::Tiles,
            default: "4x4",
            doc: "",
        },
        ParamSpec {
            name: "clamp",
            kind: ParamKind::Float { min: 0.0, max: 1e9 },
            default: "0.5",
            doc: "",
        },
    ];

    fn kv(k: &str, v: &str) -> (String, String) {
        (k.into(), v.into())
    }

    #[test]
    fn defaults_and_overrides() {
        let p = Params::parse("t", SPECS, &[kv("vpls", "64")]).unwrap();
        assert_eq!(p.int("vpls"), 64);
        assert_eq!(p.tiles("tiles"), (4, 4));
        assert_eq!(p.float("clamp"), 0.5);
    }

    #[test]
    fn unknown_parameter_is_named() {
        let e = Params::parse("t", SPECS, &[kv("vlps", "64")])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("vlps") && e.contains("vpls, tiles, clamp"),
            "{e}"
        );
    }

    #[test]
    fn bad_values_are_rejected() {
        for (k, v) in [
            ("vpls", "0"),
            ("vpls", "x"),
            ("tiles", "4x0"),
            ("tiles", "44"),
            ("clamp", "nan"),
        ] {
            let e = Params::parse("t", SPECS, &[kv(k, v)])
                .unwrap_err()
                .to_string();
            assert!(e.contains(k) && e.contains(v), "{e}");
        }
    }
}
