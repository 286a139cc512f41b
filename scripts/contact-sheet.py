#!/usr/bin/python3
"""Tiles 8-bit PNGs (RGB or RGBA, all the same size) into one RGB sheet, row by row.

Usage: scripts/contact-sheet.py COLUMNS OUT.png IN.png... (the README's time-lapse is assembled
with it by scripts/review-sheet.sh). PNGs are read and written by the tests' decoder and
encoder (tests/e2e/serve_harness.py)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests",
                                "e2e"))
from serve_harness import decode_png, encode_png  # noqa: E402


def rgb_rows(path):
    with open(path, "rb") as f:
        width, height, channels, rows = decode_png(f.read())
    if channels not in (3, 4):
        sys.exit(f"{path}: only RGB or RGBA")
    if channels == 4:
        rows = [bytes(v for i, v in enumerate(r) if i % 4 != 3) for r in rows]
    return width, height, rows


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    columns, out = int(sys.argv[1]), sys.argv[2]
    images = [rgb_rows(p) for p in sys.argv[3:]]
    width, height = images[0][0], images[0][1]
    if any(w != width or h != height for w, h, _ in images):
        sys.exit("contact-sheet: the images differ in size")
    blank = bytes(width * 3)
    sheet = []
    for first in range(0, len(images), columns):
        tiles = images[first:first + columns]
        for y in range(height):
            sheet.append(b"".join(t[2][y] for t in tiles) + blank * (columns - len(tiles)))
    with open(out, "wb") as f:
        f.write(encode_png(width * columns, len(sheet), sheet, color_type=2))


if __name__ == "__main__":
    main()
