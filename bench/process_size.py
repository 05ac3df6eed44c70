#!/usr/bin/env python3
"""A whole shoot through `rsibr process` at real size: the "Process at real size" section of
docs/performance.md.

A synthetic shoot (`rsibr synth`) of a chrome and a grey ball on stands in the CC0 lobby, with
background circles (a ringed target, a disc, a sphere), 8 hand-held views of JPEG brackets, is run
through `rsibr process` with the shoot's own lens (--lens, as with a calibrated camera; calibrate is
then a copy). Each step's seconds are set against the decode floor: the time to decode every
photo once (OpenCV's imread on all cores), which no run that reads the photos can beat. The peak
resident memory is the process's.

Usage: bench/process_size.py [--rsibr build/release/rsibr] [--size 2000x1500] [--views 8]
                             [--brackets 5] [--baseline OTHER_RSIBR] [--no-write]
--baseline runs the same shoot through another rsibr too (e.g. a build of the previous commit), in
the same run, and adds its seconds per step. Needs the environments fetched by
scripts/fetch-assets.sh and /usr/bin/python3's OpenCV.
"""
import argparse
import concurrent.futures
import glob
import json
import os
import platform
import sys
import tempfile
import time

import cv2

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from doc_section import write_section  # noqa: E402
from timed_command import timed_run  # noqa: E402

SCENE = """rsibr_synth: 1
seed: 21
environment: {{file: {env}, sanitize: true}}
balls:
  - {{name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.07, 1.3, 0]}}
  - {{name: grey, kind: grey, diameter_m: 0.1, centre: [0.07, 1.3, 0]}}
stand: true
photographer: false
clutter:
  - {{shape: disc, centre: [0.5, 1.5, -3.0], radius_m: 0.2, albedo: [0.6, 0.6, 0.6]}}
  - {{shape: disc, centre: [-1.0, 1.7, -2.6], radius_m: 0.35, rings: 3, albedo: [0.9, 0.9, 0.85], ring_albedo: [0.1, 0.1, 0.1]}}
  - {{shape: sphere, centre: [-0.5, 1.2, -1.5], radius_m: 0.12, albedo: [0.3, 0.3, 0.3]}}
camera:
  width: {width}
  height: {height}
  lens: {{model: LENSMODEL_OPENCV4, focal_px: {focal}, distortion: [-0.05, 0.01, 0.0, 0.0]}}
  response: srgb
  format: jpeg
  vignetting: [-0.5, -0.1, 0.0]
exposure: {{middle_s: 0.05, count: {brackets}, step_ev: 2, iso: 400, aperture: 5.6}}
views:
  - {{plan: handheld, count: {views}, elevation_deg: 25, distance_m: 0.55, jitter_m: 0.01, jitter_deg: 1.0}}
truth_map_size: 48
"""


def run(cmd):
    return timed_run(cmd, "process_size")


def decode_floor(photos):
    """Seconds to decode every bracket once, on all cores (the best of two passes)."""
    files = sorted(glob.glob(os.path.join(photos, "*", "*.jpg")))
    if not files:
        sys.exit(f"process_size: no JPEG brackets under {photos}")
    best = float("inf")
    for _ in range(2):
        t0 = time.perf_counter()
        with concurrent.futures.ThreadPoolExecutor(os.cpu_count()) as pool:
            for img in pool.map(cv2.imread, files):
                if img is None:
                    sys.exit("process_size: OpenCV could not decode a bracket")
        best = min(best, time.perf_counter() - t0)
    return best, len(files)


def process(rsibr, photos, lens, out):
    """Per step seconds, the total wall time and the peak memory of one rsibr process."""
    summary = out + ".json"
    wall, mb = run([rsibr, "process", photos, "--out", out, "--lens", lens, "--turntable", "1", "-q", "--json",
                    summary])
    with open(summary) as f:
        steps = json.load(f)["steps"]
    return {s["step"]: s["seconds"] for s in steps}, wall, mb


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rsibr", default=os.path.join(ROOT, "build/release/rsibr"))
    ap.add_argument("--baseline", help="another rsibr to run on the same shoot, for a ratio per step")
    ap.add_argument("--cache", default=os.path.join(ROOT, "cache/assets"))
    ap.add_argument("--size", default="2000x1500")
    ap.add_argument("--views", type=int, default=8)
    ap.add_argument("--brackets", type=int, default=5)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/performance.md"))
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    env = os.path.join(args.cache, "hdri", "lobby.exr")
    if not os.path.exists(env):
        sys.exit(f"process_size: {env} is missing (run scripts/fetch-assets.sh)")
    width, height = (int(x) for x in args.size.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "shoot.yaml")
        with open(scene, "w") as f:
            # The focal length of a 35 mm-equivalent 43 mm lens at any size: the balls fill the same share.
            f.write(SCENE.format(env=env, width=width, height=height, focal=round(1.29 * width), views=args.views,
                                 brackets=args.brackets))
        synth_s, _ = run([args.rsibr, "synth", scene, "--out", os.path.join(tmp, "syn")])
        photos = os.path.join(tmp, "syn", "photos")
        lens = os.path.join(tmp, "syn", "truth", "camera.cameramodel")
        floor, files = decode_floor(photos)
        print(f"shoot: {args.views} views x {args.brackets} brackets of {width}x{height} (synth {synth_s:.0f} s); "
              f"decode floor {floor:.2f} s for {files} files", flush=True)
        steps, wall, mb = process(args.rsibr, photos, lens, os.path.join(tmp, "run"))
        print(f"process: {wall:.1f} s, peak {mb:.0f} MiB", flush=True)
        base = None
        if args.baseline:
            base = process(args.baseline, photos, lens, os.path.join(tmp, "base"))
            print(f"baseline: {base[1]:.1f} s, peak {base[2]:.0f} MiB", flush=True)
    if args.no_write:
        return
    mp = width * height / 1e6
    body = [
        "## Process at real size",
        "",
        "Generated by `bench/process_size.py`; do not edit. A synthetic shoot (`rsibr synth`: a chrome and a grey",
        f"ball on stands in the CC0 lobby, background circles, {args.views} hand-held views of {args.brackets} JPEG",
        f"brackets of {width}x{height} = {mp:.1f} MP) through `rsibr process --lens` (the shoot's own lens). Each step",
        "against the **decode floor**: decoding every bracket once with OpenCV on all cores "
        f"({files} files, {floor:.2f} s).",
    ]
    if base:
        body.append("Baseline: another build given with `--baseline` (the commit before the balls step), "
                    "the same shoot in the same run.")
    body += [f"Machine: {platform.machine()}, {os.cpu_count()} cores, {platform.platform()}.", ""]
    header = "| step | s | / decode floor |" + (" baseline s | baseline / this |" if base else "")
    body += [header, "|---|---|---|" + ("---|---|" if base else "")]
    names = list(steps) + ([s for s in base[0] if s not in steps] if base else [])
    for name in names:
        s = steps.get(name)
        row = f"| {name} | {s:.1f} | {s / floor:.1f}x |" if s is not None else f"| {name} | - | - |"
        if base:
            b = base[0].get(name)
            row += (f" {b:.1f} |" if b is not None else " - |")
            row += (f" {b / s:.1f}x |" if b is not None and s and s > 0.05 else " - |")
        body.append(row)
    total = f"| **whole run** | {wall:.1f} | {wall / floor:.1f}x |"
    if base:
        total += f" {base[1]:.1f} | {base[1] / wall:.1f}x |"
    body += [total, "", f"Peak resident memory: {mb:.0f} MiB" + (f" (baseline {base[2]:.0f} MiB)." if base else "."), ""]
    write_section(args.out, "## Process at real size", body)


if __name__ == "__main__":
    main()
