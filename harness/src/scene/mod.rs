//! The one in-memory scene model every technique and the reference renderer use.
//!
//! A [`Scene`] is built from a [`descriptor::SceneDescriptor`] (JSON in `scenes/`): the static
//! mesh (from a glTF file found on the asset search path, or generated in code such as the
//! Cornell box), an optional tessellated copy of it for paraboloid shadow maps, the movers
//! (dynamic meshes with a path), the primary light and per-scene settings.
//!
//! All geometry is in world space (node transforms applied) and in the source's own units.
//! Vertices are never shared between materials, so a triangle's material is the material of
//! any of its vertices.

pub mod anim;
pub mod assets;
pub mod barczak;
pub mod charts;
pub mod cornell;
pub mod descriptor;
pub mod gaitatzes;
pub mod gltf_load;
pub mod maze;

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::scene::assets::AssetPaths;
use crate::Result;

pub use descriptor::SceneDescriptor;
use descriptor::{MeshSource, GENERATED_CORNELL_BOX, GENERATED_MAZE};

/// A diffuse material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Linear RGB base colour factor (the diffuse albedo when untextured).
    pub base_color: Vec3,
    /// Index into [`Scene::textures`] of the base-colour texture, if any.
    pub texture: Option<usize>,
    /// The albedo a VPL or the reference uses for this material: the base colour times the
    /// mean linear colour of its texture (Laine §4.6 uses a heavily blurred texture; the mean is
    /// the limit of that blur).
    pub average_color: Vec3,
}

impl Material {
    /// An untextured material of colour `color`.
    pub fn plain(name: &str, color: Vec3) -> Material {
        Material {
            name: name.into(),
            base_color: color,
            texture: None,
            average_color: color,
        }
    }
}

/// A base-colour texture, decoded to RGBA8 with sRGB-encoded colour channels.
#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// An indexed triangle mesh with per-vertex attributes.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// Unit shading normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (zero where the source has none).
    pub uvs: Vec<Vec2>,
    /// Material index (into [`Scene::materials`]) per vertex.
    pub materials: Vec<u32>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
    /// The three corner positions of triangle `t`.
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [
            self.positions[i[0] as usize],
            self.positions[i[1] as usize],
            self.positions[i[2] as usize],
        ]
    }
    /// Material index of triangle `t`.
    pub fn triangle_material(&self, t: usize) -> u32 {
        self.materials[self.indices[3 * t] as usize]
    }
    /// Axis-aligned bounds (min, max); `(0, 0)` for an empty mesh.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if self.positions.is_empty() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        self.positions.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }
    /// How many triangles [`Mesh::tessellated`] would make, computed without making them.
    pub fn tessellated_triangle_count(&self, max_edge: f32) -> u64 {
        if !(max_edge.is_finite() && max_edge > 0.0) {
            return self.triangle_count() as u64;
        }
        (0..self.triangle_count())
            .map(|t| {
                let longest = longest_edge_of(self.triangle(t));
                // Unclamped: an edge so short that `tessellated` would clamp it is refused.
                let n = (longest / max_edge).ceil();
                let n = if n.is_finite() { n.max(1.0) } else { f32::MAX };
                (n as f64 * n as f64).min(u64::MAX as f64) as u64
            })
            .fold(0u64, u64::saturating_add)
    }

    /// The longest edge of any triangle (0 without triangles).
    pub fn longest_edge(&self) -> f32 {
        (0..self.triangle_count())
            .map(|t| longest_edge_of(self.triangle(t)))
            .fold(0.0, f32::max)
    }

    /// A copy in which every triangle whose longest edge exceeds `max_edge` is split into an
    /// n×n grid of sub-triangles (n = ceil(longest edge / max_edge)) with attributes
    /// interpolated linearly; smaller triangles are kept. Neighbours split differently meet at
    /// T-junctions; the copy is only rendered into shadow maps, where these are sub-texel.
    pub fn tessellated(&self, max_edge: f32) -> Mesh {
        let mut out = Mesh::default();
        if !(max_edge.is_finite() && max_edge > 0.0) {
            return self.clone();
        }
        for t in 0..self.triangle_count() {
            let idx = [
                self.indices[3 * t] as usize,
                self.indices[3 * t + 1] as usize,
                self.indices[3 * t + 2] as usize,
            ];
            let p = idx.map(|i| self.positions[i]);
            let n = tessellation_factor(longest_edge_of(p), max_edge);
            let base = out.positions.len() as u32;
            // Vertices of the barycentric grid: row i (0..=n) has n - i + 1 vertices.
            let mut row_start = Vec::with_capacity(n + 1);
            for i in 0..=n {
                row_start.push(out.positions.len() as u32 - base);
                for j in 0..=(n - i) {
                    let (b1, b2) = (i as f32 / n as f32, j as f32 / n as f32);
                    let b0 = 1.0 - b1 - b2;
                    let mix3 = |a: Vec3, b: Vec3, c: Vec3| a * b0 + b * b1 + c * b2;
                    out.positions.push(mix3(p[0], p[1], p[2]));
                    let nrm = mix3(
                        self.normals[idx[0]],
                        self.normals[idx[1]],
                        self.normals[idx[2]],
                    );
                    out.normals.push(nrm.normalize_or(self.normals[idx[0]]));
                    let uv = |k: usize| self.uvs.get(idx[k]).copied().unwrap_or(Vec2::ZERO);
                    out.uvs.push(uv(0) * b0 + uv(1) * b1 + uv(2) * b2);
                    out.materials.push(self.materials[idx[0]]);
                }
            }
            let v = |i: usize, j: usize| base + row_start[i] + j as u32;
            for i in 0..n {
                for j in 0..(n - i) {
                    out.indices.extend([v(i, j), v(i + 1, j), v(i, j + 1)]);
                    if j + 1 < n - i {
                        out.indices
                            .extend([v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
                    }
                }
            }
        }
        out
    }

    /// Appends `other`, offsetting its indices and its material indices by `material_offset`.
    pub fn append(&mut self, other: &Mesh, material_offset: u32) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.uvs.extend_from_slice(&other.uvs);
        self.materials
            .extend(other.materials.iter().map(|m| m + material_offset));
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }
}

/// A `KHR_lights_punctual` light read from a glTF file (world space).
#[derive(Clone, Debug, PartialEq)]
pub struct PunctualLight {
    pub name: String,
    pub kind: PunctualKind,
    pub position: Vec3,
    /// Unit direction the light points at (−Z of its node); meaningful for spots.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity as stored in glTF (candela for point and spot lights).
    pub intensity: f32,
}

/// Kinds of glTF punctual lights.
#[derive(Clone, Debug, PartialEq)]
pub enum PunctualKind {
    Point,
    Spot {
        inner_cone_angle: f32,
        outer_cone_angle: f32,
    },
    Directional,
}

/// A dynamic object: a mesh in its own local space, already scaled by the descriptor's
/// `scale`, and the index of its path in the descriptor (`descriptor.movers[i]`). Its
/// per-frame transform (rigid: translation and rotation about +Y) comes from [`crate::scene::anim`].
#[derive(Clone, Debug)]
pub struct Mover {
    pub name: String,
    pub mesh: Mesh,
}

/// Per-scene constants computed once at load from the static mesh's bounds: the bounding box,
/// its diagonal and bounding sphere, and the ray offset ε every CPU ray uses (VPL generation,
/// Laine's management; the reference uses the same rule over its per-frame mesh).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneExtent {
    pub min: Vec3,
    pub max: Vec3,
    /// Length of the bounding-box diagonal (at least 10⁻⁶).
    pub diagonal: f32,
    /// Centre of the bounding box.
    pub centre: Vec3,
    /// Half the diagonal: the radius of a sphere around `centre` holding the whole mesh.
    pub radius: f32,
    /// 10⁻⁴ × the diagonal, or 10⁻⁶ for an empty or degenerate mesh.
    pub ray_epsilon: f32,
    /// Total area of the mesh's triangles (at least 10⁻¹²): what the VPL irradiance clamp
    /// spreads the VPLs' flux over ([`crate::kit::ir::accumulate`]).
    pub surface_area: f32,
}

impl SceneExtent {
    /// The extent of `mesh` (one pass over its vertices and one over its triangles).
    pub fn of(mesh: &Mesh) -> SceneExtent {
        let (lo, hi) = mesh.bounds();
        let area: f64 = (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.triangle(t);
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .filter(|a| a.is_finite())
            .sum();
        SceneExtent {
            surface_area: (area as f32).max(1e-12),
            ..SceneExtent::from_bounds(lo, hi)
        }
    }
    /// The extent of the box `[min, max]`, whose surface is the box's own.
    pub fn from_bounds(min: Vec3, max: Vec3) -> SceneExtent {
        let d = (max - min).length();
        let ok = d.is_finite() && d > 0.0;
        SceneExtent {
            min,
            max,
            diagonal: if ok { d } else { 1e-6 },
            centre: 0.5 * (min + max),
            radius: if ok { 0.5 * d } else { 5e-7 },
            ray_epsilon: if ok { 1e-4 * d } else { 1e-6 },
            surface_area: {
                let e = (max - min).max(Vec3::ZERO);
                let a = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
                if a.is_finite() {
                    a.max(1e-12)
                } else {
                    1e-12
                }
            },
        }
    }
}

/// Most triangles a tessellated mesh may have (2²³): a `tessellate` edge that would make more is
/// refused before any memory is asked for.
pub const MAX_TESSELLATED_TRIANGLES: u64 = 1 << 23;

/// Most rows a triangle is split into along its longest edge by [`Mesh::tessellated`]: a
/// `tessellate` edge that would need more for some triangle is refused when the scene loads,
/// not quietly coarsened.
pub const MAX_TESSELLATION_ROWS: usize = 256;

/// The longest edge of the triangle with corners `p`.
fn longest_edge_of(p: [Vec3; 3]) -> f32 {
    (p[1] - p[0])
        .length()
        .max((p[2] - p[1]).length())
        .max((p[0] - p[2]).length())
}

/// Rows of the barycentric grid a triangle with longest edge `longest` is split into.
fn tessellation_factor(longest: f32, max_edge: f32) -> usize {
    let n = (longest / max_edge).ceil();
    if n.is_finite() {
        (n as usize).clamp(1, MAX_TESSELLATION_ROWS)
    } else {
        1
    }
}

/// Largest magnitude of any world-space coordinate (scene units): positions in a descriptor,
/// and every vertex after its transforms. Beyond it f32 bounds and BVH arithmetic overflow.
pub const MAX_COORDINATE: f32 = 1e9;

/// Whether a position is past [`MAX_COORDINATE`] (or not finite).
fn out_of_range(p: Vec3) -> bool {
    !p.is_finite() || p.abs().max_element() > MAX_COORDINATE
}

/// The file (or generated mesh) a mesh source names, for messages.
fn source_label(src: &MeshSource) -> String {
    match (&src.file, &src.generated) {
        (Some(file), _) => format!("file {file}"),
        (None, Some(name)) => format!("generated '{name}'"),
        (None, None) => "no source".to_string(),
    }
}

/// Checks every vertex of `mesh` against [`MAX_COORDINATE`]; `what` names the mesh.
fn check_coordinates(scene: &str, what: &str, mesh: &Mesh) -> Result<()> {
    match mesh.positions.iter().find(|p| out_of_range(**p)) {
        None => Ok(()),
        Some(p) => Err(crate::Error::bad_file(
            format!("scene '{scene}'"),
            format!(
                "{what}: a vertex at {p} after its transforms; every coordinate must be finite and within ±{MAX_COORDINATE:e} scene units"
            ),
        )),
    }
}

/// A planar rectangular surface of the static mesh and the object it belongs to: what
/// light-mapped, visibility-culled techniques (Barczak 2006 §4.3) light and test against.
/// Generated scenes that are built from rectangles record them ([`barczak`]); other scenes
/// have none.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Corners in order, counter-clockwise seen from the front (the side `normal` points to).
    pub corners: [Vec3; 4],
    pub normal: Vec3,
    /// The object: an object never shadows itself, and its patches move together.
    pub object: u32,
    pub material: u32,
    /// How many times to split it 2 × 2 for visibility determination (the thesis set this per
    /// surface: floors more than ceilings).
    pub levels: u32,
    /// Whether it can shadow another surface (a convex room's own walls cannot; the thesis leaves
    /// them out of the occluders).
    pub casts_shadows: bool,
    /// Where the patch is a chart of a mesh that records no patches ([`charts`]): the triangles
    /// it stands for, which may cover only part of the rectangle. `None`: the rectangle is the
    /// surface.
    pub chart: Option<ChartSurface>,
}

/// The surface of a chart patch (see [`Patch::chart`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ChartSurface {
    /// Its triangles, world space, wound counter-clockwise seen from the front.
    pub triangles: Vec<[Vec3; 3]>,
    /// The convex hull of the triangles, counter-clockwise seen from the front: the blocker.
    pub hull: Vec<Vec3>,
    /// Whether the triangles fill the hull, so that it may block fully.
    pub convex: bool,
}

/// The whole scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The descriptor it was built from (name, paths, light, settings).
    pub descriptor: SceneDescriptor,
    /// Static geometry, world space. Indirect light bounces off this only (as in Laine 2007).
    pub mesh: Mesh,
    /// A finely tessellated copy of the static geometry for rendering paraboloid shadow maps
    /// (`shadow_mesh` in the descriptor); `None` means use [`Scene::mesh`].
    pub shadow_mesh: Option<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    /// One per `descriptor.movers` entry, same order.
    pub movers: Vec<Mover>,
    /// Punctual lights found in the static mesh's glTF file.
    pub gltf_lights: Vec<PunctualLight>,
    /// Bounds, diagonal and ray ε of [`Scene::mesh`], computed once at load.
    pub extent: SceneExtent,
    /// The static mesh's rectangles by object, where its source records them (see [`Patch`]).
    pub patches: Vec<Patch>,
}

/// A mesh built from a [`MeshSource`], with materials and textures indexed from zero.
struct BuiltMesh {
    mesh: Mesh,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    lights: Vec<PunctualLight>,
    patches: Vec<Patch>,
}

/// The mesh, materials and patches of the generated mesh `name` (one of
/// [`descriptor::GENERATED_MESHES`]), split into cells of about `tessellate` where given.
fn generate(name: &str, tessellate: Option<f32>) -> Result<(Mesh, Vec<Material>, Vec<Patch>)> {
    let none = |(m, mat): (Mesh, Vec<Material>)| (m, mat, Vec::new());
    Ok(match name {
        GENERATED_CORNELL_BOX => none(cornell::cornell_box(tessellate)),
        GENERATED_MAZE => none(maze::maze(tessellate)),
        "gaitatzes-test" => none(gaitatzes::test_scene(tessellate)),
        "gaitatzes-room" => none(gaitatzes::room(tessellate)),
        "gaitatzes-arena" => none(gaitatzes::arena(tessellate)),
        "barczak-area-room" => barczak::area_room(tessellate),
        "barczak-table-room" => barczak::table_room(tessellate),
        "barczak-pillar-room" => barczak::pillar_room(tessellate),
        "barczak-area-casters" => barczak::casters(barczak::area_room, tessellate),
        "barczak-table-casters" => barczak::casters(barczak::table_room, tessellate),
        "barczak-pillar-casters" => barczak::casters(barczak::pillar_room, tessellate),
        "torus-820" => none(barczak::torus()),
        _ => {
            return Err(crate::Error::Invalid(format!(
                "unknown generated mesh '{name}'; expected one of: {}",
                descriptor::GENERATED_MESHES.join(", ")
            )))
        }
    })
}

/// The corner-to-corner length of generated mesh `name`'s bounding box, untessellated: no quad
/// edge a generator splits is longer, so a `tessellate` cell that fits
/// [`cornell::MAX_CELLS_PER_EDGE`] times along it is never coarsened (the descriptor's
/// validation refuses a finer one).
pub(crate) fn generated_diagonal(name: &str) -> Result<f32> {
    let (mesh, _, _) = generate(name, None)?;
    let (lo, hi) = mesh.bounds();
    Ok((hi - lo).length())
}

/// Builds `src`; `field` names it in errors (`mesh`, `shadow_mesh`, `statics[0].mesh`, ...).
fn build_mesh(src: &MeshSource, assets: &AssetPaths, field: &str) -> Result<BuiltMesh> {
    match (&src.file, &src.generated) {
        (Some(file), _) => {
            let path = assets.find(file)?;
            let g = gltf_load::load_gltf(&path, 0)?;
            // The file's own vertices, named by the file (placed copies are checked again
            // after their transforms, named by the descriptor's field and the file).
            if let Some(p) = g.mesh.positions.iter().find(|p| out_of_range(**p)) {
                return Err(crate::Error::bad_file(
                    &path,
                    format!(
                        "{field}: a vertex at {p} (after the file's node transforms); every coordinate must be finite and within ±{MAX_COORDINATE:e} scene units"
                    ),
                ));
            }
            let mesh = match src.tessellate {
                Some(edge) => {
                    let longest = g.mesh.longest_edge();
                    let rows = (longest / edge).ceil();
                    if rows.is_nan() || rows > MAX_TESSELLATION_ROWS as f32 {
                        return Err(crate::Error::bad_file(
                            &path,
                            format!(
                                "{field}.tessellate = {edge} would split its longest triangle edge ({longest}) into {rows} rows; at most {MAX_TESSELLATION_ROWS} are allowed (use an edge of at least {})",
                                longest / MAX_TESSELLATION_ROWS as f32
                            ),
                        ));
                    }
                    let n = g.mesh.tessellated_triangle_count(edge);
                    if n > MAX_TESSELLATED_TRIANGLES {
                        return Err(crate::Error::bad_file(
                            &path,
                            format!(
                                "{field}.tessellate = {edge} would split its {} triangles into {n}; at most {MAX_TESSELLATED_TRIANGLES} are allowed (use a longer edge)",
                                g.mesh.triangle_count()
                            ),
                        ));
                    }
                    g.mesh.tessellated(edge)
                }
                None => g.mesh,
            };
            Ok(BuiltMesh {
                mesh,
                materials: g.materials,
                textures: g.textures,
                lights: g.lights,
                patches: Vec::new(),
            })
        }
        (None, Some(name)) => {
            let (mesh, materials, patches) = generate(name, src.tessellate)?;
            Ok(BuiltMesh {
                mesh,
                materials,
                textures: Vec::new(),
                lights: Vec::new(),
                patches,
            })
        }
        (None, None) => Err(crate::Error::Invalid(
            "a mesh source needs a `file` or a `generated` name".into(),
        )),
    }
}

/// Appends `textures` to `scene_textures` and returns `materials` with their texture indices
/// shifted accordingly.
fn append_textures(
    scene_textures: &mut Vec<Texture>,
    textures: Vec<Texture>,
    materials: Vec<Material>,
) -> Vec<Material> {
    let offset = scene_textures.len();
    scene_textures.extend(textures);
    materials
        .into_iter()
        .map(|m| Material {
            texture: m.texture.map(|t| t + offset),
            ..m
        })
        .collect()
}

impl Scene {
    /// Builds the scene a descriptor describes (validating it first): the static mesh (a glTF
    /// file found with `assets`, or a generated mesh), the optional shadow mesh, the movers and
    /// the glTF punctual lights of the static mesh's file.
    ///
    /// * The static mesh's materials and textures come first in [`Scene::materials`] and
    ///   [`Scene::textures`].
    /// * The shadow mesh's materials are matched by name to the static mesh's (they are
    ///   normally copies of the same scene); unmatched ones are appended.
    /// * Each mover's mesh is loaded in its local space, scaled by the mover's `scale`, and its
    ///   materials and textures are appended (per-vertex indices refer to the scene's lists).
    ///
    /// Errors: a missing asset is [`crate::Error::AssetNotFound`]; a bad file or descriptor is
    /// [`crate::Error::BadFile`].
    pub fn load(desc: &SceneDescriptor, assets: &AssetPaths) -> Result<Scene> {
        desc.validate(Path::new(&format!("scene '{}'", desc.name)))?;

        let main = build_mesh(&desc.mesh, assets, "mesh")?;
        let mut textures = Vec::new();
        let mut materials = append_textures(&mut textures, main.textures, main.materials);
        let mesh = main.mesh;

        let shadow_mesh = match &desc.shadow_mesh {
            None => None,
            Some(src) => {
                let shadow = build_mesh(src, assets, "shadow_mesh")?;
                let texture_offset = textures.len();
                let mut needs_textures = false;
                let mut remap = Vec::with_capacity(shadow.materials.len());
                for m in shadow.materials {
                    match materials.iter().position(|s| s.name == m.name) {
                        Some(i) => remap.push(i as u32),
                        None => {
                            needs_textures |= m.texture.is_some();
                            materials.push(Material {
                                texture: m.texture.map(|t| t + texture_offset),
                                ..m
                            });
                            remap.push(materials.len() as u32 - 1);
                        }
                    }
                }
                if needs_textures {
                    textures.extend(shadow.textures);
                }
                let mut shadow_mesh = shadow.mesh;
                for m in &mut shadow_mesh.materials {
                    *m = remap.get(*m as usize).copied().unwrap_or(0);
                }
                Some(shadow_mesh)
            }
        };

        // Static instances (e.g. the MAZE's statue) join the static mesh and its shadow copy.
        let mut mesh = mesh;
        let mut shadow_mesh = shadow_mesh;
        for (i, st) in desc.statics.iter().enumerate() {
            let built = build_mesh(&st.mesh, assets, &format!("statics[{i}].mesh"))?;
            let offset = materials.len() as u32;
            materials.extend(append_textures(
                &mut textures,
                built.textures,
                built.materials,
            ));
            let rot = glam::Quat::from_rotation_y(st.rotation_y_deg.to_radians());
            let mut placed = built.mesh;
            for p in &mut placed.positions {
                *p = rot * (*p * st.scale) + Vec3::from(st.position);
            }
            check_coordinates(
                &desc.name,
                &format!("statics[{i}] ({}, placed)", source_label(&st.mesh)),
                &placed,
            )?;
            for n in &mut placed.normals {
                *n = (rot * *n).normalize_or_zero();
            }
            mesh.append(&placed, offset);
            if let Some(s) = shadow_mesh.as_mut() {
                s.append(&placed, offset);
            }
        }

        let mut movers = Vec::with_capacity(desc.movers.len());
        for (i, mover) in desc.movers.iter().enumerate() {
            let built = build_mesh(&mover.mesh, assets, &format!("movers[{i}].mesh"))?;
            let offset = materials.len() as u32;
            materials.extend(append_textures(
                &mut textures,
                built.textures,
                built.materials,
            ));
            let mut local = Mesh::default();
            local.append(&built.mesh, offset);
            for p in &mut local.positions {
                *p *= mover.scale;
            }
            movers.push(Mover {
                name: mover.name.clone(),
                mesh: local,
            });
        }

        let name = &desc.name;
        check_coordinates(name, "the static mesh (with its statics)", &mesh)?;
        if let Some(s) = &shadow_mesh {
            check_coordinates(name, "the shadow mesh (with its statics)", s)?;
        }
        for (m, d) in movers.iter().zip(&desc.movers) {
            check_coordinates(
                name,
                &format!("mover '{}' ({}, scaled)", m.name, source_label(&d.mesh)),
                &m.mesh,
            )?;
            // Placed along its path: its farthest vertex from its origin plus the farthest key.
            let reach = m
                .mesh
                .positions
                .iter()
                .map(|p| p.length())
                .fold(0.0f32, f32::max);
            let far = d
                .path
                .keys
                .iter()
                .map(|k| Vec3::from(k.position).length())
                .fold(0.0f32, f32::max);
            if reach + far > MAX_COORDINATE {
                return Err(crate::Error::bad_file(
                    format!("scene '{name}'"),
                    format!(
                        "mover '{}': vertices up to {reach} from its origin on a path reaching {far} can land past ±{MAX_COORDINATE:e} scene units",
                        m.name
                    ),
                ));
            }
        }
        Ok(Scene {
            descriptor: desc.clone(),
            extent: SceneExtent::of(&mesh),
            mesh,
            shadow_mesh,
            materials,
            textures,
            movers,
            gltf_lights: main.lights,
            patches: main.patches,
        })
    }

    /// [`SceneDescriptor::resolve`]s `name_or_path` (a built-in scene name or a JSON file) and
    /// [`load`](Self::load)s it.
    pub fn load_named(name_or_path: &str, assets: &AssetPaths) -> Result<Scene> {
        Scene::load(&SceneDescriptor::resolve(name_or_path)?, assets)
    }

    /// The mesh to render paraboloid or cube VPL shadow maps from.
    pub fn shadow_caster_mesh(&self) -> &Mesh {
        self.shadow_mesh.as_ref().unwrap_or(&self.mesh)
    }
    /// The patches a light-mapped technique lights and tests against: the recorded
    /// [`Scene::patches`], or, where the scene records none, the static mesh's [`charts`]: each
    /// chart's smallest rectangle with its triangles and hull ([`Patch::chart`]), its own
    /// object, casting shadows, split up to `levels` times (fewer for small charts: until a
    /// leaf's longer side is at most 1/16 of the scene's diagonal). Errors name the scene and
    /// the count when it makes more than `max_charts` charts.
    pub fn receiver_patches(&self, levels: u32, max_charts: usize) -> Result<Vec<Patch>> {
        if !self.patches.is_empty() {
            return Ok(self.patches.clone());
        }
        let charts = charts::charts(&self.mesh, charts::ChartSettings::for_mesh(&self.mesh));
        if charts.len() > max_charts {
            return Err(crate::Error::Invalid(format!(
                "scene '{}' records no patches, and its {} triangles make {} planar charts, more than the {max_charts} allowed (barczak's `max-charts`: raise it, with memory and preparation time to match, or use a scene that records patches: barczak-area, barczak-table, barczak-pillars)",
                self.descriptor.name,
                self.mesh.triangle_count(),
                charts.len()
            )));
        }
        let leaf = self.extent.diagonal / 16.0;
        Ok(charts
            .into_iter()
            .enumerate()
            .map(|(k, c)| {
                let r = c.rectangle;
                let side = (r[1] - r[0]).length().max((r[3] - r[0]).length());
                let needed = (side / leaf).max(1.0).log2().ceil() as u32;
                Patch {
                    corners: r,
                    normal: c.normal,
                    object: k as u32,
                    material: c.material,
                    levels: needed.min(levels),
                    casts_shadows: true,
                    chart: Some(ChartSurface {
                        triangles: c
                            .triangles
                            .iter()
                            .map(|t| self.mesh.triangle(*t as usize))
                            .collect(),
                        hull: c.hull,
                        convex: c.convex,
                    }),
                }
            })
            .collect())
    }

    /// Area-weighted mean of the materials' average colours over the static mesh (Keller's
    /// average reflectance ρ̄).
    pub fn average_reflectance(&self) -> Vec3 {
        let mut sum = Vec3::ZERO;
        let mut area = 0.0;
        for t in 0..self.mesh.triangle_count() {
            let [a, b, c] = self.mesh.triangle(t);
            let w = 0.5 * (b - a).cross(c - a).length();
            sum += w * self.materials[self.mesh.triangle_material(t) as usize].average_color;
            area += w;
        }
        if area > 0.0 {
            sum / area
        } else {
            Vec3::ZERO
        }
    }
}
