//! **Shadow atlas**: every VPL's visibility map in one 2D texture, one block per slot, and the
//! WGSL that looks a receiver up in it.
//!
//! Reads: nothing by itself — the [`super::raster::AtlasRasteriser`] renders maps into a depth
//! atlas; any other pass (imperfect shadow maps' point splats and pull-push, to come) writes a
//! float atlas as a storage texture or by copies.
//! Writes (owns): the atlas texture and its `AtlasParams` uniform (slots per row, map size,
//! kind, far, bias, cube near plane, the lift, the cube faces' matrices).
//!
//! Layout: slot s's block starts at texel ((s mod columns) · block_w, (s div columns) · block_h);
//! a paraboloid map (Brabec et al. 2002; Laine et al. 2007 §4.6) fills a `size`² block, a cube
//! map's six faces a 3×2 block of `size`² faces (+X, −X, +Y / −Y, +Z, −Z), an octahedral map
//! (Barczak 2006 §4.2.1) a `size`² block: the hemisphere projected from the map's centre onto
//! the four upper faces of the octahedron |x| + |y| + |z| = 1 and unfolded to the square, each
//! face a triangle from the centre to one edge ([`octahedral_uv`]). Values are reversed
//! depth, 1 near and 0 far or empty: paraboloid and octahedral texels store 1 − d/far for the
//! nearest occluder at distance d from the map's centre ([`ShadowAtlas::paraboloid_depth`]); a
//! cube texel stores the reversed-Z NDC depth of its face.
//!
//! Memory per map: paraboloid and octahedral `size`², cube 6 · `size`². The octahedral map's
//! projection is linear on each face (a triangle's image is a triangle), so it is rasterised
//! exactly, where a paraboloid's straight edges are approximations of curves that leak light
//! under large triangles (Barczak 2006 Figure 4-3). A map's centre is the VPL lifted
//! `lift` (0.1 % of the scene diagonal) along its normal, so the VPL's own surface is behind it.
//! Laine keeps the maps in a texture array; gibench uses one atlas because depth texture arrays
//! read back as zero on wgpu's GL backend.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3};

use crate::gpu::GpuContext;
use crate::kit::passes::{cube_face_matrix, Bindings, Bound, PARAMS_USAGE};
use crate::scene::SceneExtent;
use crate::{Error, Result};

/// How a VPL's map is parameterised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapKind {
    /// One paraboloid map over the VPL's hemisphere (Laine et al. 2007).
    Paraboloid,
    /// Six cube faces (faces behind the VPL are left empty).
    Cube,
    /// Four octahedron faces over the VPL's hemisphere in one square (Barczak 2006 §4.2.1).
    Octahedral,
}

impl MapKind {
    /// The parameter words: `paraboloid`, `cube`, `octahedral`.
    pub const NAMES: &'static [&'static str] = &["paraboloid", "cube", "octahedral"];

    pub fn parse(s: &str) -> Result<MapKind> {
        match s {
            "paraboloid" => Ok(MapKind::Paraboloid),
            "cube" => Ok(MapKind::Cube),
            "octahedral" => Ok(MapKind::Octahedral),
            _ => Err(Error::param(
                "vpl-map",
                format!("expected paraboloid, cube or octahedral (got '{s}')"),
            )),
        }
    }

    /// Faces per map.
    pub fn faces(self) -> u32 {
        match self {
            MapKind::Paraboloid => 1,
            MapKind::Cube => 6,
            MapKind::Octahedral => 4,
        }
    }

    /// The kind's code in `AtlasParams.counts.z` (`atlas_lookup.wgsl`).
    fn code(self) -> u32 {
        match self {
            MapKind::Paraboloid => 0,
            MapKind::Cube => 1,
            MapKind::Octahedral => 2,
        }
    }

    /// Texels one map takes at `size`.
    pub fn texels(self, size: u32) -> u64 {
        let (w, h) = self.block();
        (w * h) as u64 * size as u64 * size as u64
    }

    /// The block a map takes, in map sizes (columns, rows).
    fn block(self) -> (u32, u32) {
        match self {
            MapKind::Paraboloid | MapKind::Octahedral => (1, 1),
            MapKind::Cube => (3, 2),
        }
    }
}

/// Where the unit direction `local` (the map's frame, z ≥ 0 along the VPL's normal) falls in an
/// octahedral map, on [-1, 1]² (v up): projected from the centre onto the octahedron face
/// |x| + |y| + z = 1 of its quadrant, o = local / (|x| + |y| + z), the diamond |o.x| + |o.y| ≤ 1
/// is turned 45° onto the square, (u, v) = (o.x + o.y, o.x − o.y). Face (sx, sy) (the signs of
/// x and y) is the triangle from the centre to one edge; on it the map is the projective
/// (x + y, x − y) / (sx·x + sy·y + z), which a rasteriser draws exactly.
/// `atlas_lookup.wgsl`'s `octahedral_texel` is the same function.
pub fn octahedral_uv(local: Vec3) -> Vec2 {
    let o = local / (local.x.abs() + local.y.abs() + local.z.max(0.0)).max(1e-30);
    Vec2::new(o.x + o.y, o.x - o.y)
}

/// The inverse of [`octahedral_uv`]: the unit direction on the upper hemisphere at `uv`
/// ([-1, 1]²).
pub fn octahedral_direction(uv: Vec2) -> Vec3 {
    let o = Vec2::new(uv.x + uv.y, uv.x - uv.y) * 0.5;
    Vec3::new(o.x, o.y, (1.0 - o.x.abs() - o.y.abs()).max(0.0)).normalize()
}

/// What the atlas stores its values in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AtlasFormat {
    /// 16-bit depth (Laine et al. 2007), rendered by the rasteriser.
    Depth16,
    /// 32-bit float depth, rendered by the rasteriser.
    Depth32,
    /// 32-bit float colour texture, written by compute passes or copies (storage binding).
    Float32,
}

impl AtlasFormat {
    /// The texture format.
    pub fn texture_format(self) -> wgpu::TextureFormat {
        match self {
            AtlasFormat::Depth16 => wgpu::TextureFormat::Depth16Unorm,
            AtlasFormat::Depth32 => wgpu::TextureFormat::Depth32Float,
            AtlasFormat::Float32 => wgpu::TextureFormat::R32Float,
        }
    }

    /// Whether the rasteriser can render into it.
    pub fn is_depth(self) -> bool {
        self != AtlasFormat::Float32
    }

    /// `depth-bits` 16 or 32.
    pub fn from_depth_bits(bits: u32) -> Result<AtlasFormat> {
        match bits {
            16 => Ok(AtlasFormat::Depth16),
            32 => Ok(AtlasFormat::Depth32),
            _ => Err(Error::param(
                "depth-bits",
                format!("expected 16 or 32 (got {bits})"),
            )),
        }
    }
}

/// What an atlas holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtlasSettings {
    pub kind: MapKind,
    pub format: AtlasFormat,
    /// Edge of one map (cube: of one face), texels.
    pub size: u32,
    /// Slots (maps) held at once.
    pub capacity: u32,
    /// Depth bias as a fraction of the VPL–receiver distance.
    pub bias: f32,
}

/// GPU layout of `AtlasParams` in `atlas_lookup.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    counts: [u32; 4],
    distances: [f32; 4],
    cube_faces: [[f32; 16]; 6],
}

/// The atlas texture, its parameters and its lookup (see the module docs).
pub struct ShadowAtlas {
    pub settings: AtlasSettings,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// Slots per atlas row.
    columns: u32,
    /// Far distance of paraboloid depth (1.5 × the scene diagonal).
    pub far: f32,
    /// Near plane of cube faces (10⁻⁴ × the scene diagonal).
    pub near: f32,
    /// How far a map's centre sits off the VPL's surface (10⁻³ × the scene diagonal).
    pub lift: f32,
    params: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
}

impl ShadowAtlas {
    /// Creates the atlas (zeroed: every map empty) for a scene of `extent`. Errors name the
    /// parameter when the maps do not fit the adapter's largest 2D texture.
    pub fn new(gpu: &GpuContext, extent: &SceneExtent, settings: AtlasSettings) -> Result<Self> {
        let device = &gpu.device;
        if settings.capacity == 0 {
            return Err(Error::param("vpls", "at least one VPL map is needed"));
        }
        if !(8..=4096).contains(&settings.size) {
            return Err(Error::param(
                "vpl-map-size",
                format!("expected 8..=4096 (got {})", settings.size),
            ));
        }
        let (bw, bh) = settings.kind.block();
        let block = (bw * settings.size, bh * settings.size);
        let max = gpu.max_texture_2d();
        let columns = (max / block.0).max(1).min(settings.capacity);
        let rows = settings.capacity.div_ceil(columns);
        if block.0 > max || rows as u64 * block.1 as u64 > max as u64 {
            return Err(Error::param(
                "vpl-map-size",
                format!(
                    "{} VPL maps of {}² do not fit in one {max}×{max} atlas (the adapter's limit); use fewer VPLs or smaller maps",
                    settings.capacity, settings.size
                ),
            ));
        }
        let usage = if settings.format.is_depth() {
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING
        } else {
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC
        };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("vpl shadow atlas"),
            size: wgpu::Extent3d {
                width: columns * block.0,
                height: rows * block.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: settings.format.texture_format(),
            usage,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpl atlas params"),
            size: std::mem::size_of::<ParamsData>() as u64,
            usage: PARAMS_USAGE,
            mapped_at_creation: false,
        });
        let stages = wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT;
        let Bound { layout, group } = Bindings::new("vpl atlas", stages)
            .params(&params)
            .texture(&view)
            .build(device);
        let atlas = ShadowAtlas {
            settings,
            texture,
            view,
            columns,
            far: extent.diagonal * 1.5,
            near: extent.diagonal * 1e-4,
            lift: extent.diagonal * 1e-3,
            params,
            layout,
            group,
        };
        let mut cube_faces = [[0f32; 16]; 6];
        for (f, m) in cube_faces.iter_mut().enumerate() {
            *m = atlas.cube_face_rotation(f).to_cols_array();
        }
        let data = ParamsData {
            counts: [columns, settings.size, settings.kind.code(), 0],
            distances: [atlas.far, settings.bias, atlas.near, atlas.lift],
            cube_faces,
        };
        gpu.queue
            .write_buffer(&atlas.params, 0, bytemuck::bytes_of(&data));
        gpu.check_errors()?;
        Ok(atlas)
    }

    /// Slots per atlas row.
    pub fn columns(&self) -> u32 {
        self.columns
    }
    pub fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Texel origin and size (w, h) of `slot`'s block.
    pub fn block(&self, slot: u32) -> ([u32; 2], [u32; 2]) {
        let (bw, bh) = self.settings.kind.block();
        let (w, h) = (bw * self.settings.size, bh * self.settings.size);
        (
            [(slot % self.columns) * w, (slot / self.columns) * h],
            [w, h],
        )
    }

    /// Texel origin of the viewport face `face` of `slot`'s map renders into (cube: its own
    /// square; paraboloid and octahedral: the whole block, an octahedral face keeping to its
    /// triangle).
    pub fn face_origin(&self, slot: u32, face: u32) -> [u32; 2] {
        let ([x, y], _) = self.block(slot);
        if self.settings.kind != MapKind::Cube {
            return [x, y];
        }
        let s = self.settings.size;
        [x + (face % 3) * s, y + (face / 3) * s]
    }

    /// Projection × rotation of cube face `f` for an eye at the origin.
    pub fn cube_face_rotation(&self, f: usize) -> Mat4 {
        cube_face_matrix(Vec3::ZERO, f, self.near)
    }

    /// The stored paraboloid value for an occluder at distance `d` from the map's centre.
    pub fn paraboloid_depth(&self, d: f32) -> f32 {
        (1.0 - d / self.far).clamp(0.0, 1.0)
    }

    /// The unit direction, in the map's frame (z along the VPL's normal), through the centre of
    /// paraboloid texel (x, y) of a `size`² map; `None` outside the paraboloid's disc.
    pub fn paraboloid_texel_direction(size: u32, x: u32, y: u32) -> Option<Vec3> {
        let uv = Vec2::new(
            (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / size as f32 * 2.0,
        );
        let r2 = uv.length_squared();
        if r2 > 1.0 {
            return None;
        }
        // Inverse of uv = d.xy / (1 + d.z) on the upper hemisphere.
        let z = (1.0 - r2) / (1.0 + r2);
        Some((uv * (1.0 + z)).extend(z).normalize())
    }

    /// The unit direction, in the map's frame (z along the VPL's normal), through the centre of
    /// octahedral texel (x, y) of a `size`² map: every texel is on the hemisphere.
    pub fn octahedral_texel_direction(size: u32, x: u32, y: u32) -> Vec3 {
        let uv = Vec2::new(
            (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / size as f32 * 2.0,
        );
        octahedral_direction(uv)
    }

    /// The atlas's bind group (binding 0: `AtlasParams`, 1: the texture), for the layout
    /// [`ShadowAtlas::layout`]; compute and fragment shaders.
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The lookup for a shader binding [`ShadowAtlas::group`] at `group`: the bindings
    /// `atlas_params` and `vpl_atlas`, then `vpl_visibility(v: GpuVpl, p, n) -> f32` and its
    /// parts for a caller that computes them once per VPL (`vpl_eye`, `vpl_map_origin`,
    /// `atlas_visibility`: the accumulation's). Needs `GpuVpl`, which the module imports.
    pub fn wgsl(group: u32) -> String {
        format!(
            "#import gibench::atlas_lookup\n@group({group}) @binding(0) var<storage, read> atlas_params: AtlasParams;\n@group({group}) @binding(1) var vpl_atlas: texture_2d<f32>;\n"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions spread over the upper hemisphere (a Fibonacci spiral), the horizon included.
    fn hemisphere(n: usize) -> impl Iterator<Item = Vec3> {
        (0..n).map(move |i| {
            let z = 1.0 - i as f32 / (n - 1) as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = i as f32 * 2.399_963;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
    }

    fn texel(uv: Vec2, size: u32) -> (u32, u32) {
        let s = size as f32;
        (
            ((uv.x * 0.5 + 0.5) * s).floor().clamp(0.0, s - 1.0) as u32,
            ((0.5 - uv.y * 0.5) * s).floor().clamp(0.0, s - 1.0) as u32,
        )
    }

    /// Every direction of the hemisphere lands in the square and comes back: a wrong unfolding
    /// (the diamond not turned, a sign swapped in the inverse) fails here.
    #[test]
    fn octahedral_map_round_trips_every_direction() {
        for d in hemisphere(20_000) {
            let uv = octahedral_uv(d);
            assert!(uv.abs().max_element() <= 1.0 + 1e-6, "{d} -> {uv}");
            let back = octahedral_direction(uv);
            assert!((back - d).length() < 1e-5, "{d} -> {uv} -> {back}");
        }
        // The horizon is the square's border, the normal its centre.
        for d in hemisphere(2_000).filter(|d| d.z == 0.0) {
            assert!((octahedral_uv(d).abs().max_element() - 1.0).abs() < 1e-6);
        }
        assert!(octahedral_uv(Vec3::Z).length() < 1e-7);
    }

    /// Every texel of the square is a direction of the upper hemisphere whose lookup is that
    /// texel (no texel wasted or unreachable, unlike the paraboloid's corners), and texels cover
    /// the hemisphere's solid angle evenly to within a factor of 2.3 (the octahedron's).
    #[test]
    fn octahedral_map_covers_the_hemisphere() {
        let size = 64;
        let mut solid = Vec::new();
        for y in 0..size {
            for x in 0..size {
                let d = ShadowAtlas::octahedral_texel_direction(size, x, y);
                assert!(
                    d.z >= 0.0 && (d.length() - 1.0).abs() < 1e-5,
                    "{x},{y}: {d}"
                );
                assert_eq!(texel(octahedral_uv(d), size), (x, y));
                // Solid angle of the texel: its corners' directions, two spherical triangles.
                let corner = |cx: f32, cy: f32| {
                    octahedral_direction(Vec2::new(
                        cx / size as f32 * 2.0 - 1.0,
                        1.0 - cy / size as f32 * 2.0,
                    ))
                };
                let (x, y) = (x as f32, y as f32);
                let [a, b, c, e] = [
                    corner(x, y),
                    corner(x + 1.0, y),
                    corner(x + 1.0, y + 1.0),
                    corner(x, y + 1.0),
                ];
                let tri = |p: Vec3, q: Vec3, r: Vec3| {
                    2.0 * (p.dot(q.cross(r)).abs()).atan2(1.0 + p.dot(q) + q.dot(r) + r.dot(p))
                };
                solid.push(tri(a, b, c) + tri(a, c, e));
            }
        }
        let total: f32 = solid.iter().sum();
        assert!(
            (total - 2.0 * std::f32::consts::PI).abs() < 1e-3,
            "texels cover {total} sr, not the hemisphere's 2π"
        );
        let (lo, hi) = solid
            .iter()
            .fold((f32::MAX, 0f32), |(l, h), &s| (l.min(s), h.max(s)));
        assert!(hi / lo < 2.3 * 2.3, "texel solid angles {lo}..{hi}");
    }

    /// On each face the map is the projective (x + y, x − y) / (sx·x + sy·y + z) the vertex
    /// shader draws, so straight edges stay straight (what makes it exact under rasterisation).
    #[test]
    fn each_octahedral_face_is_a_projective_map() {
        for d in hemisphere(5_000) {
            let (sx, sy) = (1f32.copysign(d.x), 1f32.copysign(d.y));
            let w = sx * d.x + sy * d.y + d.z;
            let projective = Vec2::new(d.x + d.y, d.x - d.y) / w;
            assert!((projective - octahedral_uv(d)).length() < 1e-5);
        }
        // Three collinear points on one face (x, y > 0) stay collinear in the map.
        let (p, q) = (Vec3::new(1.0, 0.2, 0.5), Vec3::new(0.3, 2.0, 0.1));
        let [a, b, c] = [0.0, 0.37, 1.0].map(|t| octahedral_uv(p.lerp(q, t).normalize()));
        assert!((b - a).perp_dot(c - a).abs() < 1e-6);
    }

    #[test]
    fn map_kinds_parse_and_size() {
        for name in MapKind::NAMES {
            MapKind::parse(name).unwrap();
        }
        let err = MapKind::parse("sphere").unwrap_err().to_string();
        assert!(
            err.contains("vpl-map") && err.contains("octahedral"),
            "{err}"
        );
        assert_eq!(
            MapKind::Octahedral.texels(128),
            MapKind::Paraboloid.texels(128)
        );
        assert_eq!(
            MapKind::Cube.texels(128),
            6 * MapKind::Paraboloid.texels(128)
        );
    }
}
