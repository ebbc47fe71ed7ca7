// VPLs importance-sampled from reflective-shadow-map texels by brightness (imperfect shadow
// maps, Ritschel et al. 2008; reflective shadow maps, Dachsbacher and Stamminger 2005).
// `scan`: one workgroup builds the inclusive prefix sums of the texels' luminance (the CDF)
// and the texels' total flux. `sample`: VPL i's fixed point (u, v) = ((i + ξ_i) / N,
// φ2(i) ⊕ η) picks a texel with probability its share of the luminance, either where the CDF
// over the flattened map crosses u, or a row where the rows' CDF crosses u and then the texel
// where that row's CDF crosses v (the row ends are read off the same CDF). The VPL carries the
// texel's flux scaled by total luminance / (its luminance · N): every VPL has the same
// luminance, and their sum is an unbiased estimate of the texels' total flux. Expects
// VplStore::wgsl(0, 0, true).

struct SampleParams {
    // x: texels; y: VPLs to place; z: texels per row; w: 1 for the row-then-column warp, 0 for
    // the flattened CDF
    counts: vec4<u32>,
};

@group(0) @binding(1) var<storage, read> sample_params: SampleParams;
// Per texel: xyz position, w 1 where the texel saw a surface (else 0).
@group(0) @binding(2) var<storage, read> rsm_position: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> rsm_normal: array<vec4<f32>>;
// Per texel: rgb flux the surface patch reflects.
@group(0) @binding(4) var<storage, read> rsm_flux: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> cdf: array<f32>;
// x: total luminance; yzw: total flux.
@group(0) @binding(6) var<storage, read_write> totals: vec4<f32>;

const SCAN_THREADS: u32 = 256u;
var<workgroup> partial: array<f32, 256>;
var<workgroup> partial_flux: array<vec3<f32>, 256>;

fn texel_weight(t: u32) -> f32 {
    if (rsm_position[t].w <= 0.0) {
        return 0.0;
    }
    return max(dot(rsm_flux[t].xyz, vec3<f32>(0.2126, 0.7152, 0.0722)), 0.0);
}

@compute @workgroup_size(256)
fn scan(@builtin(local_invocation_index) lid: u32) {
    let n = sample_params.counts.x;
    let chunk = (n + SCAN_THREADS - 1u) / SCAN_THREADS;
    let first = lid * chunk;
    var sum = 0.0;
    var flux = vec3<f32>(0.0);
    for (var t = first; t < min(first + chunk, n); t = t + 1u) {
        let w = texel_weight(t);
        sum = sum + w;
        if (w > 0.0) {
            flux = flux + rsm_flux[t].xyz;
        }
    }
    partial[lid] = sum;
    partial_flux[lid] = flux;
    workgroupBarrier();
    // Hillis–Steele inclusive scan of the chunk sums.
    for (var offset = 1u; offset < SCAN_THREADS; offset = offset * 2u) {
        var add = 0.0;
        var add_flux = vec3<f32>(0.0);
        if (lid >= offset) {
            add = partial[lid - offset];
            add_flux = partial_flux[lid - offset];
        }
        workgroupBarrier();
        partial[lid] = partial[lid] + add;
        partial_flux[lid] = partial_flux[lid] + add_flux;
        workgroupBarrier();
    }
    var running = 0.0;
    if (lid > 0u) {
        running = partial[lid - 1u];
    }
    for (var t = first; t < min(first + chunk, n); t = t + 1u) {
        running = running + texel_weight(t);
        cdf[t] = running;
    }
    if (lid == SCAN_THREADS - 1u) {
        totals = vec4<f32>(partial[lid], partial_flux[lid]);
    }
}

// A fixed number in [0, 1) per VPL (a hash of its index): the stratum's point is random, so the
// VPLs' flux is an unbiased estimate, and the same every frame, so VPLs stay put while the map
// does not change.
fn jitter(i: u32) -> f32 {
    var h = i * 747796405u + 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    h = (h >> 22u) ^ h;
    return f32(h >> 8u) / 16777216.0;
}

// The first texel in [lo, hi] whose inclusive sum exceeds `u` (hi if none does).
fn first_above(first: u32, last: u32, u: f32) -> u32 {
    var lo = first;
    var hi = last;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (cdf[mid] > u) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

// The texel VPL i's point picks, the CDF's total being `total`.
fn pick(i: u32, count: u32, total: f32) -> u32 {
    let n = sample_params.counts.x;
    let u = (f32(i) + jitter(i)) / f32(count) * total;
    if (sample_params.counts.w == 0u) {
        return first_above(0u, n - 1u, u);
    }
    // A row: the first whose inclusive end exceeds u.
    let row = sample_params.counts.z;
    var lo = 0u;
    var hi = n / row - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (cdf[(mid + 1u) * row - 1u] > u) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    let start = lo * row;
    var before = 0.0;
    if (start > 0u) {
        before = cdf[start - 1u];
    }
    // v: the base-2 radical inverse of i, shifted by one fixed amount (a Cranley–Patterson
    // rotation keeps the set's stratification).
    let v = fract(f32(reverseBits(i) >> 8u) / 16777216.0 + jitter(count ^ 0x5bd1e995u));
    return first_above(start, start + row - 1u, before + v * (cdf[start + row - 1u] - before));
}

// An orthonormal frame about unit `n` (any works: the atlas and the splat read it from the
// store).
fn frame_of(n: vec3<f32>) -> mat2x3<f32> {
    let a = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    let t = normalize(cross(a, n));
    return mat2x3<f32>(t, cross(n, t));
}

@compute @workgroup_size(64)
fn sample(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = sample_params.counts.x;
    let count = sample_params.counts.y;
    let i = id.x;
    if (i == 0u) {
        vpl_store.header = vec4<u32>(count, bitcast<u32>(totals.y), bitcast<u32>(totals.z), bitcast<u32>(totals.w));
    }
    if (i >= count) {
        return;
    }
    var v: GpuVpl;
    v.position = vec4<f32>(0.0, 0.0, 0.0, f32(i));
    v.normal = vec4<f32>(0.0, 0.0, 1.0, 0.0);
    v.flux = vec4<f32>(0.0);
    v.tangent = vec4<f32>(1.0, 0.0, 0.0, 0.0);
    v.bitangent = vec4<f32>(0.0, 1.0, 0.0, 0.0);
    let total = totals.x;
    if (total > 0.0 && n > 0u) {
        let lo = pick(i, count, total);
        let w = texel_weight(lo);
        if (w > 0.0) {
            let nrm = normalize(rsm_normal[lo].xyz);
            let f = frame_of(nrm);
            v.position = vec4<f32>(rsm_position[lo].xyz, f32(i));
            v.normal = vec4<f32>(nrm, 0.0);
            v.flux = vec4<f32>(rsm_flux[lo].xyz * (total / (w * f32(count))), 0.0);
            v.tangent = vec4<f32>(f[0], 0.0);
            v.bitangent = vec4<f32>(f[1], 0.0);
        }
    }
    vpl_store.items[i] = v;
}
