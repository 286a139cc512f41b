#!/usr/bin/python3
"""A time-lapse from a running skyd: sweeps the time of day and saves one PNG per step.

    /usr/bin/python3 clients/python/skyd_timelapse.py --token TOKEN --out frames \\
        --start 2026-06-21T03:00:00Z --end 2026-06-21T21:00:00Z --steps 37

Connects with skyd_client.py (beside this file; Debian's python3-websockets), becomes
controller, subscribes to a view, and for each step sets clock.utc together with
clock.sky_bodies "ephemeris" (the daemon places the sun and moon for the time and location) and
clock.time_scale 0 (the clock holds still on the step instead of running on). The frame saved
for a step is the first whose header carries a state revision at least that of the step's
`set` (protocol/PROTOCOL.md, "Binary frames"), written as OUT/frame_NNNN.png. Prints one line
per frame: file, time, the sun elevation the daemon computed, and revision. The clock stays
paused at the last step afterwards.

Exit status: 0 done, 1 the server refused a request (the message names the field),
2 bad arguments, 3 connection failure or timeout.
"""

import argparse
import asyncio
import datetime
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
try:
    import skyd_client
except ImportError as e:  # pragma: no cover - environment problem
    print(f"skyd_timelapse.py: {e} (needs Debian's python3-websockets)", file=sys.stderr)
    sys.exit(3)


def parse_utc(text):
    when = datetime.datetime.strptime(text, "%Y-%m-%dT%H:%M:%SZ")
    return when.replace(tzinfo=datetime.timezone.utc)


def format_utc(when):
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


async def timelapse(args):
    start, end = parse_utc(args.start), parse_utc(args.end)
    os.makedirs(args.out, exist_ok=True)
    # Without reconnecting: a step whose `set` was lost with the connection is not retried.
    async with skyd_client.connect(args.url, open_timeout=args.timeout,
                                   reply_timeout=args.timeout, reconnect=False) as sky:
        if args.token:
            await sky.auth(args.token)
        view = {"width": args.width, "height": args.height, "fps": args.fps}
        if args.ev100 is not None:
            view["exposure"] = {"mode": "manual", "ev100": args.ev100}
        frames = await sky.subscribe(view)
        for step in range(args.steps):
            fraction = step / (args.steps - 1) if args.steps > 1 else 0.0
            when = start + (end - start) * fraction
            wanted = await sky.set({"clock": {"utc": format_utc(when), "sky_bodies": "ephemeris",
                                              "time_scale": 0}})
            elevation = (await sky.get_state())["state"]["sun"]["elevation_deg"]
            frame = await frames.next(args.timeout)
            while frame.revision < wanted:
                frame = await frames.next(args.timeout)
            path = os.path.join(args.out, f"frame_{step:04d}.png")
            with open(path, "wb") as f:
                f.write(frame.payload)
            print(f"{path} {format_utc(when)} sun {elevation:.2f} deg revision {frame.revision} "
                  f"frame {frame.frame_number} {frame.width}x{frame.height}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", default=os.environ.get("SKYD_URL", "ws://127.0.0.1:8080/"))
    parser.add_argument("--token", default=os.environ.get("SKYD_TOKEN"),
                        help="controller token (needed to set the clock)")
    parser.add_argument("--out", default="timelapse", help="folder for frame_NNNN.png")
    parser.add_argument("--start", default="2026-06-21T03:00:00Z", help="first time, UTC")
    parser.add_argument("--end", default="2026-06-21T21:00:00Z", help="last time, UTC")
    parser.add_argument("--steps", type=int, default=37, help="frames, at least 1")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--fps", type=float, default=10)
    parser.add_argument("--ev100", type=float, default=None,
                        help="fixed exposure (EV100) instead of the world state's")
    parser.add_argument("--timeout", type=float, default=60, help="seconds per reply or frame")
    args = parser.parse_args()
    try:
        parse_utc(args.start)
        parse_utc(args.end)
    except ValueError:
        parser.error("--start and --end take UTC times like 2026-06-21T03:00:00Z")
    if args.steps < 1:
        parser.error("--steps must be at least 1")
    try:
        asyncio.run(timelapse(args))
    except skyd_client.SkydError as e:
        print(f"skyd_timelapse.py: {e}", file=sys.stderr)
        return 1
    except (OSError, asyncio.TimeoutError, ValueError) as e:  # SkydConnectionError included
        print(f"skyd_timelapse.py: {type(e).__name__}: {e}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
