#!/usr/bin/env python3
"""Tiles 8-bit PNGs (RGB or RGBA, all the same size) into one RGB sheet, row by row.

Usage: scripts/contact-sheet.py COLUMNS OUT.png IN.png... (the standard library only: the
README's time-lapse is assembled with it by scripts/review-sheet.sh)."""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, 'rb').read()
    pos, idat = 8, b''
    while pos < len(data):
        length, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b'IHDR':
            width, height, depth, colour = struct.unpack('>IIBB', body[:10])
            if depth != 8 or colour not in (2, 6):
                sys.exit(f'{path}: only 8-bit RGB or RGBA')
        elif kind == b'IDAT':
            idat += body
    bpp = 4 if colour == 6 else 3
    raw, stride = zlib.decompress(idat), width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    rgb = [bytes(r) if bpp == 3 else bytes(v for i, v in enumerate(r) if i % 4 != 3) for r in rows]
    return width, height, rgb


def write_png(path, width, height, rows):
    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack(
            '>I', zlib.crc32(kind + body) & 0xffffffff)
    raw = b''.join(b'\x00' + r for r in rows)
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n')
        f.write(chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b'IDAT', zlib.compress(raw, 9)))
        f.write(chunk(b'IEND', b''))


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    columns, out, images = int(sys.argv[1]), sys.argv[2], [read_png(p) for p in sys.argv[3:]]
    width, height = images[0][0], images[0][1]
    if any(w != width or h != height for w, h, _ in images):
        sys.exit('contact-sheet: the images differ in size')
    rows_of_tiles = (len(images) + columns - 1) // columns
    blank = bytes(width * 3)
    sheet = []
    for r in range(rows_of_tiles):
        tiles = images[r * columns:(r + 1) * columns]
        for y in range(height):
            sheet.append(b''.join(t[2][y] for t in tiles) + blank * (columns - len(tiles)))
    write_png(out, width * columns, height * rows_of_tiles, sheet)


if __name__ == '__main__':
    main()
