//! Loads a glTF 2.0 file (binary `.glb`, or `.gltf` with its buffers) into the scene model:
//! one world-space [`Mesh`], its diffuse [`Material`]s, the base-colour [`Texture`]s they use and
//! the `KHR_lights_punctual` lights.
//!
//! * The default scene (else the first scene; else every root node) is walked with node
//!   transforms applied: positions by the world matrix, normals by its inverse transpose and
//!   renormalised. Nodes with a mirroring transform (negative determinant) have their triangles'
//!   winding swapped so that front faces stay counter-clockwise.
//! * Only triangle-list primitives are read. Points, lines, strips and fans are skipped (they
//!   are rare in exported scenes); a file left with no triangles at all is an error.
//! * Missing normals: flat face normals (the primitive's triangles get their own vertices).
//!   Missing texture coordinates: zero. `u8`/`u16`/`u32` indices and non-indexed primitives are
//!   supported.
//! * Materials: `base_color` is `baseColorFactor`'s RGB (alpha ignored); the base-colour texture,
//!   if any, is decoded to RGBA8 (colour channels left sRGB-encoded, as stored). Only images
//!   used as base-colour textures are returned, once each. See [`average_texture_color`] for
//!   `average_color`. Primitives without a material get a default white (0.8) material,
//!   appended after the file's materials when needed.
//!
//! Malformed input never panics: it is an [`Error::BadFile`] naming the file.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};

use super::{Material, Mesh, PunctualKind, PunctualLight, Texture};
use crate::{Error, Result};

/// What [`load_gltf`] returns.
#[derive(Clone, Debug, Default)]
pub struct LoadedGltf {
    /// All triangles of the scene, world space; per-vertex material indices already include the
    /// `material_offset`.
    pub mesh: Mesh,
    /// The materials the mesh's (offset) indices refer to, in order: material `i` of this vec
    /// has index `material_offset + i`.
    pub materials: Vec<Material>,
    /// Base-colour textures; [`Material::texture`] values are `texture_offset + i`.
    pub textures: Vec<Texture>,
    /// Punctual lights, world space.
    pub lights: Vec<PunctualLight>,
}

/// Albedo of the default material given to primitives without one.
pub const DEFAULT_ALBEDO: f32 = 0.8;

/// Loads `path` with per-vertex material indices offset by `material_offset` and texture
/// indices relative to the returned `textures` (equivalent to
/// [`load_gltf_with_offsets`]`(path, material_offset, 0)`).
pub fn load_gltf(path: &Path, material_offset: u32) -> Result<LoadedGltf> {
    load_gltf_with_offsets(path, material_offset, 0)
}

/// Loads `path` for appending to a scene that already has `material_offset` materials and
/// `texture_offset` textures: every per-vertex material index is offset by `material_offset`
/// and every [`Material::texture`] by `texture_offset`.
///
/// Errors: an unreadable file → [`Error::Io`]; a truncated or malformed file →
/// [`Error::BadFile`] with `not a valid glTF binary: <gltf error>`; inconsistent accessors,
/// non-finite positions, index overflow or no triangles at all → [`Error::BadFile`].
pub fn load_gltf_with_offsets(
    path: &Path,
    material_offset: u32,
    texture_offset: u32,
) -> Result<LoadedGltf> {
    let (doc, buffers, images) = import_checked(path)?;
    let bad = |message: String| Error::bad_file(path, message);

    let (mut materials, textures) = load_materials(path, &doc, &images, texture_offset)?;
    let file_material_count = materials.len();
    let mut default_material: Option<u32> = None;

    let mut mesh = Mesh::default();
    let mut lights = Vec::new();
    let mut visited = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = scene_roots(&doc)
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(bad(format!(
                "node {} appears twice in the scene's hierarchy",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(bad(format!(
                "node {}: transform is not finite",
                node.index()
            )));
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, world));
        }

        if let Some(light) = node.light() {
            lights.push(punctual_light(&node, &light, world));
        }

        let Some(gmesh) = node.mesh() else { continue };
        let placement = Placement::of(world);
        for prim in gmesh.primitives() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let material = match prim.material().index() {
                Some(i) => material_offset + i as u32,
                None => *default_material.get_or_insert_with(|| {
                    materials.push(Material {
                        name: "default".into(),
                        base_color: Vec3::splat(DEFAULT_ALBEDO),
                        texture: None,
                        average_color: Vec3::splat(DEFAULT_ALBEDO),
                    });
                    material_offset + file_material_count as u32
                }),
            };
            let what = || format!("mesh {} primitive {}", gmesh.index(), prim.index());
            let Some(data) = read_primitive(path, &prim, &buffers, &what)? else {
                continue;
            };
            append_primitive(path, &mut mesh, data, &placement, material, &what)?;
        }
    }

    if mesh.triangle_count() == 0 {
        return Err(bad(
            "contains no triangles (only triangle-list primitives are read)".into(),
        ));
    }
    Ok(LoadedGltf {
        mesh,
        materials,
        textures,
        lights,
    })
}

/// The file's materials, in order, and the images they use as base colour (decoded once each,
/// in order of first use); a material's texture index is offset by `texture_offset`.
fn load_materials(
    path: &Path,
    doc: &gltf::Document,
    images: &[gltf::image::Data],
    texture_offset: u32,
) -> Result<(Vec<Material>, Vec<Texture>)> {
    let bad = |message: String| Error::bad_file(path, message);
    let mut materials = Vec::new();
    let mut textures: Vec<Texture> = Vec::new();
    let mut image_slot: HashMap<usize, usize> = HashMap::new();
    let mut texel_means: Vec<Vec3> = Vec::new();
    for (i, m) in doc.materials().enumerate() {
        let f = m.pbr_metallic_roughness().base_color_factor();
        let base_color = Vec3::new(f[0], f[1], f[2]);
        if !base_color.is_finite() {
            return Err(bad(format!("material {i}: baseColorFactor is not finite")));
        }
        let mut texture = None;
        let mut average_color = base_color;
        if let Some(info) = m.pbr_metallic_roughness().base_color_texture() {
            let image_index = info.texture().source().index();
            let slot = match image_slot.get(&image_index) {
                Some(&slot) => slot,
                None => {
                    let data = images.get(image_index).ok_or_else(|| {
                        bad(format!("material {i}: image {image_index} was not decoded"))
                    })?;
                    let rgba8 =
                        to_rgba8(data).map_err(|m| bad(format!("image {image_index}: {m}")))?;
                    let name = doc
                        .images()
                        .nth(image_index)
                        .and_then(|img| img.name().map(str::to_owned))
                        .unwrap_or_else(|| format!("image{image_index}"));
                    texel_means.push(average_texture_color(&rgba8));
                    textures.push(Texture {
                        name,
                        width: data.width,
                        height: data.height,
                        rgba8,
                    });
                    image_slot.insert(image_index, textures.len() - 1);
                    textures.len() - 1
                }
            };
            texture = Some(slot + texture_offset as usize);
            average_color = base_color * texel_means[slot];
        }
        materials.push(Material {
            name: m
                .name()
                .map(str::to_owned)
                .unwrap_or_else(|| format!("material{i}")),
            base_color,
            texture,
            average_color,
        });
    }
    Ok((materials, textures))
}

/// Roots of the scene to walk: the default scene's (else the first scene's) nodes, else every
/// node that is no other node's child.
fn scene_roots(doc: &gltf::Document) -> Vec<gltf::Node<'_>> {
    match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    }
}

/// The `KHR_lights_punctual` light `light` of `node`, placed by the node's `world` matrix.
fn punctual_light(
    node: &gltf::Node,
    light: &gltf::khr_lights_punctual::Light,
    world: Mat4,
) -> PunctualLight {
    let kind = match light.kind() {
        gltf::khr_lights_punctual::Kind::Point => PunctualKind::Point,
        gltf::khr_lights_punctual::Kind::Directional => PunctualKind::Directional,
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => PunctualKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        },
    };
    PunctualLight {
        name: light
            .name()
            .or(node.name())
            .map(str::to_owned)
            .unwrap_or_else(|| format!("light{}", light.index())),
        kind,
        position: world.transform_point3(Vec3::ZERO),
        direction: world
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z),
        color: Vec3::from(light.color()),
        intensity: light.intensity(),
    }
}

/// A node's world matrix with what its primitives need from it: the normal matrix (inverse
/// transpose; zero for a singular matrix) and whether it mirrors (then windings are swapped).
struct Placement {
    world: Mat4,
    normal_matrix: Mat3,
    mirrored: bool,
}

impl Placement {
    fn of(world: Mat4) -> Placement {
        let normal_matrix = {
            let m = Mat3::from_mat4(world);
            let det = m.determinant();
            if det.abs() > f32::MIN_POSITIVE && det.is_finite() {
                m.inverse().transpose()
            } else {
                Mat3::ZERO
            }
        };
        let mirrored = Mat3::from_mat4(world).determinant() < 0.0;
        Placement {
            world,
            normal_matrix,
            mirrored,
        }
    }
}

/// One triangle-list primitive's vertex data as stored (object space), indices checked and cut
/// to whole triangles.
struct PrimitiveData {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Vec<Vec2>,
    indices: Vec<u32>,
}

/// Reads a primitive's positions, normals, texture coordinates and indices; `None` when it has
/// no positions or no triangles. `what` names it in errors.
fn read_primitive(
    path: &Path,
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    what: &dyn Fn() -> String,
) -> Result<Option<PrimitiveData>> {
    let bad = |message: String| Error::bad_file(path, message);
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    // An accessor whose data lies outside its buffer makes the reader return None.
    let position_accessor = prim.get(&gltf::Semantic::Positions);
    if position_accessor.as_ref().is_some_and(|a| a.count() == 0) {
        return Ok(None);
    }
    let positions: Vec<Vec3> = match (position_accessor, reader.read_positions()) {
        (None, _) => return Ok(None),
        (Some(_), None) => {
            return Err(bad(format!(
                "{}: POSITION data lies outside its buffer",
                what()
            )))
        }
        (Some(_), Some(it)) => it.map(Vec3::from).collect(),
    };
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(bad(format!("{}: non-finite vertex positions", what())));
    }
    let n = positions.len();
    let normals: Option<Vec<Vec3>> = match prim.get(&gltf::Semantic::Normals) {
        None => None,
        Some(a) if a.count() != n => {
            return Err(bad(format!(
                "{}: {} normals for {n} positions",
                what(),
                a.count()
            )))
        }
        Some(_) => Some(
            reader
                .read_normals()
                .ok_or_else(|| bad(format!("{}: NORMAL data lies outside its buffer", what())))?
                .map(Vec3::from)
                .collect(),
        ),
    };
    let uvs: Vec<Vec2> = match prim.get(&gltf::Semantic::TexCoords(0)) {
        None => vec![Vec2::ZERO; n],
        Some(a) if a.count() != n => {
            return Err(bad(format!(
                "{}: {} texture coordinates for {n} positions",
                what(),
                a.count()
            )))
        }
        Some(_) => reader
            .read_tex_coords(0)
            .ok_or_else(|| {
                bad(format!(
                    "{}: TEXCOORD_0 data lies outside its buffer",
                    what()
                ))
            })?
            .into_f32()
            .map(Vec2::from)
            .map(|uv| if uv.is_finite() { uv } else { Vec2::ZERO })
            .collect(),
    };
    let mut indices: Vec<u32> = match prim.indices() {
        None => (0..n as u32).collect(),
        Some(a) if a.count() == 0 => Vec::new(),
        // The gltf crate reads indices of other types as unreachable (a panic): found by
        // fuzzing (tests/fuzz-corpus/gltf-binary).
        Some(a)
            if a.dimensions() != gltf::accessor::Dimensions::Scalar
                || !matches!(
                    a.data_type(),
                    gltf::accessor::DataType::U8
                        | gltf::accessor::DataType::U16
                        | gltf::accessor::DataType::U32
                ) =>
        {
            return Err(bad(format!(
                "{}: indices are {:?} {:?}; expected unsigned integer scalars",
                what(),
                a.data_type(),
                a.dimensions()
            )));
        }
        Some(_) => reader
            .read_indices()
            .ok_or_else(|| bad(format!("{}: index data lies outside its buffer", what())))?
            .into_u32()
            .collect(),
    };
    indices.truncate(indices.len() / 3 * 3);
    if let Some(&i) = indices.iter().find(|&&i| i as usize >= n) {
        return Err(bad(format!(
            "{}: index {i} is out of range ({n} vertices)",
            what()
        )));
    }
    if indices.is_empty() {
        return Ok(None);
    }
    Ok(Some(PrimitiveData {
        positions,
        normals,
        uvs,
        indices,
    }))
}

/// Appends a primitive to `mesh` in world space with material `material`: windings swapped
/// where the placement mirrors, stored normals transformed (a zero or degenerate one replaced
/// by a face normal of a triangle using the vertex), or flat normals on vertices of their own
/// where it has none.
fn append_primitive(
    path: &Path,
    mesh: &mut Mesh,
    data: PrimitiveData,
    placement: &Placement,
    material: u32,
    what: &dyn Fn() -> String,
) -> Result<()> {
    let bad = |message: String| Error::bad_file(path, message);
    let PrimitiveData {
        positions,
        normals,
        uvs,
        mut indices,
    } = data;
    let n = positions.len();
    let world = placement.world;
    if placement.mirrored {
        for tri in indices.chunks_exact_mut(3) {
            tri.swap(1, 2);
        }
    }
    let world_positions: Vec<Vec3> = positions
        .iter()
        .map(|p| world.transform_point3(*p))
        .collect();
    if world_positions.iter().any(|p| !p.is_finite()) {
        return Err(bad(format!(
            "{}: vertex positions overflow after the node transform",
            what()
        )));
    }
    if mesh.positions.len() + indices.len() > u32::MAX as usize {
        return Err(bad("too many vertices for 32-bit indices".into()));
    }

    let base = mesh.positions.len() as u32;
    match normals {
        Some(normals) => {
            for v in 0..n {
                mesh.positions.push(world_positions[v]);
                mesh.uvs.push(uvs[v]);
                mesh.materials.push(material);
                mesh.normals
                    .push((placement.normal_matrix * normals[v]).normalize_or_zero());
            }
            mesh.indices.extend(indices.iter().map(|i| base + i));
            // Zero or degenerate normals fall back to the face normal of a triangle
            // using the vertex.
            for tri in indices.chunks_exact(3) {
                let face = face_normal(&world_positions, tri);
                for &i in tri {
                    let slot = &mut mesh.normals[(base + i) as usize];
                    if *slot == Vec3::ZERO {
                        *slot = face;
                    }
                }
            }
            for v in 0..n {
                let slot = &mut mesh.normals[base as usize + v];
                if *slot == Vec3::ZERO {
                    *slot = Vec3::Y; // an unused vertex
                }
            }
        }
        None => {
            // Flat normals: every triangle gets its own three vertices.
            for (k, tri) in indices.chunks_exact(3).enumerate() {
                let face = face_normal(&world_positions, tri);
                for &i in tri {
                    mesh.positions.push(world_positions[i as usize]);
                    mesh.uvs.push(uvs[i as usize]);
                    mesh.materials.push(material);
                    mesh.normals.push(face);
                }
                let b = base + 3 * k as u32;
                mesh.indices.extend_from_slice(&[b, b + 1, b + 2]);
            }
        }
    }
    Ok(())
}

/// Largest glTF file, and largest file one of its URIs may name, that gibench reads (2 GiB).
pub const MAX_GLTF_FILE_BYTES: u64 = 2 << 30;

/// `gltf::import` with every read bounded and every external file checked first: the glTF
/// itself and each file a buffer or image URI names must be a regular file of at most
/// [`MAX_GLTF_FILE_BYTES`]; a URI must be a `data:` URI or a relative path that stays inside the
/// glTF's folder (no absolute path, no `..`, no other scheme); a missing file is named.
fn import_checked(
    path: &Path,
) -> Result<(
    gltf::Document,
    Vec<gltf::buffer::Data>,
    Vec<gltf::image::Data>,
)> {
    let bytes = crate::error::read_bounded(path, MAX_GLTF_FILE_BYTES)?;
    let invalid = |e: gltf::Error| Error::bad_file(path, format!("not a valid glTF binary: {e}"));
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(&bytes).map_err(invalid)?;
    drop(bytes);
    // The gltf crate's validation (1.4) indexes the accessors by a primitive's POSITION
    // unchecked: an index past them panics there (found by fuzzing, tests/fuzz-corpus).
    let json = document.into_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for index in prim.attributes.values() {
                if index.value() >= json.accessors.len() {
                    return Err(Error::bad_file(
                        path,
                        format!(
                            "not a valid glTF binary: an attribute of meshes[{m}].primitives[{p}] \
                             names accessor {} of {}",
                            index.value(),
                            json.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    let document = gltf::Document::from_json(json).map_err(invalid)?;
    let base = path.parent().unwrap_or(Path::new("."));
    for b in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = b.source() {
            let what = format!("buffer {}", b.index());
            if let Some(file) = external_file(path, base, &what, uri)? {
                let len = std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0);
                if len < b.length() as u64 {
                    return Err(Error::bad_file(
                        path,
                        format!(
                            "{what}: '{}' has {len} bytes, the buffer declares {}",
                            file.display(),
                            b.length()
                        ),
                    ));
                }
            }
        }
    }
    for img in document.images() {
        if let gltf::image::Source::Uri { uri, .. } = img.source() {
            external_file(path, base, &format!("image {}", img.index()), uri)?;
        }
    }
    let buffers = gltf::import_buffers(&document, Some(base), blob).map_err(invalid)?;
    let images = gltf::import_images(&document, Some(base), &buffers).map_err(invalid)?;
    Ok((document, buffers, images))
}

/// The file a glTF URI names, checked (see [`import_checked`]); `None` for a `data:` URI.
fn external_file(
    gltf: &Path,
    base: &Path,
    what: &str,
    uri: &str,
) -> Result<Option<std::path::PathBuf>> {
    let refuse = |why: &str| {
        Error::bad_file(
            gltf,
            format!("{what}: URI '{uri}' {why}; only data: URIs and relative paths inside the glTF's folder are read"),
        )
    };
    if uri.starts_with("data:") {
        return Ok(None);
    }
    if uri.contains(':') {
        return Err(refuse("has a scheme"));
    }
    let decoded =
        percent_decode(uri).ok_or_else(|| refuse("is not valid percent-encoded UTF-8"))?;
    let rel = Path::new(&decoded);
    if !rel.components().all(|c| {
        matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    }) {
        return Err(refuse("leaves the glTF's folder"));
    }
    let file = base.join(rel);
    // Through symlinks too: the file itself must lie inside the folder.
    if let (Ok(real), Ok(folder)) = (file.canonicalize(), base.canonicalize()) {
        if !real.starts_with(&folder) {
            return Err(refuse("leaves the glTF's folder through a symbolic link"));
        }
    }
    let meta = std::fs::metadata(&file).map_err(|e| {
        Error::bad_file(
            gltf,
            format!(
                "{what}: cannot read '{}' (URI '{uri}'): {e}",
                file.display()
            ),
        )
    })?;
    if !meta.is_file() {
        return Err(refuse("does not name a regular file"));
    }
    if meta.len() > MAX_GLTF_FILE_BYTES {
        return Err(refuse(&format!(
            "names a file of {} bytes, more than {MAX_GLTF_FILE_BYTES}",
            meta.len()
        )));
    }
    Ok(Some(file))
}

/// Decodes `%XX` escapes of a URI path (`None` for a bad escape or invalid UTF-8).
fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Unit normal of triangle `tri` (counter-clockwise front), `+Y` if it has no area.
fn face_normal(positions: &[Vec3], tri: &[u32]) -> Vec3 {
    let [a, b, c] = [0, 1, 2].map(|k| positions[tri[k] as usize]);
    (b - a).cross(c - a).normalize_or(Vec3::Y)
}

/// sRGB-encoded byte → linear value (IEC 61966-2-1 transfer function).
fn srgb_to_linear(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Mean linear colour of an RGBA8 texture: each texel's R, G, B bytes are decoded from sRGB to
/// linear (`c ≤ 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055)^2.4` with `c = byte / 255`) and
/// averaged over all texels with equal weight (alpha ignored). [`Material::average_color`] of
/// a textured material is `base_color ×` this. An empty texture gives 1 (no effect).
pub fn average_texture_color(rgba8: &[u8]) -> Vec3 {
    let texels = rgba8.len() / 4;
    if texels == 0 {
        return Vec3::ONE;
    }
    let mut lut = [0.0f64; 256];
    for (i, v) in lut.iter_mut().enumerate() {
        *v = srgb_to_linear(i as u8);
    }
    let mut sum = [0.0f64; 3];
    for px in rgba8.chunks_exact(4) {
        for c in 0..3 {
            sum[c] += lut[px[c] as usize];
        }
    }
    let n = texels as f64;
    Vec3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}

/// Converts a decoded glTF image to RGBA8, keeping the stored (sRGB) encoding: 1 channel →
/// grey, 2 channels → grey + alpha, 3 → opaque RGB; 16-bit channels keep their high byte;
/// float channels are clamped to [0, 1] and scaled.
fn to_rgba8(img: &gltf::image::Data) -> std::result::Result<Vec<u8>, String> {
    use gltf::image::Format;
    let texels = img.width as usize * img.height as usize;
    let (channels, bytes_per_channel) = match img.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    let stride = channels * bytes_per_channel;
    if img.pixels.len() < texels * stride {
        return Err(format!(
            "{} bytes of pixel data for a {}x{} {:?} image",
            img.pixels.len(),
            img.width,
            img.height,
            img.format
        ));
    }
    let channel = |px: &[u8], c: usize| -> u8 {
        let b = &px[c * bytes_per_channel..(c + 1) * bytes_per_channel];
        match bytes_per_channel {
            1 => b[0],
            2 => (u16::from_ne_bytes([b[0], b[1]]) >> 8) as u8,
            _ => {
                let f = f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
                (if f.is_finite() {
                    f.clamp(0.0, 1.0)
                } else {
                    0.0
                } * 255.0)
                    .round() as u8
            }
        }
    };
    let mut out = Vec::with_capacity(texels * 4);
    for px in img.pixels.chunks_exact(stride).take(texels) {
        let rgba = match channels {
            1 => {
                let g = channel(px, 0);
                [g, g, g, 255]
            }
            2 => {
                let g = channel(px, 0);
                [g, g, g, channel(px, 1)]
            }
            3 => [channel(px, 0), channel(px, 1), channel(px, 2), 255],
            _ => [
                channel(px, 0),
                channel(px, 1),
                channel(px, 2),
                channel(px, 3),
            ],
        };
        out.extend_from_slice(&rgba);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_average_texture_color_formula() {
        // Two texels: black and white → mean 0.5 in linear light.
        let px = [0, 0, 0, 255, 255, 255, 255, 0];
        assert!(average_texture_color(&px).abs_diff_eq(Vec3::splat(0.5), 1e-6));
        // sRGB 188 ≈ linear 0.5029.
        let c = average_texture_color(&[188, 188, 188, 255]);
        assert!((c.x - 0.5029).abs() < 1e-3, "{c}");
        assert_eq!(average_texture_color(&[]), Vec3::ONE);
    }

    #[test]
    fn gltf_to_rgba8_formats() {
        let img = |format, pixels: Vec<u8>| gltf::image::Data {
            pixels,
            format,
            width: 1,
            height: 1,
        };
        assert_eq!(
            to_rgba8(&img(gltf::image::Format::R8, vec![7])).unwrap(),
            vec![7, 7, 7, 255]
        );
        assert_eq!(
            to_rgba8(&img(gltf::image::Format::R8G8B8, vec![1, 2, 3])).unwrap(),
            vec![1, 2, 3, 255]
        );
        let px16: Vec<u8> = [0x1234u16, 0xff00, 0x0100]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        assert_eq!(
            to_rgba8(&img(gltf::image::Format::R16G16B16, px16)).unwrap(),
            vec![0x12, 0xff, 0x01, 255]
        );
        assert!(to_rgba8(&img(gltf::image::Format::R8G8B8A8, vec![1, 2])).is_err());
    }
}
