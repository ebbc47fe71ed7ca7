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
     alternations of: `gibench reference --no-cache` as a subprocess (CPU time = user+sys of
     the child from getrusage(RUSAGE_CHILDREN) deltas, whole process: scene load, BVH build,
     render, image writing), then one timed Mitsuba render (CPU = time.process_time, all
     threads, around mi.render plus the evaluation it defers, so load and compilation are
     outside). The ratio is taken per alternation; min/median/max are reported.
  3. gibench's JSON sidecar gives `seconds`, the wall time of its render call (BVH build
     included, scene load and image writing excluded). It is used for a second, render-only
     wall-clock ratio against Mitsuba's render wall time; the primary number stays the CPU one.

Caveats (read before quoting a ratio):
  * Not the same estimator. gibench shoots one primary ray per pixel and `spp` paths from that
    hit (plus one direct shadow ray per pixel); each path has 8 indirect vertices with one
    closest-hit and one shadow ray each: 16 rays per sample. Mitsuba resamples the camera ray
    per sample and, at max_depth 10, traces 1 + 9 + 9 = 19 rays per sample (NEE at 9 vertices
    and a last BSDF ray from the 9th vertex that can only find emitters). Paths that leave the
    scene stop early on both sides; gibench traces nothing for pixels that miss the scene.
  * gibench's spot light is cosine-shaped (I = I0 cos θ); Mitsuba's `spot` with
    cutoff_angle = beam_width = 90 is uniform over the front hemisphere. Images differ; the
    cost per sample is what is compared. Area lights are replaced by a spot light (their far
    field); suns map to `directional`.
  * gibench's CPU time includes its process start, scene load and output writing; Mitsuba's
    excludes everything but the render. This favours Mitsuba a little; the render-wall ratio
    shows the size of the effect.
  * Both use every core of the machine; run on an otherwise idle machine.
"""
import argparse, glob, json, os, re, resource, statistics, subprocess, sys, tempfile, time
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
    return {"cpu_s": cpu, "wall_s": wall, "render_wall_s": sidecar.get("seconds"),
            "outside_render_wall_s": wall - sidecar["seconds"] if "seconds" in sidecar else None}


def run(cmd):
    """Runs a gibench command; on failure says which and exits."""
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed (exit {r.returncode}): {' '.join(cmd)}\n{r.stderr.strip()[-2000:]}")


def spread(values):
    return {"median": statistics.median(values), "min": min(values), "max": max(values)}


def compare_scene(args, mi, dr, name, w, h, tmp):
    export = Path(tmp) / "export"
    run([args.gibench, "export-scene", "--scene", name, "--frame", "0",
         "--resolution", f"{w}x{h}", "--out", str(export)])
    meta = json.loads((export / "scene.json").read_text())
    load = time.perf_counter()
    scene = mi.load_dict(scene_dict(mi, meta, export, args.spp))
    load = time.perf_counter() - load
    # Mitsuba compiles a different kernel for 1 spp than for more (no sample-index division),
    # so a 1-spp warm-up leaves the compilation inside the first timed render: warm up at 2.
    warm_spp = min(args.spp, 2)
    warmup = dict(mitsuba_render(mi, dr, scene, warm_spp), spp=warm_spp)
    samples, runs = w * h * args.spp, []
    for i in range(args.repeats):
        g = gibench_render(args, name, w, h, Path(tmp) / f"ref{i}")
        m = mitsuba_render(mi, dr, scene, args.spp)
        g["samples_per_cpu_s"] = samples / g["cpu_s"]
        m["samples_per_cpu_s"] = samples / m["cpu_s"]
        one = {"gibench": g, "mitsuba": m,
               "ratio_cpu": g["samples_per_cpu_s"] / m["samples_per_cpu_s"]}
        if g["render_wall_s"]:
            one["ratio_render_wall"] = m["wall_s"] / g["render_wall_s"]
        runs.append(one)
        print(f"  {name} #{i + 1}: gibench {g['cpu_s']:.2f} CPU-s ({g['wall_s']:.2f} s wall, "
              f"render {g['render_wall_s'] or float('nan'):.2f} s), mitsuba {m['cpu_s']:.2f} "
              f"CPU-s ({m['wall_s']:.2f} s wall), ratio {one['ratio_cpu']:.3f}", flush=True)
    summary = {"gibench_samples_per_cpu_s": spread([r["gibench"]["samples_per_cpu_s"] for r in runs]),
               "mitsuba_samples_per_cpu_s": spread([r["mitsuba"]["samples_per_cpu_s"] for r in runs]),
               "ratio_cpu": spread([r["ratio_cpu"] for r in runs])}
    if all("ratio_render_wall" in r for r in runs):
        summary["ratio_render_wall"] = spread([r["ratio_render_wall"] for r in runs])
    return {"scene": name, "triangles": meta.get("triangles"), "light_kind": meta["light"]["kind"],
            "mitsuba_load_s": load, "mitsuba_warmup": warmup, "runs": runs, "summary": summary}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scenes", default="cornell,sibenik")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--resolution", default="256x192")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--out", default="results/perf")
    p.add_argument("--gibench", default="target/release/gibench")
    p.add_argument("--variant", default="llvm_ad_rgb")
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
              "gibench_cpu": "user+sys of the whole `gibench reference` process (getrusage "
                             "RUSAGE_CHILDREN); its sidecar 'seconds' (render call incl. BVH "
                             "build, wall) gives ratio_render_wall",
              "mitsuba_cpu": "time.process_time around mi.render + dr.eval + dr.sync_thread"}
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
             f"{dr.__version__})", "",
             f"{w}x{h}, {args.spp} spp, {BOUNCES} indirect bounces (Mitsuba max_depth "
             f"{MAX_DEPTH}, no Russian roulette), {os.cpu_count()} CPUs, {args.repeats} "
             "alternations; samples = width x height x spp.", "",
             "| scene | triangles | gibench samples/CPU-s (median) | Mitsuba samples/CPU-s "
             "(median) | ratio gibench/Mitsuba, median [min–max] | render-wall ratio |",
             "|---|---:|---:|---:|---:|---:|"]
    for r in results:
        s = r["summary"]
        lines.append(f"| {r['scene']} | {r['triangles']} | {s['gibench_samples_per_cpu_s']['median']:,.0f}"
                     f" | {s['mitsuba_samples_per_cpu_s']['median']:,.0f} | {rng(s['ratio_cpu'])}"
                     f" | {rng(s['ratio_render_wall']) if 'ratio_render_wall' in s else '–'} |")
    lines += ["", "CPU: gibench's whole process (load, BVH, render, image output); Mitsuba's "
              "render only, after a warm-up. Render-wall ratio: gibench's sidecar render time "
              "(BVH build included) against Mitsuba's render wall time.", "",
              f"Light: {LIGHT_NOTE}", "", "Per sample gibench traces 16 rays (+2 per pixel), "
              f"Mitsuba 19 (max_depth {MAX_DEPTH}); see scripts/compare_mitsuba.py for caveats."]
    (out / "mitsuba.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {out}/mitsuba.md and mitsuba-<scene>.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
