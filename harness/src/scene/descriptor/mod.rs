//! Scene descriptors: JSON files in `scenes/` that say which mesh to load, how the camera, the
//! primary light and the movers move, and per-scene settings. Unknown fields are errors that
//! name the field (serde `deny_unknown_fields`).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

mod validate;

/// Name of the generated Cornell box ([`crate::scene::cornell`]).
pub const GENERATED_CORNELL_BOX: &str = "cornell-box";
/// Name of the generated maze of Laine et al. 2007's MAZE scene ([`crate::scene::maze`]).
pub const GENERATED_MAZE: &str = "maze";
/// Every generated mesh name: the Cornell box, the maze, the scenes of Gaitatzes et al. 2010
/// ([`crate::scene::gaitatzes`]) and of Barczak 2006 with its torus mover
/// ([`crate::scene::barczak`]).
pub const GENERATED_MESHES: &[&str] = &[
    GENERATED_CORNELL_BOX,
    GENERATED_MAZE,
    "gaitatzes-test",
    "gaitatzes-room",
    "gaitatzes-arena",
    "barczak-area-room",
    "barczak-table-room",
    "barczak-pillar-room",
    "barczak-area-casters",
    "barczak-table-casters",
    "barczak-pillar-casters",
    "torus-820",
];

/// Where a mesh comes from: exactly one of `file` (a glTF binary on the asset search path) or
/// `generated` (a scene built in code, e.g. `"cornell-box"`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSource {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generated: Option<String>,
    /// Split the mesh finely: generated meshes split every quad into cells of about this edge
    /// length; loaded meshes split every triangle whose longest edge exceeds it into a regular
    /// grid of sub-triangles with edges no longer than it (for paraboloid shadow maps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tessellate: Option<f32>,
}

/// One keyframe of a path: where the object is and what it looks at.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Key {
    /// Seconds from the start of the animation.
    pub time: f32,
    pub position: [f32; 3],
    /// Camera and lights: the point looked at (spot/area direction). Movers: the point the
    /// object's +Z axis faces (horizontal component only); omitted → no rotation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<[f32; 3]>,
}

/// What happens after the last key.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Wrap {
    /// Jump back to the first key (the path should end where it starts).
    #[default]
    Loop,
    /// Run the path backwards, then forwards again.
    PingPong,
    /// Stay at the last key.
    Clamp,
}

/// A keyframed path, interpolated with centripetal-free uniform Catmull–Rom splines.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathDesc {
    pub keys: Vec<Key>,
    #[serde(default)]
    pub wrap: Wrap,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// Near plane distance (scene units).
    pub near: f32,
    pub path: PathDesc,
}

/// Kinds of primary light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightKind {
    /// 180° spot light with cosine falloff (Laine et al. 2007).
    Spot,
    /// Omnidirectional point light.
    Omni,
    /// One-sided Lambertian rectangle of `size`, facing its target.
    Area,
    /// Directional light (the sun): parallel rays along position → target; `power` is the
    /// irradiance E⊥ it gives a surface facing it (see [`crate::cpu::light`]).
    Sun,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    pub kind: LightKind,
    /// Total emitted flux Φ, linear RGB (see the harness's radiometric convention); for a
    /// `sun`, the irradiance E⊥ on a surface facing it.
    pub power: [f32; 3],
    /// Area lights: width and height in scene units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f32; 2]>,
    pub path: PathDesc,
}

/// A mesh placed once into the static geometry (e.g. the MAZE's statue): scaled, turned about
/// +Y, then moved. It bounces light, casts shadows and is in the CPU BVH like the main mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StaticInstance {
    pub mesh: MeshSource,
    #[serde(default = "one")]
    pub scale: f32,
    #[serde(default)]
    pub position: [f32; 3],
    #[serde(default)]
    pub rotation_y_deg: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MoverDesc {
    pub name: String,
    pub mesh: MeshSource,
    /// Uniform scale applied to the mesh before the path's transform.
    #[serde(default = "one")]
    pub scale: f32,
    pub path: PathDesc,
}

/// Per-scene settings that depend on the scene's scale or look.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSettings {
    /// Laine's α: the geometry-aware filter's distance threshold (scene units).
    pub filter_distance: f32,
    /// Laine's β: the filter's normal threshold (cosine).
    #[serde(default = "default_beta")]
    pub filter_normal: f32,
    /// Multiplier applied to radiance before PNG encoding.
    #[serde(default = "one")]
    pub exposure: f32,
    /// Shadow-map depth bias as a fraction of the distance to the light.
    #[serde(default = "default_bias")]
    pub shadow_bias: f32,
}

fn one() -> f32 {
    1.0
}
fn default_beta() -> f32 {
    0.8
}
fn default_bias() -> f32 {
    0.01
}

impl Default for SceneSettings {
    fn default() -> Self {
        SceneSettings {
            filter_distance: 1.0,
            filter_normal: default_beta(),
            exposure: 1.0,
            shadow_bias: default_bias(),
        }
    }
}

/// A whole scene descriptor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescriptor {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub mesh: MeshSource,
    /// Tessellated copy of the static mesh for paraboloid VPL shadow maps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shadow_mesh: Option<MeshSource>,
    pub camera: CameraDesc,
    pub light: LightDesc,
    #[serde(default)]
    pub movers: Vec<MoverDesc>,
    /// Meshes added to the static geometry (and to the shadow-map copy).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub statics: Vec<StaticInstance>,
    pub settings: SceneSettings,
    /// Animation frames per second: frame i is at time i / fps.
    #[serde(default = "default_fps")]
    pub fps: f32,
}

fn default_fps() -> f32 {
    30.0
}

/// Built-in descriptors (the JSON files in the workspace's `scenes/` directory), embedded at
/// compile time: (name, JSON text).
const BUILTINS: &[(&str, &str)] = &[
    ("cornell", include_str!("../../../../scenes/cornell.json")),
    (
        "cornell-gltf",
        include_str!("../../../../scenes/cornell-gltf.json"),
    ),
    (
        "cornell-bunny",
        include_str!("../../../../scenes/cornell-bunny.json"),
    ),
    (
        "cornell-bunny-still-light",
        include_str!("../../../../scenes/cornell-bunny-still-light.json"),
    ),
    (
        "cornell-omni",
        include_str!("../../../../scenes/cornell-omni.json"),
    ),
    (
        "cornell-sun",
        include_str!("../../../../scenes/cornell-sun.json"),
    ),
    (
        "cornell-area",
        include_str!("../../../../scenes/cornell-area.json"),
    ),
    ("sibenik", include_str!("../../../../scenes/sibenik.json")),
    (
        "sibenik-omni",
        include_str!("../../../../scenes/sibenik-omni.json"),
    ),
    ("sponza", include_str!("../../../../scenes/sponza.json")),
    (
        "sponza-sun",
        include_str!("../../../../scenes/sponza-sun.json"),
    ),
    (
        "gaitatzes-test",
        include_str!("../../../../scenes/gaitatzes-test.json"),
    ),
    (
        "gaitatzes-room",
        include_str!("../../../../scenes/gaitatzes-room.json"),
    ),
    (
        "gaitatzes-arena",
        include_str!("../../../../scenes/gaitatzes-arena.json"),
    ),
    (
        "barczak-area",
        include_str!("../../../../scenes/barczak-area.json"),
    ),
    (
        "barczak-table",
        include_str!("../../../../scenes/barczak-table.json"),
    ),
    (
        "barczak-pillars",
        include_str!("../../../../scenes/barczak-pillars.json"),
    ),
    ("maze", include_str!("../../../../scenes/maze.json")),
    (
        "conference",
        include_str!("../../../../scenes/conference.json"),
    ),
];

/// Largest light power (flux, or a sun's irradiance) per component. The shipped scenes use at
/// most 1e7; a light's flux reaches a pixel multiplied by 1/(π d²) and summed over thousands of
/// VPLs or paths, all in 32-bit floats (largest 3.4e38), and 1e20 leaves eighteen orders of
/// magnitude for those factors. (1e33 gave NaN pixels in the VPL techniques' indirect images.)
pub const MAX_LIGHT_POWER: f32 = 1e20;

/// Names of the built-in scene descriptors, in a fixed order.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTINS.iter().map(|(name, _)| *name).collect()
}

impl SceneDescriptor {
    /// Parses a descriptor from JSON `text`. Syntax errors, missing or unknown fields and wrong
    /// types become [`Error::BadFile`] with serde's message (which names the field and gives
    /// the line and column) reported against `path_for_errors`. Does not [`validate`](Self::validate).
    pub fn from_json(path_for_errors: &Path, text: &str) -> Result<Self> {
        crate::error::from_json(text.as_bytes()).map_err(|e| Error::bad_file(path_for_errors, e))
    }

    /// Finds a descriptor by built-in name (see [`builtin_names`]) or as a path to a JSON file,
    /// then parses and validates it.
    ///
    /// A built-in name wins over a file of the same name in the current directory. Anything
    /// that is not a built-in name but ends in `.json` or contains a path separator is read as
    /// a file ([`Error::Io`] if it cannot be read). Anything else is [`Error::Invalid`] listing
    /// the built-in names.
    pub fn resolve(name_or_path: &str) -> Result<Self> {
        if let Some((name, text)) = BUILTINS.iter().find(|(name, _)| *name == name_or_path) {
            let path = PathBuf::from(format!("scenes/{name}.json"));
            let desc = Self::from_json(&path, text)?;
            desc.validate(&path)?;
            return Ok(desc);
        }
        let path = Path::new(name_or_path);
        let looks_like_path = name_or_path.ends_with(".json")
            || name_or_path.contains('/')
            || name_or_path.contains(std::path::MAIN_SEPARATOR)
            || path.is_file();
        if !looks_like_path {
            return Err(Error::Invalid(format!(
                "unknown scene '{name_or_path}'; built-in scenes are: {}; or give the path of a .json scene descriptor",
                builtin_names().join(", ")
            )));
        }
        let what = "--scene takes a built-in scene name or a scene descriptor JSON; glTF files \
                    are referenced from a descriptor's `mesh.file` (see scenes/cornell-gltf.json)";
        let gltf = path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("glb") || x.eq_ignore_ascii_case("gltf"));
        if gltf {
            return Err(Error::bad_file(
                path,
                format!("a glTF file, not a scene descriptor: {what}"),
            ));
        }
        // A descriptor is a few kilobytes; 16 MiB bounds the read (`--scene /dev/zero`).
        let bytes = crate::error::read_bounded(path, 16 << 20)?;
        let text = String::from_utf8(bytes).map_err(|_| {
            Error::bad_file(
                path,
                format!("not UTF-8 text, so not a scene descriptor: {what}"),
            )
        })?;
        let desc = Self::from_json(path, &text)?;
        desc.validate(path)?;
        Ok(desc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell() -> SceneDescriptor {
        SceneDescriptor::resolve("cornell").expect("built-in cornell")
    }

    fn message(e: Error) -> String {
        match e {
            Error::BadFile { message, .. } => message,
            other => panic!("expected BadFile, got {other:?}"),
        }
    }

    #[test]
    fn descriptor_builtins_parse_and_validate() {
        let names = builtin_names();
        assert!(names.len() >= 6);
        for name in names {
            let d = SceneDescriptor::resolve(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(d.name, name);
            // Both the camera and the light move (Laine measured with both moving), but in
            // Barczak's rooms (the thesis measured fixed views); a `-still-light` variant holds
            // its light only.
            let barczak = name.starts_with("barczak-");
            let still_light = barczak || name.ends_with("-still-light");
            assert_eq!(d.camera.path.keys.len() >= 2, !barczak, "{name}: camera");
            assert_eq!(d.light.path.keys.len() >= 2, !still_light, "{name}: light");
        }
    }

    #[test]
    fn descriptor_roundtrips_through_json() {
        let d = cornell();
        let text = serde_json::to_string(&d).unwrap();
        assert_eq!(
            SceneDescriptor::from_json(Path::new("x.json"), &text).unwrap(),
            d
        );
    }

    #[test]
    fn descriptor_unknown_fields_are_named() {
        let mut v: serde_json::Value = serde_json::to_value(cornell()).unwrap();
        v["colour"] = serde_json::json!(1);
        let text = serde_json::to_string_pretty(&v).unwrap();
        let e = SceneDescriptor::from_json(Path::new("top.json"), &text).unwrap_err();
        let shown = e.to_string();
        assert!(shown.starts_with("top.json: "), "{shown}");
        assert!(
            shown.contains("unknown field `colour`") && shown.contains("line"),
            "{shown}"
        );

        let mut v: serde_json::Value = serde_json::to_value(cornell()).unwrap();
        v["light"]["colour"] = serde_json::json!([1, 1, 1]);
        let e = SceneDescriptor::from_json(Path::new("nested.json"), &v.to_string()).unwrap_err();
        assert!(message(e).contains("unknown field `colour`"));

        let mut v: serde_json::Value = serde_json::to_value(cornell()).unwrap();
        v["camera"]["path"]["keys"][0]["rotation"] = serde_json::json!(0);
        assert!(message(
            SceneDescriptor::from_json(Path::new("k.json"), &v.to_string()).unwrap_err()
        )
        .contains("unknown field `rotation`"));

        let e = SceneDescriptor::from_json(Path::new("bad.json"), "{ not json").unwrap_err();
        assert!(matches!(e, Error::BadFile { .. }));
        let mut v: serde_json::Value = serde_json::to_value(cornell()).unwrap();
        v["light"]["kind"] = serde_json::json!("laser");
        assert!(message(
            SceneDescriptor::from_json(Path::new("k.json"), &v.to_string()).unwrap_err()
        )
        .contains("unknown variant `laser`"));
    }

    /// A wrong value deep in the file is named by its field's path, not only a line and column.
    #[test]
    fn descriptor_errors_give_the_fields_path() {
        let mut v: serde_json::Value = serde_json::to_value(cornell()).unwrap();
        v["light"]["path"]["keys"][1]["position"] = serde_json::json!("up");
        let e =
            message(SceneDescriptor::from_json(Path::new("k.json"), &v.to_string()).unwrap_err());
        assert!(e.starts_with("light.path.keys[1].position: "), "{e}");
        assert!(e.contains("line"), "{e}");
        v["light"]["path"]["keys"][1]["position"] = serde_json::json!([0, 1, 2]);
        v["movers"] = serde_json::json!([{"name": "m", "mesh": {}, "scale": "big"}]);
        let e =
            message(SceneDescriptor::from_json(Path::new("k.json"), &v.to_string()).unwrap_err());
        assert!(e.starts_with("movers[0].scale: "), "{e}");
    }

    #[test]
    fn descriptor_resolve_errors() {
        match SceneDescriptor::resolve("atlantis") {
            Err(Error::Invalid(m)) => {
                assert!(
                    m.contains("atlantis") && m.contains("cornell") && m.contains("sponza"),
                    "{m}"
                )
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            SceneDescriptor::resolve("/no/such/dir/scene.json"),
            Err(Error::Io { .. })
        ));

        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("mine.json");
        let mut d = cornell();
        d.name = "mine".into();
        std::fs::write(&good, serde_json::to_string(&d).unwrap()).unwrap();
        assert_eq!(SceneDescriptor::resolve(good.to_str().unwrap()).unwrap(), d);

        d.fps = 0.0;
        let bad = dir.path().join("bad.json");
        std::fs::write(&bad, serde_json::to_string(&d).unwrap()).unwrap();
        match SceneDescriptor::resolve(bad.to_str().unwrap()) {
            Err(Error::BadFile { path, message }) => {
                assert_eq!(path, bad);
                assert!(message.starts_with("fps:"), "{message}");
            }
            other => panic!("{other:?}"),
        }
    }

    type Edit = Box<dyn Fn(&mut SceneDescriptor)>;

    fn with_mover(d: &mut SceneDescriptor) {
        d.movers = SceneDescriptor::resolve("cornell-bunny").unwrap().movers;
    }

    /// Invalid descriptors of the mesh, the camera and the paths' times, with the message each
    /// must start with.
    fn mesh_and_path_cases() -> Vec<(&'static str, Edit)> {
        vec![
            (
                "mesh: give either",
                Box::new(|d| d.mesh.file = Some("a.glb".into())),
            ),
            (
                "mesh: needs a `file`",
                Box::new(|d| d.mesh.generated = None),
            ),
            (
                "mesh.generated: unknown generated mesh 'teapot'",
                Box::new(|d| d.mesh.generated = Some("teapot".into())),
            ),
            (
                "mesh.file: must not be empty",
                Box::new(|d| {
                    d.mesh = MeshSource {
                        file: Some(" ".into()),
                        ..Default::default()
                    }
                }),
            ),
            (
                "mesh.tessellate: must be a positive",
                Box::new(|d| {
                    d.mesh = MeshSource {
                        file: Some("a.glb".into()),
                        generated: None,
                        tessellate: Some(-3.0),
                    }
                }),
            ),
            (
                "shadow_mesh.tessellate: must be a positive",
                Box::new(|d| d.shadow_mesh.as_mut().unwrap().tessellate = Some(0.0)),
            ),
            (
                "camera.fov_y_deg:",
                Box::new(|d| d.camera.fov_y_deg = 180.0),
            ),
            ("camera.fov_y_deg:", Box::new(|d| d.camera.fov_y_deg = 0.0)),
            ("camera.near:", Box::new(|d| d.camera.near = 0.0)),
            (
                "camera.path.keys: needs at least one key",
                Box::new(|d| d.camera.path.keys.clear()),
            ),
            (
                "camera.path.keys[0].time: the first key must be at time 0",
                Box::new(|d| d.camera.path.keys[0].time = 0.5),
            ),
            (
                "camera.path.keys[1].time: must be a finite",
                Box::new(|d| d.camera.path.keys[1].time = f32::NAN),
            ),
        ]
    }

    /// Invalid descriptors of the light, the movers and the settings.
    fn light_mover_and_settings_cases() -> Vec<(&'static str, Edit)> {
        vec![
            (
                "light.path.keys[2].time: key times must be strictly increasing",
                Box::new(|d| d.light.path.keys[2].time = 1.5),
            ),
            (
                "light.path.keys[1].position:",
                Box::new(|d| d.light.path.keys[1].position[0] = f32::INFINITY),
            ),
            (
                "camera.path.keys[0].target: is missing",
                Box::new(|d| d.camera.path.keys[0].target = None),
            ),
            (
                "light.path.keys[3].target: is missing",
                Box::new(|d| d.light.path.keys[3].target = None),
            ),
            (
                "light.path.keys[0].target: must differ",
                Box::new(|d| d.light.path.keys[0].target = Some(d.light.path.keys[0].position)),
            ),
            (
                "light.power: every component",
                Box::new(|d| d.light.power[1] = -1.0),
            ),
            (
                "light.power: every component",
                Box::new(|d| d.light.power[2] = f32::NAN),
            ),
            (
                "light.power: is zero",
                Box::new(|d| d.light.power = [0.0; 3]),
            ),
            (
                "light.power: every component must be at most 1e20",
                Box::new(|d| d.light.power = [1e33, 1.0, 1.0]),
            ),
            (
                "light.size: [3e38, 1e0] puts the light's corners",
                Box::new(|d| {
                    d.light.kind = LightKind::Area;
                    d.light.size = Some([3e38, 1.0]);
                }),
            ),
            (
                "light.size: area lights need a [width, height] size",
                Box::new(|d| d.light.kind = LightKind::Area),
            ),
            (
                "light.size: width and height must be positive",
                Box::new(|d| {
                    d.light.kind = LightKind::Area;
                    d.light.size = Some([100.0, 0.0]);
                }),
            ),
            (
                "light.size: only area lights",
                Box::new(|d| d.light.size = Some([1.0, 1.0])),
            ),
            (
                "movers[0].scale: must be positive",
                Box::new(move |d| {
                    with_mover(d);
                    d.movers[0].scale = 0.0;
                }),
            ),
            (
                "movers[0].name: must not be empty",
                Box::new(move |d| {
                    with_mover(d);
                    d.movers[0].name.clear();
                }),
            ),
            (
                "movers[0].mesh: needs a `file`",
                Box::new(move |d| {
                    with_mover(d);
                    d.movers[0].mesh.file = None;
                }),
            ),
            (
                "movers[0].path.keys[1].target: is missing; give a target on every key or on none",
                Box::new(move |d| {
                    with_mover(d);
                    d.movers[0].path.keys[1].target = None;
                }),
            ),
            (
                "settings.filter_distance:",
                Box::new(|d| d.settings.filter_distance = 0.0),
            ),
            (
                "settings.filter_normal:",
                Box::new(|d| d.settings.filter_normal = 1.5),
            ),
            (
                "settings.exposure:",
                Box::new(|d| d.settings.exposure = -1.0),
            ),
            (
                "settings.shadow_bias:",
                Box::new(|d| d.settings.shadow_bias = f32::NAN),
            ),
            ("fps:", Box::new(|d| d.fps = 0.0)),
        ]
    }

    #[test]
    fn descriptor_validation_rules() {
        let cases = mesh_and_path_cases()
            .into_iter()
            .chain(light_mover_and_settings_cases());
        for (expected, edit) in cases {
            let mut d = cornell();
            edit(&mut d);
            let e = d
                .validate(Path::new("scenes/edited.json"))
                .expect_err(expected);
            let shown = e.to_string();
            assert!(shown.starts_with("scenes/edited.json: "), "{shown}");
            let m = message(e);
            assert!(m.starts_with(expected), "expected '{expected}…', got '{m}'");
        }
    }

    #[test]
    fn optional_descriptor_parts_validate() {
        // Optional things that are fine: an omni light without targets, a mover without targets,
        // a single-key path, an area light with a size.
        let mut d = cornell();
        d.light.kind = LightKind::Omni;
        for k in &mut d.light.path.keys {
            k.target = None;
        }
        d.camera.path.keys.truncate(1);
        with_mover(&mut d);
        for k in &mut d.movers[0].path.keys {
            k.target = None;
        }
        d.validate(Path::new("ok.json")).unwrap();
        d.light.kind = LightKind::Area;
        d.light.size = Some([100.0, 50.0]);
        for k in &mut d.light.path.keys {
            k.target = Some([278.0, 0.0, 280.0]);
        }
        d.validate(Path::new("ok.json")).unwrap();
    }
}
