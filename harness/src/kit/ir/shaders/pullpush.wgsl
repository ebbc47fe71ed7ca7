// Pull-push hole filling of every imperfect shadow map at once (Ritschel et al. 2008), in one
// of two modes (`offsets.z`). 0, depth-aware (Marroquim et al. 2007): pull keeps, of each 2x2
// block's valid depths, those within the level's depth interval of the front-most one and
// stores their mean with a weight (kept children, at most 1); push fills, from the
// coarsest level down, each texel that is empty or occluded (behind its parent by more than
// the interval) with its parent. 1, average (Grossman and Dally 1998): pull averages the valid
// depths; push blends each texel of weight < 1 with its parent. Level 0 is the splat's buffer
// (reversed depth bits, 0 = empty: nearer is larger); levels 1.. are (depth, weight) pairs in
// one pyramid buffer. Each map is its own slot: no read crosses a map's tile border.

struct PullPushParams {
    // x: the level written; y: its map edge; z: slots; w: atlas slots per row
    counts: vec4<u32>,
    // x: offset of the level written in the pyramid (items); y: offset of its source level;
    // z: the mode (0 depth-aware, 1 average)
    offsets: vec4<u32>,
    // Depth-aware: the depth interval of the level compared, max(x, y * (1 - front depth)):
    // the points' diameter (x) or a slanted surface's depth change across a texel (y, by the
    // front-most surface's distance), whichever is larger; z: a texel's angular size at the
    // level compared; w: the points' diameter at level 0 (depth units: over the far distance).
    fill: vec4<f32>,
};

// The depth interval behind a front-most depth `front`: two depths closer are one surface.
fn interval(front: f32) -> f32 {
    return max(pp.fill.x, pp.fill.y * (1.0 - front));
}

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
@compute @workgroup_size(8, 8)
fn pull(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = pp.counts.y;
    let x = id.x;
    let y = id.y;
    let slot = id.z;
    if (x >= size || y >= size || slot >= pp.counts.z) {
        return;
    }
    var children: array<vec2<f32>, 4>;
    var front = 0.0;
    for (var k = 0u; k < 4u; k = k + 1u) {
        let cx = 2u * x + (k & 1u);
        let cy = 2u * y + (k >> 1u);
        var c: vec2<f32>;
        if (pp.counts.x == 1u) {
            c = level0(slot, cx, cy, 2u * size);
        } else {
            c = texel(pp.offsets.y, slot, cx, cy, 2u * size);
        }
        children[k] = c;
        if (c.y > 0.0) {
            front = max(front, c.x);
        }
    }
    let aware = pp.offsets.z == 0u;
    let behind = interval(front);
    var sum = vec2<f32>(0.0);
    for (var k = 0u; k < 4u; k = k + 1u) {
        let c = children[k];
        if (!aware || c.x >= front - behind) {
            sum = sum + vec2<f32>(c.x * c.y, c.y);
        }
    }
    var out = vec2<f32>(0.0);
    if (sum.y > 0.0) {
        out = vec2<f32>(sum.x / sum.y, min(sum.y, 1.0));
    }
    pyramid[pp.offsets.x + (slot * size + y) * size + x] = out;
}

// Level `counts.x` (>= 1, below the top) completed from its parent level (already pushed).
@compute @workgroup_size(8, 8)
fn push(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = pp.counts.y;
    let x = id.x;
    let y = id.y;
    let slot = id.z;
    if (x >= size || y >= size || slot >= pp.counts.z) {
        return;
    }
    let i = pp.offsets.x + (slot * size + y) * size + x;
    let t = pyramid[i];
    let parent = texel(pp.offsets.y, slot, x / 2u, y / 2u, size / 2u);
    if (pp.offsets.z == 0u) {
        if (filled_from(t, parent)) {
            pyramid[i] = vec2<f32>(parent.x, 1.0);
        }
    } else if (t.y < 1.0 && parent.y > 0.0) {
        pyramid[i] = vec2<f32>(t.x * t.y + parent.x * (1.0 - t.y), 1.0);
    }
}

// Depth-aware push: whether texel `t` takes its parent's depth: the parent holds a surface and
// `t` is empty, or lies behind it by more than the interval (occluded: a farther surface seen
// through a hole in the parent's) where the parent's points, discs of their diameter, cover a
// texel of `t`'s level (its footprint at the parent's distance is no wider than a point): a
// coarser parent would spread an occluder past its silhouette.
fn filled_from(t: vec2<f32>, parent: vec2<f32>) -> bool {
    let covered = pp.fill.w >= pp.fill.z * (1.0 - parent.x);
    return parent.y > 0.0
        && (t.y <= 0.0 || (covered && t.x < parent.x - interval(parent.x)));
}
