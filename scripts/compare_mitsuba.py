#!/usr/bin/env python3
"""Throughput of gibench's CPU reference path tracer against Mitsuba 3 on the same scene.

What it measures: path samples per CPU-second (width * height * spp / CPU seconds) of
`gibench reference` and of Mitsuba 3's `path` integrator (variant llvm_ad_rgb by default)
rendering the same frame of a gibench scene, and the ratio gibench / Mitsuba.

How:
  1. `gibench export-scene` writes the frame's geometry (one binary PLY per material), the
     camera, the primary light and the albedos; the script builds the same scene with
     `mi.load_dict` (perspective camera, box-filtered hdrfilm, independent sampler, two-sided
     diffuse BSDFs, a spot/point/directional light).
  2. Per scene, one Mitsuba warm-up render (JIT compilation, reported apart), then `--repeats`
     alternations of: `gibench reference --no-cache` as a subprocess, then one timed Mitsuba
     render (CPU = time.process_time, all threads, around mi.render plus the evaluation it
     defers, so load, BVH build and compilation are outside). gibench's CPU time is read
     three ways: its JSON sidecar's `cpu_seconds` less `bvh_build_cpu_seconds`, the CPU of
     every thread while it traces (its render call without the frame's mesh and BVH, which
     Mitsuba builds at load) — the primary ratio, like for like with Mitsuba's; `cpu_seconds`
     itself (BVH build included); and user+sys of the whole child process from
     getrusage(RUSAGE_CHILDREN) deltas (process start, scene load, BVH build and image writing
     added). The ratio is taken per alternation; min/median/max are reported.
  3. Raw rays (`--rays N`, default 262144; 0 skips): `gibench export-scene --rays N` also
     writes N closest-hit rays (from primary hits, cosine-distributed like the reference's path
     segments) and N shadow segments to the light; per alternation `gibench raycast` casts both
     sets through the reference's BVH across all cores (its own CPU time of every thread during
     each cast), then Mitsuba casts the same rays with ray_intersect_preliminary and ray_test
     (Embree; process CPU time around the call and its evaluation, after a warm-up cast). The
     agreement of the answers (blocked or not; hit distance within 10^-3) is reported.
  4. gibench's JSON sidecar gives `seconds`, the wall time of its render call, and
     `bvh_build_seconds`, that of its BVH build; their difference against Mitsuba's render
     wall time gives a tracing wall-clock ratio; the primary number stays the CPU one.
  5. Per ray traced, beside per sample: trace-CPU rays per second, gibench's against
     Mitsuba's, i.e. the per-sample ratio times (gibench's rays per sample / Mitsuba's).
     gibench's rays are counted exactly: its sidecar's `rays` (closest-hit and shadow rays,
     each pixel counting its own, summed once the render is done). Mitsuba has no ray counter,
     so its rays are counted by a render of the same scene, spp and film with `RayCount`, a
     Python integrator that mirrors the `path` integrator's loop (Mitsuba 3.9's path.cpp): per
     sample one camera ray, then at each valid vertex before max_depth one `ray_test` where
     Mitsuba issues it (Smooth BSDF and the emitter sample's pdf non-zero, Scene::
     sample_emitter_direction's mask) and one BSDF ray while the throughput is non-zero. It
     calls the same scene's ray_intersect, BSDF sample and emitter sample, so its paths have
     the same distribution as the timed render's, with other random numbers: the count is an
     estimate whose standard error (over pixels) is reported, and is far below 1 %. The
     per-ray ratio with Mitsuba's upper bound (19 rays per sample at max_depth 10) is
     reported beside it and labelled as a bound: it over-counts Mitsuba's rays (paths leave
     the scene early), so it FAVOURS Mitsuba (understates gibench); taking gibench's nominal
     16 per sample instead of its count would over-count gibench's and favour it. Per ray
     rewards rays that carry nothing: Mitsuba traces shadow rays from surfaces facing away
     from the light or outside a spot's cone, where gibench traces none; per sample (the same
     estimate's cost) stays the primary figure.

Caveats (read before quoting a ratio):
  * Not the same estimator. gibench shoots one primary ray per pixel and `spp` paths from that
    hit (plus one direct shadow ray per pixel); each path has at most 8 indirect vertices with
    one closest-hit and one shadow ray each: at most 16 rays per sample. Mitsuba resamples the
    camera ray per sample and, at max_depth 10, traces at most 1 + 9 + 9 = 19 rays per sample
    (NEE at 9 vertices and a last BSDF ray from the 9th vertex that can only find emitters).
    Paths that leave the scene stop early on both sides (on Cornell, open at the front, most
    do: both trace far fewer rays than these bounds, see point 5); gibench traces nothing for
    pixels that miss the scene and no shadow ray where the light cannot reach the receiver.
  * gibench's spot light is cosine-shaped (I = I0 cos θ); Mitsuba's `spot` with
    cutoff_angle = beam_width = 90 is uniform over the front hemisphere. Images differ; the
    cost per sample is what is compared. Area lights are replaced by a spot light (their far
    field); suns map to `directional`.
  * Mitsuba's render CPU excludes its BVH build (Embree's, at load), so the primary ratio
    takes gibench's out too (2-3 % of its render CPU on Sibenik at 256x192, 16 spp); the
    render-CPU ratio keeps it in and the whole-process ratio adds gibench's start, load and
    output, both against Mitsuba's render CPU alone.
  * Raw rays: gibench's closest_hit returns a full hit record (normals, uv, material), Mitsuba's
    ray_intersect_preliminary only the distance, primitive and barycentrics; Mitsuba casts all
    rays as one vectorised wavefront (Embree's packet or stream traversal under Dr.Jit), gibench
    one ray at a time per thread.
  * Both use every core of the machine; run on an otherwise idle machine.
"""
import argparse, array, glob, json, os, re, resource, statistics, subprocess, sys, tempfile, time
from pathlib import Path

INSTALL = """Mitsuba 3 is not usable here; to install it:
    pip install mitsuba drjit
The llvm_ad_rgb variant needs an LLVM shared library that Dr.Jit can drive: LLVM 14 and 15
abort with 'LLVM ERROR: Cannot select ... fminimum'; LLVM 19 works. On Debian 12:
    apt-get install -y libllvm19
Dr.Jit then finds /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 by itself; elsewhere point it at
the library with DRJIT_LIBLLVM_PATH=/path/to/libLLVM-19.so (this script sets it to the newest
libLLVM it finds under /usr/lib when the variable is unset)."""

LIGHT_NOTE = ("gibench's cosine spot (I0 cos θ) is approximated by Mitsuba's spot with "
              "cutoff_angle = beam_width = 90 (uniform over the front hemisphere); area lights "
              "by that spot; omni by point; sun by directional. Per-sample cost is compared, "
              "not images.")
# gibench's B indirect bounces as Mitsuba path segments: 1 camera segment (to the primary hit
# x0) + B segments x0 -> y1 -> ... -> yB + 1 shadow segment from yB to the light. Mitsuba's
# max_depth counts exactly these segments (1 = emitters seen directly, 2 = direct light only).
BOUNCES = 8
MAX_DEPTH = 1 + BOUNCES + 1
# Mitsuba's rays per sample at most (camera ray, then a shadow and a BSDF ray at each of the
# first MAX_DEPTH - 1 vertices).
MITSUBA_RAYS_BOUND = 1 + 2 * (MAX_DEPTH - 1)


def newest_llvm():
    """Sets DRJIT_LIBLLVM_PATH to the newest libLLVM under /usr/lib if it is unset."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    found = []
    for path in glob.glob("/usr/lib/*/libLLVM*.so*") + glob.glob("/usr/lib/libLLVM*.so*"):
        m = re.search(r"libLLVM[-.](?:so\.)?(\d+)", os.path.basename(path))
        if m:
            found.append((int(m.group(1)), path))
    if not found:
        return None
    os.environ["DRJIT_LIBLLVM_PATH"] = max(found)[1]
    return os.environ["DRJIT_LIBLLVM_PATH"]


def variant_works(variant):
    """Renders a tiny scene in a child process: a bad LLVM aborts the process, not raises."""
    code = ("import mitsuba as mi, drjit as dr\nmi.set_variant(%r)\nd = mi.cornell_box()\n"
            "d['sensor']['film'].update(width=16, height=16)\n"
            "d['spot'] = {'type': 'spot', 'cutoff_angle': 90.0, 'beam_width': 90.0}\n"
            "d['integrator'] = {'type': 'path', 'max_depth': %d, 'rr_depth': %d}\n"
            "img = mi.render(mi.load_dict(d), spp=2)\ndr.eval(img)\ndr.sync_thread()\n"
            % (variant, MAX_DEPTH, MAX_DEPTH + 1))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"mitsuba variant {variant} failed its test render (exit {r.returncode}):\n"
              + "\n".join((r.stderr or r.stdout).strip().splitlines()[:3]), file=sys.stderr)
    return r.returncode == 0


def scene_dict(mi, meta, folder, spp):
    """The exported frame as a Mitsuba scene description."""
    w, h = meta["resolution"]
    cam, light = meta["camera"], meta["light"]
    T = mi.ScalarTransform4f
    rgb = lambda v: {"type": "rgb", "value": [float(x) for x in v]}
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": MAX_DEPTH, "rr_depth": MAX_DEPTH + 1},
         "sensor": {"type": "perspective", "fov": float(cam["fov_y_deg"]), "fov_axis": "y",
                    "to_world": T().look_at(origin=cam["origin"], target=cam["target"],
                                            up=cam["up"]),
                    "sampler": {"type": "independent", "sample_count": spp},
                    "film": {"type": "hdrfilm", "width": w, "height": h,
                             "rfilter": {"type": "box"}}}}
    kind, pos = light["kind"], light.get("position", [0.0, 0.0, 0.0])
    if kind == "omni":
        d["light"] = {"type": "point", "position": pos, "intensity": rgb(light["intensity"])}
    elif kind == "sun":
        d["light"] = {"type": "directional", "direction": light["direction"],
                      "irradiance": rgb(light["intensity"])}
    else:  # spot, and area as its far field
        dx, dy, dz = light["direction"]
        up = [0.0, 0.0, 1.0] if abs(dy) > 0.99 else [0.0, 1.0, 0.0]
        d["light"] = {"type": "spot", "cutoff_angle": 90.0, "beam_width": 90.0,
                      "intensity": rgb(light["intensity"]),
                      "to_world": T().look_at(origin=pos, target=[pos[0] + dx, pos[1] + dy,
                                                                  pos[2] + dz], up=up)}
    for k, m in enumerate(meta["materials"]):
        # gibench's surfaces are two-sided Lambertian; Mitsuba's diffuse alone is black from
        # behind and would end those paths early, so it is wrapped in twosided.
        d[f"mesh{k}"] = {"type": "ply", "filename": str(Path(folder) / m["file"]),
                         "face_normals": True,
                         "bsdf": {"type": "twosided",
                                  "bsdf": {"type": "diffuse", "reflectance": rgb(m["albedo"])}}}
    return d


def ray_count_integrator(mi, dr):
    """An integrator whose every sample returns the rays Mitsuba's `path` integrator traces
    for it (R: closest-hit, G: shadow, B: both): the path loop of path.cpp (3.9) at MAX_DEPTH
    without Russian roulette, tracing what it traces and accumulating nothing else."""

    class RayCount(mi.SamplingIntegrator):
        def sample(self, scene, sampler, ray, medium=None, active=True):
            ray, active = mi.Ray3f(ray), mi.Bool(active)
            closest, shadow, throughput = mi.Float(0.0), mi.Float(0.0), mi.Spectrum(1.0)
            ctx = mi.BSDFContext()
            for depth in range(MAX_DEPTH):
                # path.cpp intersects every active lane's ray at the top of its loop.
                closest += dr.select(active, 1.0, 0.0)
                si = scene.ray_intersect(ray, active)
                active_next = active & si.is_valid() & (depth + 1 < MAX_DEPTH)
                bsdf = si.bsdf(ray)
                active_em = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
                # Scene::sample_emitter_direction ray_tests the lanes left active with a
                # non-zero pdf; visibility is not needed for the count.
                ds, _ = scene.sample_emitter_direction(si, sampler.next_2d(), False, active_em)
                shadow += dr.select(active_em & (ds.pdf != 0.0), 1.0, 0.0)
                bs, weight = bsdf.sample(ctx, si, sampler.next_1d(), sampler.next_2d(),
                                         active_next)
                throughput = throughput * weight
                ray = si.spawn_ray(si.to_world(bs.wo))
                active = active_next & (dr.max(throughput) != 0.0)
            return mi.Spectrum(closest, shadow, closest + shadow), mi.Bool(True), []

    mi.register_integrator("gibench_ray_count", lambda props: RayCount(props))
    return mi.load_dict({"type": "gibench_ray_count"})


def mitsuba_ray_counts(mi, scene, spp, counter):
    """Mitsuba's mean closest-hit, shadow and total rays per sample over the film (box filter:
    each pixel is the mean of its spp samples), with the total's standard error over pixels."""
    img = mi.TensorXf(mi.render(scene, spp=spp, integrator=counter))
    rows = [list(map(float, img[..., c].array)) for c in range(3)]
    n = len(rows[2])
    mean = [sum(r) / n for r in rows]
    se = statistics.stdev(rows[2]) / n ** 0.5 if n > 1 else float("nan")
    return {"closest": mean[0], "shadow": mean[1], "total": mean[2], "total_standard_error": se}


def mitsuba_render(mi, dr, scene, spp):
    """Wall and CPU seconds of one render; mi.render is lazy, so evaluate and sync inside."""
    wall, cpu = time.perf_counter(), time.process_time()
    img = mi.render(scene, spp=spp)
    dr.eval(img)
    dr.sync_thread()
    return {"wall_s": time.perf_counter() - wall, "cpu_s": time.process_time() - cpu}


def gibench_render(args, name, w, h, out):
    """One `gibench reference` run: child CPU time, wall time and its sidecar's render time."""
    cmd = [args.gibench, "reference", "--scene", name, "--frame", "0", "--resolution",
           f"{w}x{h}", "--spp", str(args.spp), "--bounces", str(BOUNCES), "--no-cache",
           "--out", str(out)]
    before, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    run(cmd)
    wall, after = time.perf_counter() - wall, resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    sidecar = json.loads(next(Path(out).glob("*-reference.json")).read_text())
    minus = lambda a, b: a - b if a is not None and b is not None else None
    return {"cpu_s": cpu, "wall_s": wall, "render_wall_s": sidecar.get("seconds"),
            "render_cpu_s": sidecar.get("cpu_seconds"),
            "bvh_build_wall_s": sidecar.get("bvh_build_seconds"),
            "bvh_build_cpu_s": sidecar.get("bvh_build_cpu_seconds"),
            "trace_wall_s": minus(sidecar.get("seconds"), sidecar.get("bvh_build_seconds")),
            "trace_cpu_s": minus(sidecar.get("cpu_seconds"), sidecar.get("bvh_build_cpu_seconds")),
            "rays": sidecar.get("rays"),
            "outside_render_wall_s": wall - sidecar["seconds"] if "seconds" in sidecar else None}


def run(cmd):
    """Runs a gibench command; on failure says which and exits."""
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed (exit {r.returncode}): {' '.join(cmd)}\n{r.stderr.strip()[-2000:]}")


def spread(values):
    return {"median": statistics.median(values), "min": min(values), "max": max(values)}


def read_rays(mi, path):
    """A ray file of `gibench export-scene --rays` as one Mitsuba Ray3f (origin, direction,
    maxt; seven little-endian float32 per ray) and the ray count."""
    a = array.array("f")
    a.frombytes(Path(path).read_bytes())
    if sys.byteorder != "little":
        a.byteswap()
    col = lambda k: mi.Float(a[k::7])
    ray = mi.Ray3f(mi.Point3f(col(0), col(1), col(2)), mi.Vector3f(col(3), col(4), col(5)))
    ray.maxt = col(6)
    return ray, len(a) // 7


def mitsuba_cast(dr, scene, ray, shadow):
    """Wall and CPU seconds of one cast of every ray (ray_test or ray_intersect_preliminary,
    evaluated and synchronised inside), and its per-ray result."""
    wall, cpu = time.perf_counter(), time.process_time()
    if shadow:
        out = scene.ray_test(ray)
    else:
        out = scene.ray_intersect_preliminary(ray, coherent=False).t
    dr.eval(out)
    dr.sync_thread()
    return {"wall_s": time.perf_counter() - wall, "cpu_s": time.process_time() - cpu}, out


def agreement(dr, gib_dir, closest_t, shadow_hit, n):
    """Fractions of rays on which gibench and Mitsuba agree: shadow rays blocked or not;
    closest-hit rays both missing, or both hitting at distances within 10^-3 (relative)."""
    g = array.array("f")
    g.frombytes((Path(gib_dir) / "closest-t.bin").read_bytes())
    m = list(closest_t)
    big = 1e30
    same_t = sum(1 for a, b in zip(g, m)
                 if (a > big and b > big) or (a <= big and b <= big and abs(a - b) <= 1e-3 * max(a, 1e-3)))
    gs = (Path(gib_dir) / "shadow-hit.bin").read_bytes()
    same_s = sum(1 for a, b in zip(gs, list(shadow_hit)) if bool(a) == bool(b))
    return {"closest_same": same_t / n, "shadow_same": same_s / n}


def compare_rays(args, mi, dr, name, scene, export, tmp):
    """Raw ray throughput on the same rays: `gibench raycast` against Mitsuba's (Embree's)
    ray_intersect_preliminary and ray_test, alternated `--repeats` times."""
    closest, n = read_rays(mi, export / "rays-closest.bin")
    shadow, _ = read_rays(mi, export / "rays-shadow.bin")
    warm = {"closest": mitsuba_cast(dr, scene, closest, False)[0],
            "shadow": mitsuba_cast(dr, scene, shadow, True)[0]}
    runs = []
    for i in range(args.repeats):
        out = Path(tmp) / f"raycast{i}"
        run([args.gibench, "raycast", "--rays", str(export), "--repeats", "1", "--out", str(out)])
        g = json.loads((out / "raycast.json").read_text())["passes"][0]
        mc, t = mitsuba_cast(dr, scene, closest, False)
        ms, hit = mitsuba_cast(dr, scene, shadow, True)
        one = {"gibench": g, "mitsuba": {"closest": mc, "shadow": ms}}
        for kind, m in (("closest", mc), ("shadow", ms)):
            one[f"{kind}_gibench_rays_per_cpu_s"] = n / g[f"{kind}_cpu_s"]
            one[f"{kind}_mitsuba_rays_per_cpu_s"] = n / m["cpu_s"]
            one[f"{kind}_ratio_cpu"] = one[f"{kind}_gibench_rays_per_cpu_s"] / one[f"{kind}_mitsuba_rays_per_cpu_s"]
        print(f"  {name} rays #{i + 1}: closest ratio {one['closest_ratio_cpu']:.3f}, "
              f"shadow ratio {one['shadow_ratio_cpu']:.3f}", flush=True)
        runs.append(one)
    agree = agreement(dr, out, t, hit, n)
    summary = {k: spread([r[k] for r in runs]) for k in runs[0] if k.endswith(("_s", "_cpu"))}
    return {"rays": n, "mitsuba_warmup": warm, "runs": runs, "agreement": agree, "summary": summary}


def compare_scene(args, mi, dr, name, w, h, tmp):
    export = Path(tmp) / "export"
    run([args.gibench, "export-scene", "--scene", name, "--frame", "0",
         "--resolution", f"{w}x{h}", "--rays", str(args.rays), "--out", str(export)])
    meta = json.loads((export / "scene.json").read_text())
    load = time.perf_counter()
    scene = mi.load_dict(scene_dict(mi, meta, export, args.spp))
    load = time.perf_counter() - load
    # Mitsuba compiles a different kernel for 1 spp than for more (no sample-index division),
    # so a 1-spp warm-up leaves the compilation inside the first timed render: warm up at 2.
    warm_spp = min(args.spp, 2)
    warmup = dict(mitsuba_render(mi, dr, scene, warm_spp), spp=warm_spp)
    mitsuba_rays = mitsuba_ray_counts(mi, scene, args.spp, ray_count_integrator(mi, dr))
    rays = compare_rays(args, mi, dr, name, scene, export, tmp) if args.rays > 0 else None
    samples, runs = w * h * args.spp, []
    for i in range(args.repeats):
        g = gibench_render(args, name, w, h, Path(tmp) / f"ref{i}")
        m = mitsuba_render(mi, dr, scene, args.spp)
        g["samples_per_cpu_s"] = samples / g["cpu_s"]
        m["samples_per_cpu_s"] = samples / m["cpu_s"]
        one = {"gibench": g, "mitsuba": m,
               "ratio_cpu": g["samples_per_cpu_s"] / m["samples_per_cpu_s"]}
        if g["render_cpu_s"]:
            g["samples_per_render_cpu_s"] = samples / g["render_cpu_s"]
            one["ratio_render_cpu"] = g["samples_per_render_cpu_s"] / m["samples_per_cpu_s"]
        if g["trace_cpu_s"]:
            g["samples_per_trace_cpu_s"] = samples / g["trace_cpu_s"]
            one["ratio_trace_cpu"] = g["samples_per_trace_cpu_s"] / m["samples_per_cpu_s"]
        if g["trace_wall_s"]:
            one["ratio_trace_wall"] = m["wall_s"] / g["trace_wall_s"]
        if g["rays"] and "ratio_trace_cpu" in one:
            g["rays_per_sample"] = g["rays"]["total"] / samples
            # Rays per trace-CPU-second against Mitsuba's: the per-sample ratio scaled by the
            # two renderers' rays per sample (counted; and with Mitsuba's bound, which favours it).
            one["ratio_per_ray_trace_cpu"] = (one["ratio_trace_cpu"] * g["rays_per_sample"]
                                              / mitsuba_rays["total"])
            one["ratio_per_ray_bound_trace_cpu"] = (one["ratio_trace_cpu"] * g["rays_per_sample"]
                                                    / MITSUBA_RAYS_BOUND)
        runs.append(one)
        nan = float("nan")
        print(f"  {name} #{i + 1}: gibench {g['cpu_s']:.2f} CPU-s (render "
              f"{g['render_cpu_s'] or nan:.2f}, of which BVH build {g['bvh_build_cpu_s'] or nan:.2f}"
              f" CPU-s; {g['wall_s']:.2f} s wall, render {g['render_wall_s'] or nan:.2f} s), "
              f"mitsuba {m['cpu_s']:.2f} CPU-s ({m['wall_s']:.2f} s wall), ratio trace CPU "
              f"{one.get('ratio_trace_cpu', nan):.3f}, render CPU "
              f"{one.get('ratio_render_cpu', nan):.3f}, whole process {one['ratio_cpu']:.3f}, "
              f"per ray (trace CPU) {one.get('ratio_per_ray_trace_cpu', nan):.3f}",
              flush=True)
    summary = {"gibench_samples_per_cpu_s": spread([r["gibench"]["samples_per_cpu_s"] for r in runs]),
               "mitsuba_samples_per_cpu_s": spread([r["mitsuba"]["samples_per_cpu_s"] for r in runs]),
               "ratio_cpu": spread([r["ratio_cpu"] for r in runs])}
    if all("ratio_render_cpu" in r for r in runs):
        summary["gibench_samples_per_render_cpu_s"] = spread(
            [r["gibench"]["samples_per_render_cpu_s"] for r in runs])
        summary["ratio_render_cpu"] = spread([r["ratio_render_cpu"] for r in runs])
    if all("ratio_trace_cpu" in r for r in runs):
        summary["gibench_samples_per_trace_cpu_s"] = spread(
            [r["gibench"]["samples_per_trace_cpu_s"] for r in runs])
        summary["ratio_trace_cpu"] = spread([r["ratio_trace_cpu"] for r in runs])
    if all("ratio_trace_wall" in r for r in runs):
        summary["ratio_trace_wall"] = spread([r["ratio_trace_wall"] for r in runs])
    for k in ("ratio_per_ray_trace_cpu", "ratio_per_ray_bound_trace_cpu"):
        if all(k in r for r in runs):
            summary[k] = spread([r[k] for r in runs])
    return {"scene": name, "triangles": meta.get("triangles"), "light_kind": meta["light"]["kind"],
            "mitsuba_load_s": load, "mitsuba_warmup": warmup, "runs": runs, "summary": summary,
            "gibench_rays": runs[0]["gibench"]["rays"], "mitsuba_rays_per_sample": mitsuba_rays,
            "raw_rays": rays}


def git_commit():
    """The checkout's commit, "-dirty" when files outside results/ differ from it (as
    results/regenerate.sh decides: results being regenerated beside this run are not the code
    that made them); None outside a git checkout."""
    root = Path(__file__).resolve().parent.parent
    git = lambda *a: subprocess.run(["git", *a], capture_output=True, text=True, cwd=root)
    head = git("rev-parse", "--short=7", "HEAD").stdout.strip()
    if not head:
        return None
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)results")
    return head + ("-dirty" if dirty.stdout.strip() else "")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scenes", default="cornell,sibenik")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--resolution", default="256x192")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--out", default="results/perf")
    p.add_argument("--gibench", default="target/release/gibench")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--rays", type=int, default=262144,
                   help="closest-hit and shadow rays of the raw throughput comparison (0: none)")
    args = p.parse_args()
    w, h = (int(v) for v in args.resolution.lower().split("x"))
    llvm = newest_llvm() if args.variant.startswith("llvm") else None
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        print(f"cannot import mitsuba/drjit ({e}).\n{INSTALL}")
        return 0
    if not variant_works(args.variant):
        print(INSTALL)
        return 0
    mi.set_variant(args.variant)
    common = {"mitsuba_version": mi.__version__, "drjit_version": dr.__version__,
              "variant": args.variant, "drjit_libllvm_path": llvm, "cpu_count": os.cpu_count(),
              "spp": args.spp, "resolution": [w, h], "gibench_bounces": BOUNCES,
              "max_depth": MAX_DEPTH, "rr_depth": MAX_DEPTH + 1, "light_note": LIGHT_NOTE,
              "gibench_cpu": "its sidecar's 'cpu_seconds' (CPU of every thread during the "
                             "render call) less 'bvh_build_cpu_seconds' (the frame's mesh and "
                             "BVH) gives ratio_trace_cpu, 'cpu_seconds' itself ratio_render_cpu, "
                             "user+sys of the whole `gibench reference` process (getrusage "
                             "RUSAGE_CHILDREN) ratio_cpu; 'seconds' less 'bvh_build_seconds' "
                             "(wall) gives ratio_trace_wall",
              "mitsuba_cpu": "time.process_time around mi.render + dr.eval + dr.sync_thread"}
    common["gibench_git_commit"] = git_commit()
    out = Path(args.out)
    results = []
    for name in [s.strip() for s in args.scenes.split(",") if s.strip()]:
        print(f"{name}: {w}x{h}, {args.spp} spp, {args.repeats} alternations", flush=True)
        with tempfile.TemporaryDirectory(prefix="gibench-mitsuba-") as tmp:
            r = dict(common, **compare_scene(args, mi, dr, name, w, h, tmp))
        out.mkdir(parents=True, exist_ok=True)
        (out / f"mitsuba-{name}.json").write_text(json.dumps(r, indent=2) + "\n")
        results.append(r)
    rng = lambda s: f"{s['median']:.3f} [{s['min']:.3f}–{s['max']:.3f}]"
    lines = [f"# gibench reference vs Mitsuba {mi.__version__} ({args.variant}, drjit "
             f"{dr.__version__}), gibench commit {common['gibench_git_commit']}", "",
             f"{w}x{h}, {args.spp} spp, {BOUNCES} indirect bounces (Mitsuba max_depth "
             f"{MAX_DEPTH}, no Russian roulette), {os.cpu_count()} CPUs, {args.repeats} "
             "alternations; samples = width x height x spp.", "",
             "| scene | triangles | gibench samples/trace-CPU-s (median) | Mitsuba "
             "samples/CPU-s (median) | ratio gibench/Mitsuba, trace CPU, median [min–max] "
             "| render CPU ratio (BVH build in) | whole-process CPU ratio | trace-wall ratio |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    dash = "–"
    for r in results:
        s = r["summary"]
        trace = s.get("gibench_samples_per_trace_cpu_s")
        trace = f"{trace['median']:,.0f}" if trace else dash
        opt = lambda k: rng(s[k]) if k in s else dash
        lines.append(f"| {r['scene']} | {r['triangles']} | {trace}"
                     f" | {s['mitsuba_samples_per_cpu_s']['median']:,.0f}"
                     f" | {opt('ratio_trace_cpu')} | {opt('ratio_render_cpu')}"
                     f" | {rng(s['ratio_cpu'])} | {opt('ratio_trace_wall')} |")
    lines += ["", "Trace CPU: the CPU of every thread of gibench during its render call less "
              "that of its BVH build (the frame's mesh and BVH), both from its JSON sidecar, "
              "against Mitsuba's render CPU after a warm-up (its BVH is built when the scene "
              "loads, outside). Render CPU: gibench's BVH build kept in. Whole-process CPU: "
              "gibench's process start, scene load, BVH build and image output added. "
              "Trace-wall ratio: the render call's wall time less the BVH build's against "
              "Mitsuba's render wall time.", "",
              f"Light: {LIGHT_NOTE}", "", "Per sample gibench traces at most 16 rays (+2 per pixel), "
              f"Mitsuba 19 (max_depth {MAX_DEPTH}) at most; see the table below and "
              "scripts/compare_mitsuba.py for caveats."]
    lines += ["", "## Per ray traced", "",
              "Trace-CPU rays per second, gibench's against Mitsuba's: the per-sample ratio "
              "times gibench's rays per sample over Mitsuba's. gibench's rays are counted in "
              "its tracer (sidecar `rays`); Mitsuba's by a render with an integrator that "
              "mirrors its `path` loop and traces what it traces (same scene, spp, film; "
              "another random stream: ± its standard error over pixels). The bound column "
              f"takes Mitsuba's {MITSUBA_RAYS_BOUND} rays per sample instead: it over-counts "
              "Mitsuba's rays and so favours Mitsuba. Per ray rewards rays that carry nothing "
              "(Mitsuba traces shadow rays gibench skips: receivers facing away from the "
              "light, points outside a spot's cone); per sample stays the primary figure.", "",
              "| scene | gibench rays/sample (closest + shadow) | Mitsuba rays/sample "
              "(closest + shadow) | per-sample ratio, trace CPU | per-ray ratio, trace CPU, "
              "median [min–max] | per-ray ratio with Mitsuba's bound (favours Mitsuba) | "
              "every alternation's per-ray ratio |", "|---|---:|---:|---:|---:|---:|---|"]
    for r in results:
        s, g, m = r["summary"], r["gibench_rays"], r["mitsuba_rays_per_sample"]
        if not g or "ratio_per_ray_trace_cpu" not in s:
            continue
        n = w * h * args.spp
        each = ", ".join(f"{x['ratio_per_ray_trace_cpu']:.3f}" for x in r["runs"])
        lines.append(f"| {r['scene']} | {g['total'] / n:.3f} ({g['closest'] / n:.3f} + "
                     f"{g['shadow'] / n:.3f}) | {m['total']:.3f} ± {m['total_standard_error']:.3f}"
                     f" ({m['closest']:.3f} + {m['shadow']:.3f}) | {rng(s['ratio_trace_cpu'])}"
                     f" | {rng(s['ratio_per_ray_trace_cpu'])}"
                     f" | {rng(s['ratio_per_ray_bound_trace_cpu'])} | {each} |")
    if args.rays > 0:
        lines += ["", "## Raw ray throughput on the same rays", "",
                  f"{args.rays:,} closest-hit and {args.rays:,} shadow rays per scene (`gibench "
                  "export-scene --rays`: from primary hits, cosine-distributed like the "
                  "reference's path segments, and segments to the light), each caster over all "
                  f"cores, {args.repeats} alternations. gibench: `SceneBvh::closest_hit` (full hit "
                  "record) and `any_hit` (`gibench raycast`, CPU of every thread during the cast); "
                  "Mitsuba: `ray_intersect_preliminary` and `ray_test` (Embree), CPU of the "
                  "process during the cast, after a warm-up cast.", "",
                  "| scene | rays | gibench closest rays/CPU-s | Mitsuba closest rays/CPU-s | "
                  "closest ratio, median [min–max] | gibench shadow rays/CPU-s | Mitsuba shadow "
                  "rays/CPU-s | shadow ratio, median [min–max] | agreement closest / shadow |",
                  "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in results:
            q = r["raw_rays"]
            s = q["summary"]
            lines.append(f"| {r['scene']} | {q['rays']:,} | {s['closest_gibench_rays_per_cpu_s']['median']:,.0f}"
                         f" | {s['closest_mitsuba_rays_per_cpu_s']['median']:,.0f} | {rng(s['closest_ratio_cpu'])}"
                         f" | {s['shadow_gibench_rays_per_cpu_s']['median']:,.0f}"
                         f" | {s['shadow_mitsuba_rays_per_cpu_s']['median']:,.0f} | {rng(s['shadow_ratio_cpu'])}"
                         f" | {q['agreement']['closest_same']:.4f} / {q['agreement']['shadow_same']:.4f} |")
    (out / "mitsuba.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {out}/mitsuba.md and mitsuba-<scene>.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
