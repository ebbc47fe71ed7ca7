
// The harness's interleave passes: split (G-buffer → split buffers), combine (split_irradiance →
// combined) and the geometry-aware box filter of Laine et al. 2007, Figure 5 (split position and
// normal, combined → output).
#import gibench::interleave

@group(0) @binding(0) var<storage, read> interleave: InterleaveParams;
@group(0) @binding(1) var<storage, read_write> split_position: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> split_normal: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> split_irradiance: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> combined: array<vec4<f32>>;
@group(0) @binding(5) var output: texture_storage_2d<rgba16float, write>;

@group(1) @binding(0) var<uniform> view: View;
@group(1) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(1) @binding(2) var gbuffer_normal: texture_2d<f32>;

struct Surface {
    position: vec3<f32>,
    normal: vec3<f32>,
    hit: bool,
};

// World position and normal of full-resolution pixel `pix` (inside the image).
fn surface_at(pix: vec2<u32>) -> Surface {
    var s: Surface;
    let n = textureLoad(gbuffer_normal, vec2<i32>(pix), 0);
    s.hit = n.w != 0.0;
    s.normal = n.xyz;
    s.position = vec3<f32>(0.0);
    if (s.hit) {
        let depth = textureLoad(gbuffer_depth, vec2<i32>(pix), 0).r;
        s.position = world_from_depth(view, vec2<f32>(pix) + 0.5, depth);
    }
    return s;
}

// The same surface read back from the split buffers (written by split_main this frame): the
// filter's taps, without rebuilding each tap's position from depth.
fn split_surface_at(pix: vec2<u32>) -> Surface {
    return split_surface_at_texel(split_texel_of_pixel(pix.x, pix.y));
}

// The surface at split texel `s`.
fn split_surface_at_texel(s: vec2<u32>) -> Surface {
    let i = split_index(s.x, s.y);
    let p = split_position[i];
    var out: Surface;
    out.hit = p.w != 0.0;
    out.position = p.xyz;
    out.normal = split_normal[i].xyz;
    return out;
}

@compute @workgroup_size(8, 8)
fn split_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (!split_in_range(id.x, id.y)) {
        return;
    }
    let p = split_original_pixel(id.x, id.y);
    var position = vec4<f32>(0.0);
    var normal = vec4<f32>(0.0);
    if (all(p < interleave.full)) {
        let s = surface_at(p);
        if (s.hit) {
            position = vec4<f32>(s.position, 1.0);
            normal = vec4<f32>(s.normal, 0.0);
        }
    }
    let i = split_index(id.x, id.y);
    split_position[i] = position;
    split_normal[i] = normal;
}

@compute @workgroup_size(8, 8)
fn combine_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= interleave.full.x || id.y >= interleave.full.y) {
        return;
    }
    let s = split_texel_of_pixel(id.x, id.y);
    combined[id.y * interleave.full.x + id.x] = split_irradiance[split_index(s.x, s.y)];
}

@compute @workgroup_size(8, 8)
fn filter_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let full = interleave.full;
    if (id.x >= full.x || id.y >= full.y) {
        return;
    }
    let pix = id.xy;
    let centre = split_surface_at(pix);
    var result = vec4<f32>(0.0);
    if (centre.hit) {
        // The n×m box starts at p − floor(n/2), shifted to lie inside the image where it would
        // cross a border (so it still covers one pixel of every tile); taps outside the image
        // exist only when the image is smaller than the box.
        let tiles = vec2<i32>(interleave.tiles);
        let size = vec2<i32>(full);
        let origin = vec2<u32>(clamp(vec2<i32>(pix) - tiles / 2, vec2<i32>(0), max(size - tiles, vec2<i32>(0))));
        let alpha = interleave.thresholds.x;
        let beta = interleave.thresholds.y;
        // The box spans n×m consecutive pixels, so the taps' split texels
        // (split_texel_of_pixel: (t % n) · tile_size + t / n) follow from the origin's quotient
        // and remainder without a division per tap: the remainder steps by one and wraps once.
        let n = interleave.tiles;
        let quotient = origin / n;
        let remainder = origin % n;
        var accum = vec3<f32>(0.0);
        var count = 0.0;
        for (var y = 0u; y < n.y; y += 1u) {
            var ry = remainder.y + y;
            var qy = quotient.y;
            if (ry >= n.y) {
                ry -= n.y;
                qy += 1u;
            }
            for (var x = 0u; x < n.x; x += 1u) {
                var rx = remainder.x + x;
                var qx = quotient.x;
                if (rx >= n.x) {
                    rx -= n.x;
                    qx += 1u;
                }
                let t = origin + vec2<u32>(x, y);
                if (any(t >= full)) {
                    continue;
                }
                var take = all(t == pix);
                if (!take) {
                    let split = vec2<u32>(rx, ry) * interleave.tile_size + vec2<u32>(qx, qy);
                    let s = split_surface_at_texel(split);
                    take = s.hit && length(s.position - centre.position) < alpha
                        && dot(s.normal, centre.normal) > beta;
                }
                if (take) {
                    accum += combined[t.y * full.x + t.x].rgb;
                    count += 1.0;
                }
            }
        }
        result = vec4<f32>(accum / count, 1.0);
    }
    textureStore(output, vec2<i32>(pix), result);
}
