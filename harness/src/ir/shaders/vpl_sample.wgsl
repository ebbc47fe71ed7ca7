// VPLs importance-sampled from reflective-shadow-map texels by brightness (imperfect shadow
// maps, Ritschel et al. 2008; reflective shadow maps, Dachsbacher and Stamminger 2005).
// `scan`: one workgroup builds the inclusive prefix sums of the texels' luminance (the CDF)
// and the texels' total flux. `sample`: VPL i takes the texel where the CDF crosses
// (i + ξ_i) / N of the total (ξ_i a fixed hash of i), and carries that texel's flux scaled by total luminance /
// (its luminance · N): every VPL has the same luminance, and their sum is an unbiased
// estimate of the texels' total flux. Expects VplStore::wgsl(0, 0, true).

struct SampleParams {
    // x: texels; y: VPLs to place; z, w: unused
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
        let u = (f32(i) + jitter(i)) / f32(count) * total;
        // The first texel whose inclusive sum exceeds u (it has a positive weight).
        var lo = 0u;
        var hi = n - 1u;
        while (lo < hi) {
            let mid = (lo + hi) / 2u;
            if (cdf[mid] > u) {
                hi = mid;
            } else {
                lo = mid + 1u;
            }
        }
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
