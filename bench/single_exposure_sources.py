#!/usr/bin/env python3
"""One exposure is a shoot: a chrome and a grey ball, each photographed once, lit by a flash.

The corpus's mit-chrome-grey set (see its README) holds, for five flash directions, a single LDR
JPEG crop of a chrome ball and one of a grey ball from the same camera. Per direction: `rsibr hdr`
(one exposure per view: the stated sRGB response, clipped pixels flagged), `rsibr extract` of each
ball at its annotated circle through a far-camera pinhole (the crops are the ball), and `rsibr
probe` of the chrome map with the grey map, which recovers the light clipped in the chrome ball
from the grey ball's shading. The check: the recovered source of the largest clipped region (the
flash's highlight) against that region's own direction on the chrome ball, in degrees and in the
source's stated sigmas.

Writes the section "One exposure with a grey ball" of docs/tradeoffs.md (--no-write: print only).
Exits 77 when the corpus is absent.

  /usr/bin/python3 bench/single_exposure_sources.py [--rsibr build/release/rsibr] [--photos ../shared/real-photos]
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from convert_roundtrip import replace_section  # noqa: E402

SKIPPED = 77


def angle_deg(a, b):
    na, nb = math.sqrt(sum(x * x for x in a)), math.sqrt(sum(x * x for x in b))
    c = sum(x * y for x, y in zip(a, b)) / (na * nb)
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("%s: %s" % (" ".join(cmd[:2]), r.stderr.strip()))
    return r


def one_direction(rsibr, folder, work, n, circles):
    d = os.path.join(work, "dir_%d" % n)
    os.makedirs(d, exist_ok=True)
    chrome, grey = "dir_%d_chrome256.jpg" % n, "dir_%d_gray256.jpg" % n
    with open(os.path.join(d, "photoset.yaml"), "w") as f:
        yaml.safe_dump({"rsibr_photoset": 1,
                        "balls": [{"name": "chrome", "kind": "chrome"}, {"name": "grey", "kind": "grey"}],
                        "views": [{"name": "chrome", "brackets": [{"file": os.path.join(folder, chrome),
                                                                   "exposure_s": 1}]},
                                  {"name": "grey", "brackets": [{"file": os.path.join(folder, grey),
                                                                 "exposure_s": 1}]}]}, f)
    run([rsibr, "hdr", os.path.join(d, "photoset.yaml"), "--out", os.path.join(d, "hdr"), "-q"])
    # The crops are the ball: a far camera (focal length 100 x the side), principal point at the centre.
    with open(os.path.join(d, "far.cameramodel"), "w") as f:
        f.write("{'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [25600, 25600, 127.5, 127.5], "
                "'extrinsics': [0, 0, 0, 0, 0, 0], 'imagersize': [256, 256]}\n")
    for kind, photo, size in (("chrome", chrome, 256), ("grey", grey, 128)):
        c = circles[photo]
        run([rsibr, "extract", os.path.join(d, "hdr", kind + ".exr"), "--lens", os.path.join(d, "far.cameramodel"),
             "--kind", kind, "--ball", "%.2f,%.2f,%.2f" % (c["cx"], c["cy"], c["r"]), "--size", str(size),
             "--out", os.path.join(d, kind + "-map.exr"), "-q"])
    run([rsibr, "probe", os.path.join(d, "chrome-map.exr"), "--grey", os.path.join(d, "grey-map.exr"),
         "--out", os.path.join(d, "probe.exr"), "--json", os.path.join(d, "probe.json"), "-q"])
    j = json.load(open(os.path.join(d, "probe.json")))
    ls = j["light_sources"]
    row = {"n": n, "regions": len(ls["regions"]), "covered": j["covered_fraction"], "filled": j.get("filled_fraction")}
    if not ls["regions"]:
        return row
    region = ls["regions"][0]  # the largest lower bound: the flash
    row["region_sr"] = region["solid_angle_sr"]
    src = [s for s in ls["sources"] if (s.get("region") or {}).get("index") == region["index"]]
    if src:
        s = src[0]
        row["angle"] = angle_deg(s["direction"], region["direction"])
        row["sigma"] = s.get("direction_sigma_deg")
        row["share"] = max(ls["missing_fraction"])
    else:
        row["note"] = region.get("note", "not recovered")
    return row


def table(rows):
    lines = ["| flash direction | clipped regions | flash region (sr) | recovered source vs its region | "
             "source's sigma | recovered share of the light | probe seen / filled |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        if "angle" in r:
            rec = "%.1f deg (%.1f sigma)" % (r["angle"], r["angle"] / r["sigma"] if r.get("sigma") else float("nan"))
            sig, share = "%.1f deg" % r["sigma"], "%.0f%%" % (100 * r["share"])
        else:
            rec, sig, share = r.get("note", "-"), "-", "-"
        lines.append("| %d | %d | %s | %s | %s | %s | %.0f%% / %.0f%% |" % (
            r["n"], r["regions"], "%.3f" % r["region_sr"] if "region_sr" in r else "-", rec, sig, share,
            100 * r["covered"], 100 * (r["filled"] or 0)))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rsibr", default=os.path.join(ROOT, "build/release/rsibr"))
    ap.add_argument("--photos", default=os.path.join(os.path.dirname(ROOT), "shared", "real-photos"))
    ap.add_argument("--no-write", action="store_true")
    a = ap.parse_args()
    folder = os.path.join(a.photos, "mit-chrome-grey")
    if not os.path.isdir(folder):
        print("single_exposure_sources: %s: no such folder; skipped" % folder)
        return SKIPPED
    ann = yaml.safe_load(open(os.path.join(folder, "annotations.yaml")))
    circles = {}
    for p in ann.get("photos", []):
        c = p.get("chrome_ball") or p.get("grey_ball")
        if c:
            circles[p["file"]] = c
    work = tempfile.mkdtemp(prefix="rsibr-mit-")
    rows = []
    try:
        for n in (0, 3, 7, 12, 22):
            rows.append(one_direction(a.rsibr, folder, work, n, circles))
            print(rows[-1], flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    text = table(rows)
    print(text)
    if not a.no_write:
        body = ("A single LDR photo per ball (no brackets): the corpus's mit-chrome-grey crops of a chrome and a "
                "grey ball lit by a flash from five directions (`rsibr hdr` with the stated sRGB response, "
                "`rsibr extract` at the annotated circles through a far-camera pinhole, `rsibr probe --grey`). "
                "The flash and the windows are clipped in the chrome ball; the grey ball's shading recovers them. "
                "The recovered source of the largest clipped region (the flash) against that region's own "
                "direction on the chrome ball (its centroid: a large clipped region's centroid need not be where "
                "its light is), and the source's stated sigma.\n\n"
                "Regenerate: `/usr/bin/python3 bench/single_exposure_sources.py` (needs ../shared/real-photos).\n\n"
                + text)
        replace_section(os.path.join(ROOT, "docs", "tradeoffs.md"), "One exposure with a grey ball", body)
    return 0


if __name__ == "__main__":
    sys.exit(main())
