#!/usr/bin/python3
"""A time-lapse from a running skyd: sweeps the time of day and saves one PNG per step.

    /usr/bin/python3 clients/python/skyd_timelapse.py --token TOKEN --out frames \\
        --start 2026-06-21T03:00:00Z --end 2026-06-21T21:00:00Z --steps 37

Connects (Debian's python3-websockets, asyncio API), becomes controller, subscribes to a view,
and for each step sets clock.utc together with clock.sky_bodies "ephemeris" (the daemon places
the sun and moon for the time and location) and clock.time_scale 0 (the clock holds still on
the step instead of running on). The frame saved for a step is the first whose header carries
a state revision at least that of the step's `set` (protocol/PROTOCOL.md, "Binary frames"),
written as OUT/frame_NNNN.png. Prints one line per frame: file, time, the sun elevation the
daemon computed, and revision. The clock stays paused at the last step afterwards.

Exit status: 0 done, 1 the server refused a request (the message names the field),
2 bad arguments, 3 connection failure or timeout.
"""

import argparse
import asyncio
import datetime
import json
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
        view = {"width": args.width, "height": args.height, "fps": args.fps}
        if args.ev100 is not None:
            view["exposure"] = {"mode": "manual", "ev100": args.ev100}
        await session.request("subscribe", {"type": "subscribe", "view": view})
        for step in range(args.steps):
            fraction = step / (args.steps - 1) if args.steps > 1 else 0.0
            when = start + (end - start) * fraction
            patch = {"clock": {"utc": format_utc(when), "sky_bodies": "ephemeris",
                               "time_scale": 0}}
            ack = await session.request("set", {"type": "set", "patch": patch})
            wanted = ack["revision"]
            state = (await session.request("get_state", {"type": "get_state"}))["state"]
            elevation = state["sun"]["elevation_deg"]
            while True:
                number, revision, width, height, png = await session.next_frame()
                if revision >= wanted:
                    break
            path = os.path.join(args.out, f"frame_{step:04d}.png")
            with open(path, "wb") as f:
                f.write(png)
            print(f"{path} {format_utc(when)} sun {elevation:.2f} deg revision {revision} "
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
