#!/usr/bin/env python3
"""Orientation accuracy of `rsibr orient`'s pipeline (calib/orientation/view_orientation.h) against the ball's
radius in pixels and the image noise, with and without the joint ball refinement and the tracks'
re-location by patch alignment.

Runs build/release/rsibr_orientation_accuracy (bench/orientation_accuracy.cpp: four rendered views 20
degrees apart of a chrome ball in the CC0 `lobby` environment, the ball found and the views oriented
from the images alone) over a grid and seeds; then two views 20, 60 and 90 degrees apart in three
environments with the features found on the cube faces (the default) or in the image itself; and
writes the section "Orientation (rsibr orient)" of docs/tradeoffs.md.

  python3 bench/orientation_accuracy.py [--build build/release] [--seeds 2] [--wide-only]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from convert_roundtrip import replace_section  # noqa: E402


def run(exe, argv):
    out = subprocess.run([exe] + argv, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit("orientation_accuracy: run failed: %s" % out.stderr[-500:])
    return json.loads(out.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build/release"))
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/tradeoffs.md"))
    ap.add_argument("--wide-only", action="store_true", help="only the wide-baseline table (print, do not write)")
    args = ap.parse_args()
    exe = os.path.join(args.build, "rsibr_orientation_accuracy")
    if not os.path.exists(exe):
        sys.exit("orientation_accuracy: %s not built (cmake --build %s --target rsibr_orientation_accuracy)" % (exe, args.build))
    wide = []
    for env in ("lobby", "park", "sky"):
        for spacing in (20, 60, 90):
            for domain in ("cube", "image"):
                errs, chi2, tracks, failed = [], [], [], 0
                for seed in range(args.seeds):
                    out = subprocess.run([exe, "--views", "2", "--spacing", str(spacing), "--domain", domain,
                                          "--env", os.path.join(ROOT, "cache/assets/hdri/%s.exr" % env),
                                          "--seed", str(5 + 10 * seed)], capture_output=True, text=True)
                    if out.returncode != 0:
                        sys.exit("orientation_accuracy: run failed: %s" % out.stderr[-500:])
                    j = json.loads(out.stdout)
                    if "failed" in j:
                        failed += 1
                        continue
                    errs += j["error_deg"]
                    chi2 += [(e / s) ** 2 for e, s in zip(j["error_deg"], j["sigma_deg"])]
                    tracks.append(j["tracks"])
                ok = args.seeds - failed
                wide.append("| %s | %d | %s | %d/%d | %s | %s | %s | %s |" % (
                    env, spacing, domain, ok, args.seeds, "%.0f" % statistics.mean(tracks) if tracks else "-",
                    "%.3f" % statistics.median(errs) if errs else "-", "%.3f" % max(errs) if errs else "-",
                    "%.1f" % statistics.mean(chi2) if chi2 else "-"))
                print(wide[-1], flush=True)
    if args.wide_only:
        return
    rows = []
    modes = (("fixed", ["--refine", "0", "--refine-tracks", "0"]),
             ("centres", ["--refine", "1", "--radius-prior-px", "0", "--refine-tracks", "0"]),
             ("centres + radii", ["--refine", "1", "--refine-tracks", "0"]),
             ("centres + radii, tracks re-located", ["--refine", "1"]))
    for radius in (120, 200):
        for noise in (0.003, 0.01, 0.03):
            for mode, flags in modes:
                errs, chi2, cerr, rerr, tracks, secs = [], [], [], [], [], []
                for seed in range(args.seeds):
                    j = run(exe, ["--radius-px", str(radius), "--noise", str(noise), "--seed", str(5 + 10 * seed)] + flags)
                    errs += j["error_deg"]
                    chi2 += [(e / s) ** 2 for e, s in zip(j["error_deg"], j["sigma_deg"])]
                    cerr += j["centre_error_px"]
                    rerr += [abs(x) for x in j["radius_error_px"]]
                    tracks.append(j["tracks"])
                    secs.append(j["seconds"])
                rows.append("| %d | %.3f | %s | %.0f | %.2f | %.2f | %.3f | %.3f | %.1f | %.1f |" % (
                    radius, noise, mode, statistics.mean(tracks), statistics.median(cerr), statistics.median(rerr),
                    statistics.median(errs), max(errs), statistics.mean(chi2), statistics.mean(secs)))
                print(rows[-1], flush=True)
    ring = []
    for radius in (120, 200, 400):
        for views, spacing in ((8, 45), (12, 30)):
            for relocate in ("0", "1"):
                j = run(exe, ["--radius-px", str(radius), "--views", str(views), "--spacing", str(spacing),
                              "--refine-tracks", relocate])
                errs = j["error_deg"]
                chi2 = statistics.mean([(e / s) ** 2 for e, s in zip(errs, j["sigma_deg"])])
                ring.append("| %d | %d x %d | %s | %d | %.3f | %.3f | %.3f | %.4f | %.4f | %.1f | %.0f |" % (
                    radius, views, spacing, "yes" if relocate == "1" else "no", j["tracks"],
                    statistics.median(j["centre_error_px"]), max(j["centre_error_px"]),
                    statistics.median([abs(x) for x in j["radius_error_px"]]), statistics.median(errs), max(errs),
                    chi2, j["seconds"]))
                print(ring[-1], flush=True)
    load = os.getloadavg()[0]
    body = (
        "Four views 20 degrees apart of a chrome ball (no stand) in the CC0 `lobby` environment, rendered by capture/\n"
        "(features on the cube faces, calib/orientation/ball_cube_features.h),\n"
        "with Gaussian noise of relative std dev `noise` (plus a 0.02 floor), the ball found and every view oriented\n"
        "from the images alone (calib/orientation/view_orientation.h; gauge: the first view's true up). Ball `fixed` at its\n"
        "outline fit, its `centres` refined jointly with the orientations (a prior of max(outline RMS, 0.25 px)),\n"
        "or `centres + radii` (the half angle too, a prior of 2 px of image radius); these three with SIFT's\n"
        "keypoints as they are. `tracks re-located` (the default) then aligns every observation of a track with its\n"
        "sharpest one by a patch on the cube faces and solves again (calib/orientation/track_refinement.h).\n"
        "Errors over %d seeds x 3 oriented views; chi2 = mean (error / reported sigma)^2 (1 when the sigmas are\n"
        "honest). Regenerate: `python3 bench/orientation_accuracy.py` (load average %.1f when this was written).\n\n"
        "| ball radius px | noise | ball refined | tracks | median centre error px | median radius error px | median error deg | max error deg | chi2 | seconds |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n" % (args.seeds, load)
        + "\n".join(rows) + "\n\n"
        "A mirror ball's limb reflects what lies just behind the ball, so its outline has little contrast on a\n"
        "textured background and the steepest edge lies inside the limb: the outline's centre is off by up to a few\n"
        "pixels and its radius is too small by 0.3-2 px. A pixel moves the reflected directions by ~2 / radius_px\n"
        "radians (~1 degree at 120 px). A centre error looks like a rotation near the ball's centre and is told\n"
        "apart only by the rim's features; a radius error scales the rim's directions radially, which no rotation\n"
        "absorbs, so refining the half angle as well as the centre is what brings the radius errors to tenths of a\n"
        "pixel and lowers the orientation errors. Four views on a 60-degree arc leave a common scale of all radii\n"
        "weakly determined; views all around the ball fix it:\n\n"
        "| ball radius px | views x spacing deg | tracks re-located | tracks | median centre error px | max centre error px | median radius error px | median error deg | max error deg | chi2 | seconds |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n"
        + "\n".join(ring) + "\n\n"
        "(one seed each, noise 0.01, centres and radii refined.) With SIFT's keypoints as they are, 400 px and 12\n"
        "views reach about the 0.05-degree target (0.048-0.058 over three seeds): the keypoints' own noise, ~0.25 px.\n"
        "Re-located by patch alignment, the tracks agree to a few hundredths of a pixel and the median error falls\n"
        "4-9x, the centres and radii to hundredths of a pixel, at honest sigmas; the alignment models a brightness\n"
        "gain, bias and ramp across the patch (the mirror's Fresnel grows toward the rim: without the ramp a shift\n"
        "took it up, and the 12 views drifted around the ring, chi2 6.8) and maps the patch exactly on a 3 x 3 grid,\n"
        "biquadratic between (an affine map biased a 120-px ball's 14-degree patches: 0.2-0.3 degrees on four views).\n"
        "tests/calib/view_orientation_test.cpp checks the 400-px ring against the truth, tests/calib/track_refinement_test.cpp the re-located tracks.\n\n"
        "Wide baselines: two views `spacing` degrees apart (120-px ball, noise 0.01, refined centres and radii, %d\n"
        "seeds), features detected on gnomonic cube faces of the reflected world (`cube`, calib/orientation/ball_cube_features.h,\n"
        "the default) or by SIFT on the ball's image itself (`image`, the earlier front end). A world feature near the\n"
        "ball's centre in one view lies near the rim, compressed up to ~10x radially, in the other; on the cube\n"
        "faces it looks the same in both. `oriented` counts the runs that solved (the others: too few shared\n"
        "features).\n\n"
        "| environment | spacing deg | features | oriented | tracks | median error deg | max error deg | chi2 |\n"
        "|---|---|---|---|---|---|---|---|\n" % args.seeds
        + "\n".join(wide) + "\n\n"
        "The cube faces find more shared tracks in every case (7-14x at 60-90 degrees in `park`, 1.2-5x elsewhere)\n"
        "and, with the tracks re-located, have the lower error in every case. With two views the error is mostly\n"
        "the ball's (one view's centre and radius are barely fixed by the features of one other view: `lobby` at 60\n"
        "degrees shares 22 tracks). The direct front end stays as an option (ViewOrientationOptions::domain).\n")
    replace_section(args.out, "Orientation (rsibr orient)", body)


if __name__ == "__main__":
    main()
