// The last push: level 0 into the atlas. Average mode: a texel where a point landed keeps its
// depth exactly; a hole takes its filled parent's depth (level 1), or stays empty (0) where
// nothing was within the levels pulled. Depth-aware mode: the same, and a texel occluded by
// its parent (behind it by more than the interval) takes the parent's depth too. Adds a
// binding to pullpush.wgsl's.
#import gibench::pullpush

@group(0) @binding(3) var atlas_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn store(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = pp.counts.y;
    let x = id.x;
    let y = id.y;
    let slot = id.z;
    if (x >= size || y >= size || slot >= pp.counts.z) {
        return;
    }
    var v = level0(slot, x, y, size);
    if (pp.offsets.y != 0xffffffffu) {
        let parent = texel(pp.offsets.y, slot, x / 2u, y / 2u, size / 2u);
        let aware = pp.offsets.z == 0u;
        if ((v.y <= 0.0 && parent.y > 0.0) || (aware && filled_from(v, parent))) {
            v = vec2<f32>(parent.x, 1.0);
        }
    }
    let cols = pp.counts.w;
    let origin = vec2<i32>(i32((slot % cols) * size), i32((slot / cols) * size));
    textureStore(atlas_out, origin + vec2<i32>(i32(x), i32(y)), vec4<f32>(v.x, 0.0, 0.0, 1.0));
}
