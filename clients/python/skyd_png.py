"""A small pure-Python PNG reader for skyd's frames (standard library only).

skyd sends 8-bit sRGB RGBA frames (format "png") and 16-bit linear RGB ones ("png16", with the
luminance scale in a tEXt chunk). decode_png() checks the signature and chunk CRCs, inflates
the IDAT data with zlib and undoes the row filters; it reads grey, grey+alpha, RGB and RGBA at
8 or 16 bits, not palette or interlaced images (skyd writes neither). It is written for
clarity, not speed: a 640x360 frame takes a fraction of a second.
"""

import struct
import zlib
from collections import namedtuple

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# rows: one bytes object per row, filter byte removed; 16-bit samples are big-endian.
# text: the tEXt chunks, keyword -> value.
PngImage = namedtuple("PngImage", "width height channels depth rows text")

_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}  # PNG colour type -> samples per pixel


def _chunks(data):
    if data[:8] != PNG_SIGNATURE:
        raise ValueError("not a PNG file (bad signature)")
    pos = 8
    while pos + 12 <= len(data):
        length, kind = struct.unpack_from(">I4s", data, pos)
        end = pos + 12 + length
        if end > len(data):
            raise ValueError(f"chunk {kind!r} at offset {pos} runs past the end")
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack_from(">I", data, pos + 8 + length)
        if zlib.crc32(kind + body) & 0xFFFFFFFF != crc:
            raise ValueError(f"bad CRC in chunk {kind!r} at offset {pos}")
        yield kind, body
        if kind == b"IEND":
            return
        pos = end
    raise ValueError("no IEND chunk")


def _unfilter(raw, height, stride, bpp):
    rows = []
    prev = bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind = raw[start]
        line = bytearray(raw[start + 1:start + 1 + stride])
        if kind == 1:  # Sub
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif kind == 2:  # Up
            for i in range(stride):
                line[i] = (line[i] + prev[i]) & 0xFF
        elif kind == 3:  # Average
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xFF
        elif kind == 4:  # Paeth
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) \
                    & 0xFF
        elif kind != 0:
            raise ValueError(f"row {y}: unknown filter type {kind}")
        rows.append(bytes(line))
        prev = line
    return rows


def decode_png(data):
    """A PngImage from PNG bytes; ValueError (or zlib.error) says what is wrong."""
    ihdr = None
    idat = []
    text = {}
    for kind, body in _chunks(bytes(data)):
        if ihdr is None and kind != b"IHDR":
            raise ValueError(f"first chunk is {kind!r}, not IHDR")
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"tEXt" and b"\0" in body:
            key, value = body.split(b"\0", 1)
            text[key.decode("latin-1")] = value.decode("latin-1")
    width, height, depth, colour, compression, filtering, interlace = ihdr
    channels = _CHANNELS.get(colour)
    if channels is None or depth not in (8, 16) or compression or filtering or interlace:
        raise ValueError(f"unsupported PNG: colour type {colour}, depth {depth}, "
                         f"interlace {interlace}")
    if not idat:
        raise ValueError("no IDAT chunk")
    raw = zlib.decompress(b"".join(idat))
    bpp = channels * depth // 8
    stride = width * bpp
    if len(raw) != height * (stride + 1):
        raise ValueError(f"image data is {len(raw)} bytes, expected {height * (stride + 1)}")
    return PngImage(width, height, channels, depth, _unfilter(raw, height, stride, bpp), text)


def samples(image, y):
    """Row y of a PngImage as a list of integer samples (16-bit ones combined)."""
    row = image.rows[y]
    if image.depth == 8:
        return list(row)
    return list(struct.unpack(f">{len(row) // 2}H", row))
