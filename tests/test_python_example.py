#!/usr/bin/python3
"""Runs clients/python/skyd_timelapse.py against the real daemon and checks its time-lapse.

Usage: /usr/bin/python3 tests/test_python_example.py PATH_TO_SKYD EXAMPLE OUTPUT_DIR

Sweeps 04:00 to 20:00 UTC on 21 June at 45 N 6 E in four steps with a fixed exposure: the
four PNGs must exist with the requested size, each saved from a frame of its step's revision
or later (revisions rise), the midday frames must be brighter than the dawn and dusk ones, the
sun below the horizon at 20:00 must give the darkest frame, and the world clock must end at the
last step. A wrong token must exit 1 naming the failure. Exit 0 when every check passed.
"""

import asyncio
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


async def world_clock(daemon):
    client = await Client.connect(daemon.url(), "checker")
    try:
        return (await client.get_state())["state"]["clock"]["utc"]
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
        utc = asyncio.run(world_clock(daemon))
        check("the world clock ends at the last step", utc == TIMES[-1], utc)

        bad = run_example(example, daemon, os.path.join(out, "bad"), "wrong-token")
        check("wrong token: exit status 1", bad.returncode == 1, f"status {bad.returncode}")
        check("wrong token: the message says why", "auth_failed" in bad.stderr, bad.stderr)
    except Exception as e:  # noqa: BLE001 - any failure is a failed check
        check("example test ran", False, f"{type(e).__name__}: {e}")
    finally:
        status = daemon.terminate()
        check("skyd exits 0 on SIGTERM", status == 0, f"status {status}; {daemon.log_tail()}")
    print(f"{serve_harness.passed} passed, {serve_harness.failed} failed "
          f"in {time.monotonic() - started:.1f} s")
    return 0 if serve_harness.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
