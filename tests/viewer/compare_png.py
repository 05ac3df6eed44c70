#!/usr/bin/env python3
"""Compares two 8-bit RGBA PNGs (rsibr view --screenshot against rsibr render) pixel by pixel.

Usage: compare_png.py A.png B.png MAX_DIFF MAX_FRACTION
Passes (exit 0) when the images have the same size, and the pixels whose alpha differs or whose
colour differs by more than MAX_DIFF (0..255, any channel) are at most MAX_FRACTION of all pixels.
Pure Python (zlib), so the CLI test needs no imaging package.
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                sys.exit(f"{path}: expected 8-bit RGB or RGBA, non-interlaced")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    bpp = 4 if colour == 6 else 3
    raw, stride = zlib.decompress(idat), width * bpp
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(height):
        f, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b, c = prev[x], prev[x - bpp] if x >= bpp else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        # RGB rows are returned as RGBA, alpha 255.
        rows.append(line if bpp == 4 else bytearray(b for x in range(width) for b in (*line[3 * x:3 * x + 3], 255)))
    return width, height, rows


def main():
    a, b, max_diff, max_fraction = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    wa, ha, ra = read_png(a)
    wb, hb, rb = read_png(b)
    if (wa, ha) != (wb, hb):
        sys.exit(f"sizes differ: {wa}x{ha} against {wb}x{hb}")
    bad = covered = 0
    worst = 0
    for la, lb in zip(ra, rb):
        for x in range(0, len(la), 4):
            covered += la[x + 3] > 0
            if la[x + 3] != lb[x + 3]:
                bad += 1
                continue
            d = max(abs(la[x + k] - lb[x + k]) for k in range(3))
            worst = max(worst, d)
            bad += d > max_diff
    fraction = bad / (wa * ha)
    print(f"{a} vs {b}: {covered} covered pixels, {bad} differ (> {max_diff} or alpha), "
          f"{100 * fraction:.3f}%, max colour difference {worst}")
    if covered == 0:
        sys.exit("nothing covered")
    sys.exit(0 if fraction <= max_fraction else 1)


if __name__ == "__main__":
    main()
