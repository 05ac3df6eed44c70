#!/usr/bin/env python3
"""A process run's report orbits in a browser and matches its own turntable frames.

Usage: report_viewer_check.py RUN CHROMIUM [MAX_FRACTION]

Opens RUN/report.html in headless Chromium (WebGL2 on SwiftShader), finds the turntable's viewer
(the render step's page in the report's frame), sets up to four of the turntable's cameras through
the page's hook (window.rsibrViewer: the render step's first camera turned about world up through
the pivot, as core/camera.h orbit() does) and reads the canvas as shown. Each frame is compared
with the render step's PNG frame over the pixels the page covers (the frames show the probe behind
the object, the page does not): passes (exit 0) when at most MAX_FRACTION (default 0.03) of them
differ by more than 2 codes in a channel (silhouette pixels, where the rasteriser and the ray
tracer may cover differently, are most of those). Pure Python, so the CLI test needs no imaging
package. Prints one line per frame.
"""
import base64
import json
import math
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_png import read_png  # noqa: E402
from page_probe import frames_script  # noqa: E402


def orbit(cam, pivot, k, n):
    """core/camera.h orbit() about world +Y: eye and world_from_cam turned by 2 pi k / n."""
    a = 2 * math.pi * k / n
    R = [[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]]
    W = [cam["world_from_cam"][3 * r:3 * r + 3] for r in range(3)]
    d = [cam["eye"][i] - pivot[i] for i in range(3)]
    out = dict(cam)
    out["eye"] = [pivot[i] + sum(R[i][j] * d[j] for j in range(3)) for i in range(3)]
    out["world_from_cam"] = [sum(R[i][k2] * W[k2][j] for k2 in range(3)) for i in range(3) for j in range(3)]
    return out


def main():
    run, chromium = sys.argv[1], sys.argv[2]
    max_fraction = float(sys.argv[3]) if len(sys.argv) > 3 else 0.03
    report = open(os.path.join(run, "report.html")).read()
    page = open(os.path.join(run, "render", "viewer.html")).read()
    data = json.loads(re.search(r'<script type="application/json" id="rsibr-data">(.*?)</script>', page, re.S).group(1))
    frames = sorted(f for f in os.listdir(os.path.join(run, "render")) if re.fullmatch(r"frame_\d+\.png", f))
    n = len(frames)
    views = list(range(0, n, max(1, n // 4)))[:4]
    cams = [orbit(data["camera"], data["pivot"], k, n) for k in views]
    viewer = "(document.querySelector('iframe[title=\"turntable viewer\"]') || {}).contentWindow?.rsibrViewer"
    probe = "<script>window.addEventListener('load', () => {%s});</script>" % frames_script(viewer, cams, "rsibr-check")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "report.html")
        open(path, "w").write(report.replace("</body>", probe + "</body>"))
        r = subprocess.run([chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                            "--dump-dom", "file://" + path], capture_output=True, text=True, timeout=600)
    found = re.findall(r'<pre id="rsibr-check">(.*?)</pre>', r.stdout, re.S)
    if not found or found[-1].startswith("ERROR"):
        print("the report's turntable viewer did not draw: %s" % (found[-1] if found else "no result"))
        return 1
    w, h = data["camera"]["width"], data["camera"]["height"]
    ok = True
    for k, f in zip(views, json.loads(found[-1])):
        shown, cover = base64.b64decode(f["shown"]), base64.b64decode(f["cover"])
        rw, rh, rows = read_png(os.path.join(run, "render", frames[k]))
        if (rw, rh) != (w, h):
            print("frame %d: %dx%d, the page draws %dx%d" % (k, rw, rh, w, h))
            return 1
        covered = differ = 0
        for y in range(h):
            for x in range(w):
                i = y * w + x
                if not cover[i]:
                    continue
                covered += 1
                differ += max(abs(shown[4 * i + c] - rows[y][4 * x + c]) for c in range(3)) > 2
        frac = differ / max(covered, 1)
        good = covered > 0 and frac <= max_fraction
        ok &= good
        print("frame %d of %d: %d pixels covered, %.2f%% differ by > 2 codes%s" % (k, n, covered, 100 * frac,
                                                                                 "" if good else "  FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
