#!/usr/bin/python3
"""The forecast's cover grid as the weather map (weather.map_source "forecast"), with the real
daemon and a GRIB2 file whose low cloud is clear over the west half of the map's square and
overcast over the east half (forecast_grib.py, ecCodes' tools).

A client's own map is sent first. weather.source "forecast" then selects the forecast's map:
GET /api/weather/forecast's map has the file's pattern (r: clear west, overcast east; g the
high cover; a no rain) and it is written beside the state. Across a restart the daemon comes
back following with the forecast's map. A client's set of a weather field stops following and
brings the procedural map back; the client's map is as it was, on disk too, and selecting it
again is accepted. map_source "forecast" while not following is refused as inconsistent.
`skyd render --forecast` of the same file, looking low to the west and to the east (the upper
half of each image: cloud bases 6 to 30 km away) at one fixed exposure: clear sky westward
between the cumulus where the cover climbs towards the line, at least a third of the pixels;
eastward the base of a deck, half as bright as that sky or less, with under one pixel in twenty
as bright.

Usage: /usr/bin/python3 tests/e2e/test_forecast_map.py PATH_TO_SKYD SCRATCH_DIR
Exit 0 when every check passed.
"""

import asyncio
import base64
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import forecast_grib as fg  # noqa: E402
from png_codec import decode_png_full  # noqa: E402
from serve_harness import (Client, Daemon, check, daemon_environment, info,  # noqa: E402
                           make_config, run_daemon_test, short)
from test_forecast_follow import CLOCK, RUN, drop, get_state, status_when  # noqa: E402

# 44 to 46 N, 4 to 6 E every 0.1 degree; the place 45 N 5 E, the square 60 km.
GRID = fg.Grid(46, 44, 0.1, 4, 21, 0.1)
PLACE = (45.0, 5.0)
CLIENT_MAP = base64.b64encode(bytes([255, 0, 160, 0, 128, 64, 160, 40])).decode()


def half_file(work, out):
    """Low cover 0 west of 5 E and 1 east of it, the rest constant, at +0 and +6 h."""
    low = [0.0 if lon < 4.999 else 1.0 if lon > 5.001 else 0.5 for _, lon in GRID.points()]
    constant = {"mcc": 0.0, "hcc": 0.2, "2t": 290.0, "2d": 283.0, "10u": 0.5, "10v": 0.0}
    parts = []
    for hours in (0, 6):
        parts.append(fg.message(work, "lcc-%d" % hours, GRID, RUN, hours, fg.ECMWF["lcc"], low))
        for name, value in constant.items():
            parts.append(fg.message(work, "%s-%d" % (name, hours), GRID, RUN, hours,
                                    fg.ECMWF[name], [value] * len(GRID.points())))
        parts.append(fg.message(work, "tp-%d" % hours, GRID, RUN, hours, [("shortName", "tp")],
                                [0.0] * len(GRID.points()), accumulated_from=0))
    return fg.concatenate(out, parts)


def columns(body):
    """The map's r, g and a channels as mean per column, west to east, with its size."""
    m = body.get("map") or {}
    w, h = m.get("width", 0), m.get("height", 0)
    texels = base64.b64decode(m.get("data", "")) if w else b""
    if len(texels) != w * h * 4 or not w:
        return None
    mean = [[sum(texels[(y * w + x) * 4 + c] for y in range(h)) / h for x in range(w)]
            for c in range(4)]
    return w, h, mean


def read(path):
    with open(path, "rb") as f:
        return f.read()


async def check_map(port, state_file, folder, grib, ctl):
    r = await ctl.request({"type": "set_weather_map", "format": "rgba8", "width": 2,
                           "height": 1, "data": CLIENT_MAP})
    check("a client's map first", r.get("type") == "ack", short(r))
    client_png = state_file.replace(".json", ".weather-map.png")
    client_bytes = read(client_png) if os.path.exists(client_png) else None
    r = await ctl.request({"type": "set", "patch": {"weather": {"map_source": "forecast"}}})
    check("map_source forecast while not following: inconsistent",
          r.get("type") == "error" and r.get("code") == "inconsistent"
          and (r.get("fields") or [{}])[0].get("pointer") == "/patch/weather/map_source",
          short(r))

    drop(grib, folder, "halves.grib2", time.time())
    await status_when(port, lambda b: b.get("loaded") is True)
    r = await ctl.request({"type": "set", "patch": {"weather": {"source": "forecast"}}})
    state = await get_state(ctl)
    check("following selects the forecast's map", r.get("type") == "ack"
          and state["weather"]["map_source"] == "forecast", short(state.get("weather")))
    body = await status_when(port, lambda b: columns(b) is not None)
    got = columns(body)
    if check("GET /api/weather/forecast carries the map", got is not None, short(body)):
        w, h, (r_, g_, b_, a_) = got
        # The map tiles its extent, laid against the wind's drift: as simulated time passes
        # (more of it on a loaded machine) the column at each edge mixes with the other edge's.
        west, east = r_[1:w * 3 // 8], r_[w - w * 3 // 8:w - 1]
        info("map %dx%d, low cover by column: %s" % (w, h, " ".join("%.0f" % v for v in r_)))
        check("the forecast's grid size", (w, h) == (16, 16), f"{w}x{h}")
        check("west of the place clear, east overcast",
              max(west) < 8 and min(east) > 247, f"west {west}, east {east}")
        check("the high cover in g, no rain in a",
              all(abs(v - 51) <= 1 for v in g_) and all(v == 0 for v in a_),
              f"g {g_[:3]}, a {a_[:3]}")
    forecast_png = state_file.replace(".json", ".forecast-map.png")
    check("the forecast's map is written beside the state", os.path.exists(forecast_png)
          and read(forecast_png)[:8] == b"\x89PNG\r\n\x1a\n", forecast_png)
    return client_png, client_bytes


async def check_after_restart(port, ctl, client_png, client_bytes, daemon):
    state = await get_state(ctl)
    check("after a restart: following, the forecast's map selected",
          state["weather"]["source"] == "forecast"
          and state["weather"]["map_source"] == "forecast", short(state.get("weather")))
    check("the forecast's map restored at start",
          "restored the forecast's weather map (16x16)" in daemon.log_text(), "not in the log")
    r = await ctl.request({"type": "set", "patch": {"clouds": {"low": {"coverage": 0.3}}}})
    state = await get_state(ctl)
    check("a client's weather: following stops, the procedural map is back",
          r.get("type") == "ack" and state["weather"]["source"] == "client"
          and state["weather"]["map_source"] == "procedural", short(state.get("weather")))
    check("the client's map is untouched on disk", client_bytes is not None
          and read(client_png) == client_bytes, client_png)
    r = await ctl.request({"type": "set", "patch": {"weather": {"map_source": "client"}}})
    check("and can be selected again", r.get("type") == "ack", short(r))


BLUE = 1.5  # b/r above which a pixel is clear sky; a cloud's face or base is nearer 1


def linear_level(rgb):
    """The linear level of an sRGB pixel: the mean of r, g and b decoded."""
    return sum(((v / 255.0 + 0.055) / 1.055) ** 2.4 for v in rgb) / 3.0


def upper_half(skyd, scratch, grib, yaw):
    """The pixels (r, g, b) of the upper half of a render looking low towards `yaw`, at one
    manual exposure for every render."""
    path = os.path.join(scratch, "render-%d.png" % yaw)
    p = subprocess.run([skyd, "render", "--width", "64", "--height", "32",
                        "--set", "clock.utc=" + CLOCK,
                        "--set", "location.latitude_deg=%g" % PLACE[0],
                        "--set", "location.longitude_deg=%g" % PLACE[1],
                        "--set", "camera.yaw_deg=%d" % yaw, "--set", "camera.pitch_deg=8",
                        "--set", "camera.fov_deg=12", "--set", "camera.altitude_km=0.002",
                        "--set", "exposure.mode=manual", "--set", "exposure.ev100=14",
                        "--forecast", grib, "--out", path],
                       capture_output=True, text=True, env=daemon_environment())
    if not check("skyd render --forecast, yaw %d" % yaw, p.returncode == 0, p.stderr[-300:]):
        return None
    with open(path, "rb") as f:
        png = decode_png_full(f.read())
    w, c = png["width"], png["channels"]
    return [tuple(png["rows"][y][x * c:x * c + 3]) for y in range(png["height"] // 2)
            for x in range(w)]


def median(values):
    values = sorted(values)
    return values[len(values) // 2] if values else 0.0


def check_render(skyd, scratch, grib):
    """The camera stands on the line between the halves, and the map's cover climbs over a few
    texels west of it, so cumulus of that ramp fill about half of the western view: the check
    is that clear sky shows between them, not that the view is clear. Eastward, no pixel is
    clear sky as bright as the west's: the deck's base, half as bright or less."""
    west, east = (upper_half(skyd, scratch, grib, yaw) for yaw in (270, 90))
    if west is None or east is None:
        return
    sky = [linear_level(p) for p in west if p[2] > BLUE * max(p[0], 1)]
    sky_share, sky_level = len(sky) / len(west), median(sky)
    east_level = median(linear_level(p) for p in east)
    east_bright = sum(linear_level(p) > 0.75 * sky_level for p in east) / len(east)
    info("skyd render --forecast: westward %.2f of the pixels clear sky at level %.3f; "
         "eastward median level %.3f, %.2f of the pixels as bright as that sky"
         % (sky_share, sky_level, east_level, east_bright))
    check("skyd render --forecast: clear sky westward, a deck's base eastward",
          sky_share >= 1.0 / 3.0 and east_level < sky_level / 2.0 and east_bright < 0.05,
          "west: %.2f clear at %.3f; east: median %.3f, %.2f bright"
          % (sky_share, sky_level, east_level, east_bright))


async def run(skyd, scratch):
    work = os.path.join(scratch, "grib")
    folder = os.path.join(scratch, "forecasts")
    for path in (work, folder):
        shutil.rmtree(path, ignore_errors=True)
        os.makedirs(path)
    grib = half_file(work, os.path.join(work, "halves.grib2"))
    state_file = os.path.join(scratch, "state.json")
    for stale in os.listdir(scratch):
        if stale.startswith("state."):
            os.remove(os.path.join(scratch, stale))
    config = make_config(scratch, state_file)
    config["weather"] = {"forecast_dir": folder, "forecast_poll_s": 0.2}
    config["initial_state"] = {"clock": {"utc": CLOCK, "time_scale": 1},
                               "location": {"latitude_deg": PLACE[0],
                                            "longitude_deg": PLACE[1]}}
    daemon = Daemon(skyd, scratch, "forecast_map", config)
    daemon.start()
    try:
        ctl = await Client.connect(daemon.url(), "controller")
        await ctl.auth()
        client_png, client_bytes = await check_map(daemon.port, state_file, folder, grib, ctl)
        await ctl.close()
        status = daemon.terminate()
        check("daemon exits 0 on SIGTERM", status == 0, f"status {status}")
        daemon.start()
        ctl = await Client.connect(daemon.url(), "controller")
        await ctl.auth()
        await check_after_restart(daemon.port, ctl, client_png, client_bytes, daemon)
        await ctl.close()
        check_render(skyd, scratch, grib)
    finally:
        status = daemon.terminate()
        check("daemon exits 0 on SIGTERM", status == 0, f"status {status}")
        info(f"log tail: {daemon.log_tail(600)}")


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 180))
