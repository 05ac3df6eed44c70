#!/usr/bin/env python3
"""Multi-lobe maps against one mirror-warped map set at the same number of maps.

Runs build/release/rsibr_multi_lobe (bench/multi_lobe.cpp) for the clear-coat BRDF under CC0
environments and writes the section "Multi-lobe maps (clear coat)" of docs/tradeoffs.md: for each
total number of maps, the relative RMS error at novel views of (a) one mirror-warped set of the
whole BRDF and (b) a normal-lobe set plus a mirror-lobe set, each warped with its own warp and
summed, with bake and blend times.

Usage: bench/multi_lobe.py [--tool build/release/rsibr_multi_lobe] [--cache cache/assets]
                           [--envs studio,park] [--paints red,white] [--configs fib24,n:fib4+fib20,...] [--res 64]
                           [--samples 128] [--truth-samples 512] [--novel 6] [--no-write]
Build first: cmake --build build/release --target rsibr_multi_lobe. Standard library only.
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from convert_roundtrip import replace_section  # noqa: E402
TITLE = "Multi-lobe maps (clear coat)"


def machine():
    return f"{platform.machine()}, {os.cpu_count()} cores, {platform.platform()}"


PAINTS = {
    # The clear coat of the earlier sections: a dark red binder, copper-coloured flakes; the coat dominates.
    "red": "{type: clearcoat, coat: {ior: 1.5, roughness: 0.05}, flakes: {coverage: 0.3, roughness: 0.3, fresnel: "
           "{type: conductor, eta: [1.66, 0.88, 0.52], k: [9.22, 6.27, 4.84]}}, base: {albedo: [0.5, 0.05, 0.03]}}",
    # A light paint: the binder carries most of the radiance away from the coat's highlights.
    "white": "{type: clearcoat, coat: {ior: 1.5, roughness: 0.05}, flakes: {coverage: 0.1, roughness: 0.3, fresnel: "
             "{type: conductor, eta: [1.66, 0.88, 0.52], k: [9.22, 6.27, 4.84]}}, base: {albedo: [0.8, 0.8, 0.75]}}",
}


def describe(config):
    norm = config.startswith("n:")
    c = config[2:] if norm else config
    if "+" in c:
        a, b = c.split("+")
        what = f"normal {a} + mirror {b}"
    else:
        what = f"one mirror set {c}"
    return what + (", albedo-normalised" if norm else "")


def table(doc, args, wall):
    rows = doc["rows"]
    r0 = rows[0]
    lines = [
        "Multi-lobe maps (the paper's future work; `bake/brdf_lobes.h`): the clear coat split into its normal-centred",
        "part (the binder, T(wo) T(wi) (1-c) rho/pi cos) and its mirror-centred part (coat + flakes), each baked as its",
        "own map set (`rsibr bake --lobe normal|mirror`), warped with its own warp and summed, against one mirror-warped",
        "set of the whole BRDF (`--lobe all`, the default) with the same total number of maps. Error: relative RMS",
        "against the whole BRDF baked directly at novel views in no set, over RGB of the texels inside the disc where",
        "every blend has weight > 0, pooled over the views; 'inner': normals within 60 degrees of the view (away from",
        "the grazing rim, where the coat's Fresnel reflectance rises toward 1); 'worst': the worst single view;",
        "'normal part' / 'mirror part': each lobe set's blend against that part's own truth, relative to the whole",
        "truth (split rows only). Bake: all maps of the row (sets shared between rows are baked once); blend: per",
        "novel view, all sets of the row (precomputed warp).",
        "",
        "Albedo-normalised rows (`rsibr bake --normalise albedo`, `core/albedo_normalisation.h`): every map stores",
        "L / A(n.v), A the part's directional albedo, and the blend multiplies A(n.d) back at the destination. The",
        "binder's part is T(wo) times a function of n alone and its albedo is T(wo) times a constant, so its",
        "normalised maps are exactly view independent: 4 views (the fewest that surround the sphere) carry it with",
        "resampling error only.",
        "",
        "Paints: " + "; ".join(f"{k}: `{v}`" for k, v in doc["paints"].items()) + ".",
        "",
        f"Maps {r0['res']}x{r0['res']}, MIS {r0['samples']} samples per texel; truth MIS "
        f"{r0['truth_samples']} samples at {r0['novel']} random novel views (>= 3 degrees from every set's views). "
        "View sets: fibN = N Fibonacci-sphere points (icosa, 42: `ViewSet::named`); `A+B` = normal part at A + mirror "
        "part at B. Whole-BRDF rows with no split of equal size (e.g. fib18, fib48) are the whole BRDF at a split's mirror "
        "views: they separate the cost of the views given to the normal part from the gain of warping it right.",
        "",
        "| environment | paint | configuration | maps | error | inner | worst view | normal part | mirror part | bake s | blend ms |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    noise = {}
    for r in rows:
        noise[(r["env"], r["paint"])] = r["truth_noise"]
        split = r["kind"] == "split"
        what = describe(r["config"])
        parts = (f"{r['normal_part_rel_rms']:.4f} | {r['mirror_part_rel_rms']:.4f}" if split else "  |  ")
        lines.append(f"| {r['env']} | {r['paint']} | {what} | {r['sets'] if split else r['maps']} | {r['rel_rms']:.4f} | "
                     f"{r['rel_rms_inner']:.4f} | {r['worst_view']:.4f} | {parts} | {r['bake_s']:.1f} | "
                     f"{r['blend_ms']:.2f} |")
    lines += ["", "At the same number of maps (error of one mirror set / error of the split; > 1: the split wins):", ""]
    for env, paint in dict.fromkeys((r["env"], r["paint"]) for r in rows):
        er = [r for r in rows if r["env"] == env and r["paint"] == paint]
        for maps in dict.fromkeys(r["maps"] for r in er):
            single = [r for r in er if r["maps"] == maps and r["kind"] == "single"]
            split = [r for r in er if r["maps"] == maps and r["kind"] == "split"]
            if not single or not split:
                continue
            a = min(single, key=lambda r: r["rel_rms"])  # the better one-set row
            for b in split:
                lines.append(f"- {env}, {paint}, {maps} maps: best one set {a['config']} {a['rel_rms']:.4f} vs "
                             f"{b['config']} {b['rel_rms']:.4f}: {a['rel_rms'] / b['rel_rms']:.2f}x (inner "
                             f"{a['rel_rms_inner']:.4f} vs {b['rel_rms_inner']:.4f}: "
                             f"{a['rel_rms_inner'] / b['rel_rms_inner']:.2f}x)")
    lines += [
        "",
        "Reading: a split row and the whole-BRDF row at the split's mirror views differ only in how the binder is "
        "stored (mirror-warped inside one set, or normal-warped in a set of its own): their difference is what the "
        "split buys; the maps it gives to the normal part are what it costs.",
        "",
        "The truth's own noise (the whole BRDF baked with seeds 1 and 2, relative RMS): "
        + ", ".join(f"{e}/{p} {n:.1e}" for (e, p), n in noise.items()) + ".",
        "",
        f"Regenerate: `bench/multi_lobe.py{''.join(' ' + a for a in args)}` ({wall:.0f} s on {machine()}).",
    ]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tool", default=os.path.join(ROOT, "build/release/rsibr_multi_lobe"))
    ap.add_argument("--cache", default=os.path.join(ROOT, "cache/assets"))
    ap.add_argument("--envs", default="studio,park")
    ap.add_argument("--paints", default="red,white", help="clear coats by name: " + ", ".join(PAINTS))
    ap.add_argument("--configs", default="fib24,n:fib24,fib6+fib18,n:fib4+fib20,fib54,n:fib54,n:fib4+fib50",
                    help="A = the whole BRDF at view set A; A+B = normal part at A + mirror part at B; "
                         "prefix n: = albedo-normalised maps")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--truth-samples", type=int, default=512)
    ap.add_argument("--novel", type=int, default=12)
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs/tradeoffs.md"))
    ap.add_argument("--no-write", action="store_true", help="print the section instead of writing it")
    args = ap.parse_args()
    envs = [os.path.join(args.cache, "hdri", e + ".exr") for e in args.envs.split(",")]
    missing = [e for e in envs if not os.path.exists(e)]
    if missing:
        sys.exit(f"multi_lobe.py: missing {', '.join(missing)} (run scripts/fetch-assets.sh)")
    if not os.path.exists(args.tool):
        sys.exit(f"multi_lobe.py: {args.tool} not built (cmake --build build/release --target rsibr_multi_lobe)")
    paints = args.paints.split(",")
    unknown = [p for p in paints if p not in PAINTS]
    if unknown:
        sys.exit(f"multi_lobe.py: unknown paint {', '.join(unknown)} (known: {', '.join(PAINTS)})")
    doc = {"rows": [], "paints": {p: PAINTS[p] for p in paints}}
    t0 = time.perf_counter()
    for paint in paints:
        with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as f:
            out = f.name
        subprocess.run([args.tool, "--envs", ",".join(envs), "--configs", args.configs, "--res", str(args.res),
                        "--samples", str(args.samples), "--truth-samples", str(args.truth_samples),
                        "--novel", str(args.novel), "--out", out, "--brdf", PAINTS[paint]], check=True)
        with open(out) as f:
            for r in json.load(f)["rows"]:
                r["paint"] = paint
                doc["rows"].append(r)
        os.unlink(out)
    wall = time.perf_counter() - t0
    given = [a for a in sys.argv[1:] if not a.startswith("--no-write")]
    body = table(doc, given, wall)
    if args.no_write:
        print(body)
    else:
        replace_section(args.docs, TITLE, body)
        print(f"wrote '## {TITLE}' in {args.docs}")


if __name__ == "__main__":
    main()
