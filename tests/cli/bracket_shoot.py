#!/usr/bin/env python3
"""A bracketed 8-bit photo set for the command-line contract: one view "north" of a radiance ramp
with a clipped sun, 5 exposures through a gamma-2.2 camera with 1% noise, written by a
standard-library PNG writer. Usage: bracket_shoot.py FOLDER (FOLDER/north/ is created)."""
import os, random, struct, sys, zlib
root = sys.argv[1]
os.makedirs(os.path.join(root, "north"), exist_ok=True)
def png(path, w, h, pixel):
    raw = b"".join(b"\x00" + bytes(v for x in range(w) for v in pixel(x, y)) for y in range(h))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
rng = random.Random(1)
W, H = 96, 64
radiance = [[(10 ** (-3 + 4 * (x + 0.5) / W)) * (1e4 if (x - 80) ** 2 + (y - 12) ** 2 < 16 else 1) for x in range(W)] for y in range(H)]
times = [1 / 256, 1 / 64, 1 / 16, 1 / 4, 1.0]
lines = ["rsibr_photoset: 1", "views:", "  - name: north", "    brackets:"]
for j, t in enumerate(times):
    def pixel(x, y, t=t):
        out = []
        for c, tint in enumerate((0.9, 1.0, 1.1)):
            X = min(1.0, max(0.0, radiance[y][x] * tint * t * (1 + 0.01 * rng.gauss(0, 1))))
            out.append(int(round(255 * X ** (1 / 2.2))))
        return out
    png(os.path.join(root, "north", "%d.png" % j), W, H, pixel)
    lines.append("      - {file: north/%d.png, exposure_s: %r}" % (j, t))
open(os.path.join(root, "photoset.yaml"), "w").write("\n".join(lines) + "\n")
