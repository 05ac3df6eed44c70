#!/usr/bin/env python3
"""HDR merge against the peers in one run: rsibr's automatic curve and merge, OpenCV's Debevec and
Robertson, luminance-hdr-cli and pfstools (pfsinhdrgen | pfshdrcalibrate | pfsoutexr) on the same
synthetic consumer-camera brackets with known truth (bench/hdr_peers.cpp, tests/hdr/camera_shoot.h),
as PNG and as JPEG, for several CC0 environments and seeds. Writes the docs/tradeoffs.md section
"## HDR merge: against the peers".

Protocol. Every tool gets the same 8-bit codes (all views of a shoot side by side; for JPEG the
decoded codes, stored losslessly as PNG and TIFF) and the true exposure times (EXIF-like: the
relative exposures e_j read as seconds). Each peer's settings are chosen once per format by a sweep
on a tuning shoot of an environment that is not in the table (--tune-env), by the sum of its
mid-tone and colour-ratio errors there, then fixed for every shoot of the table. rsibr runs with
its defaults (automatic model, channels and saturation). Errors are measured after one global
scale per method per shoot (a single scalar for all three channels, never a per-channel gain).

Usage: bench/hdr_peers.py [--bench build/release/rsibr_hdr_peers] [--envs bridge,workshop,sunset]
                          [--seeds 1,2] [--tune-env hall] [--jpeg-quality 90]
                          [--save results.json] [--json results.json (format a saved run)]
A missing peer (luminance-hdr-cli: Debian package luminance-hdr; pfsinhdrgen, pfshdrcalibrate,
pfsoutexr: pfstools) is named on stderr and its rows are left out. Standard library only.
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

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TITLE = "## HDR merge: against the peers"
NICE = ["nice", "-n", "10"]

# Sweeps (each peer's options that change the result; the defaults are among them).
LUMINANCE_SWEEP = ([(m, r, w) for m in ("debevec", "robertson") for r in ("linear", "gamma", "log", "srgb")
                    for w in ("triangular", "gaussian", "plateau", "flat")] +
                   [("robertsonauto", "linear", w) for w in ("triangular", "gaussian", "plateau", "flat")])
PFS_SWEEP = ([("robertson", r, y, o) for r in ("linear", "gamma", "log") for y in (False, True) for o in (0.01, 0.05)] +
             [("mitsunaga", "linear", False, o) for o in (0.01, 0.05)])
OPENCV_DEBEVEC_SWEEP = ["70,10", "70,100", "300,10", "300,100"]
TOP = 3  # sweep rows listed per tool and format in the doc


def log(msg):
    print("hdr_peers.py: " + msg, file=sys.stderr, flush=True)


def tools():
    """Which peers can run: {name: reason missing or None}."""
    need = {"luminance-hdr-cli": (["luminance-hdr-cli"], "Debian package luminance-hdr"),
            "pfstools": (["pfsinhdrgen", "pfsin", "pfshdrcalibrate", "pfsoutexr"], "Debian package pfstools")}
    missing = {}
    for name, (progs, pkg) in need.items():
        absent = [p for p in progs if shutil.which(p) is None]
        missing[name] = None if not absent else "%s not found (%s)" % (", ".join(absent), pkg)
        if absent:
            log("%s: %s; its rows are skipped" % (name, missing[name]))
    return missing


def run_timed(cmd, **kw):
    t0 = time.monotonic()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kw)
    return time.monotonic() - t0, r


def luminance_settings(c):
    return "--hdrModel %s --hdrResponseCurve %s --hdrWeight %s" % tuple(c)


def pfs_settings(c):
    model, resp, lum, off = c
    s = "-c %s -b 8 -o %g" % (model, off)
    if model == "robertson":
        s += " -r %s" % resp
    return s + (" -Y" if lum else "")


def setting_label(tool, c):
    if isinstance(c, str):
        return c
    return luminance_settings(c) if tool == "luminance-hdr-cli" else pfs_settings(c)


def run_luminance(d, shoot, c, out):
    evs = ",".join("%.6g" % math.log2(t) for t in shoot["exposures"])  # luminance-hdr: time = 2^EV
    files = [os.path.join(d, "bracket_%d.tif" % j) for j in range(len(shoot["exposures"]))]
    cmd = NICE + ["luminance-hdr-cli", "-e", evs, "--hdrModel", c[0], "--hdrResponseCurve", c[1], "--hdrWeight", c[2],
                  "-s", out] + files
    t, r = run_timed(cmd)
    ok = r.returncode == 0 and os.path.exists(out)
    if not ok:
        log("luminance-hdr-cli %s failed: %s" % (luminance_settings(c), r.stderr.decode(errors="replace").strip()[-300:]))
    return t, ok


def run_pfs(d, shoot, c, out):
    model, resp, lum, off = c
    # hdrgen script: file, 1 / exposure time, aperture, ISO (pfsinhdrgen), longest first as pfsinme sorts
    order = sorted(range(len(shoot["exposures"])), key=lambda j: -shoot["exposures"][j])
    hdrgen = os.path.join(d, "shoot.hdrgen")
    with open(hdrgen, "w") as f:
        for j in order:
            f.write("%s %.10g 1 100 0\n" % (os.path.join(d, "bracket_%d.png" % j), 1.0 / shoot["exposures"][j]))
    cal = ["pfshdrcalibrate", "-c", model, "-b", "8", "-o", str(off)] + (["-r", resp] if model == "robertson" else []) + \
          (["-Y"] if lum else [])
    pipe = " | ".join(" ".join(NICE + p) for p in (["pfsinhdrgen", hdrgen], cal, ["pfsoutexr", "--float32", out]))
    t, r = run_timed(["bash", "-o", "pipefail", "-c", pipe])
    ok = r.returncode == 0 and os.path.exists(out)
    if not ok:
        log("pfstools %s failed: %s" % (pfs_settings(c), r.stderr.decode(errors="replace").strip()[-300:]))
    return t, ok


def shoot_args(bench, env, q, seed):
    return NICE + [bench, "--env", os.path.join(ROOT, "cache/assets/hdri", env + ".exr"), "--jpeg", str(q), "--seed", str(seed)]


def write_shoot(bench, env, q, seed, d):
    subprocess.run(shoot_args(bench, env, q, seed) + ["--write", d], check=True)
    return json.load(open(os.path.join(d, "shoot.json")))


def score(bench, env, q, seed, d, files, opencv_debevec):
    out = os.path.join(d, "score.json")
    cmd = shoot_args(bench, env, q, seed) + ["--out", out]
    for name, path in files:
        cmd += ["--score", "%s=%s" % (name, path)]
    for s in opencv_debevec:
        cmd += ["--opencv-debevec", s]
    subprocess.run(cmd, check=True)
    return json.load(open(out))["methods"]


def merit(e):
    return e["mid"] + e["colour"]


def tune(bench, env, q, seed, missing, work):
    """Each peer's best setting on the tuning shoot (by mid-tone + colour-ratio error)."""
    d = os.path.join(work, "tune_%s_%d" % (env, q))
    shoot = write_shoot(bench, env, q, seed, d)
    files, labels = [], {}
    if not missing["luminance-hdr-cli"]:
        for i, c in enumerate(LUMINANCE_SWEEP):
            out = os.path.join(d, "lum_%d.exr" % i)
            if run_luminance(d, shoot, c, out)[1]:
                files.append(("lum%d" % i, out)), labels.update({"lum%d" % i: ("luminance-hdr-cli", c)})
    if not missing["pfstools"]:
        for i, c in enumerate(PFS_SWEEP):
            out = os.path.join(d, "pfs_%d.exr" % i)
            if run_pfs(d, shoot, c, out)[1]:
                files.append(("pfs%d" % i, out)), labels.update({"pfs%d" % i: ("pfstools", c)})
    methods = score(bench, env, q, seed, d, files, OPENCV_DEBEVEC_SWEEP)
    best, sweep = {}, []
    for m in methods:
        if m["method"] in labels:
            tool, c = labels[m["method"]]
        elif m["method"] == "OpenCV Debevec":
            tool, c = "OpenCV Debevec", m["settings"]
        else:
            continue
        sweep.append({"tool": tool, "setting": c, "mid": m["errors"]["mid"], "colour": m["errors"]["colour"]})
        if tool not in best or merit(m["errors"]) < merit(best[tool][1]):
            best[tool] = (c, m["errors"])
    for tool, (c, e) in best.items():
        log("tuning %s q%d: %s best: %s (mid %.4f, colour %.4f stops)" % (env, q, tool, c, e["mid"], e["colour"]))
    return {tool: c for tool, (c, e) in best.items()}, sweep


def measure(bench, env, q, seed, chosen, missing, work):
    d = os.path.join(work, "%s_%d_%d" % (env, q, seed))
    shoot = write_shoot(bench, env, q, seed, d)
    files, times = [], {}
    if "luminance-hdr-cli" in chosen:
        out = os.path.join(d, "luminance.exr")
        t, ok = run_luminance(d, shoot, chosen["luminance-hdr-cli"], out)
        if ok:
            files.append(("luminance-hdr-cli", out)), times.update({"luminance-hdr-cli": t})
    if "pfstools" in chosen:
        out = os.path.join(d, "pfstools.exr")
        t, ok = run_pfs(d, shoot, chosen["pfstools"], out)
        if ok:
            files.append(("pfstools", out)), times.update({"pfstools": t})
    cv = chosen.get("OpenCV Debevec", "CalibrateDebevec samples 70, lambda 10 + MergeDebevec")
    cv_arg = cv.split("samples ")[1].split(" +")[0].replace(", lambda ", ",")
    methods = score(bench, env, q, seed, d, files, [cv_arg])
    for m in methods:
        if m["method"] in times:
            m["seconds"] = times[m["method"]]
            c = chosen[m["method"]]
            m["settings"] = luminance_settings(c) if m["method"] == "luminance-hdr-cli" else pfs_settings(c)
    return {"env": env, "jpeg_quality": q, "seed": seed, "views": shoot["views"], "width": shoot["width"],
            "height": shoot["height"], "exposures": shoot["exposures"], "methods": methods}


def replace_section(path, lines):
    text = open(path).read().splitlines() if os.path.exists(path) else []
    start = next((i for i, l in enumerate(text) if l.strip() == TITLE), None)
    if start is None:
        # After the "## HDR merge (rsibr hdr)" section when there is one, else at the end.
        merge = next((i for i, l in enumerate(text) if l.startswith("## HDR merge (")), None)
        at = len(text) if merge is None else next((i for i in range(merge + 1, len(text)) if text[i].startswith("## ")), len(text))
        out = text[:at] + ([""] if at and text[at - 1] != "" else []) + lines + ([""] if at < len(text) else []) + text[at:]
    else:
        end = next((i for i in range(start + 1, len(text)) if text[i].startswith("## ")), len(text))
        out = text[:start] + lines + ([""] if end < len(text) else []) + text[end:]
    with open(path, "w") as f:
        f.write("\n".join(out).rstrip("\n") + "\n")


def mean(xs):
    return sum(xs) / len(xs) if xs else float("nan")


ORDER = ["rsibr", "OpenCV Debevec", "OpenCV Robertson", "luminance-hdr-cli", "pfstools"]
DEFAULTS = {"luminance-hdr-cli": luminance_settings(("debevec", "linear", "triangular")),
            "pfstools": pfs_settings(("robertson", "linear", False, 0.01)),
            "OpenCV Debevec": "CalibrateDebevec samples 70, lambda 10 + MergeDebevec"}


def avg_time(rs, m):
    return mean([next(x for x in r["methods"] if x["method"] == m)["seconds"] for r in rs])


def fmt_time(s):
    return "%.0f ms" % (1000 * s) if s < 10 else "%.1f s" % s


def section(j):
    runs, machine = j["runs"], j["machine"]
    fmts = sorted({r["jpeg_quality"] for r in runs})
    envs = sorted({r["env"] for r in runs})
    seeds = sorted({r["seed"] for r in runs})
    r0 = runs[0]
    lines = [TITLE, "",
             "Generated by `bench/hdr_peers.py` from `rsibr_hdr_peers`; do not edit. " + machine, "",
             "Shoots: the consumer camera of the HDR tests (raw sensitivities 0.55 / 1 / 0.72, automatic white balance, "
             "a colour matrix with saturation 1.3, the filmic tone curve with a toe and a highlight shoulder, 8-bit codes; "
             "JPEG at quality %d or lossless PNG), %d brackets two stops apart, %d views of %dx%d each, of the CC0 "
             "environments %s (no test was tuned to them), seeds %s; %d shoots in all. Truth: the camera's linear output "
             "before clipping and the tone curve. Every tool gets the same codes (all views side by side in one image per "
             "bracket; for JPEG the decoded codes, stored losslessly) and the true exposure times (%s s)." % (
                 max(fmts), len(r0["exposures"]), r0["views"], r0["width"] // r0["views"], r0["height"],
                 ", ".join("`%s`" % e for e in envs), ", ".join(str(s) for s in seeds), len(runs),
                 " ".join(("1/%g" % (1 / t)) if t < 1 else "%g" % t for t in r0["exposures"])), "",
             "Errors are measured after ONE global scale fitted per method per shoot: a single scalar, the same for all "
             "three channels (the median of truth / estimate luminance over mid-tone pixels), never a per-channel gain, so "
             "a colour cast counts as colour error. Pixel classes by truth luminance over the views: dark (below the 10th "
             "percentile), mid, bright (above the 90th), clipped (a channel saturated in the shortest bracket); pixels "
             "with a channel under 2% of their luminance (outside the output gamut) are left out. Tone: RMS of log2 "
             "(estimate / truth) luminance, in stops. Colour ratio: RMS of log2 of R/G and of B/G against the truth's "
             "(each channel floored at 5% of the truth luminance), in stops, over dark + mid + bright. Clipped: the same "
             "tone error (how far the lower bound sits below the truth) and the fraction of saturated channel values at "
             "or below the truth. Neutral patch: a grey card's mean R/G and B/G in the estimate. Time: rsibr (response "
             "recovery, noise model, merge of every view) and OpenCV (calibration + merge) in process; the "
             "command-line peers' wall time, reading the brackets and writing the EXR included; all under `nice`.", "",
             "Settings (each peer's chosen per format by the sweep below on the tuning shoot `%s`, seed %d, by mid-tone + "
             "colour-ratio error; rsibr and OpenCV Robertson at their defaults):" % (j["tune_env"], j["tune_seed"]), ""]
    for q in fmts:
        lines.append("- %s: %s" % ("JPEG" if q else "PNG", "; ".join(
            "%s `%s`" % (t, s) for t, s in j["chosen_settings"][str(q)].items()) +
            "; OpenCV Robertson `CalibrateRobertson (30 iterations, threshold 0.01) + MergeRobertson`; rsibr `rsibr hdr` defaults"))
    for t, why in j["missing"].items():
        if why:
            lines.append("- %s: not run (%s)" % (t, why))
    lines.append("")
    verdicts = []
    for q in fmts:
        rs = [r for r in runs if r["jpeg_quality"] == q]
        name = "JPEG q%d" % q if q else "PNG"
        lines += ["### %s: mean over %d shoots" % (name, len(rs)), "",
                  "| method | dark | mid | bright | clipped | clipped <= truth | colour ratio (R/G, B/G) | colour ratio, mid | "
                  "neutral patch R/G, B/G | time |", "|---|---|---|---|---|---|---|---|---|---|"]
        present = [m for m in ORDER if all(any(x["method"] == m for x in r["methods"]) for r in rs)]
        for m in present:
            es = [next(x for x in r["methods"] if x["method"] == m) for r in rs]
            e = lambda k: mean([x["errors"][k] for x in es])
            lines.append("| %s | %.3f | %.3f | %.3f | %.2f | %.1f%% | %.3f | %.3f | %.3f, %.3f | %s |" % (
                m, e("dark"), e("mid"), e("bright"), e("clipped"), 100 * e("clipped_at_or_below"), e("colour"),
                e("colour_mid"), e("patch_rg"), e("patch_bg"), fmt_time(mean([x["seconds"] for x in es]))))
        lines += ["", "Per shoot, mid-tone and colour-ratio error (stops) of each method, and rsibr's chosen curve:", "",
                  "| shoot | " + " | ".join(present) + " | rsibr's curve |", "|---|" + "---|" * (len(present) + 1)]
        wins_mid = wins_col = 0
        for r in rs:
            cells = []
            for m in present:
                e = next(x for x in r["methods"] if x["method"] == m)["errors"]
                cells.append("%.3f / %.3f" % (e["mid"], e["colour"]))
            ours = next(x for x in r["methods"] if x["method"] == "rsibr")
            peers = [x for x in r["methods"] if x["method"] != "rsibr"]
            wins_mid += ours["errors"]["mid"] <= min(x["errors"]["mid"] for x in peers)
            wins_col += ours["errors"]["colour"] <= min(x["errors"]["colour"] for x in peers)
            lines.append("| %s seed %d | %s | %s |" % (r["env"], r["seed"], " | ".join(cells), ours["chosen"]))
        peers = [m for m in present if m != "rsibr"]
        avg = lambda m, k: mean([next(x for x in r["methods"] if x["method"] == m)["errors"][k] for r in rs])
        best_mid = min(peers, key=lambda m: avg(m, "mid"))
        best_col = min(peers, key=lambda m: avg(m, "colour"))
        choices = sorted({next(x for x in r["methods"] if x["method"] == "rsibr")["chosen"] for r in rs})
        verdicts.append(
            "%s: rsibr's automatic curve %s the best peer on mid-tone error (%.3f stops against %s's %.3f; at or below "
            "every peer in %d of %d shoots) and %s it on colour-ratio error (%.3f against %s's %.3f; %d of %d shoots); "
            "its choice: %s." % (
                name, "beats" if avg("rsibr", "mid") <= avg(best_mid, "mid") else "does not beat", avg("rsibr", "mid"),
                best_mid, avg(best_mid, "mid"), wins_mid, len(rs),
                "beats" if avg("rsibr", "colour") <= avg(best_col, "colour") else "does not beat", avg("rsibr", "colour"),
                best_col, avg(best_col, "colour"), wins_col, len(rs),
                ("the same for every shoot (%s)" % choices[0]) if len(choices) == 1 else "varies: " + ", ".join(choices)))
        t = {m: avg_time(rs, m) for m in present}
        fastest = min(t, key=t.get)
        verdicts.append(
            "%s: rsibr's worst shoot for clipped values kept at or below the truth: %.1f%%; bright-class error %.3f stops "
            "against the best peer's %.3f (%s). Time: rsibr %s, %s fastest (%s)." % (
                name, 100 * min(next(x for x in r["methods"] if x["method"] == "rsibr")["errors"]["clipped_at_or_below"] for r in rs),
                avg("rsibr", "bright"), min(avg(m, "bright") for m in peers), min(peers, key=lambda m: avg(m, "bright")),
                fmt_time(t["rsibr"]), "rsibr" if fastest == "rsibr" else fastest + " is the", fmt_time(t[fastest])))
        lines.append("")
    lines += ["What the numbers say:", ""] + ["- " + v for v in verdicts] + [""]
    lines += ["Sweep on the tuning shoot (mid-tone / colour-ratio error in stops; bold: the setting chosen for that "
              "format; listed: the %d best of each tool per format by mid + colour and its default, the others rank below "
              "those in both formats):" % TOP,
              "", "| tool | setting | PNG mid | PNG colour ratio | JPEG mid | JPEG colour ratio |", "|---|---|---|---|---|---|"]
    table = {}  # (tool, label) -> {q: (mid, colour)}
    for q in fmts:
        for sw in j["sweeps"][str(q)]:
            table.setdefault((sw["tool"], setting_label(sw["tool"], sw["setting"])), {})[q] = (sw["mid"], sw["colour"])
    for tool in [t for t in ORDER if any(k[0] == t for k in table)]:
        rows = [k for k in table if k[0] == tool]
        keep = {DEFAULTS.get(tool)}
        for q in fmts:
            ranked = sorted((k for k in rows if q in table[k]), key=lambda k: sum(table[k][q]))
            keep.update(k[1] for k in ranked[:TOP])
        for k in rows:
            if k[1] not in keep:
                continue
            cells = []
            for q in fmts:
                if q not in table[k]:
                    cells += ["-", "-"]
                    continue
                b = j["chosen_settings"][str(q)].get(tool) == k[1]
                cells += [("**%.3f**" if b else "%.3f") % v for v in table[k][q]]
            lines.append("| %s | `%s`%s | %s |" % (tool, k[1], " (default)" if k[1] == DEFAULTS.get(tool) else "", " | ".join(cells)))
    lines.append("")
    n = {t: sum(1 for k in table if k[0] == t) for t in ORDER if any(k[0] == t for k in table)}
    lines += ["Settings swept per format: " + ", ".join("%s %d" % (t, c) for t, c in n.items()) +
              " (luminance-hdr-cli: --hdrModel debevec and robertson with each --hdrResponseCurve and --hdrWeight, and "
              "robertsonauto, its own response recovery, with each weight; pfstools: pfshdrcalibrate's own recovery, "
              "-c robertson from each initial -r curve, on R, G, B or on luminance (-Y), and -c mitsunaga, each with "
              "saturation offsets -o 0.01 and 0.05; OpenCV: CalibrateDebevec samples and lambda)."]
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", default=os.path.join(ROOT, "build/release/rsibr_hdr_peers"))
    ap.add_argument("--envs", default="bridge,workshop,sunset")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--tune-env", default="hall")
    ap.add_argument("--tune-seed", type=int, default=101)
    ap.add_argument("--jpeg-quality", type=int, default=90)
    ap.add_argument("--save", help="also write the raw results to this JSON file")
    ap.add_argument("--json", help="format this saved result instead of running")
    args = ap.parse_args()
    if args.json:
        j = json.load(open(args.json))
    else:
        for env in args.envs.split(",") + [args.tune_env]:
            p = os.path.join(ROOT, "cache/assets/hdri", env + ".exr")
            if not os.path.exists(p):
                sys.exit("hdr_peers.py: %s: no such environment (the CC0 assets live in cache/assets/hdri/)" % p)
        if not os.access(args.bench, os.X_OK):
            sys.exit("hdr_peers.py: %s: not built (cmake --build --preset release --target rsibr_hdr_peers)" % args.bench)
        missing = tools()
        t0 = time.monotonic()
        work = tempfile.mkdtemp(prefix="hdr_peers_")
        try:  # nothing is written to the docs unless every run succeeds
            fmts = [0, args.jpeg_quality]
            chosen, sweeps = {}, {}
            for q in fmts:
                c, s = tune(args.bench, args.tune_env, q, args.tune_seed, missing, work)
                chosen[str(q)], sweeps[str(q)] = c, s
            runs = []
            for q in fmts:
                for env in args.envs.split(","):
                    for seed in (int(s) for s in args.seeds.split(",")):
                        log("%s %s seed %d" % (env, "JPEG q%d" % q if q else "PNG", seed))
                        runs.append(measure(args.bench, env, q, seed, chosen[str(q)], missing, work))
        finally:
            shutil.rmtree(work, ignore_errors=True)
        load = os.getloadavg()[0]
        machine = "Machine: %d CPUs, %s; load average %.1f when the run ended (%.0f s in all)." % (
            os.cpu_count(), platform.platform(), load, time.monotonic() - t0)
        printable = {q: {t: setting_label(t, c) for t, c in v.items()} for q, v in chosen.items()}
        j = {"machine": machine, "tune_env": args.tune_env, "tune_seed": args.tune_seed, "missing": missing,
             "chosen_settings": printable, "sweeps": sweeps, "runs": runs}
        if args.save:
            with open(args.save, "w") as f:
                json.dump(j, f, indent=1)
    replace_section(os.path.join(ROOT, "docs/tradeoffs.md"), section(j))


if __name__ == "__main__":
    try:
        main()
    except subprocess.CalledProcessError as e:
        sys.exit("hdr_peers.py: %s failed (exit %d); docs/tradeoffs.md left as it was" % (" ".join(e.cmd[3:]), e.returncode))
