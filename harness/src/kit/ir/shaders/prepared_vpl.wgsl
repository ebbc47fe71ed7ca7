// The VPL store's per-VPL terms for the accumulation's pair loop (`PreparedVpl`, written by
// accumulate_prepare.wgsl once per VPL and frame, read by accumulate.wgsl per texel): the
// module `gibench::prepared_vpl`.

// What the pair loop needs of one VPL (80 bytes, as GpuVpl).
struct PreparedVpl {
    // xyz: position; w: the largest geometric term the clamp lets through (3.4e38 without a
    // clamp), below 0 for an empty slot
    position: vec4<f32>,
    // xyz: unit normal; w: the bits of the map's tile origin in the atlas, x | y << 16
    normal: vec4<f32>,
    // xyz: the map's eye point; w: flux / pi, red
    eye: vec4<f32>,
    // xyz: the map's frame (tangent); w: flux / pi, green
    tangent: vec4<f32>,
    // xyz: the map's frame (bitangent); w: flux / pi, blue
    bitangent: vec4<f32>,
};

// The tile origin packed in `normal.w`, unpacked.
fn prepared_origin(v: PreparedVpl) -> vec2<i32> {
    let packed = bitcast<u32>(v.normal.w);
    return vec2<i32>(i32(packed & 0xffffu), i32(packed >> 16u));
}

// The tile origin `o` (each coordinate below 65536: an atlas is at most 16384 texels wide)
// packed into the bits of an f32.
fn pack_origin(o: vec2<i32>) -> f32 {
    let u = vec2<u32>(o);
    return bitcast<f32>(u.x | (u.y << 16u));
}
