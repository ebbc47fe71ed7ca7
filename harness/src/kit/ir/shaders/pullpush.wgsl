// Pull-push hole filling of every imperfect shadow map at once (Ritschel et al. 2008; the
// pull-push of Grossman and Dally 1998): pull averages the valid depths of each 2x2 block into
// the next coarser level with a weight (valid children, at most 1); push fills, from the
// coarsest level down, each texel of weight < 1 with its parent, and a texel of level 0
// without a point from its filled parent. Level 0 is the splat's buffer (reversed depth bits,
// 0 = empty); levels 1.. are (mean depth, weight) pairs in one pyramid buffer.

struct PullPushParams {
    // x: the level written; y: its map edge; z: slots; w: atlas slots per row
    counts: vec4<u32>,
    // x: offset of the level written in the pyramid (items); y: offset of its source level
    offsets: vec4<u32>,
};

@group(0) @binding(0) var<storage, read> pp: PullPushParams;
@group(0) @binding(1) var<storage, read> ism_depth: array<u32>;
@group(0) @binding(2) var<storage, read_write> pyramid: array<vec2<f32>>;

// Level 0 texel (x, y) of `slot`'s map of edge `size`: (depth, 1) where a point landed, else 0.
fn level0(slot: u32, x: u32, y: u32, size: u32) -> vec2<f32> {
    let v = bitcast<f32>(ism_depth[(slot * size + y) * size + x]);
    return select(vec2<f32>(0.0), vec2<f32>(v, 1.0), v > 0.0);
}

fn texel(offset: u32, slot: u32, x: u32, y: u32, size: u32) -> vec2<f32> {
    return pyramid[offset + (slot * size + y) * size + x];
}

// Level `counts.x` (>= 1) from level `counts.x - 1`.
@compute @workgroup_size(64)
fn pull(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = pp.counts.y;
    let slot = id.y;
    if (id.x >= size * size || slot >= pp.counts.z) {
        return;
    }
    let x = id.x % size;
    let y = id.x / size;
    var sum = vec2<f32>(0.0);
    for (var k = 0u; k < 4u; k = k + 1u) {
        let cx = 2u * x + (k & 1u);
        let cy = 2u * y + (k >> 1u);
        var c: vec2<f32>;
        if (pp.counts.x == 1u) {
            c = level0(slot, cx, cy, 2u * size);
        } else {
            c = texel(pp.offsets.y, slot, cx, cy, 2u * size);
        }
        sum = sum + vec2<f32>(c.x * c.y, c.y);
    }
    var out = vec2<f32>(0.0);
    if (sum.y > 0.0) {
        out = vec2<f32>(sum.x / sum.y, min(sum.y, 1.0));
    }
    pyramid[pp.offsets.x + (slot * size + y) * size + x] = out;
}

// Level `counts.x` (>= 1, below the top) completed from its parent level (already pushed).
@compute @workgroup_size(64)
fn push(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = pp.counts.y;
    let slot = id.y;
    if (id.x >= size * size || slot >= pp.counts.z) {
        return;
    }
    let x = id.x % size;
    let y = id.x / size;
    let i = pp.offsets.x + (slot * size + y) * size + x;
    let t = pyramid[i];
    let parent = texel(pp.offsets.y, slot, x / 2u, y / 2u, size / 2u);
    if (t.y < 1.0 && parent.y > 0.0) {
        pyramid[i] = vec2<f32>(t.x * t.y + parent.x * (1.0 - t.y), 1.0);
    }
}
