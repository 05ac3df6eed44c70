#!/usr/bin/env python3
"""rsibr's integrators against Blender's Cycles on the spheres of tests/blender (docs/blender.md):
how long each takes to bake one sphere map, and how close it gets to rsibr's reference bake.
Writes the "## Against Cycles" section of docs/performance.md (replacing it, or before "Notes:").

For each environment (sky: a sun; studio: small bright softboxes; forest: no sun) and sphere
(Lambert; GGX alpha 0.5 and 0.05 without Fresnel), one view (+Z), an N x N sphere map:
  * rsibr bake --method reference (the truth here), reference over coarser MIP levels
    (--reference-width), mis and fis at several --samples, sh (Lambert only);
  * Cycles (scripts/blender/render_sphere.py) at several sample counts, two seeds each.
Error: relative RMS over the texels within 0.98 of the disc's radius, all channels,
sqrt(sum (a - r)^2 / sum r^2), r the reference bake. For Cycles the error that counts toward the
thresholds is its noise, sqrt(sum (c1 - c2)^2 / 2 / sum r^2) from the two seeds (its distance from
its own converged answer): Cycles 3.x's GGX masks with the separable Smith form, rsibr's with the
height-correlated one, and Cycles' environment lookup blurs a sun's highlight a little, so its
distance from rsibr's reference stops falling at a floor (shown beside it; docs/blender.md).
Times are wall-clock seconds of one whole process: rsibr bake reading the environment, building
its tables, integrating and writing the map; Cycles as one `blender -b` run of one render:
Blender's start-up, the scene built in Python, Cycles' scene setup (BVH, the environment's
importance map) and the render and its EXR (measured as the two-seed process minus the second
seed's render). The time to reach 1% and 0.1% is interpolated in log-log between the measured
settings; for the unbiased Monte Carlo integrators (mis, Cycles) beyond the last setting it is
extrapolated at error ~ 1/sqrt(samples) and marked "~"; otherwise "not reached".

Usage: bench/against_cycles.py [--rsibr build/release/rsibr] [--blender blender] [--res 64]
                               [--envs sky studio forest] [--json saved.json] [--save out.json]
                               [--no-write] [--keep DIR]
Standard library only (run with the system python3): the array work runs in Blender's Python,
which has numpy, with the rsibr module of build/release/python.
"""
import argparse
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time

from doc_section import write_section

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TITLE = "## Against Cycles"
RENDER = os.path.join(ROOT, "scripts/blender/render_sphere.py")

SPHERES = [
    ("Lambert", "lambert", "{type: lambert, albedo: [1, 1, 1]}", ["--bsdf", "lambert"]),
    ("GGX 0.5", "ggx_rough", "{type: ggx, roughness: 0.5, fresnel: {type: none}}", ["--bsdf", "ggx", "--alpha", "0.5"]),
    ("GGX 0.05", "ggx_sharp", "{type: ggx, roughness: 0.05, fresnel: {type: none}}",
     ["--bsdf", "ggx", "--alpha", "0.05"]),
]
REFERENCE_WIDTHS = [64, 128, 256]
MIS = [16, 64, 256, 1024, 4096]
FIS = [16, 64, 256]
CYCLES = [64, 256, 1024]
THRESHOLDS = [0.01, 0.001]

# Blender-side helpers (Blender's Python: numpy and the rsibr module).
CONVERT = r'''
import sys
argv = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, argv[0])
import rsibr
# rsibr.read_environment folds lossy-codec ringing as every rsibr verb does; then the same radiance
# in Blender's cell-centred lat-long convention at k times the resolution (core/cell_centred_latlong.h).
env = rsibr.read_environment(argv[1])
k = int(argv[3])
rsibr.write_environment(argv[2], rsibr.to_cell_centred_latlong(env, k * env.layout.width, k * env.layout.height))
'''

METRICS = r'''
import sys, json, numpy as np, bpy
argv = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, argv[0])
import rsibr
jobs = json.load(open(argv[1]))
cache = {}
def map_set(path):
    if path not in cache:
        cache[path] = np.asarray(rsibr.read_map_set(path)[0].rgb, dtype=np.float64)
    return cache[path]
def cycles(path):
    im = bpy.data.images.load(path)
    w, h = im.size
    px = np.array(im.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1, :, :3]  # rows bottom first
    bpy.data.images.remove(im)
    return px
out = {}
for job in jobs:
    r = map_set(job["reference"])
    n = r.shape[0]
    yy, xx = np.mgrid[0:n, 0:n]
    x = (2 * xx + 1) / n - 1
    y = 1 - (2 * yy + 1) / n
    m = x * x + y * y < 0.98 ** 2
    rr = r[m]
    s2 = (rr ** 2).sum()
    if job["kind"] == "mapset":
        a = map_set(job["a"])[m]
        out[job["id"]] = {"rel_rms": float(np.sqrt(((a - rr) ** 2).sum() / s2)),
                          "bias": float((a - rr).sum() / rr.sum())}
    else:
        c1, c2 = cycles(job["a"])[m], cycles(job["b"])[m]
        out[job["id"]] = {"rel_rms": float(np.sqrt(((c1 - rr) ** 2).sum() / s2)),
                          "noise": float(np.sqrt(((c1 - c2) ** 2).sum() / 2 / s2)),
                          "bias": float((0.5 * (c1 + c2) - rr).sum() / rr.sum())}
json.dump(out, open(argv[2], "w"), indent=1)
'''


# Debian's Blender takes its Python's home from the first python3 on PATH: under pyenv or a
# virtual environment that is another Python, without numpy. Blender runs with /usr/bin first.
BLENDER_ENV = dict(os.environ, PATH="/usr/bin" + os.pathsep + os.environ.get("PATH", ""))


def run(cmd, **kw):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)
    dt = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit("against_cycles: failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout[-3000:]))
    return dt, p.stdout


def blender_python(blender, code, work, name, args):
    script = os.path.join(work, name + ".py")
    with open(script, "w") as f:
        f.write(code)
    return run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", script, "--"] + args,
               env=BLENDER_ENV)


def measure(args, work):
    python_dir = os.path.join(os.path.dirname(os.path.abspath(args.rsibr)), "python")
    views = os.path.join(work, "view.txt")
    with open(views, "w") as f:
        f.write("0 0 1\n")
    runs, jobs = [], []
    blender_version = None
    for env in args.envs:
        env_path = os.path.join(ROOT, "cache/assets/hdri", env + ".exr")
        cycles_env = os.path.join(work, env + "_cell_centred.exr")
        blender_python(args.blender, CONVERT, work, "convert", [python_dir, env_path, cycles_env, "2"])
        for label, key, spec, bsdf in SPHERES:
            case = "%s_%s" % (env, key)
            brdf = os.path.join(work, key + ".yaml")
            with open(brdf, "w") as f:
                f.write(spec + "\n")
            print("against_cycles: %s %s" % (env, label), flush=True)

            def bake(family, setting, *extra):
                out = os.path.join(work, "%s_%s_%s.exr" % (case, family.replace(" ", "_"), setting))
                dt, _ = run([args.rsibr, "bake", "--env", env_path, "--brdf", brdf, "--views", views, "--res",
                             str(args.res), "-q", *extra, out])
                runs.append({"case": case, "env": env, "sphere": label, "family": family, "setting": setting,
                             "seconds": dt, "id": out})
                return out

            reference = bake("reference", 0, "--method", "reference")
            baked = [bake("reference (MIP)", w, "--method", "reference", "--reference-width", str(w))
                     for w in REFERENCE_WIDTHS]
            baked += [bake("mis", n, "--method", "mis", "--samples", str(n)) for n in MIS]
            baked += [bake("fis", n, "--method", "fis", "--samples", str(n)) for n in FIS]
            if key == "lambert":
                baked.append(bake("sh", 0, "--method", "sh"))
            jobs += [{"id": b, "kind": "mapset", "a": b, "reference": reference} for b in baked]
            for n in CYCLES:
                pattern = os.path.join(work, "%s_cycles_%d_{seed}.exr" % (case, n))
                dt, log = run([args.blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", RENDER,
                               "--", "--env", cycles_env, *bsdf, "--size", str(args.res), "--samples", str(n),
                               "--seed", "1", "2", "--out", pattern], env=BLENDER_ENV)
                renders = [line for line in log.splitlines() if line.startswith("render_sphere: ")]
                if len(renders) != 2:
                    sys.exit("against_cycles: no render times in Blender's output:\n" + log[-3000:])
                blender_version = renders[0].split()[2].rstrip(",")
                second = float(renders[1].split("render ")[1].split(" s")[0])
                rid = pattern.replace("{seed}", "x")
                runs.append({"case": case, "env": env, "sphere": label, "family": "Cycles", "setting": n,
                             "seconds": dt - second, "id": rid})
                jobs.append({"id": rid, "kind": "cycles", "a": pattern.replace("{seed}", "1"),
                             "b": pattern.replace("{seed}", "2"), "reference": reference})
    job_file, metric_file = os.path.join(work, "jobs.json"), os.path.join(work, "metrics.json")
    with open(job_file, "w") as f:
        json.dump(jobs, f)
    blender_python(args.blender, METRICS, work, "metrics", [python_dir, job_file, metric_file])
    metrics = json.load(open(metric_file))
    for r in runs:
        r.update(metrics.get(r["id"], {"rel_rms": 0.0, "bias": 0.0}))
        r["id"] = os.path.basename(r["id"])
    return {"runs": runs, "blender": blender_version, "res": args.res, "cpus": os.cpu_count(),
            "platform": platform.platform(), "load_start": args.load_start, "load_end": list(os.getloadavg())}


def error_of(r):
    return r["noise"] if r["family"] == "Cycles" else r["rel_rms"]


def time_to(points, threshold, extrapolate):
    """points: [(samples, seconds, error)] in order of samples -> the time to reach `threshold`, as text:
    interpolated in log-log between the settings around it, "<=" the first setting's time when that
    already reaches it. Beyond the last setting, when `extrapolate` (Monte Carlo) and the error still
    falls at least as samples^-1/4 between the last two settings: extrapolated at the slope measured
    there (at most samples^-1/2) with time linear in samples, as "~"; else "not reached", with the
    smallest error (an error that stops falling is a bias against the reference)."""
    for i, (n, t, e) in enumerate(points):
        if e <= threshold:
            if i == 0:
                return "<= " + secs(t)
            n0, t0, e0 = points[i - 1]
            if not (e0 > e > 0):
                return secs(t)
            f = (math.log(threshold) - math.log(e0)) / (math.log(e) - math.log(e0))
            return secs(math.exp(math.log(t0) + f * (math.log(t) - math.log(t0))))
    if extrapolate and len(points) >= 2:
        (n0, t0, e0), (n1, t1, e1) = points[-2], points[-1]
        slope = math.log(e0 / e1) / math.log(n1 / n0) if e0 > 0 and e1 > 0 else 0.0
        if slope >= 0.25:
            need = n1 * (e1 / threshold) ** (1.0 / min(slope, 0.5))
            return "~" + secs(t1 + max(0.0, (t1 - t0) / (n1 - n0)) * (need - n1))
    return "not reached (%s)" % pct(min(e for _, _, e in points))


def secs(t):
    return "%.2g s" % t if t < 10 else "%.0f s" % t


def pct(e):
    return "%.1f%%" % (100 * e) if e >= 0.01 else "%.2g%%" % (100 * e)


def format_section(data):
    runs = data["runs"]
    cases = []
    for r in runs:
        if (r["env"], r["sphere"]) not in cases:
            cases.append((r["env"], r["sphere"]))
    families = ["reference", "reference (MIP)", "mis", "fis", "sh", "Cycles"]

    def of(env, sphere, family):
        return sorted((r for r in runs if r["env"] == env and r["sphere"] == sphere and r["family"] == family),
                      key=lambda r: r["setting"])

    lines = [TITLE, "",
             "Generated by `bench/against_cycles.py`; do not edit. Machine: %d CPUs, %s; Blender %s (Cycles on the "
             "CPU, all threads; rsibr all threads). Load average %.1f at the start, %.1f at the end: the machine is "
             "shared, so times move with the load. The whole run took %.0f s." % (
                 data["cpus"], data["platform"], data["blender"], data["load_start"][0], data["load_end"][0],
                 data.get("total_seconds", float("nan"))),
             "",
             "One " + str(data["res"]) + "^2 sphere map (view +Z) of the spheres of tests/blender (docs/blender.md): Lambert, GGX alpha 0.5 "
             "and 0.05 (F = 1) under sky (a sun), studio (softboxes) and forest. Error: relative RMS against rsibr's "
             "reference bake over the disc (radius < 0.98); for Cycles, its noise (the two seeds' difference), "
             "since its converged answer differs from rsibr's by the Smith masking form (GGX 0.5: 0.85-1.0%) and a "
             "slight blur of the sun's highlight (GGX 0.05: 0.1-0.5%); its distance from rsibr's reference is in "
             "the second table. Times: wall-clock seconds of one process, start-up and setup included (rsibr bake: "
             "reading the environment, its tables, the integration, writing the map; Cycles: Blender's start-up, "
             "the scene, Cycles' BVH and importance map, the render, writing the EXR). `~`: extrapolated from the "
             "last two settings (mis, Cycles) at their slope (error ~ 1/sqrt(samples) at most), where the error still "
             "falls; `not reached (x)`: the smallest error measured, when it does not. Reference (MIP): the fastest MIP level "
             "reaching it; reference: the full quadrature (error 0 by definition). An error that stops falling "
             "with more samples is a difference in what is computed, not noise: a bias of the integrator (fis by "
             "design), or, for the sharp lobe under a sun, possibly of the reference's point quadrature; Cycles "
             "cannot tell the latter apart (docs/blender.md).",
             ""]
    for threshold in THRESHOLDS:
        lines += ["Time to %s relative RMS:" % pct(threshold), "",
                  "| environment | sphere | " + " | ".join(families) + " |",
                  "|---|---|" + "---|" * len(families)]
        for env, sphere in cases:
            cells = []
            for fam in families:
                rs = of(env, sphere, fam)
                if not rs:
                    cells.append("")
                    continue
                pts = [(r["setting"], r["seconds"], error_of(r)) for r in rs]
                if fam == "reference":
                    cells.append(secs(rs[0]["seconds"]))
                elif fam == "reference (MIP)":
                    ok = [r for r in rs if r["rel_rms"] <= threshold]
                    cells.append("%s (width %d)" % (secs(min(r["seconds"] for r in ok)),
                                                    min(ok, key=lambda r: r["seconds"])["setting"]) if ok
                                 else "not reached (%s)" % pct(min(r["rel_rms"] for r in rs)))
                elif fam == "sh":
                    cells.append(secs(rs[0]["seconds"]) if rs[0]["rel_rms"] <= threshold
                                 else "not reached (%s)" % pct(rs[0]["rel_rms"]))
                else:
                    cells.append(time_to(pts, threshold, fam in ("mis", "Cycles")))
            lines.append("| %s | %s | %s |" % (env, sphere, " | ".join(cells)))
        lines.append("")
    lines += ["Every setting (samples or MIP width: time, error; Cycles: time, noise / distance from rsibr's "
              "reference):", "",
              "| environment | sphere | method | settings |", "|---|---|---|---|"]
    for env, sphere in cases:
        for fam in families:
            rs = of(env, sphere, fam)
            if not rs:
                continue
            if fam == "Cycles":
                cells = ["%d: %s, %s / %s" % (r["setting"], secs(r["seconds"]), pct(r["noise"]), pct(r["rel_rms"]))
                         for r in rs]
            elif fam in ("reference", "sh"):
                cells = ["%s, %s" % (secs(r["seconds"]), pct(r["rel_rms"])) for r in rs]
            else:
                cells = ["%d: %s, %s" % (r["setting"], secs(r["seconds"]), pct(r["rel_rms"])) for r in rs]
            lines.append("| %s | %s | %s | %s |" % (env, sphere, fam, "; ".join(cells)))
    lines.append("")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rsibr", default=os.path.join(ROOT, "build/release/rsibr"))
    ap.add_argument("--blender", default=shutil.which("blender") or "blender")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--envs", nargs="+", default=["sky", "studio", "forest"])
    ap.add_argument("--json", help="format this saved result instead of running")
    ap.add_argument("--save", help="save the measurements as JSON here")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/performance.md"))
    ap.add_argument("--no-write", action="store_true", help="print the section instead of writing it")
    ap.add_argument("--keep", help="work in this folder and keep it (default: a temporary folder)")
    args = ap.parse_args()
    args.load_start = list(os.getloadavg())
    if args.json:
        data = json.load(open(args.json))
    else:
        if not shutil.which(args.blender):
            sys.exit("against_cycles: blender not found (--blender)")
        work = args.keep or tempfile.mkdtemp(prefix="against_cycles_")
        os.makedirs(work, exist_ok=True)
        t0 = time.perf_counter()
        try:
            data = measure(args, work)
        finally:
            if not args.keep:
                shutil.rmtree(work, ignore_errors=True)
        data["total_seconds"] = time.perf_counter() - t0
        print("against_cycles: measured in %.0f s" % data["total_seconds"])
    if args.save:
        with open(args.save, "w") as f:
            json.dump(data, f, indent=1)
    section = format_section(data)
    if args.no_write:
        print("\n".join(section))
    else:
        write_section(args.out, TITLE, section)
        print("against_cycles: wrote", args.out)


if __name__ == "__main__":
    main()
