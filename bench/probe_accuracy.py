#!/usr/bin/env python3
"""Light probe accuracy on the synthetic datasets, and the sweep of extract's --camera-mask-deg.

For every dataset with a chrome ball (datasets-synthetic/onset-outdoor.yaml, indoor.yaml):
  rsibr synth -> rsibr hdr (merged views) -> rsibr extract on every view's chrome ball -> rsibr probe
and the probe against the true environment (build/release/rsibr_probe_accuracy: relative RMS over
the covered sphere after a per-channel gain, with and without the sun, and inside 15-degree caps
around the camera directions, where the camera and the photographer reflect).

The merged views carry no pose and `rsibr orient` may not be there: the view's true orientation
(truth/truth.yaml) is given to extract through `extract --poses poses.yaml` when the verb has that
option, else written into a copy of the merged view's header as rsibr.worldFromCam (the attribute
extract reads). The lens is the true one (truth/camera.cameramodel), and also the one
`rsibr calibrate` fits to the dataset's chessboards (at the default mask).

Writes the section "Light probe accuracy (rsibr probe)" of docs/tradeoffs.md and, under the work
folder, each probe and a comparison picture (rsibr compare --out) per mask to look at.

  python3 bench/probe_accuracy.py [--build build/release] [--work /tmp/rsibr-probe-accuracy]
"""
import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from convert_roundtrip import replace_section  # noqa: E402

DATASETS = ["onset-outdoor", "indoor"]
MASKS = [0, 6, 12, 20, 30]
DEFAULT_MASK = 12


def run(*cmd):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("probe_accuracy: %s failed:\n%s" % (" ".join(map(str, cmd)), r.stderr.strip()))
    return r.stdout


def add_world_from_cam(src, dst, m):
    """Copies a single-part scanline OpenEXR file, adding the M33f attribute rsibr.worldFromCam
    (row-major, as capture/truth_image.cpp writes it). The header grows by the attribute's bytes, so
    every offset of the scanline offset table grows by as much."""
    data = open(src, "rb").read()
    if data[:4] != b"\x76\x2f\x31\x01":
        sys.exit("probe_accuracy: %s: not an OpenEXR file" % src)
    flags = struct.unpack("<I", data[4:8])[0]
    if flags & 0xFFFFFF00 & ~0x400:  # tiled, deep or multi-part (0x400: long names, harmless)
        sys.exit("probe_accuracy: %s: not a single-part scanline file" % src)
    pos, attrs = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        name = data[pos:name_end].decode()
        type_end = data.index(b"\0", name_end + 1)
        size = struct.unpack("<i", data[type_end + 1:type_end + 5])[0]
        attrs[name] = data[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
    if "rsibr.worldFromCam" in attrs:
        sys.exit("probe_accuracy: %s already has a pose" % src)
    header_end = pos  # the terminating 0 byte
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attrs["dataWindow"])
    lines = {0: 1, 1: 1, 2: 16, 3: 32, 4: 32, 5: 16, 6: 32, 7: 32, 8: 256, 9: 256}[attrs["compression"][0]]
    chunks = (ymax - ymin + lines) // lines
    attr = b"rsibr.worldFromCam\0m33f\0" + struct.pack("<i", 36) + struct.pack("<9f", *[v for row in m for v in row])
    table = struct.unpack("<%dQ" % chunks, data[header_end + 1:header_end + 1 + 8 * chunks])
    table = struct.pack("<%dQ" % chunks, *[o + len(attr) for o in table])
    out = data[:header_end] + attr + b"\0" + table + data[header_end + 1 + 8 * chunks:]
    with open(dst + ".tmp", "wb") as f:
        f.write(out)
    os.replace(dst + ".tmp", dst)


def flow(node):
    return yaml.safe_dump(node, default_flow_style=True, width=1000).strip()


def measure_dataset(args, name):
    spec = os.path.join(ROOT, "datasets-synthetic", name + ".yaml")
    work = os.path.join(args.work, name)
    syn, hdr, posed = (os.path.join(work, d) for d in ("syn", "hdr", "posed"))
    if not os.path.exists(os.path.join(syn, "truth", "truth.yaml")):
        shutil.rmtree(syn, ignore_errors=True)
        os.makedirs(work, exist_ok=True)
        run(args.rsibr, "synth", spec, "--out", syn, "-q")
    if not os.path.isdir(hdr):
        run(args.rsibr, "hdr", os.path.join(syn, "photos"), "--out", hdr, "--no-preview", "-q")
    truth = yaml.safe_load(open(os.path.join(syn, "truth", "truth.yaml")))
    scene = yaml.safe_load(open(spec))
    env = os.path.normpath(os.path.join(os.path.dirname(spec), scene["environment"]["file"]))
    chrome = next(b for b in truth["balls"] if b["kind"] == "chrome")
    fresnel = flow(yaml.safe_load(chrome["material"])["fresnel"])
    true_lens = os.path.join(syn, "truth", "camera.cameramodel")
    lens_text = open(true_lens).read()
    f = float(lens_text.split("'intrinsics':")[1].split("[")[1].split(",")[0])

    extract_help = run(args.rsibr, "extract", "--help")
    use_poses = "--poses" in extract_help
    os.makedirs(posed, exist_ok=True)
    views, cameras = [], []
    poses = {"rsibr_poses": 1, "gauge": "up", "views": []}
    for v in truth["views"]:
        ball = next(b for b in v["balls"] if b["name"] == chrome["name"])
        r_px = f * 0.5 * chrome["diameter_m"] / ball["distance_m"]
        merged = os.path.join(hdr, v["name"] + ".exr")
        m = v["world_from_cam"]
        if use_poses:
            image = merged
            poses["views"].append({"name": v["name"], "world_from_cam": [x for row in m for x in row], "sigma_deg": 0.0})
        else:
            image = os.path.join(posed, v["name"] + ".exr")
            if not os.path.exists(image):
                add_world_from_cam(merged, image, m)
        radiance = os.path.join(syn, "truth", v["radiance"])  # unclipped, noise-free, carries the pose
        views.append((v["name"], image, radiance, "%.2f,%.2f,%.2f" % (ball["centre_px"][0], ball["centre_px"][1], r_px)))
        d = [e - c for e, c in zip(v["eye"], chrome["centre"])]
        cameras.append("%.6f,%.6f,%.6f" % tuple(d))
    # The rig's other balls as the chrome ball sees them: caps of half angle asin(r / distance).
    occluders = []
    for b in truth["balls"]:
        if b["name"] == chrome["name"]:
            continue
        d = [p - c for p, c in zip(b["centre"], chrome["centre"])]
        dist = math.sqrt(sum(x * x for x in d))
        half = math.degrees(math.asin(min(1.0, 0.5 * b["diameter_m"] / dist)))
        occluders.append("%.6f,%.6f,%.6f,%.3f" % (d[0], d[1], d[2], half + 2))
    poses_file = os.path.join(work, "poses.yaml")
    if use_poses:
        with open(poses_file, "w") as fo:
            yaml.safe_dump(poses, fo)

    calibrated = os.path.join(work, "calibrated.cameramodel")
    cal = json.loads(run(args.rsibr, "calibrate", os.path.join(syn, "photos"), "--out", calibrated, "--json", "-", "-q"))
    truth_latlong = os.path.join(work, "truth-latlong.exr")
    run(args.rsibr, "convert", env, truth_latlong, "--to", "latlong", "--size", args.width, "--sanitize", "-q")

    rows = []
    runs = ([("merged", mask, "true", true_lens) for mask in MASKS] +
            [("merged", DEFAULT_MASK, "calibrated", calibrated), ("radiance", DEFAULT_MASK, "true", true_lens)])
    for source, mask, lens_name, lens in runs:
        out = os.path.join(work, "%s-%s-mask%02d" % (source, lens_name, mask))
        os.makedirs(out, exist_ok=True)
        maps = []
        for vname, image, radiance, ball in views:
            mp = os.path.join(out, vname + ".exr")
            extra = ["--poses", poses_file] if use_poses and source == "merged" else []
            run(args.rsibr, "extract", image if source == "merged" else radiance, "--lens", lens, "--out", mp,
                "--ball", ball, "--kind", "chrome",
                "--size", args.size, "--camera-mask-deg", mask, "-q", *extra)
            maps.append(mp)
        probe = os.path.join(out, "probe.exr")
        if os.path.exists(probe):
            os.remove(probe)
        run(args.rsibr, "probe", *maps, "--out", probe, "--width", args.width, "--fresnel", fresnel, "-q")
        acc = json.loads(run(args.metric, probe, env, *sum([["--camera", c] for c in cameras], []),
                             *sum([["--occluder", o] for o in occluders], [])))
        # The same maps into a coarse probe: how much of the error is the ball's resolution.
        coarse = os.path.join(out, "probe-coarse.exr")
        if os.path.exists(coarse):
            os.remove(coarse)
        run(args.rsibr, "probe", *maps, "--out", coarse, "--width", args.coarse_width, "--fresnel", fresnel, "-q")
        acc["no_sun_coarse"] = json.loads(run(args.metric, coarse, env))["no_sun"]
        pictures = os.path.join(out, "compare")
        shutil.rmtree(pictures, ignore_errors=True)
        run(args.rsibr, "compare", probe, truth_latlong, "--out", pictures, "-q")
        log_rms = acc["log_rms_stops"]
        rows.append({"dataset": name, "source": source, "lens": lens_name, "mask": mask, "log_rms": log_rms, **acc})
        print("%-14s %-8s %-10s mask %2d: covered %.4f, rel RMS all %.4f, no sun %.4f (coarse %.4f), at cameras %.4f, "
              "no rig %.4f, sun energy %.3f, log RMS %.3f stops" % (name, source, lens_name, mask, acc["covered_fraction"], acc["all"],
                                                acc["no_sun"], acc["no_sun_coarse"], acc["cameras"], acc["no_rig"],
                                                acc["sun_energy"], log_rms),
              flush=True)
    return rows, cal, len(views)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build/release"))
    ap.add_argument("--work", default="/tmp/rsibr-probe-accuracy")
    ap.add_argument("--size", type=int, default=256, help="extracted map size (texels)")
    ap.add_argument("--width", type=int, default=256, help="probe width (lat-long)")
    ap.add_argument("--coarse-width", type=int, default=64, help="width of the coarse probe (resolution-limited error)")
    ap.add_argument("--datasets", nargs="*", default=DATASETS)
    ap.add_argument("--no-docs", action="store_true", help="print only; leave docs/tradeoffs.md alone")
    args = ap.parse_args()
    args.rsibr = os.path.join(args.build, "rsibr")
    args.metric = os.path.join(args.build, "rsibr_probe_accuracy")
    for exe in (args.rsibr, args.metric):
        if not os.access(exe, os.X_OK):
            sys.exit("probe_accuracy: %s missing (cmake --build %s --target rsibr rsibr_probe_accuracy)" % (exe, args.build))
    os.makedirs(args.work, exist_ok=True)

    table, notes = [], []
    for name in args.datasets:
        rows, cal, nviews = measure_dataset(args, name)
        table += rows
        notes.append("%s: %d views; calibrate chose %s (RMS %.3f px, worst projection 1-sigma %.2f px)" %
                     (name, nviews, cal["model"], cal["rms_px"], cal["uncertainty"]["worst_projection_sigma_px"]))

    lines = [
        "Generated by `bench/probe_accuracy.py`: each synthetic dataset with a chrome ball through `rsibr synth`, "
        "`rsibr hdr`, `rsibr extract` (every view's chrome ball, true orientation from truth.yaml, map %d texels) "
        "and `rsibr probe` (lat-long %d), against the true environment resampled to the probe's grid "
        "(`rsibr_probe_accuracy`). Relative RMS = sqrt(sum w|g a - b|^2 / sum w|b|^2) over the covered sphere "
        "(w = solid angle) after a per-channel gain g (exposure and white balance of the merged views); *no sun* "
        "leaves out a 10-degree cap around the truth's brightest texel; *cameras* is the same inside 15-degree caps "
        "around the directions from the ball to every camera (where the camera and the photographer reflect); *coarse* is "
        "*no sun* for a probe %d texels wide from the same maps (the ball spans under 100 pixels in these images, so "
        "the full-width probe's error is partly resolution); *sun energy* is the probe's over the truth's inside the "
        "sun's cap (below 1: the shortest bracket clipped the sun); *no rig* also leaves out the rig's other balls as "
        "the chrome ball sees them (caps of asin(radius / distance) + 2 degrees: about 40 degrees across for the "
        "neighbour, which the chrome ball reflects and extract does not mask). "
        "*views*: `merged` are `rsibr hdr`'s merged views (the pipeline), `radiance` the synth's true linear "
        "images (no clipping, noise or response: what extraction and blending alone cost). "
        "*log RMS*: sqrt(mean w log2((g a + eps)/(b + eps))^2) outside the sun's cap over the covered texels, eps "
        "= 1%% of the truth's median level, g fitted in the log domain, in stops (the shape error where the relative RMS is dominated by a few "
        "bright lamps). Pictures: WORK/DATASET/VIEWS-LENS-maskNN/compare/."
        % (args.size, args.width, args.coarse_width),
        "",
        "| dataset | views | lens | --camera-mask-deg | covered | rel. RMS (all) | rel. RMS (no sun) | (coarse) | rel. RMS (cameras) | rel. RMS (no sun, no rig) | sun energy | log RMS no sun (stops) | log RMS no sun, no rig (stops) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in table:
        lines.append("| %s | %s | %s | %d | %.4f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %s | %.3f |" % (
            r["dataset"], r["source"], r["lens"], r["mask"], r["covered_fraction"], r["all"], r["no_sun"], r["no_sun_coarse"],
            r["cameras"], r["no_rig"], r["sun_energy"],
            "%.3f" % r["log_rms"], r["log_rms_no_rig_stops"]))
    lines += ["", *["- " + n for n in notes]]
    # The mask sweep's verdict, per dataset: the mask with the lowest error outside the sun, and the
    # one with the lowest error at the camera directions (merged views, true lens).
    for name in args.datasets:
        sweep = [r for r in table if r["dataset"] == name and r["source"] == "merged" and r["lens"] == "true"]
        best = min(sweep, key=lambda r: (round(r["no_sun"], 3), abs(r["mask"] - DEFAULT_MASK)))
        best_cam = min(sweep, key=lambda r: (round(r["cameras"], 3), abs(r["mask"] - DEFAULT_MASK)))
        lines.append("- %s: lowest error outside the sun at --camera-mask-deg %d, at the camera directions at %d "
                     "(default %d)" % (name, best["mask"], best_cam["mask"], DEFAULT_MASK))
    body = "\n".join(lines)
    print(body)
    if not args.no_docs:
        replace_section(os.path.join(ROOT, "docs", "tradeoffs.md"), "Light probe accuracy (rsibr probe)", body)


if __name__ == "__main__":
    main()
