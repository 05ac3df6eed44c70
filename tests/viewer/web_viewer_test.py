#!/usr/bin/env python3
"""The page viewer (rsibr view --html, runtime/web_viewer_page.h) against rsibr render, frame for frame.

Usage: web_viewer_test.py RSIBR CHROMIUM WORK

A GGX map set is baked from a synthetic sky; `rsibr view --html` writes the page of a ball (a
sphere mesh written here, every normal) lit by it (once per view, for the cameras rsibr itself makes), `rsibr render` the same four views as PNG at
the same exposure. Headless Chromium (WebGL2 on SwiftShader, no GPU) opens one page, sets each
camera through the page's hook (window.rsibrViewer.setCamera), and reads back the canvas as shown
(displayed(): 8-bit) and the drawn radiance's coverage (radiance()); the page's DOM carries them
out. Tolerance, as the desktop viewer's CLI test: the pixels whose coverage or colour differs by
more than 2 codes are at most 0.5% of the frame. The page draws with the desktop viewer's shader
in float32 from half-float maps (2^-11 relative) and shows through a 33^3 table of the display
transform, where the render applies the transform per pixel in double and float.
Also: the page is one file with no network reference, and a page without WebGL2 says so.
"""
import base64
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_png import read_png  # noqa: E402
from page_probe import frames_script  # noqa: E402

rsibr, chromium, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
failures = []


def run(*args):
    r = subprocess.run(list(args), capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s%s" % (" ".join(args), r.stdout, r.stderr))
    return r.stdout


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    if not ok:
        failures.append(name)


def page_data(path):
    html = open(path).read()
    m = re.search(r'<script type="application/json" id="rsibr-data">(.*?)</script>', html, re.S)
    return html, json.loads(m.group(1))


def in_chromium(html, script, name):
    """The page with `script` appended, its DOM after loading: the text of <pre id="rsibr-test">."""
    path = os.path.join(work, name)
    open(path, "w").write(html.replace("</body>", "<script>" + script + "</script></body>"))
    r = subprocess.run([chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader",
                        "--enable-unsafe-swiftshader", "--dump-dom", "file://" + os.path.abspath(path)],
                       capture_output=True, text=True, timeout=300)
    # The last such element: the script's own text holds the tag too.
    found = re.findall(r'<pre id="rsibr-test">(.*?)</pre>', r.stdout, re.S)
    if not found:
        sys.exit("%s: no result in the page's DOM (exit %d)\n%s" % (name, r.returncode, r.stderr[-2000:]))
    return found[-1]


# The ball: a UV sphere with its normals, 48 rings by 96 segments, off the origin.
mesh = os.path.join(work, "ball.obj")
with open(mesh, "w") as f:
    rings, segs = 48, 96
    for i in range(rings + 1):
        for j in range(segs + 1):
            t, p = math.pi * i / rings, 2 * math.pi * j / segs
            n = (math.sin(t) * math.sin(p), math.cos(t), math.sin(t) * math.cos(p))
            f.write("v %.7f %.7f %.7f\nvn %.7f %.7f %.7f\n" % (0.3 + n[0], 0.1 + n[1], -0.2 + n[2], *n))
    at = lambda i, j: i * (segs + 1) + j + 1
    for i in range(rings):
        for j in range(segs):
            for tri in ((at(i, j), at(i + 1, j), at(i, j + 1)), (at(i, j + 1), at(i + 1, j), at(i + 1, j + 1))):
                if len(set(tri)) == 3 and not (i == 0 and tri[0] == at(i, j)) and not (i + 1 == rings and tri[0] != at(i, j)):
                    f.write("f %d//%d %d//%d %d//%d\n" % (tri[0], tri[0], tri[1], tri[1], tri[2], tri[2]))

# A sky (a sun over a gradient) and a glossy map set of 12 views.
sky = os.path.join(work, "sky.exr")
maps = os.path.join(work, "maps.exr")
brdf = os.path.join(work, "ggx.yaml")
open(brdf, "w").write("type: ggx\nroughness: 0.3\nfresnel: {type: schlick, f0: [0.9, 0.6, 0.5]}\n")
run(rsibr, "pattern", "sun-sky", sky, "--size", "128")
run(rsibr, "bake", "--env", sky, "--brdf", brdf, "--views", "icosa", "--res", "32", "--method", "mis",
    "--samples", "64", "--seed", "1", "-q", maps)

size, exposure = "128x96", "0"
views = ["0,0.3,1", "1,0.5,0.2", "-0.6,-0.4,0.7", "0.1,1,0.05"]
cameras = []
for k, d in enumerate(views):
    page = os.path.join(work, "page%d.html" % k)
    run(rsibr, "view", "--html", page, "--maps", maps, "--mesh", mesh, "--size", size, "--from", d,
        "--exposure", exposure)
    html, data = page_data(page)
    cameras.append(data["camera"])
    run(rsibr, "render", "--maps", maps, "--mesh", mesh, "--size", size, "--from", d, "--exposure", exposure, "-q",
        "--out", os.path.join(work, "render%d.png" % k))
    if k == 0:
        first = html
        check("the page is one file: no network reference",
              not re.search(r'(src|href)\s*=\s*"(https?:)?//', html) and "fetch(" not in html)

script = frames_script("window.rsibrViewer", cameras, "rsibr-test")
result = in_chromium(first, script, "probe.html")
if result.startswith("ERROR"):
    sys.exit("the page did not draw: " + result)
frames = json.loads(result)
for k, f in enumerate(frames):
    shown, cover = base64.b64decode(f["shown"]), base64.b64decode(f["cover"])
    w, h, rows = read_png(os.path.join(work, "render%d.png" % k))
    ref = b"".join(bytes(r) for r in rows)
    bad = covered = coverage = 0
    worst = 0
    for i in range(w * h):
        ra = ref[4 * i + 3] > 0
        covered += ra
        if bool(cover[i]) != ra:
            bad += 1
            coverage += 1
        elif ra:
            d = max(abs(shown[4 * i + c] - ref[4 * i + c]) for c in range(3))
            worst = max(worst, d)
            bad += d > 2
    frac = bad / float(w * h)
    print("view %d: %d pixels covered, %.3f%% differ (%d in coverage, %d by > 2 codes), largest difference %d codes"
          % (k, covered, 100 * frac, coverage, bad - coverage, worst))
    open(os.path.join(work, "shown%d.rgba" % k), "wb").write(shown)
    check("view %d matches rsibr render" % k, covered > 0.05 * w * h and frac <= 0.005 and bad <= 0.02 * covered,
          "%.3f%% of the pixels differ" % (100 * frac))

# Two sets (--maps2): one camera, the first set left of the wipe, the second right of it; each side
# matches rsibr render of its own set.
grey, grey_brdf = os.path.join(work, "grey.exr"), os.path.join(work, "grey.yaml")
open(grey_brdf, "w").write("type: lambert\nalbedo: [0.5, 0.4, 0.3]\n")
run(rsibr, "bake", "--env", sky, "--brdf", grey_brdf, "--views", "icosa", "--res", "32", "--method", "sh", "-q", grey)
wipe_page = os.path.join(work, "wipe.html")
run(rsibr, "view", "--html", wipe_page, "--maps", maps, "--maps2", grey, "--mesh", mesh, "--size", size, "--from", views[0],
    "--exposure", exposure)
run(rsibr, "render", "--maps", grey, "--mesh", mesh, "--size", size, "--from", views[0], "--exposure", exposure, "-q",
    "--out", os.path.join(work, "render-grey.png"))
html, data = page_data(wipe_page)
shown = base64.b64decode(in_chromium(html, """
(function () {
  const v = window.rsibrViewer, u = (v.setWipe(0.5), v.displayed());
  let s = ''; for (let i = 0; i < u.length; ++i) s += String.fromCharCode(u[i]);
  document.body.insertAdjacentHTML('beforeend', '<pre id="rsibr-' + 'test">' + btoa(s) + '</pre>');
})();""", "wipe-probe.html"))
w, h = map(int, size.split("x"))
refs = [read_png(os.path.join(work, n))[2] for n in ("render0.png", "render-grey.png")]
bad = [0, 0]
covered = [0, 0]
for y in range(h):
    for x in range(w):
        side = 0 if x < w // 2 else 1
        ref = refs[side][y]
        if ref[4 * x + 3] == 0:
            continue
        covered[side] += 1
        bad[side] += max(abs(shown[4 * (y * w + x) + c] - ref[4 * x + c]) for c in range(3)) > 2
print("wipe: %d / %d pixels covered left / right, %d / %d differ by > 2 codes" % (covered[0], covered[1], bad[0], bad[1]))
check("a wipe shows each set on its side of one camera",
      min(covered) > 0 and all(b <= 0.02 * c for b, c in zip(bad, covered)), "%s of %s" % (bad, covered))

# The page without a mesh draws the ball (framed by its bounding box: a seventh of this frame).
plain = os.path.join(work, "plain.html")
run(rsibr, "view", "--html", plain, "--maps", maps, "--size", size)
html, _ = page_data(plain)
drawn = in_chromium(html, "document.body.insertAdjacentHTML('beforeend', '<pre id=\"rsibr-test\">' + "
                    "window.rsibrViewer.radiance().filter((x, i) => i % 4 == 3 && x > 0).length + '</pre>');",
                    "plain-probe.html")
w, h = map(int, size.split("x"))
check("without --mesh the page draws the ball", drawn.isdigit() and int(drawn) > 0.1 * w * h, drawn)

# Without WebGL2 the page says why instead of drawing.
no_gl = first.replace("canvas.getContext('webgl2'", "(() => null)('webgl2'")
said = in_chromium(no_gl, "document.body.insertAdjacentHTML('beforeend', '<pre id=\"rsibr-test\">' + "
                   "(window.rsibrViewer.error || '') + '|' + document.getElementById('rsibr-fallback').hidden + "
                   "'</pre>');", "nogl.html")
check("without WebGL2 the page shows why", said == "this browser has no WebGL2|false", said)

sys.exit(1 if failures else 0)
