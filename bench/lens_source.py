#!/usr/bin/env python3
"""What the lens's source costs: rsibr process on the same synthetic shoot with the lens from the
truth (--lens), from the chessboards (mrcal, model by cross-validation) and from the photos' EXIF
(a pinhole from the 35 mm-equivalent focal length: no chessboards in the photo set) or lensfun's
profile of the lens the EXIF names.

Two lenses on the minimal-grey rig (320x240, 3 views, a chrome and a grey ball, 6 chessboards
where used): its pinhole (f = 700 px) and a wide lens with distortion (OPENCV8, f = 350 px, the
balls nearer, so they sit where the distortion is); and a kit zoom lensfun knows (the Canon
EF-S 18-55mm f/3.5-5.6 IS at 18 mm on an EOS 600D, 360x240, rendered through lensfun's profile;
the exif row names no lens, so it gets the pinhole). Orientations are the truth's in every row
(--poses), so the rows differ by the lens alone. Reported: the focal length against the truth,
the captured grey against the computed one (relative RMS after the gain fit), and the calibrate
step's time. Writes the section "Lens source (rsibr
process)" of docs/tradeoffs.md.

  /usr/bin/python3 bench/lens_source.py [--rsibr build/release/rsibr]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from convert_roundtrip import replace_section  # noqa: E402

FRESNEL = "{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}"
KIT = ("  make: Canon\n  name: Canon EOS 600D\n  lens_name: Canon EF-S 18-55mm f/3.5-5.6 IS\n"
       "  lens: {model: lensfun, focal_mm: 18, lens: Canon EF-S 18-55mm f/3.5-5.6 IS}\n")
WIDE = ("  lens: {model: LENSMODEL_OPENCV8, focal_px: 350, "
        "distortion: [-0.12, 0.03, 0.0004, -0.0003, 0.0, 0.01, 0.0, 0.005]}\n")


def run(cmd, allow_failure=False):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        if allow_failure:
            return r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "failed"
        sys.exit("lens_source: %s failed:\n%s" % (" ".join(cmd[:3]), r.stderr[-2000:]))
    return None


def spec(lens, boards, lens_name=True):
    text = open(os.path.join(ROOT, "datasets-synthetic/minimal-grey.yaml")).read()
    if lens in ("kit", "kit-4%"):
        kit = KIT if lens_name else KIT.replace("  lens_name: Canon EF-S 18-55mm f/3.5-5.6 IS\n", "")
        if lens == "kit-4%":
            kit += "  exif_focal_scale: 0.96\n"
        text = re.sub(r"  lens: \{model: LENSMODEL_PINHOLE, focal_px: 700\}\n", kit, text)
        text = text.replace("width: 320", "width: 360").replace("distance_m: 1.0", "distance_m: 0.45")
    if lens == "pinhole, no focal length":
        text = text.replace("  format: png\n", "  format: png\n  exif_focal_scale: 0\n")
    if lens == "wide":
        text = re.sub(r"  lens: \{model: LENSMODEL_PINHOLE, focal_px: 700\}\n", WIDE, text)
        text = text.replace("distance_m: 1.0", "distance_m: 0.55")
    if not boards:
        text = "\n".join(l for l in text.splitlines() if not l.startswith("chessboards:")) + "\n"
    return text


def LensModelFocal(path):
    """fx of a .cameramodel (a Python literal: the intrinsics' first number)."""
    text = open(path).read()
    return float(re.search(r"'intrinsics':\s*\[\s*([-+0-9.eE]+)", text).group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rsibr", default=os.path.join(ROOT, "build/release/rsibr"))
    a = ap.parse_args()
    rows = []
    # (lens, source, self-calibration): exif and lensfun with and without the lens step's refinement.
    cases = []
    for lens in ["pinhole", "wide", "kit", "kit-4%"]:
        if lens != "kit-4%":
            cases += [(lens, "truth", False), (lens, "chessboards", False)]
        cases += [(lens, "exif", False), (lens, "exif", True)]
        if lens.startswith("kit"):
            cases += [(lens, "lensfun", False), (lens, "lensfun", True)]
    cases += [("pinhole, no focal length", "exif", True)]
    with tempfile.TemporaryDirectory() as work:
        for lens, source, outlines in cases:
            d = os.path.join(work, "%s-%s-%d" % (lens.replace(", ", "-").replace(" ", "-"), source, outlines))
            os.makedirs(d)
            with open(os.path.join(d, "scene.yaml"), "w") as f:
                f.write(spec(lens, source in ("truth", "chessboards"), source != "exif"))
            run([a.rsibr, "synth", os.path.join(d, "scene.yaml"), "--out", os.path.join(d, "syn"), "-q"])
            syn = os.path.join(d, "syn")
            cmd = [a.rsibr, "process", os.path.join(syn, "photos"), "--out", os.path.join(d, "run"),
                   "--poses", os.path.join(syn, "truth", "truth.yaml"), "--chrome-fresnel", FRESNEL,
                   "--map-size", "32", "--turntable", "1", "--size", "64x48", "--json", os.path.join(d, "run.json"), "-q"]
            if source == "truth":
                cmd += ["--lens", os.path.join(syn, "truth", "camera.cameramodel")]
            if not outlines:
                cmd += ["--no-self-calibration"]
            failure = run(cmd, allow_failure=True)
            true_f = LensModelFocal(os.path.join(syn, "truth", "camera.cameramodel"))
            label = source + (" + outlines" if outlines else "")
            if lens == "pinhole, no focal length":
                label = "outlines alone"
            row = {"lens": lens, "source": label, "failure": failure}
            if not failure:
                j = json.load(open(os.path.join(d, "run.json")))
                cal, ls = j["results"]["calibrate"], j["results"]["lens"]
                row.update({"model": cal.get("model", ""), "focal_error": ls["focal_px"] / true_f - 1,
                            "sigma": ls["sigma_relative"] if ls.get("refined") else cal.get("focal_sigma_relative"),
                            "grey": j["results"]["compare"]["balls"][0]["overall"]["after"]["relative_rms"],
                            "seconds": sum(s.get("seconds", 0.0) for s in j["steps"] if s["step"] in ("calibrate", "lens"))})
            rows.append(row)
            print(row, flush=True)
    body = ["Where the lens comes from, and what it costs (`bench/lens_source.py`): rsibr process on the",
            "minimal-grey rig (320x240, 3 views, orientations from the truth so rows differ by the lens alone)",
            "with its pinhole lens (f = 700 px), a wide distorting lens (OPENCV8, f = 350 px, the rig at",
            "0.55 m), and a kit zoom lensfun profiles (Canon EF-S 18-55mm f/3.5-5.6 IS at 18 mm on an EOS 600D,",
            "360x240, the rig at 0.45 m, rendered through lensfun's profile and vignetting), once with an EXIF",
            "that states its focal length right and once 4% short (kit-4%: a zoom's nominal focal length,",
            "focus breathing). truth: `--lens` the true model; chessboards: 6 boards, mrcal, model by",
            "cross-validation; exif: no boards, a pinhole from the photos' FocalLengthIn35mmFilm",
            "(calib/lens/photo_optics.h; the kit's EXIF names no lens in these rows, so neither its distortion nor",
            "its vignetting is corrected); lensfun: no boards, lensfun's profile of the lens the EXIF names",
            "(core/lensfun_lens.h: its distortion, and its vignetting in the hdr step; with a right EXIF it",
            "equals the truth by construction, so it measures the chain from the EXIF to the model: the",
            "module's tests check the fit against lensfun's own mapping); + outlines: the lens step's",
            "self-calibration of the focal length from the balls' outlines (calib/lens/outline_focal.h), combined",
            "with the metadata's as a prior (the default); outlines alone: the pinhole rig's EXIF carries no",
            "focal length (stripped by a messaging app), so the outlines measure it from a guess of the image",
            "diagonal, searched over a factor 4 either way. Focal error of the lens the later steps use, against",
            "the truth (its stated 1-sigma in brackets), captured grey against computed after the gain fit",
            "(relative RMS), and the calibrate and lens steps' time.",
            "",
            "| lens | source | model | focal error | captured vs computed grey | calibrate + lens (s) |",
            "|---|---|---|---|---|---|"]
    for r in rows:
        if r["failure"]:
            body.append("| %s | %s | | | process failed: %s | |" % (r["lens"], r["source"], r["failure"].replace("|", "/")))
            continue
        sigma = " (sigma %.1f%%)" % (100 * r["sigma"]) if r["sigma"] else ""
        body.append("| %s | %s | %s | %+.2f%%%s | %.1f%% | %.2f |" % (
            r["lens"], r["source"], r["model"], 100 * r["focal_error"], sigma, 100 * r["grey"], r["seconds"]))
    body += ["",
             "Reading it: the EXIF pinhole's focal length is within its stated sigma, and on an undistorted lens",
             "it costs nothing measurable against the chessboards; on the wide lens it ignores the distortion,",
             "which bends the balls' outlines and their reflections, and the captured-vs-computed row shows what",
             "that costs; chessboards then pay for themselves, and so does lensfun's profile where the database",
             "knows the lens, without a board in the photos. The outlines constrain the focal length where the",
             "balls sit away from the image centre (the kit and wide rigs) and little near it (the pinhole rig at",
             "1 m: the prior dominates); with an EXIF a few percent off they bring it back within their sigma,",
             "where without them the balls' positions disagree across views and the grey ball is lost. Through",
             "a distorting lens with no profile (the exif rows of the wide and kit lenses) barrel distortion",
             "makes the outlines rounder than a pinhole's: on the kit lens they disagree with the EXIF by more",
             "than 4 sigmas and the step keeps the EXIF's (its JSON says why); on the wide lens they pull the",
             "focal length about 6% long (2 sigmas), a pinhole that fits the balls better (the grey comparison",
             "falls from 17% to 5%) without being the true focal length. With no focal length in the EXIF the",
             "outlines alone find it within their sigma; that sigma is mostly the outline detector's systematic",
             "shape error (calib/lens/outline_focal.h), which more balls do not lower."]
    replace_section(os.path.join(ROOT, "docs/tradeoffs.md"), "Lens source (rsibr process)", "\n".join(body))
    print("wrote docs/tradeoffs.md section 'Lens source (rsibr process)'")


if __name__ == "__main__":
    main()
