#!/usr/bin/python3
"""Deterministic worlds with two real daemons: `skyd serve` twice, started at different times
from copies of the same state file, read the same world.

Usage: /usr/bin/python3 tests/e2e/test_world_clock.py PATH_TO_SKYD SCRATCH_DIR

- Paused (clock.time_scale 0): both report the same state, field for field (the clock, the
  sun in ephemeris mode, the wind offsets integrated from the stored anchor), and the same
  view's snapshot from both differs by no more than the same daemon's two snapshots of it (a
  render's own noise), while a view an hour later differs by far more.
- Running (time scale 1, the epoch a minute in the past): each reports the simulated time its
  epoch gives at the wall instant of the reply, not the stored clock.utc, and the two clocks,
  measured against the wall clock at the same instants, differ by under 50 ms.
Exit status 0 when every check passed.
"""

import asyncio
import os
import shutil
import sys
import time
from datetime import datetime, timezone

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (FIRST_FRAME_TIMEOUT, TOKEN, Client, Daemon, check,  # noqa: E402
                           decode_png, info, make_config, run_daemon_test, short)
import json  # noqa: E402

CLOCK_TOLERANCE_S = 0.050
VIEW = {"width": 160, "height": 90, "camera": {"pitch_deg": 25, "yaw_deg": 200, "fov_deg": 80}}


def iso(unix_s):
    """ISO 8601 UTC to the millisecond, as the daemon writes times."""
    ms = round(unix_s * 1000)
    dt = datetime.fromtimestamp(ms // 1000, tz=timezone.utc)
    return dt.strftime("%Y-%m-%dT%H:%M:%S") + f".{ms % 1000:03d}Z"


def unix(text):
    return datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


def stored_state(time_scale, epoch_wall):
    """A state file's tree: clouds, wind, the ephemeris; the clock's epoch at epoch_wall and
    the wind's anchor an hour of simulated time before the clock."""
    return {
        "revision": 7,
        "clock": {"utc": "2026-06-21T16:00:00Z", "time_scale": time_scale,
                  "sky_bodies": "ephemeris",
                  "epoch": {"wall": iso(epoch_wall), "utc": "2026-06-21T17:00:00Z"}},
        "location": {"latitude_deg": 46.2, "longitude_deg": 6.1, "altitude_m": 400},
        "clouds": {"low": {"coverage": 0.55, "type": 0.7}},
        "weather": {"wind": {"speed_m_s": 14, "direction_deg": 250},
                    "offset_east_km": 3.5, "offset_north_km": -1.25,
                    "anchor": {"utc": "2026-06-21T16:00:00Z", "offset_east_km": 3.5,
                               "offset_north_km": -1.25}},
    }


def start_node(skyd, scratch, name, state):
    path = os.path.join(scratch, f"{name}-state.json")
    with open(path, "w") as f:
        json.dump(state, f)
    d = Daemon(skyd, scratch, name, make_config(scratch, path))
    d.start()
    return d


def pixels(binary):
    _, _, channels, rows = decode_png(binary[48:])
    return channels, rows


def mean_abs_diff(a, b):
    """Mean absolute difference of two decoded images' colour channels, in 8-bit levels."""
    ca, ra = a
    cb, rb = b
    total = count = 0
    for row_a, row_b in zip(ra, rb):
        for i in range(0, len(row_a), ca):
            for k in range(3):
                total += abs(row_a[i + k] - row_b[i + k])
                count += 1
    return total / max(count, 1)


async def snapshot(client, tag):
    r = await client.request({"type": "snapshot", "id": tag, "view": VIEW}, FIRST_FRAME_TIMEOUT)
    binary = r.get("_binary")
    if not check(f"snapshot {tag}", r.get("type") == "frame" and isinstance(binary, bytes),
                 short({k: v for k, v in r.items() if k != "_binary"})):
        return None
    return pixels(binary)


def without_revision(state):
    return {k: v for k, v in state.items() if k != "revision"}


async def paused(skyd, scratch):
    state = stored_state(0, time.time() - 60.0)
    a = start_node(skyd, scratch, "paused-a", state)
    await asyncio.sleep(1.5)  # another start time
    b = start_node(skyd, scratch, "paused-b", state)
    ca = await Client.connect(a.url(), "paused-a")
    cb = await Client.connect(b.url(), "paused-b")
    try:
        sa, sb = await ca.get_state(), await cb.get_state()
        wa, wb = sa.get("state", {}), sb.get("state", {})
        check("paused: both read the stored clock", wa.get("clock", {}).get("utc")
              == wb.get("clock", {}).get("utc") == "2026-06-21T17:00:00Z",
              f"{wa.get('clock')} / {wb.get('clock')}")
        check("paused: the same state on both, field for field", wa == wb,
              f"{short(wa)} / {short(wb)}")
        east = wa.get("weather", {}).get("offset_east_km", 0)
        # An hour of 14 m/s from 250 deg: 50.4 km toward 70 deg, 47.4 km of it east.
        check("paused: the wind moved the map from its anchor", abs(east - (3.5 + 47.36)) < 0.1,
              f"offset_east_km {east}")
        a1 = await snapshot(ca, "a1")
        a2 = await snapshot(ca, "a2")
        b1 = await snapshot(cb, "b1")
        if a1 and a2 and b1:
            noise = mean_abs_diff(a1, a2)
            between = mean_abs_diff(a1, b1)
            info(f"paused: mean |A1 - A2| {noise:.4f}, mean |A1 - B1| {between:.4f} "
                 f"(8-bit levels)")
            check("paused: the nodes' snapshots differ by no more than one node's noise",
                  between <= max(2.0 * noise, 0.02), f"{between:.4f} against noise {noise:.4f}")
            # The comparison can see a difference: the same view an hour later on A.
            await ca.request({"type": "auth", "id": "auth", "token": TOKEN})
            r = await ca.request({"type": "set", "id": "later",
                                  "patch": {"clock": {"utc": "2026-06-21T18:00:00Z"}}})
            check("paused: set the clock an hour on", r.get("type") == "ack", short(r))
            later = await snapshot(ca, "a-later")
            if later:
                moved = mean_abs_diff(a1, later)
                info(f"paused: an hour later, mean |A1 - A'| {moved:.4f}")
                check("paused: an hour later looks different", moved > 10 * max(between, 0.1),
                      f"{moved:.4f}")
    finally:
        await ca.close()
        await cb.close()
        for d in (a, b):
            check(f"{d.name}: exits 0", d.terminate() == 0, d.log_tail())


async def clock_offset(client, epoch_wall, epoch_utc, samples=12):
    """(simulated - wall) seconds at the reply of the fastest of `samples` get_state round
    trips, its round trip, and its distance from what the epoch gives."""
    best = None
    for _ in range(samples):
        t0 = time.time()
        s = await client.get_state()
        t1 = time.time()
        wall = 0.5 * (t0 + t1)
        sim = unix(s["state"]["clock"]["utc"])
        if best is None or t1 - t0 < best[1]:
            best = (sim - wall, t1 - t0, sim - (epoch_utc + (wall - epoch_wall)))
        await asyncio.sleep(0.05)
    return best


async def running(skyd, scratch):
    epoch_wall = round(time.time() - 60.0, 3)
    state = stored_state(1, epoch_wall)
    epoch_utc = unix(state["clock"]["epoch"]["utc"])
    a = start_node(skyd, scratch, "running-a", state)
    await asyncio.sleep(2.0)
    b = start_node(skyd, scratch, "running-b", state)
    ca = await Client.connect(a.url(), "running-a")
    cb = await Client.connect(b.url(), "running-b")
    try:
        for round_ in range(3):
            off_a, rtt_a, from_epoch_a = await clock_offset(ca, epoch_wall, epoch_utc)
            off_b, rtt_b, from_epoch_b = await clock_offset(cb, epoch_wall, epoch_utc)
            info(f"running {round_}: sim - wall A {off_a:.4f} s (rtt {rtt_a * 1e3:.1f} ms), "
                 f"B {off_b:.4f} s (rtt {rtt_b * 1e3:.1f} ms)")
            check(f"running {round_}: A reads the epoch's time, not the stored one",
                  abs(from_epoch_a) < CLOCK_TOLERANCE_S + rtt_a / 2, f"{from_epoch_a:.4f} s")
            check(f"running {round_}: B reads the epoch's time, not the stored one",
                  abs(from_epoch_b) < CLOCK_TOLERANCE_S + rtt_b / 2, f"{from_epoch_b:.4f} s")
            check(f"running {round_}: the two clocks differ by under 50 ms",
                  abs(off_a - off_b) < CLOCK_TOLERANCE_S, f"{(off_a - off_b) * 1e3:.1f} ms")
            await asyncio.sleep(1.0)
        sa, sb = await ca.get_state(), await cb.get_state()
        check("running: the same epoch on both",
              sa["state"]["clock"].get("epoch") == sb["state"]["clock"].get("epoch")
              == {"wall": iso(epoch_wall), "utc": "2026-06-21T17:00:00Z"},
              f"{sa['state']['clock']} / {sb['state']['clock']}")
    finally:
        await ca.close()
        await cb.close()
        for d in (a, b):
            check(f"{d.name}: exits 0", d.terminate() == 0, d.log_tail())


async def run(skyd, scratch):
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(os.path.join(scratch, "web"), exist_ok=True)
    await paused(skyd, scratch)
    await running(skyd, scratch)


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 240))
