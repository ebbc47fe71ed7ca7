//! Validation of scene descriptors: the values serde cannot check (names, mesh sources, key
//! times and targets, camera and light parameters, settings), each failure naming its field.

use std::path::Path;

use super::{
    LightDesc, LightKind, MeshSource, PathDesc, SceneDescriptor, GENERATED_MESHES, MAX_LIGHT_POWER,
};
use crate::scene::{cornell, generated_diagonal, MAX_COORDINATE};
use crate::{Error, Result};

/// A validation failure: `field: message`, reported against the descriptor's file.
fn invalid(path: &Path, field: &str, message: impl std::fmt::Display) -> Error {
    Error::bad_file(path, format!("{field}: {message}"))
}

fn check_finite3(path: &Path, field: &str, v: &[f32; 3]) -> Result<()> {
    if v.iter().all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE) {
        Ok(())
    } else {
        Err(invalid(
            path,
            field,
            format!(
                "every component must be a finite number within ±{:e}, got {v:?}",
                MAX_COORDINATE
            ),
        ))
    }
}

impl SceneDescriptor {
    /// Checks the values serde cannot: mesh sources, key times, camera and light parameters and
    /// settings. The first problem found is returned as [`Error::BadFile`] against
    /// `path_for_errors`, with a message that starts with the offending field, e.g.
    /// `light.size: area lights need a [width, height] size`.
    pub fn validate(&self, path_for_errors: &Path) -> Result<()> {
        let p = path_for_errors;
        self.validate_name(p)?;
        validate_mesh_source(p, "mesh", &self.mesh)?;
        if let Some(shadow) = &self.shadow_mesh {
            validate_mesh_source(p, "shadow_mesh", shadow)?;
        }
        self.validate_statics(p)?;
        self.validate_camera(p)?;
        self.validate_light(p)?;
        self.validate_movers(p)?;
        self.validate_settings(p)?;
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(invalid(
                p,
                "fps",
                format!("must be positive, got {}", self.fps),
            ));
        }
        Ok(())
    }

    /// The name becomes part of output and cache file names: a plain file stem only.
    fn validate_name(&self, p: &Path) -> Result<()> {
        let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
        if self.name.is_empty()
            || self.name.len() > 64
            || self.name.starts_with('.')
            || !self.name.chars().all(plain)
        {
            return Err(invalid(
                p,
                "name",
                format!(
                    "must be 1 to 64 letters, digits, '-', '_' or '.' not starting with '.' (it names output files), got {:?}",
                    self.name
                ),
            ));
        }
        Ok(())
    }

    /// Each static instance: its mesh source, a positive scale, a finite placement.
    fn validate_statics(&self, p: &Path) -> Result<()> {
        for (i, st) in self.statics.iter().enumerate() {
            let field = format!("statics[{i}]");
            validate_mesh_source(p, &format!("{field}.mesh"), &st.mesh)?;
            if !(st.scale.is_finite() && st.scale > 0.0) {
                return Err(invalid(
                    p,
                    &format!("{field}.scale"),
                    format!("must be positive, got {}", st.scale),
                ));
            }
            if !st
                .position
                .iter()
                .all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE)
                || !st.rotation_y_deg.is_finite()
            {
                return Err(invalid(
                    p,
                    &field,
                    "position and rotation_y_deg must be finite",
                ));
            }
        }
        Ok(())
    }

    /// The camera: its field of view, near plane and path (every key with a target).
    fn validate_camera(&self, p: &Path) -> Result<()> {
        let cam = &self.camera;
        if !(cam.fov_y_deg.is_finite() && cam.fov_y_deg > 0.0 && cam.fov_y_deg < 180.0) {
            return Err(invalid(
                p,
                "camera.fov_y_deg",
                format!("must be in (0, 180) degrees, got {}", cam.fov_y_deg),
            ));
        }
        if !(cam.near.is_finite() && cam.near > 0.0) {
            return Err(invalid(
                p,
                "camera.near",
                format!("must be a positive distance, got {}", cam.near),
            ));
        }
        validate_path(
            p,
            "camera.path",
            &cam.path,
            TargetRule::Required("the camera needs a point to look at"),
        )?;
        Ok(())
    }

    /// The primary light: its power, its size (area lights only) and its path, whose keys need
    /// a target for every kind but the omni light.
    fn validate_light(&self, p: &Path) -> Result<()> {
        let light = &self.light;
        if light.power.iter().any(|c| !c.is_finite() || *c < 0.0) {
            return Err(invalid(
                p,
                "light.power",
                format!(
                    "every component must be a finite flux >= 0, got {:?}",
                    light.power
                ),
            ));
        }
        if light.power.iter().any(|c| *c > MAX_LIGHT_POWER) {
            return Err(invalid(
                p,
                "light.power",
                format!(
                    "every component must be at most {MAX_LIGHT_POWER:e}, got {:?}: past it the \
                     irradiance the techniques and the reference compute in 32-bit floats \
                     overflows (use larger scene units)",
                    light.power
                ),
            ));
        }
        if light.power.iter().all(|c| *c == 0.0) {
            return Err(invalid(
                p,
                "light.power",
                "is zero; the light would emit nothing",
            ));
        }
        validate_light_size(p, light)?;
        let rule = match light.kind {
            LightKind::Omni => TargetRule::Optional,
            LightKind::Spot => TargetRule::Required("spot lights point at their target"),
            LightKind::Area => TargetRule::Required("area lights face their target"),
            LightKind::Sun => {
                TargetRule::Required("the sun shines from its position towards its target")
            }
        };
        validate_path(p, "light.path", &light.path, rule)?;
        Ok(())
    }

    /// Each mover: a name, its mesh source, a positive scale and its path.
    fn validate_movers(&self, p: &Path) -> Result<()> {
        for (i, mover) in self.movers.iter().enumerate() {
            let field = format!("movers[{i}]");
            if mover.name.trim().is_empty() {
                return Err(invalid(p, &format!("{field}.name"), "must not be empty"));
            }
            validate_mesh_source(p, &format!("{field}.mesh"), &mover.mesh)?;
            if !(mover.scale.is_finite() && mover.scale > 0.0) {
                return Err(invalid(
                    p,
                    &format!("{field}.scale"),
                    format!("must be positive, got {}", mover.scale),
                ));
            }
            validate_path(
                p,
                &format!("{field}.path"),
                &mover.path,
                TargetRule::Optional,
            )?;
        }
        Ok(())
    }

    /// The per-scene settings: filter thresholds, exposure and shadow bias.
    fn validate_settings(&self, p: &Path) -> Result<()> {
        let s = &self.settings;
        if !(s.filter_distance.is_finite() && s.filter_distance > 0.0) {
            return Err(invalid(
                p,
                "settings.filter_distance",
                format!("must be a positive distance, got {}", s.filter_distance),
            ));
        }
        if !(s.filter_normal.is_finite() && (-1.0..=1.0).contains(&s.filter_normal)) {
            return Err(invalid(
                p,
                "settings.filter_normal",
                format!(
                    "is a cosine and must be in [-1, 1], got {}",
                    s.filter_normal
                ),
            ));
        }
        if !(s.exposure.is_finite() && s.exposure > 0.0) {
            return Err(invalid(
                p,
                "settings.exposure",
                format!("must be positive, got {}", s.exposure),
            ));
        }
        if !(s.shadow_bias.is_finite() && s.shadow_bias >= 0.0) {
            return Err(invalid(
                p,
                "settings.shadow_bias",
                format!("must be >= 0, got {}", s.shadow_bias),
            ));
        }
        Ok(())
    }
}

/// An area light's size: given, positive, and small enough that its corners stay within the
/// coordinate limit at every key; other kinds have none.
fn validate_light_size(p: &Path, light: &LightDesc) -> Result<()> {
    match (light.kind, light.size) {
        (LightKind::Area, None) => {
            return Err(invalid(
                p,
                "light.size",
                "area lights need a [width, height] size",
            ));
        }
        (LightKind::Area, Some(size)) if size.iter().any(|s| !s.is_finite() || *s <= 0.0) => {
            return Err(invalid(
                p,
                "light.size",
                format!("width and height must be positive, got {size:?}"),
            ));
        }
        (LightKind::Spot | LightKind::Omni | LightKind::Sun, Some(_)) => {
            return Err(invalid(p, "light.size", "only area lights have a size"));
        }
        (LightKind::Area, Some([w, h])) => {
            // Its corners, at any key and facing any way, lie within half its diagonal of
            // the key's position: they obey the coordinate limit as positions do.
            let half = 0.5 * (w as f64).hypot(h as f64);
            for (i, key) in light.path.keys.iter().enumerate() {
                let far = key
                    .position
                    .iter()
                    .map(|c| c.abs() as f64)
                    .fold(0.0, f64::max);
                if far + half > MAX_COORDINATE as f64 {
                    return Err(invalid(
                        p,
                        "light.size",
                        format!(
                            "[{w:e}, {h:e}] puts the light's corners up to {half:.3e} from its \
                             position at light.path.keys[{i}] ({:?}), past ±{:e} scene units",
                            key.position, MAX_COORDINATE
                        ),
                    ));
                }
            }
        }
        _ => {}
    }
    Ok(())
}

/// Whether the keys of a path must, may or must not carry a `target`.
enum TargetRule {
    /// Every key needs a target; the string says why.
    Required(&'static str),
    /// Either every key has a target or none has.
    Optional,
}

fn validate_mesh_source(p: &Path, field: &str, src: &MeshSource) -> Result<()> {
    match (&src.file, &src.generated) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                p,
                field,
                "give either `file` or `generated`, not both",
            ));
        }
        (None, None) => {
            return Err(invalid(
                p,
                field,
                "needs a `file` (a glTF binary) or a `generated` mesh name",
            ));
        }
        (Some(file), None) => {
            if file.trim().is_empty() {
                return Err(invalid(p, &format!("{field}.file"), "must not be empty"));
            }
        }
        (None, Some(name)) => {
            if !GENERATED_MESHES.contains(&name.as_str()) {
                return Err(invalid(
                    p,
                    &format!("{field}.generated"),
                    format!(
                        "unknown generated mesh '{name}'; expected one of: {}",
                        GENERATED_MESHES.join(", ")
                    ),
                ));
            }
        }
    }
    if let Some(cell) = src.tessellate {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(invalid(
                p,
                &format!("{field}.tessellate"),
                format!("must be a positive cell size, got {cell}"),
            ));
        }
        if let (None, Some(name)) = (&src.file, &src.generated) {
            // A generator caps each quad edge at MAX_CELLS_PER_EDGE cells: refuse a cell
            // that could hit the cap instead of letting it be coarsened without a word.
            let most = cornell::MAX_CELLS_PER_EDGE;
            let diagonal = generated_diagonal(name)?;
            let cells = (diagonal / cell).round();
            if cells.is_nan() || cells > most as f32 {
                return Err(invalid(
                    p,
                    &format!("{field}.tessellate"),
                    format!(
                        "{cell} would split the generated mesh '{name}' ({diagonal} corner to corner) into up to {cells} cells along an edge; at most {most} are allowed (use a cell of at least {})",
                        diagonal / most as f32
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn validate_path(p: &Path, field: &str, path: &PathDesc, rule: TargetRule) -> Result<()> {
    if path.keys.is_empty() {
        return Err(invalid(
            p,
            &format!("{field}.keys"),
            "needs at least one key",
        ));
    }
    let with_target = path.keys.iter().filter(|k| k.target.is_some()).count();
    for (i, key) in path.keys.iter().enumerate() {
        let kf = format!("{field}.keys[{i}]");
        if !key.time.is_finite() {
            return Err(invalid(
                p,
                &format!("{kf}.time"),
                format!("must be a finite number, got {}", key.time),
            ));
        }
        if i == 0 && key.time != 0.0 {
            return Err(invalid(
                p,
                &format!("{kf}.time"),
                format!("the first key must be at time 0, got {}", key.time),
            ));
        }
        if i > 0 && key.time <= path.keys[i - 1].time {
            return Err(invalid(
                p,
                &format!("{kf}.time"),
                format!(
                    "key times must be strictly increasing ({} follows {})",
                    key.time,
                    path.keys[i - 1].time
                ),
            ));
        }
        check_finite3(p, &format!("{kf}.position"), &key.position)?;
        match (&key.target, &rule) {
            (None, TargetRule::Required(why)) => {
                return Err(invalid(
                    p,
                    &format!("{kf}.target"),
                    format!("is missing; {why}"),
                ));
            }
            (None, TargetRule::Optional) if with_target > 0 => {
                return Err(invalid(
                    p,
                    &format!("{kf}.target"),
                    "is missing; give a target on every key or on none",
                ));
            }
            (Some(target), _) => {
                check_finite3(p, &format!("{kf}.target"), target)?;
                if target == &key.position {
                    return Err(invalid(
                        p,
                        &format!("{kf}.target"),
                        "must differ from the key's position",
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(())
}
