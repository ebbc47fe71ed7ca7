// The VPL store's per-VPL terms for the accumulation's pair loop (`PreparedVpl`, written by
// accumulate_prepare.wgsl once per VPL and frame, read by accumulate.wgsl per texel): the
// module `gibench::prepared_vpl`.

// What the pair loop needs of one VPL (80 bytes, as GpuVpl).
struct PreparedVpl {
    // xyz: position; w: the largest geometric term the clamp lets through (3.4e38 without a
    // clamp), below 0 for an empty slot
    position: vec4<f32>,
    // unit normal
    normal: vec3<f32>,
    // the map's tile origin in the atlas, x | y << 16 (an integer: as a float's bits, small
    // values would be subnormal, which a driver may flush to zero)
    origin: u32,
    // xyz: the map's eye point; w: flux / pi, red
    eye: vec4<f32>,
    // xyz: the map's frame (tangent); w: flux / pi, green
    tangent: vec4<f32>,
    // xyz: the map's frame (bitangent); w: flux / pi, blue
    bitangent: vec4<f32>,
};

// The tile origin of `v`, unpacked.
fn prepared_origin(v: PreparedVpl) -> vec2<i32> {
    return vec2<i32>(i32(v.origin & 0xffffu), i32(v.origin >> 16u));
}

// The tile origin `o` packed (each coordinate below 65536, the most texels an atlas side may
// have under any adapter's 2D texture limit we have met: 32768).
fn pack_origin(o: vec2<i32>) -> u32 {
    let u = vec2<u32>(o);
    return u.x | (u.y << 16u);
}
