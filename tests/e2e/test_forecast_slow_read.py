#!/usr/bin/python3
"""A slow forecast read does not hold up frames: the forecast folder is read on a thread of its
own, so while a read takes seconds (SKYD_FAULT_DIR's forecast_read_delay, as a global 0.25
degree file with many steps would) a subscription's frames keep arriving at their rate, and
the forecast is taken up once read.

Usage: /usr/bin/python3 tests/e2e/test_forecast_slow_read.py PATH_TO_SKYD SCRATCH_DIR [GRIB]
With GRIB (a large file, bench/forecast_bench.c: run 2026-06-21 12 UTC) no delay is injected:
that file is linked into the folder and the read's time and the frames' longest gap are
reported (docs/PERFORMANCE.md). Exit 0 when every check passed.
"""

import asyncio
import os
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (Client, Daemon, check, info, make_config,  # noqa: E402
                           run_daemon_test, short)
from test_forecast_follow import (CLOCK, drop, forecast_file, status_when)  # noqa: E402

DELAY_S = 4.0
FPS = 8
# The longest gap between two frames allowed while the read is under way: a few periods on a
# busy machine, far below the read's DELAY_S.
MAX_GAP_S = 1.5


LARGE = sys.argv.pop(3) if len(sys.argv) > 3 else None


async def run(skyd, scratch):
    work = os.path.join(scratch, "grib")
    folder = os.path.join(scratch, "forecasts")
    faults = os.path.join(scratch, "faults")
    for path in (work, folder, faults):
        shutil.rmtree(path, ignore_errors=True)
        os.makedirs(path)
    grib = forecast_file(work, os.path.join(work, "cover.grib2"), 0.4)
    state_file = os.path.join(scratch, "state.json")
    for stale in (state_file, state_file + ".token"):
        if os.path.exists(stale):
            os.remove(stale)
    config = make_config(scratch, state_file)
    config["weather"] = {"forecast_dir": folder, "forecast_poll_s": 0.2}
    config["initial_state"] = {"clock": {"utc": CLOCK, "time_scale": 1},
                               "location": {"latitude_deg": 45.0, "longitude_deg": 5.0}}
    daemon = Daemon(skyd, scratch, "forecast_slow_read", config,
                    env={"SKYD_FAULT_DIR": faults})
    daemon.start()
    try:
        viewer = await Client.connect(daemon.url(), "viewer")
        r = await viewer.request({"type": "subscribe", "id": "sub", "view": {
            "width": 32, "height": 18, "fps": FPS}})
        check("subscribed", r.get("type") == "subscribed", short(r))
        await viewer.wait_frame(timeout=30)
        await viewer.pump(1.0)
        if not LARGE:
            with open(os.path.join(faults, "forecast_read_delay"), "w") as f:
                f.write(f"{DELAY_S}\n")
        viewer.frames.clear()
        dropped = time.monotonic()
        if LARGE:
            os.symlink(os.path.abspath(LARGE), os.path.join(folder, "large.grib2"))
        else:
            drop(grib, folder, "run.grib2", time.time())
        loaded_at = None
        while time.monotonic() - dropped < DELAY_S + 10:
            await viewer.pump(0.25)
            body = await status_when(daemon.port, lambda b: True)
            if body.get("loaded"):
                loaded_at = time.monotonic()
                break
        read_s = (loaded_at or time.monotonic()) - dropped
        times = [t for _, _, t in viewer.frames if t <= (loaded_at or time.monotonic())]
        gaps = [b - a for a, b in zip(times, times[1:])]
        longest = max(gaps) if gaps else float("inf")
        info(f"read {read_s:.2f} s; {len(times)} frames meanwhile, longest gap {longest:.3f} s "
             f"(period {1 / FPS:.3f} s)")
        check("the forecast is taken up once read", loaded_at is not None
              and (LARGE or read_s >= DELAY_S - 0.1), f"after {read_s:.2f} s")
        check("frames keep arriving during the read",
              (LARGE or len(times) >= DELAY_S * FPS / 3) and longest <= MAX_GAP_S,
              f"{len(times)} frames, longest gap {longest:.3f} s")
        await viewer.close()
    finally:
        status = daemon.terminate()
        check("daemon exits 0 on SIGTERM", status == 0, f"status {status}")
        info(f"log tail: {daemon.log_tail(400)}")


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 120))
