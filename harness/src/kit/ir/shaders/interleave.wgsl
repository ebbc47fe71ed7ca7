// Interleaved sampling (Keller & Heidrich 2001; Laine et al. 2007 §5): the split layout and its
// helpers. Declares no bindings: a technique's accumulate shader gets this file followed by
// `interleave_bindings.wgsl` (together `INTERLEAVE_WGSL`); the harness's own split, combine and
// filter passes declare their bindings in `interleave_passes.wgsl`.
//
// Full resolution W×H (`full`), n×m tiles (`tiles`), tile size tw×th = ceil(W/n)×ceil(H/m)
// (`tile_size`), split buffers of (n·tw)×(m·th) texels (`split`), row-major in split coordinates
// (sx, sy). Split texel (sx, sy) lies in tile (i, j) = (sx / tw, sy / th) at (a, b) =
// (sx % tw, sy % th) and holds the original pixel (a·n + i, b·m + j); texels whose original
// pixel lies outside W×H are invalid (split_position.w = 0). Dispatch 8×8 workgroups over the
// split size.

struct InterleaveParams {
    full: vec2<u32>,
    tiles: vec2<u32>,
    tile_size: vec2<u32>,
    split: vec2<u32>,
    // x: α, distance threshold (scene units); y: β, normal threshold (cosine); z, w: unused.
    // Only the filter reads these.
    thresholds: vec4<f32>,
};

// Whether (sx, sy) lies inside the split buffers (dispatches round up to 8×8).
fn split_in_range(sx: u32, sy: u32) -> bool {
    return sx < interleave.split.x && sy < interleave.split.y;
}

// Index of split texel (sx, sy) in the split buffers.
fn split_index(sx: u32, sy: u32) -> u32 {
    return sy * interleave.split.x + sx;
}

// Tile index j·n + i of split texel (sx, sy): the VPL subset this texel accumulates.
fn split_tile(sx: u32, sy: u32) -> u32 {
    let t = vec2<u32>(sx, sy) / interleave.tile_size;
    return t.y * interleave.tiles.x + t.x;
}

// The full-resolution pixel (a·n + i, b·m + j) that split texel (sx, sy) holds (may lie outside
// the image: see split_valid).
fn split_original_pixel(sx: u32, sy: u32) -> vec2<u32> {
    let s = vec2<u32>(sx, sy);
    let t = s / interleave.tile_size;
    let ab = s % interleave.tile_size;
    return ab * interleave.tiles + t;
}

// Whether split texel (sx, sy) holds a pixel inside the image (it may still be background).
fn split_valid(sx: u32, sy: u32) -> bool {
    return all(split_original_pixel(sx, sy) < interleave.full);
}

// The split texel (sx, sy) that holds full-resolution pixel (x, y): the inverse of
// split_original_pixel.
fn split_texel_of_pixel(x: u32, y: u32) -> vec2<u32> {
    let p = vec2<u32>(x, y);
    return (p % interleave.tiles) * interleave.tile_size + p / interleave.tiles;
}
