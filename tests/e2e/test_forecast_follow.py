#!/usr/bin/python3
"""The daemon following a forecast folder (weather.forecast_dir), with the real daemon on
loopback and GRIB2 files made with ecCodes' own tools (forecast_grib.py).

Usage: /usr/bin/python3 tests/e2e/test_forecast_follow.py PATH_TO_SKYD SCRATCH_DIR

With the folder empty, weather.source "forecast" is refused at /patch/weather/source (the
Python module's follow_forecast raises it too). A file dropped in is read (GET
/api/weather/forecast names it, its run and steps); weather.source "forecast" (`skyctl
forecast`, $SKYCTL) then makes the weather move to the file's cover through a transition in a
revision of the forecast's own that every client hears of. A newer file is taken up; a newer
file that is not GRIB is refused with the reader's error and the one in use stays, as does the
weather. A client's set of a weather field makes weather.source "client", after a forecast and
after a METAR alike; the autopilot switched on, or a weather preset, makes it "procedural". A
clock outside the steps keeps the weather and says so (in_range false, the
skyd_forecast_in_range gauge). Exit 0 when every check passed.
"""

import asyncio
import json
import os
import subprocess
import shutil
import sys
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "clients", "python"))
import skyd_client  # noqa: E402
import forecast_grib as fg  # noqa: E402
from serve_harness import (TOKEN, Client, Daemon, check, info, make_config,  # noqa: E402
                           run_daemon_test, short)

RUN = (20260621, 1200)          # 12:00 UTC; steps at 0 and 6 h
CLOCK = "2026-06-21T13:00:00Z"  # within them
GRID = fg.Grid(50, 40, 1, 0, 11, 1)  # 50 N to 40 N, 0 to 10 E, every degree
FAIR = "METAR LFLY 211200Z 18008KT 9999 FEW040 22/10 Q1018"


def forecast_file(work, out, low_cover):
    """Every field constant over the grid and the steps, the low cover `low_cover`."""
    constant = {"lcc": low_cover, "mcc": 0.1, "hcc": 0.2, "2t": 290.0, "2d": 283.0,
                "10u": 3.0, "10v": 4.0}
    parts = []
    for hours in (0, 6):
        for name, value in constant.items():
            parts.append(fg.message(work, "%s-%d-%g" % (name, hours, low_cover), GRID, RUN,
                                    hours, fg.ECMWF[name], [value] * len(GRID.points())))
        parts.append(fg.message(work, "tp-%d-%g" % (hours, low_cover), GRID, RUN, hours,
                                [("shortName", "tp")], [0.0] * len(GRID.points()),
                                accumulated_from=0))
    return fg.concatenate(out, parts)


def drop(path, folder, name, mtime):
    """As a cron job should: written beside, then renamed in; `mtime` orders the files."""
    target = os.path.join(folder, name)
    shutil.copyfile(path, target + ".part")
    os.utime(target + ".part", (mtime, mtime))
    os.rename(target + ".part", target)


def http(port, path):
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=30) as r:
            status, raw = r.status, r.read()
    except urllib.error.HTTPError as e:
        status, raw = e.code, e.read()
    try:
        return status, json.loads(raw)
    except ValueError:
        return status, raw.decode(errors="replace")


async def status_when(port, pred, timeout=10.0):
    """GET /api/weather/forecast until pred holds (the last answer either way)."""
    deadline = time.monotonic() + timeout
    while True:
        _, body = await asyncio.get_running_loop().run_in_executor(
            None, lambda: http(port, "/api/weather/forecast"))
        if (isinstance(body, dict) and pred(body)) or time.monotonic() > deadline:
            return body
        await asyncio.sleep(0.1)


async def get_state(client):
    """The state with its revision."""
    r = await client.get_state()
    return dict(r.get("state", {}), revision=r.get("revision"))


async def state_when(client, pred, timeout=10.0):
    deadline = time.monotonic() + timeout
    while True:
        state = await get_state(client)
        if pred(state) or time.monotonic() > deadline:
            return state
        await asyncio.sleep(0.1)


def target_low(state):
    to = state.get("weather", {}).get("transition", {}).get("to", {})
    return to.get("clouds", {}).get("low", {}).get("coverage")


def source(state):
    return state.get("weather", {}).get("source")


async def check_follow(port, folder, files, ctl, viewer):
    body = await status_when(port, lambda b: True)
    check("empty folder: configured, nothing loaded",
          body.get("configured") is True and body.get("loaded") is False
          and body.get("dir") == folder, short(body))
    r = await ctl.request({"type": "set", "patch": {"weather": {"source": "forecast"}}})
    fields = r.get("fields") or [{}]
    check("no forecast yet: weather.source forecast refused at /patch/weather/source",
          r.get("type") == "error" and r.get("code") == "bad_value"
          and fields[0].get("pointer") == "/patch/weather/source"
          and "no forecast" in fields[0].get("reason", ""), short(r))
    async with skyd_client.connect("ws://127.0.0.1:%d/" % port, reconnect=False) as py:
        await py.auth(token=TOKEN)
        try:
            await py.follow_forecast()
            refused = None
        except skyd_client.SkydError as e:
            refused = e
    check("the Python module's follow_forecast raises it", refused is not None
          and refused.pointers == ["/patch/weather/source"], str(refused))

    now = time.time()
    drop(files[0.4], folder, "run-a.grib2", now - 100)
    body = await status_when(port, lambda b: b.get("loaded"))
    check("a file dropped in is read: its name, run and steps",
          body.get("file") == "run-a.grib2" and body.get("run") == "2026-06-21T12:00:00Z"
          and body.get("steps") == 2 and body.get("first_step") == "2026-06-21T12:00:00Z"
          and body.get("last_step") == "2026-06-21T18:00:00Z" and body.get("loads") == 1
          and body.get("last_error") is None, short(body))

    p = subprocess.run([os.environ["SKYCTL"], "--url", "ws://127.0.0.1:%d/" % port, "--token",
                        TOKEN, "forecast"], capture_output=True, text=True, timeout=30)
    words = p.stdout.split()
    check("skyctl forecast: weather.source forecast accepted, the new revision printed",
          p.returncode == 0 and len(words) == 2 and words[0] == "revision"
          and words[1].isdigit(), f"status {p.returncode}: {p.stdout!r} {p.stderr[-300:]!r}")
    asked = int(words[1]) if len(words) == 2 and words[1].isdigit() else 0
    state = await state_when(ctl, lambda s: target_low(s) is not None
                             and abs(target_low(s) - 0.4) < 1e-9)
    check("following: the weather moves to the file's low cover through a transition",
          source(state) == "forecast" and abs((target_low(state) or -1) - 0.4) < 1e-9
          and state["weather"]["transition"].get("duration_s", 0) >= 299
          and state.get("revision", 0) > asked,
          short(state.get("weather")))
    event = await viewer.wait_event(lambda e: e.get("event") == "state_changed"
                                    and e.get("revision", 0) > asked)
    check("a viewer hears of the forecast's revision",
          event is not None and event.get("by") == "forecast", short(event))
    body = await status_when(port, lambda b: b.get("following"))
    check("status: following, in range", body.get("following") is True
          and body.get("in_range") is True, short(body))

    drop(files[0.7], folder, "run-b.grib2", now - 50)
    body = await status_when(port, lambda b: b.get("file") == "run-b.grib2")
    check("a newer file is taken up", body.get("file") == "run-b.grib2"
          and body.get("loads") == 2, short(body))
    state = await state_when(ctl, lambda s: abs((target_low(s) or -1) - 0.7) < 1e-9)
    check("the weather follows the newer file", source(state) == "forecast"
          and abs((target_low(state) or -1) - 0.7) < 1e-9, short(state.get("weather")))
    revision = state.get("revision")

    with open(os.path.join(folder, "broken.part"), "w") as f:
        f.write("not a forecast\n")
    os.utime(os.path.join(folder, "broken.part"), (now, now))
    os.rename(os.path.join(folder, "broken.part"), os.path.join(folder, "broken.grib2"))
    body = await status_when(port, lambda b: b.get("refusals", 0) >= 1)
    check("a newer file that is not GRIB: refused with the reader's error, the old one stays",
          body.get("refusals") == 1 and body.get("file") == "run-b.grib2"
          and (body.get("last_error") or "").startswith("broken.grib2: ")
          and body.get("loaded") is True, short(body))
    await asyncio.sleep(0.5)
    state = await get_state(ctl)
    check("nothing half-applied: the weather and revision as they were",
          state.get("revision") == revision and abs((target_low(state) or -1) - 0.7) < 1e-9,
          short(state.get("weather")))
    status, text = await asyncio.get_running_loop().run_in_executor(
        None, lambda: http(port, "/metrics"))
    check("metrics: loaded, refusals counted", status == 200
          and "skyd_forecast_loaded 1" in text and "skyd_forecast_refusals_total 1" in text,
          text[-400:] if isinstance(text, str) else text)

    r = await ctl.request({"type": "set", "patch": {"clouds": {"low": {"coverage": 0.2}}}})
    state = await get_state(ctl)
    check("a client's set of a weather field: weather.source client, following stops",
          r.get("type") == "ack" and source(state) == "client"
          and state["clouds"]["low"]["coverage"] == 0.2, short(state.get("weather")))
    await asyncio.sleep(0.5)
    state = await get_state(ctl)
    check("and stays so", source(state) == "client" and state["clouds"]["low"]["coverage"] == 0.2,
          short(state.get("weather")))

    r = await ctl.request({"type": "apply_observation", "metar": FAIR})
    r2 = await ctl.request({"type": "set", "patch": {"weather": {"humidity": 0.9}}})
    state = await get_state(ctl)
    check("after a METAR, a client's set makes weather.source client",
          r.get("type") == "observation" and r2.get("type") == "ack"
          and source(state) == "client", short(state.get("weather")))
    r = await ctl.request({"type": "apply_observation", "metar": FAIR})
    r2 = await ctl.request({"type": "set", "patch": {"weather": {"autopilot": "on"}}})
    state = await get_state(ctl)
    check("after a METAR, the autopilot switched on makes weather.source procedural",
          r2.get("type") == "ack" and source(state) == "procedural", short(state.get("weather")))
    r = await ctl.request({"type": "apply_observation", "metar": FAIR})
    r2 = await ctl.request({"type": "apply_preset", "kind": "weather", "name": "overcast"})
    state = await get_state(ctl)
    check("after a METAR, a weather preset makes weather.source procedural",
          r2.get("type") == "ack" and source(state) == "procedural", short(r2))
    r = await ctl.request({"type": "apply_observation", "metar": FAIR})
    r2 = await ctl.request({"type": "set", "patch": {"clock": {"time_scale": 1}}})
    state = await get_state(ctl)
    check("a set of no weather field leaves weather.source metar",
          r2.get("type") == "ack" and source(state) == "metar", short(state.get("weather")))

    r = await ctl.request({"type": "set", "patch": {"clock": {"utc": "2026-06-23T00:00:00Z"},
                                                    "weather": {"source": "forecast"}}})
    check("weather.source forecast with the clock past the steps: accepted",
          r.get("type") == "ack", short(r))
    body = await status_when(port, lambda b: b.get("in_range") is False)
    check("the clock outside the steps: in_range false", body.get("following") is True
          and body.get("in_range") is False, short(body))
    state = await get_state(ctl)
    check("the weather stays as it was", source(state) == "forecast"
          and state.get("revision") == r.get("revision")
          and state["clouds"]["low"]["coverage"] != 0.7,
          short(state.get("weather")))
    status, text = await asyncio.get_running_loop().run_in_executor(
        None, lambda: http(port, "/metrics"))
    check("metrics: skyd_forecast_in_range 0", "skyd_forecast_in_range 0" in str(text),
          str(text)[-300:])


async def run(skyd, scratch):
    started = time.monotonic()
    work = os.path.join(scratch, "grib")
    folder = os.path.join(scratch, "forecasts")
    for path in (work, folder):
        shutil.rmtree(path, ignore_errors=True)
        os.makedirs(path)
    files = {cover: forecast_file(work, os.path.join(work, "cover-%g.grib2" % cover), cover)
             for cover in (0.4, 0.7)}
    info(f"GRIB2 files made in {time.monotonic() - started:.1f} s")
    state_file = os.path.join(scratch, "state.json")
    for stale in (state_file, state_file + ".token"):
        if os.path.exists(stale):
            os.remove(stale)
    config = make_config(scratch, state_file)
    config["weather"] = {"forecast_dir": folder, "forecast_poll_s": 0.2}
    config["initial_state"] = {"clock": {"utc": CLOCK, "time_scale": 1},
                               "location": {"latitude_deg": 45.0, "longitude_deg": 5.0}}
    daemon = Daemon(skyd, scratch, "forecast_follow", config)
    daemon.start()
    try:
        ctl = await Client.connect(daemon.url(), "controller")
        await ctl.auth()
        viewer = await Client.connect(daemon.url(), "viewer")
        await check_follow(daemon.port, folder, files, ctl, viewer)
        await ctl.close()
        await viewer.close()
    finally:
        status = daemon.terminate()
        check("daemon exits 0 on SIGTERM", status == 0, f"status {status}")
        info(f"log tail: {daemon.log_tail(600)}")


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 120))
