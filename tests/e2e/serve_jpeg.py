"""JPEG frames and bandwidth-bounded subscriptions (PROTOCOL.md, the view object's format,
quality and max_kbps; stats' subscriptions)."""

import asyncio
import struct
import time

from serve_harness import (FIRST_FRAME_TIMEOUT, HEADER, Client, bad_input, check, info,
                           short)

JPEG_FORMAT = 3


def jpeg_size(payload):
    """(width, height) from a baseline or progressive JPEG's SOF marker, or None."""
    i = 2
    while i + 9 < len(payload):
        if payload[i] != 0xFF:
            return None
        marker = payload[i + 1]
        length = struct.unpack_from(">H", payload, i + 2)[0]
        if marker in (0xC0, 0xC1, 0xC2):
            h, w = struct.unpack_from(">HH", payload, i + 5)
            return w, h
        i += 2 + length
    return None


def check_jpeg_frame(name, text_msg, binary, width, height):
    if not check(f"{name}: binary message of at least 48 bytes",
                 isinstance(binary, bytes) and len(binary) >= 48, short(binary)):
        return
    (magic, version, fmt, frame_number, _rev, _t, w, h, payload_length,
     reserved) = HEADER.unpack_from(binary)
    check(f"{name}: header", magic == b"SKYF" and version == 1 and reserved == 0
          and frame_number == text_msg.get("frame_number"), short(text_msg))
    check(f"{name}: format 3 (JPEG)", fmt == JPEG_FORMAT, str(fmt))
    check(f"{name}: header size", (w, h) == (width, height), f"{w}x{h}")
    check(f"{name}: payload_length", payload_length == len(binary) - 48,
          f"{payload_length} vs {len(binary) - 48}")
    payload = binary[48:]
    check(f"{name}: SOI and EOI markers", payload[:2] == b"\xff\xd8" and payload[-2:] == b"\xff\xd9",
          payload[:4].hex() + ".." + payload[-4:].hex())
    check(f"{name}: JPEG's own size", jpeg_size(payload) == (width, height),
          str(jpeg_size(payload)))


async def t_jpeg(d, viewer):
    r = await viewer.request({"type": "subscribe", "id": "jpeg-sub",
                              "view": {"width": 320, "height": 180, "fps": 5,
                                       "format": "jpeg", "quality": 70}})
    if not check("jpeg subscribe: subscribed", r.get("type") == "subscribed", short(r)):
        return
    sub = r["subscription"]
    view = r.get("view", {})
    check("jpeg subscribe: normalized view", view.get("format") == "jpeg"
          and view.get("quality") == 70, short(view))
    m, b = await viewer.wait_frame(lambda m: m.get("subscription") == sub, FIRST_FRAME_TIMEOUT)
    check_jpeg_frame("jpeg subscription frame", m, b, 320, 180)
    await viewer.request({"type": "unsubscribe", "subscription": sub})
    await viewer.pump(0.3)

    r = await viewer.request({"type": "subscribe", "id": "jpeg-default",
                              "view": {"width": 16, "height": 8, "format": "jpeg"}})
    check("jpeg subscribe: quality defaults to 85",
          r.get("view", {}).get("quality") == 85, short(r))
    if r.get("type") == "subscribed":
        await viewer.request({"type": "unsubscribe", "subscription": r["subscription"]})
        await viewer.pump(0.3)

    r = await viewer.request({"type": "snapshot", "id": "jpeg-snap",
                              "view": {"width": 200, "height": 100, "format": "jpeg",
                                       "quality": 90}}, FIRST_FRAME_TIMEOUT)
    if check("jpeg snapshot: frame reply", r.get("type") == "frame"
             and r.get("id") == "jpeg-snap", short({k: v for k, v in r.items() if k != "_binary"})):
        check_jpeg_frame("jpeg snapshot frame", r, r.get("_binary"), 200, 100)

    v = {"width": 16, "height": 8}
    await bad_input("jpeg: quality with png", viewer,
                    {"type": "subscribe", "id": "q1", "view": dict(v, format="png", quality=80)},
                    "inconsistent", "/view/quality", "q1")
    await bad_input("jpeg: quality without a format", viewer,
                    {"type": "snapshot", "id": "q2", "view": dict(v, quality=80)},
                    "inconsistent", "/view/quality", "q2")
    await bad_input("jpeg: quality 0", viewer,
                    {"type": "subscribe", "id": "q3", "view": dict(v, format="jpeg", quality=0)},
                    "out_of_range", "/view/quality", "q3")
    await bad_input("jpeg: quality 101", viewer,
                    {"type": "subscribe", "id": "q4", "view": dict(v, format="jpeg", quality=101)},
                    "out_of_range", "/view/quality", "q4")
    await bad_input("jpeg: unknown format", viewer,
                    {"type": "subscribe", "id": "q5", "view": dict(v, format="webp")},
                    "bad_value", "/view/format", "q5")
    await bad_input("max_kbps 0", viewer,
                    {"type": "subscribe", "id": "q6", "view": dict(v, max_kbps=0)},
                    "out_of_range", "/view/max_kbps", "q6")
    await bad_input("max_kbps negative", viewer,
                    {"type": "subscribe", "id": "q7", "view": dict(v, format="jpeg",
                                                                   max_kbps=-10)},
                    "out_of_range", "/view/max_kbps", "q7")


async def measure(client, sub, seconds):
    """Bytes per second of the subscription's binary frames over `seconds`, counted from its
    first frame (which is sent at once and not counted)."""
    await client.wait_frame(lambda m: m.get("subscription") == sub, FIRST_FRAME_TIMEOUT)
    start = time.monotonic()
    total = frames = 0
    while time.monotonic() - start < seconds:
        try:
            _m, b = await client.wait_frame(lambda m: m.get("subscription") == sub,
                                            seconds - (time.monotonic() - start))
        except asyncio.TimeoutError:
            break
        total += len(b)
        frames += 1
    return total / seconds, frames


async def t_bandwidth(d, seconds=5.0):
    view = {"width": 320, "height": 180, "fps": 10, "format": "jpeg", "quality": 90}
    free = await Client.connect(d.url(), "unbounded")
    bounded = await Client.connect(d.url(), "bounded")
    try:
        r = await free.request({"type": "subscribe", "id": "free", "view": view})
        free_rate, free_frames = await measure(free, r["subscription"], seconds)
        await free.request({"type": "unsubscribe", "subscription": r["subscription"]})
        # A bound well under what the unbounded stream used.
        max_kbps = max(1.0, free_rate * 8 / 1000 / 4)
        r = await bounded.request({"type": "subscribe", "id": "bound",
                                   "view": dict(view, max_kbps=max_kbps)})
        check("max_kbps: subscribed with the bound",
              r.get("view", {}).get("max_kbps") == max_kbps, short(r))
        sub = r["subscription"]
        rate, frames = await measure(bounded, sub, seconds)
        bound = max_kbps * 1000 / 8
        info(f"bandwidth: unbounded {free_rate:.0f} B/s ({free_frames} frames), bound "
             f"{bound:.0f} B/s, bounded {rate:.0f} B/s ({frames} frames)")
        check("max_kbps: unbounded stream exceeds the bound", free_rate > bound,
              f"{free_rate:.0f} B/s vs {bound:.0f}")
        check("max_kbps: bounded stream within 1.2x the bound", rate <= 1.2 * bound,
              f"{rate:.0f} B/s vs {bound:.0f}")
        check("max_kbps: bounded stream still sends frames", frames >= 1, str(frames))
        st = await bounded.request({"type": "stats", "id": "bw-stats"})
        subs = st.get("subscriptions", [])
        mine = [s for s in subs if s.get("subscription") == sub]
        ok = check("stats: the connection's subscription", len(mine) == 1, short(st))
        if ok:
            s = mine[0]
            check("stats: bytes_sent counts the frames", s.get("bytes_sent", 0) >= rate,
                  short(s))
            check("stats: effective fps lowered", 0 < s.get("fps", 0) < 10, short(s))
            check("stats: quality within [50, 90]", 50 <= s.get("quality", 0) <= 90,
                  short(s))
            check("stats: max_kbps shown", s.get("max_kbps") == max_kbps, short(s))
    finally:
        await free.close()
        await bounded.close()
