"""test_serve.py's checks of a client weather map (set_weather_map) on the main daemon: roles,
bad uploads (each leaving the state as it was), an upload above max_message_bytes that only a
controller may send, rgba8 and PNG encodings, the revision and event it makes, frames that
show it, the file beside the state, and returning to the procedural map."""

import base64
import os
import random
import time
import urllib.request

from serve_harness import (FIRST_FRAME_TIMEOUT, bad_input, check, check_error, decode_png,
                           encode_png, info, short)


def blueness(binary):
    """Mean of blue minus red over the upper half of a frame's PNG (after its 48-byte
    header): a clear sky is blue, an overcast one grey. (Auto exposure evens out brightness.)"""
    width, height, channels, rows = decode_png(binary[48:])
    total = 0
    for row in rows[:height // 2]:
        for i in range(0, len(row), channels):
            total += row[i + 2] - row[i]
    return total / (width * (height // 2))


def rgba8_map(width, height, texel):
    return bytes(b for y in range(height) for x in range(width) for b in texel(x, y))


async def snapshot_mean(d, client, tag):
    r = await client.request({"type": "snapshot", "id": tag,
                              "view": {"width": 96, "height": 54,
                                       "camera": {"pitch_deg": 30, "fov_deg": 90}}},
                             FIRST_FRAME_TIMEOUT)
    binary = r.get("_binary")
    if not check(f"weather map: snapshot {tag}", r.get("type") == "frame"
                 and isinstance(binary, bytes), short({k: v for k, v in r.items()
                                                       if k != "_binary"})):
        return None
    with open(os.path.join(d.scratch, f"{tag}.png"), "wb") as f:  # for review
        f.write(binary[48:])
    return blueness(binary)


# While a stream is subscribed the daemon builds new weather and shadow maps over frames
# (frame_scheduler.c), and frames show the maps shown until then: a change appears once its
# maps are built, which takes longer the busier the machine. A snapshot is one of those frames.
# With nobody streaming the daemon builds a snapshot's maps whole (a stale build started over),
# so the first snapshot after a change shows it whatever the load.
MAPS_BUILT_TIMEOUT = 60.0


def streams(d):
    """skyd_subscriptions from /metrics (None when it cannot be read)."""
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{d.port}/metrics", timeout=10) as r:
            for line in r.read().decode().splitlines():
                if line.startswith("skyd_subscriptions "):
                    return int(float(line.split()[1]))
    except (OSError, ValueError):
        pass
    return None


async def settled_snapshot_mean(d, client, tag, settled):
    """The blueness of a snapshot that shows the change (`settled(blueness)`): with nobody
    streaming, the first snapshot must; otherwise snapshots follow one another, each a frame
    that builds the maps further, until one does or MAPS_BUILT_TIMEOUT has passed. No sleeping:
    what is waited for is frames. None when a snapshot failed."""
    streaming = streams(d)
    deadline = time.monotonic() + MAPS_BUILT_TIMEOUT
    count = 0
    while True:
        value = await snapshot_mean(d, client, tag)
        count += 1
        if value is None or settled(value) or streaming == 0 or time.monotonic() > deadline:
            break
    if streaming == 0:
        check(f"weather map: {tag}: with nobody streaming the first snapshot shows the change",
              value is not None and settled(value), f"blue - red {value}")
    else:
        info(f"weather map: {tag}: {count} snapshots while {streaming} streams build the maps")
    return value


async def t_weather_map(d, ctl, viewer):
    small = base64.b64encode(rgba8_map(2, 2, lambda x, y: (255, 0, 128, 0))).decode()
    message = {"type": "set_weather_map", "format": "rgba8", "width": 2, "height": 2,
               "data": small}

    # Roles and a state that selects a map nobody sent.
    await bad_input("weather map: from a viewer", viewer, dict(message, id="wv"), "forbidden",
                    id_="wv")
    await bad_input("weather map: map_source client before any map", ctl,
                    {"type": "set", "id": "wm0", "patch": {"weather": {"map_source": "client"}}},
                    "inconsistent", "/patch/weather/map_source", "wm0")

    # Bad uploads name their field; nothing changes.
    no_width = {k: v for k, v in message.items() if k != "width"}
    await bad_input("weather map: rgba8 without width", ctl, dict(no_width, id="w1"),
                    "missing_field", "/width", "w1")
    await bad_input("weather map: texel count", ctl, dict(message, id="w2", width=3),
                    "bad_value", "/data", "w2")
    await bad_input("weather map: bad base64", ctl, dict(message, id="w3", data="AAA*"),
                    "bad_value", "/data", "w3")
    await bad_input("weather map: side 513", ctl, dict(message, id="w4", width=513),
                    "out_of_range", "/width", "w4")
    await bad_input("weather map: format jpeg", ctl, dict(message, id="w5", format="jpeg"),
                    "bad_value", "/format", "w5")
    await bad_input("weather map: data a number", ctl, dict(message, id="w6", data=7),
                    "wrong_type", "/data", "w6")
    await bad_input("weather map: unknown field", ctl, dict(message, id="w7", scale=2),
                    "unknown_field", "/scale", "w7")
    wide = encode_png(600, 1, [bytes(600 * 4)])
    await bad_input("weather map: PNG of 600x1", ctl,
                    {"type": "set_weather_map", "id": "w8", "format": "png",
                     "data": base64.b64encode(wide).decode()}, "bad_value", "/data", "w8")
    await bad_input("weather map: truncated PNG", ctl,
                    {"type": "set_weather_map", "id": "w9", "format": "png",
                     "data": base64.b64encode(encode_png(4, 4, [bytes(16)] * 4)[:40]).decode()},
                    "bad_value", "/data", "w9")

    # Above max_message_bytes only a set_weather_map, and only a controller's, is read.
    limit = d.config["limits"]["max_message_bytes"]
    padded = '{"type":"get_state","id":"big"' + " " * limit + "}"
    await bad_input("weather map: a controller's large get_state", ctl, padded,
                    "message_too_large")
    await bad_input("weather map: a viewer's large set_weather_map", viewer,
                    dict(message, id="wv2", data=small + " " * limit), "message_too_large")

    r = await ctl.request({"type": "apply_preset", "id": "wmc", "kind": "weather",
                           "name": "clear"})
    check("weather map: clear weather first", r.get("type") == "ack", short(r))
    # The daemon's config lets the sun follow the real clock: at some hours of the day it is
    # low or down, and the clear sky is grey. A sun held 40 deg up makes the comparisons below
    # independent of when the test runs.
    r = await ctl.request({"type": "set", "id": "wms", "patch": {
        "clock": {"sky_bodies": "manual"}, "sun": {"elevation_deg": 40, "azimuth_deg": 180}}})
    check("weather map: a fixed sun", r.get("type") == "ack", short(r))
    procedural = await settled_snapshot_mean(d, viewer, "wm-before", lambda v: v > 40)
    before = await ctl.get_state()

    # 512 x 512 texels (1 MiB, 1.4 MB of base64): overcast low cloud with noise in every
    # channel, so that the upload cannot shrink.
    rng = random.Random(7)
    texels = rgba8_map(512, 512, lambda x, y: (235 + rng.randrange(20), rng.randrange(40),
                                               rng.randrange(80), rng.randrange(30)))
    data = base64.b64encode(texels).decode()
    check("weather map: the upload exceeds max_message_bytes", len(data) > limit,
          f"{len(data)} bytes")
    r = await ctl.request({"type": "set_weather_map", "id": "wm1", "format": "rgba8",
                           "width": 512, "height": 512, "data": data}, 30)
    revision = before.get("revision", 0) + 1  # nothing else changes the state meanwhile
    check("weather map: 512x512 rgba8 ack with a new revision", r.get("type") == "ack"
          and r.get("id") == "wm1" and r.get("revision") == revision, short(r))
    event = await viewer.wait_event(lambda e: e.get("revision") == revision)
    changed = event.get("changed", []) if event else []
    check("weather map: event names /weather/map and /weather/map_source",
          "/weather/map" in changed and "/weather/map_source" in changed, short(event))
    check("weather map: the event's values have map_source, not the map",
          (event or {}).get("values") == {"/weather/map_source": "client"}, short(event))
    state = (await ctl.get_state()).get("state", {})
    check("weather map: map_source client", state.get("weather", {}).get("map_source")
          == "client", short(state.get("weather")))
    state_file = d.config["state_file"]
    map_file = state_file[:-len(".json")] + ".weather-map.png"
    try:
        with open(map_file, "rb") as f:
            saved = decode_png(f.read())
        check("weather map: saved beside the state as a 512x512 PNG",
              saved[:3] == (512, 512, 4) and bytes(saved[3][0]) == texels[:512 * 4],
              f"{saved[:3]}")
    except (OSError, ValueError) as e:
        check("weather map: saved beside the state as a 512x512 PNG", False, repr(e))

    overcast = await settled_snapshot_mean(
        d, viewer, "wm-overcast", lambda v: procedural is not None and v < 0.5 * procedural)
    if procedural is not None and overcast is not None:
        check("weather map: frames show it (an overcast map greys the clear sky)",
              procedural > 40 and overcast < 0.5 * procedural,
              f"blue - red: procedural clear {procedural:.1f}, overcast map {overcast:.1f}")

    # A PNG without alpha: a clear map; the same revision rule.
    clear = encode_png(8, 8, [bytes(8 * 3)] * 8, color_type=2)
    r = await ctl.request({"type": "set_weather_map", "id": "wm2", "format": "png",
                           "data": base64.b64encode(clear).decode()})
    check("weather map: PNG ack", r.get("type") == "ack" and r.get("revision") == revision + 1,
          short(r))
    event = await viewer.wait_event(lambda e: e.get("revision") == revision + 1)
    check("weather map: event for a second map names only /weather/map",
          event is not None and event.get("changed") == ["/weather/map"], short(event))
    cleared = await settled_snapshot_mean(
        d, viewer, "wm-clear", lambda v: procedural is not None
        and abs(v - procedural) < 0.1 * procedural)
    if None not in (procedural, cleared):
        check("weather map: a clear map shows the clear sky again",
              abs(cleared - procedural) < 0.1 * procedural,
              f"blue - red: procedural clear {procedural:.1f}, clear map {cleared:.1f}")

    # The last map stays on disk for a restart that selects it; back to overcast for that.
    r = await ctl.request({"type": "set_weather_map", "id": "wm3", "format": "rgba8",
                           "width": 512, "height": 512, "data": data}, 30)
    check("weather map: overcast again", r.get("type") == "ack", short(r))
    r = await ctl.request({"type": "set", "id": "wm4",
                           "patch": {"weather": {"map_source": "procedural"}}})
    check("weather map: back to procedural", r.get("type") == "ack", short(r))
    r = await ctl.request({"type": "set", "id": "wm5",
                           "patch": {"weather": {"map_source": "client"}}})
    check("weather map: client again without an upload (a map was sent)", r.get("type") == "ack",
          short(r))
    check("weather map: file kept", os.path.exists(map_file), map_file)
