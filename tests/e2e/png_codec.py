"""PNG decoding and encoding for the end-to-end tests (re-exported by serve_harness.py): the
decoder checks the signature, chunk CRCs and IHDR, inflates IDAT and undoes the row filters; the
encoder writes an unfiltered PNG of given rows."""

import struct
import zlib

# ------------------------------------------------------------------------------------------
# PNG decoding (signature, chunk CRCs, IHDR, inflate IDAT, undo filters)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def decode_png_full(data):
    """Returns a dict: width, height, channels, depth (8 or 16), rows (bytes, samples
    big-endian for 16 bits), text (tEXt key -> value), gamma (gAMA's integer or None); or
    raises ValueError with the reason."""
    if data[:8] != PNG_SIGNATURE:
        raise ValueError(f"bad signature {data[:8]!r}")
    pos = 8
    ihdr = None
    idat = []
    text = {}
    gamma = None
    seen_iend = False
    while pos < len(data):
        if pos + 12 > len(data):
            raise ValueError(f"truncated chunk at offset {pos}")
        length, ctype = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if len(body) != length or pos + 12 + length > len(data):
            raise ValueError(f"chunk {ctype!r} at {pos} runs past the end")
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        if zlib.crc32(ctype + body) & 0xFFFFFFFF != crc:
            raise ValueError(f"bad CRC in chunk {ctype!r} at offset {pos}")
        if ihdr is None and ctype != b"IHDR":
            raise ValueError(f"first chunk is {ctype!r}, not IHDR")
        if ctype == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif ctype == b"IDAT":
            idat.append(body)
        elif ctype == b"tEXt" and b"\0" in body:
            key, value = body.split(b"\0", 1)
            text[key.decode("latin-1")] = value.decode("latin-1")
        elif ctype == b"gAMA" and length == 4:
            (gamma,) = struct.unpack(">I", body)
        elif ctype == b"IEND":
            seen_iend = True
            pos += 12 + length
            break
        pos += 12 + length
    if not seen_iend:
        raise ValueError("no IEND chunk")
    if pos != len(data):
        raise ValueError(f"{len(data) - pos} bytes after IEND")
    width, height, depth, color, comp, filt, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(color)
    if depth not in (8, 16) or channels is None or comp != 0 or filt != 0 or interlace != 0:
        raise ValueError(f"unsupported IHDR depth={depth} color={color} comp={comp} "
                         f"filter={filt} interlace={interlace}")
    if not idat:
        raise ValueError("no IDAT chunk")
    raw = zlib.decompress(b"".join(idat))
    bpp = channels * depth // 8
    stride = width * bpp
    if len(raw) != height * (stride + 1):
        raise ValueError(f"inflated {len(raw)} bytes, expected {height * (stride + 1)}")
    rows = []
    prev = bytearray(stride)
    for y in range(height):
        ftype = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if ftype == 0:
            pass
        elif ftype == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif ftype == 2:
            for i in range(stride):
                line[i] = (line[i] + prev[i]) & 0xFF
        elif ftype == 3:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xFF
        elif ftype == 4:
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if (pa <= pb and pa <= pc) else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 0xFF
        else:
            raise ValueError(f"row {y}: bad filter type {ftype}")
        rows.append(bytes(line))
        prev = line
    return {"width": width, "height": height, "channels": channels, "depth": depth,
            "rows": rows, "text": text, "gamma": gamma}


def decode_png(data):
    """Returns (width, height, channels, rows) of an 8-bit PNG or raises ValueError."""
    png = decode_png_full(data)
    if png["depth"] != 8:
        raise ValueError(f"{png['depth']}-bit PNG where 8-bit was expected")
    return png["width"], png["height"], png["channels"], png["rows"]


def encode_png(width, height, rows, color_type=6, bit_depth=8):
    """A PNG of `rows` (bytes per row, without the filter byte)."""
    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0)
    return (PNG_SIGNATURE + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw))
            + chunk(b"IEND", b""))
