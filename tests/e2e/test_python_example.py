#!/usr/bin/python3
"""Runs clients/python/skyd_timelapse.py against the real daemon and checks its time-lapse.

Usage: /usr/bin/python3 tests/e2e/test_python_example.py PATH_TO_SKYD EXAMPLE OUTPUT_DIR

Sweeps 04:00 to 20:00 UTC on 21 June at 45 N 6 E in four steps with a fixed exposure. The
daemon starts in manual mode; the example switches it to the ephemeris with the clock paused.
The four PNGs must exist with the requested size, each saved from a frame of its step's
revision or later (revisions rise); the sun elevation the daemon reports must agree with
NOAA's general solar position equations (an independent, coarser reference); the midday
frames must be brighter than the dawn and dusk ones, the sun below the horizon at 20:00 must
give the darkest frame, and the world clock must stay paused at the last step in ephemeris
mode. A wrong token must exit 1 naming the failure. Exit 0 when every check passed.
"""

import asyncio
import datetime
import math
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness  # noqa: E402
from serve_harness import TOKEN, Client, Daemon, check, decode_png, info, make_config  # noqa: E402

LINE = re.compile(r"(\S+/frame_(\d{4})\.png) (\S+) sun (-?[0-9.]+) deg revision (\d+) "
                  r"frame (\d+) (\d+)x(\d+)")
TIMES = ["2026-06-21T04:00:00Z", "2026-06-21T09:20:00Z", "2026-06-21T14:40:00Z",
         "2026-06-21T20:00:00Z"]


def noaa_sun_elevation(when, latitude_deg, longitude_deg):
    """Sun elevation in degrees without refraction: NOAA Global Monitoring Division, "General
    Solar Position Calculations" (about 0.1 degree away from the horizon)."""
    year_start = datetime.datetime(when.year, 1, 1, tzinfo=datetime.timezone.utc)
    days_in_year = 366 if when.year % 4 == 0 and (when.year % 100 or when.year % 400 == 0) else 365
    hours = when.hour + when.minute / 60 + when.second / 3600
    gamma = 2 * math.pi / days_in_year * ((when - year_start).days + (hours - 12) / 24)
    eqtime = 229.18 * (0.000075 + 0.001868 * math.cos(gamma) - 0.032077 * math.sin(gamma)
                       - 0.014615 * math.cos(2 * gamma) - 0.040849 * math.sin(2 * gamma))
    decl = (0.006918 - 0.399912 * math.cos(gamma) + 0.070257 * math.sin(gamma)
            - 0.006758 * math.cos(2 * gamma) + 0.000907 * math.sin(2 * gamma)
            - 0.002697 * math.cos(3 * gamma) + 0.00148 * math.sin(3 * gamma))
    hour_angle = math.radians((hours * 60 + eqtime + 4 * longitude_deg) / 4 - 180)
    lat = math.radians(latitude_deg)
    cos_zenith = (math.sin(lat) * math.sin(decl)
                  + math.cos(lat) * math.cos(decl) * math.cos(hour_angle))
    return 90 - math.degrees(math.acos(max(-1.0, min(1.0, cos_zenith))))


def mean_luma(path):
    width, height, channels, rows = decode_png(open(path, "rb").read())
    total = 0
    for row in rows:
        for i in range(0, len(row), channels):
            total += 0.2126 * row[i] + 0.7152 * row[i + 1] + 0.0722 * row[i + 2]
    return width, height, total / (width * height)


def run_example(example, daemon, out, token):
    env = dict(os.environ)
    env.pop("SKYD_DAEMON_LD_PRELOAD", None)
    return subprocess.run(
        [sys.executable, example, "--url", daemon.url(), "--token", token, "--out", out,
         "--start", TIMES[0], "--end", TIMES[-1], "--steps", "4", "--width", "160",
         "--height", "90", "--fps", "10", "--ev100", "13", "--timeout", "60"],
        capture_output=True, text=True, timeout=240, env=env)


async def world_state(daemon):
    client = await Client.connect(daemon.url(), "checker")
    try:
        return (await client.get_state())["state"]
    finally:
        await client.close()


def main():
    skyd, example, out = (os.path.abspath(p) for p in sys.argv[1:4])
    os.makedirs(out, exist_ok=True)
    frames = os.path.join(out, "frames")
    for folder in (out, frames):
        if os.path.isdir(folder):
            for name in os.listdir(folder):
                if name.endswith(".png") or name.endswith(".json"):
                    os.unlink(os.path.join(folder, name))
    daemon = Daemon(skyd, out, "skyd", make_config(out, os.path.join(out, "state.json")))
    started = time.monotonic()
    try:
        daemon.start()
        result = run_example(example, daemon, frames, TOKEN)
        check("example exits 0", result.returncode == 0,
              f"status {result.returncode}; stderr {result.stderr[-600:]}")
        lines = [LINE.fullmatch(line) for line in result.stdout.splitlines()]
        check("one line per frame in the expected format", len(lines) == 4 and all(lines),
              result.stdout)
        revisions = []
        lumas = []
        for step, m in enumerate(lines if all(lines) else []):
            path = m.group(1)
            check(f"step {step}: file name", m.group(2) == f"{step:04d}", m.group(0))
            check(f"step {step}: time", m.group(3) == TIMES[step], m.group(0))
            revisions.append(int(m.group(5)))
            when = datetime.datetime.strptime(TIMES[step], "%Y-%m-%dT%H:%M:%SZ").replace(
                tzinfo=datetime.timezone.utc)
            reference = noaa_sun_elevation(when, 45.0, 6.0)
            # The daemon's elevation is refracted (up to 0.6 degree at the horizon).
            check(f"step {step}: the daemon placed the sun", abs(float(m.group(4)) - reference)
                  < 0.8, f"{m.group(4)} deg, NOAA {reference:.2f} deg")
            if not check(f"step {step}: PNG written", os.path.isfile(path), path):
                continue
            width, height, luma = mean_luma(path)
            check(f"step {step}: 160x90", (width, height) == (160, 90), f"{width}x{height}")
            lumas.append(luma)
            info(f"{TIMES[step]} sun {m.group(4)} deg, mean luma {luma:.1f}")
        check("revisions rise with each step", revisions == sorted(set(revisions))
              and len(revisions) == 4, str(revisions))
        if len(lumas) == 4:
            check("midday frames are brighter than dawn", min(lumas[1], lumas[2]) > lumas[0],
                  str(lumas))
            check("the frame after sunset is the darkest", lumas[3] == min(lumas), str(lumas))
        clock = asyncio.run(world_state(daemon))["clock"]
        check("the world clock stays paused at the last step",
              clock["utc"] == TIMES[-1] and clock["time_scale"] == 0, str(clock))
        check("the sun follows the ephemeris", clock["sky_bodies"] == "ephemeris", str(clock))

        bad = run_example(example, daemon, os.path.join(out, "bad"), "wrong-token")
        check("wrong token: exit status 1", bad.returncode == 1, f"status {bad.returncode}")
        check("wrong token: the message says why", "auth_failed" in bad.stderr, bad.stderr)
    except Exception as e:  # noqa: BLE001 - any failure is a failed check
        check("example test ran", False, f"{type(e).__name__}: {e}")
    finally:
        status = daemon.terminate()
        check("skyd exits 0 on SIGTERM", status == 0, f"status {status}; {daemon.log_tail()}")
    return serve_harness.summary(started)


if __name__ == "__main__":
    sys.exit(main())
