#!/usr/bin/env python3
"""The viewer in a process run's report (report.html: its render step's viewer.html in a frame) in
headless Chromium: the turntable's frames drawn by the page against the render step's own PNG frames
(rsibr render's engine), the page's frame time, and the report's size with and without it. Writes
the "## Page viewer" section of docs/performance.md.

A page frame is setCamera (the mesh pass per pixel, the display pass) and reading the shown canvas
back (which waits for the drawing); the first frame (shader compilation, texture upload) is left out
and the median of the rest reported. Chromium draws WebGL2 with SwiftShader on the CPU here.

Matching: the page draws no background (the render step's frames show the probe behind the object),
so pixels the page covers are compared; a pixel counts as different when a channel differs by more
than 2 codes.

Usage: bench/page_viewer.py RUN [--chromium chromium] [--frames 30] [--no-write]
RUN: an rsibr process output folder with a render step (README's main job: out/default/onset/process).
Needs numpy and OpenCV's Python module (to read the PNG frames).
"""
import argparse
import base64
import json
import math
import os
import re
import subprocess
import tempfile

import cv2
import numpy as np

from doc_section import write_section

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TITLE = "## Page viewer"


def orbit(cam, pivot, k, n):
    """core/camera.h orbit() about world +Y."""
    a = 2 * math.pi * k / n
    R = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    W = np.array(cam["world_from_cam"]).reshape(3, 3)
    eye = np.array(pivot) + R @ (np.array(cam["eye"]) - np.array(pivot))
    out = dict(cam)
    out["eye"] = eye.tolist()
    out["world_from_cam"] = (R @ W).reshape(-1).tolist()
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--chromium", default="chromium")
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    report = open(os.path.join(args.run, "report.html")).read()
    page = open(os.path.join(args.run, "render", "viewer.html")).read()
    data = json.loads(re.search(r'<script type="application/json" id="rsibr-data">(.*?)</script>', page, re.S).group(1))
    summary = json.load(open(os.path.join(args.run, "steps", "render.json")))["summary"]
    n = int(summary["frames"])
    views = [k for k in range(0, n, max(1, n // 4))][:4]
    cams = [orbit(data["camera"], data["pivot"], k, n) for k in views]
    timing = [orbit(data["camera"], data["pivot"], k, args.frames) for k in range(args.frames)]
    probe = """<script>
window.addEventListener('load', () => {
  const frame = document.querySelector('iframe.viewer'), out = document.createElement('pre');
  out.id = 'rsibr-' + 'bench';
  const v = frame && frame.contentWindow.rsibrViewer;
  const b64 = u => { let s = ''; for (let i = 0; i < u.length; ++i) s += String.fromCharCode(u[i]); return btoa(s); };
  if (!v || v.error || !v.ready) { out.textContent = 'ERROR ' + (v ? v.error || 'not drawn' : 'no viewer'); }
  else {
    const res = { frames: [], ms: [], renderer: '' };
    for (const c of %s) {
      v.setCamera(c);
      const r = v.radiance(), cover = new Uint8Array(r.length / 4);
      for (let i = 0; i < cover.length; ++i) cover[i] = r[4 * i + 3] > 0 ? 1 : 0;
      res.frames.push({ shown: b64(v.displayed()), cover: b64(cover) });
    }
    for (const c of %s) { const t = performance.now(); v.setCamera(c); v.displayed(); res.ms.push(performance.now() - t); }
    out.textContent = JSON.stringify(res);
  }
  document.body.appendChild(out);
});
</script>""" % (json.dumps(cams), json.dumps(timing))
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "report.html")
        open(path, "w").write(report.replace("</body>", probe + "</body>"))
        r = subprocess.run([args.chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader",
                            "--enable-unsafe-swiftshader", "--virtual-time-budget=600000", "--dump-dom",
                            "file://" + path], capture_output=True, text=True, timeout=900)
    found = re.findall(r'<pre id="rsibr-bench">(.*?)</pre>', r.stdout, re.S)
    if not found or found[-1].startswith("ERROR"):
        raise SystemExit("the report's viewer did not draw: %s\n%s" % (found[-1] if found else "no result",
                                                                        r.stderr[-1500:]))
    res = json.loads(found[-1])
    w, h = data["camera"]["width"], data["camera"]["height"]
    rows = []
    for k, f in zip(views, res["frames"]):
        shown = np.frombuffer(base64.b64decode(f["shown"]), np.uint8).reshape(h, w, 4)[:, :, :3]
        cover = np.frombuffer(base64.b64decode(f["cover"]), np.uint8).reshape(h, w) > 0
        ref = cv2.imread(os.path.join(args.run, "render", "frame_%02d.png" % k))[:, :, ::-1]
        d = np.abs(shown.astype(int) - ref.astype(int)).max(axis=2)[cover]
        rows.append((k, int(cover.sum()), float((d > 2).mean()) if d.size else 0.0, int(d.max()) if d.size else 0))
    ms = sorted(res["ms"][1:])
    median = ms[len(ms) // 2]
    without = re.sub(r'<p>Drag to orbit.*?</iframe>', '', report, flags=re.S)
    lines = [TITLE, "",
             "Generated by `bench/page_viewer.py RUN`; do not edit. The viewer in a process run's report "
             "(`rsibr process`: the render step's `viewer.html`, embedded in `report.html`; README's main job) "
             "opened in headless Chromium, WebGL2 drawn by SwiftShader on the CPU (no GPU). A frame: the mesh "
             "pass per pixel and the display pass, then the canvas read back; the first frame left out, the "
             "median of %d. Matching: the page's frames against the render step's PNG frames (the runtime's CPU "
             "renderer) at the same cameras, over the pixels the page covers (the frames show the probe "
             "behind the object, the page does not)." % (len(ms)), "",
             "| frame | pixels covered | differ by > 2 codes | largest difference (codes) |", "|---|---|---|---|"]
    for k, covered, frac, worst in rows:
        lines.append("| %d of %d | %d | %.2f%% | %d |" % (k, n, covered, 100 * frac, worst))
    lines += ["", "Canvas %dx%d, %s triangles: median frame %.1f ms (%.0f frames/s). Report %.2f MB, of which "
              "the viewer %.2f MB (the page: %.2f MB; HTML-escaped in the report's frame)."
              % (w, h, summary["triangles"], median, 1000 / median, len(report) / 1e6,
                 (len(report) - len(without)) / 1e6, len(page) / 1e6), ""]
    print("\n".join(lines))
    if not args.no_write:
        write_section(os.path.join(ROOT, "docs", "performance.md"), TITLE, lines)


if __name__ == "__main__":
    main()
