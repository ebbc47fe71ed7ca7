// The grid shared by the combine, propagation and reconstruction passes. Expects the constants
// N (cells per axis), COLS (slice tiles per atlas row), ORIGIN (vec3: the grid's min corner),
// CELL (cell edge), MODE (0: occluded propagation with reflections, Gaitatzes et al. 2010;
// 1: plain light propagation volume, Kaplanyan 2009), STORED_ALBEDO (0: the paper's constant
// 0.5 for secondary bounces, 1: the voxel's albedo), TRANSPORT (how flux arrives in a void cell:
// 0 as a clamped-cosine lobe along the face's axis; 1 with the sending cell's own angular
// distribution; 2 with that of the light through the face's pyramid) prepended, then sh::wgsl().

struct Voxel {
    // xyz: average unit normal of its surfaces (the side it emits and reflects on); w: 1 if
    // occupied, else 0
    normal: vec4<f32>,
    // rgb: average albedo
    albedo: vec4<f32>,
    // rgb: direct radiosity (the largest of the three axes' averages)
    radiosity: vec4<f32>,
};

// Second-order SH per colour channel.
struct Sh3 {
    r: vec4<f32>,
    g: vec4<f32>,
    b: vec4<f32>,
};

fn cell_index(c: vec3<i32>) -> u32 {
    return u32(c.x) + N * (u32(c.y) + N * u32(c.z));
}

fn in_grid(c: vec3<i32>) -> bool {
    return all(c >= vec3<i32>(0)) && all(c < vec3<i32>(i32(N)));
}

// The unit axis of face k (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z).
fn face_axis(k: u32) -> vec3<i32> {
    var d = vec3<i32>(0);
    d[k / 2u] = select(1, -1, (k & 1u) == 1u);
    return d;
}
