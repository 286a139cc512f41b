#!/usr/bin/python3
"""A time-lapse from a running skyd: sweeps the time of day and saves one PNG per step.

    /usr/bin/python3 clients/python/skyd_timelapse.py --token TOKEN --out frames \\
        --start 2026-06-21T03:00:00Z --end 2026-06-21T21:00:00Z --steps 37

Connects (Debian's python3-websockets, asyncio API), becomes controller, subscribes to a view,
and for each step sets clock.utc; while clock.sky_bodies is "manual" the same `set` moves the
sun to where it stands at that time and place (NOAA's general solar position equations), so
the sky follows the clock whether or not the server computes an ephemeris. The frame saved for
a step is the first whose header carries a state revision at least that of the step's `set`
(protocol/PROTOCOL.md, "Binary frames"), written as OUT/frame_NNNN.png. Prints one line per
frame: file, time, sun elevation and revision.

Exit status: 0 done, 1 the server refused a request (the message names the field),
2 bad arguments, 3 connection failure or timeout.
"""

import argparse
import asyncio
import datetime
import json
import math
import os
import struct
import sys

try:
    import websockets
    import websockets.exceptions
except ImportError:  # pragma: no cover - environment problem
    print("skyd_timelapse.py: needs the websockets package (Debian: python3-websockets)",
          file=sys.stderr)
    sys.exit(3)

HEADER = struct.Struct("<4sHHQQdIIII")  # the 48-byte binary frame header


class ServerError(Exception):
    """An `error` reply; str() names each field the server complained about."""

    def __init__(self, what, reply):
        fields = reply.get("fields") or []
        if fields:
            text = "; ".join(f"{f.get('pointer')}: {f.get('reason')} [{f.get('code')}]"
                             for f in fields)
        else:
            text = f"{reply.get('message')} [{reply.get('code')}]"
        super().__init__(f"{what}: {text}")


def sun_position(when, latitude_deg, longitude_deg):
    """(elevation, azimuth from north through east) in degrees. NOAA Global Monitoring
    Division, "General Solar Position Calculations" (about 0.1 degree)."""
    year_start = datetime.datetime(when.year, 1, 1, tzinfo=datetime.timezone.utc)
    days_in_year = 366 if when.year % 4 == 0 and (when.year % 100 or when.year % 400 == 0) else 365
    hours = when.hour + when.minute / 60 + when.second / 3600
    day = (when - year_start).days  # day of the year - 1
    gamma = 2 * math.pi / days_in_year * (day + (hours - 12) / 24)  # NOAA: fractional year
    eqtime = 229.18 * (0.000075 + 0.001868 * math.cos(gamma) - 0.032077 * math.sin(gamma)
                       - 0.014615 * math.cos(2 * gamma) - 0.040849 * math.sin(2 * gamma))
    decl = (0.006918 - 0.399912 * math.cos(gamma) + 0.070257 * math.sin(gamma)
            - 0.006758 * math.cos(2 * gamma) + 0.000907 * math.sin(2 * gamma)
            - 0.002697 * math.cos(3 * gamma) + 0.00148 * math.sin(3 * gamma))
    hour_angle = math.radians((hours * 60 + eqtime + 4 * longitude_deg) / 4 - 180)
    lat = math.radians(latitude_deg)
    cos_zenith = (math.sin(lat) * math.sin(decl)
                  + math.cos(lat) * math.cos(decl) * math.cos(hour_angle))
    zenith = math.acos(max(-1.0, min(1.0, cos_zenith)))
    east = -math.cos(decl) * math.sin(hour_angle)
    north = math.sin(decl) * math.cos(lat) - math.cos(decl) * math.cos(hour_angle) * math.sin(lat)
    azimuth = math.degrees(math.atan2(east, north)) % 360
    return 90 - math.degrees(zenith), azimuth


def parse_utc(text):
    when = datetime.datetime.strptime(text, "%Y-%m-%dT%H:%M:%SZ")
    return when.replace(tzinfo=datetime.timezone.utc)


def format_utc(when):
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


class Session:
    """Requests matched to replies by id; frames read in order."""

    def __init__(self, ws, timeout):
        self.ws = ws
        self.timeout = timeout
        self.next_id = 1
        self.frames = []  # (header fields, png) read while waiting for a reply

    async def receive(self):
        return await asyncio.wait_for(self.ws.recv(), self.timeout)

    async def request(self, what, message):
        message = dict(message, id=self.next_id)
        self.next_id += 1
        await self.ws.send(json.dumps(message))
        while True:
            data = await self.receive()
            if isinstance(data, bytes):
                continue  # a frame whose announcement went by: frames are read in next_frame
            reply = json.loads(data)
            if reply.get("id") == message["id"] and reply.get("type") != "frame":
                if reply.get("type") == "error":
                    raise ServerError(what, reply)
                return reply

    async def next_frame(self):
        """The next subscription frame: (frame_number, state_revision, width, height, png)."""
        while True:
            data = await self.receive()
            if isinstance(data, bytes):
                continue
            announce = json.loads(data)
            if announce.get("type") != "frame":
                continue
            binary = await self.receive()
            while not isinstance(binary, bytes):
                binary = await self.receive()
            (magic, version, fmt, number, revision, _sim_time, width, height, length,
             _reserved) = HEADER.unpack_from(binary)
            if magic != b"SKYF" or version != 1 or fmt != 1 or length != len(binary) - 48:
                raise ValueError(f"bad frame header {binary[:48]!r}")
            if number != announce.get("frame_number"):
                raise ValueError(f"frame {number} announced as {announce.get('frame_number')}")
            return number, revision, width, height, binary[48:]


async def timelapse(args):
    start, end = parse_utc(args.start), parse_utc(args.end)
    os.makedirs(args.out, exist_ok=True)
    async with websockets.connect(args.url, max_size=1 << 26, open_timeout=args.timeout,
                                  ping_interval=None) as ws:
        session = Session(ws, args.timeout)
        hello = json.loads(await session.receive())
        if hello.get("type") != "hello":
            raise ServerError("connect", hello)
        if args.token:
            await session.request("auth", {"type": "auth", "token": args.token})
        state = (await session.request("get_state", {"type": "get_state"}))["state"]
        manual_sun = state["clock"]["sky_bodies"] == "manual"
        latitude = state["location"]["latitude_deg"]
        longitude = state["location"]["longitude_deg"]
        view = {"width": args.width, "height": args.height, "fps": args.fps}
        if args.ev100 is not None:
            view["exposure"] = {"mode": "manual", "ev100": args.ev100}
        await session.request("subscribe", {"type": "subscribe", "view": view})
        for step in range(args.steps):
            fraction = step / (args.steps - 1) if args.steps > 1 else 0.0
            when = start + (end - start) * fraction
            patch = {"clock": {"utc": format_utc(when)}}
            elevation = None
            if manual_sun:
                elevation, azimuth = sun_position(when, latitude, longitude)
                patch["sun"] = {"elevation_deg": round(elevation, 3),
                                "azimuth_deg": round(azimuth, 3)}
            ack = await session.request("set", {"type": "set", "patch": patch})
            wanted = ack["revision"]
            while True:
                number, revision, width, height, png = await session.next_frame()
                if revision >= wanted:
                    break
            path = os.path.join(args.out, f"frame_{step:04d}.png")
            with open(path, "wb") as f:
                f.write(png)
            sun_text = f"sun {elevation:.2f} deg" if elevation is not None else "sun ephemeris"
            print(f"{path} {format_utc(when)} {sun_text} revision {revision} "
                  f"frame {number} {width}x{height}", flush=True)


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
    except ServerError as e:
        print(f"skyd_timelapse.py: {e}", file=sys.stderr)
        return 1
    except (OSError, asyncio.TimeoutError, websockets.exceptions.WebSocketException,
            ValueError) as e:
        print(f"skyd_timelapse.py: {type(e).__name__}: {e}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
