#!/usr/bin/python3
"""Soak: the real daemon, with clients attached, under random valid changes for a stretch of
simulated time (30 minutes by default), with the Vulkan validation layer on.

Usage: /usr/bin/python3 bench/soak.py [--simulated-minutes 30] [--time-scale 10] [--seed 1] ...
       make soak SOAK_ARGS="--simulated-minutes 60 --time-scale 20"

Any two of --simulated-minutes, --time-scale and --real-seconds set the third (default: 30
simulated minutes at a time scale of 10, about 3 real minutes). The real seconds and the
simulated minutes are those measured, after the warm-up's --warmup-minutes (10).

The daemon (`skyd serve`, validation on, a scratch state directory) gets these clients:
  - a controller that sends random valid changes: `set` patches drawn from the world state's
    field table (protocol/world_fields.c, checked against what `get_state` returns) within
    each field's range or enum, weather and atmosphere presets, weather transitions,
    `set_weather_map` uploads (rgba8 and PNG, 1x1 to 512x512), the autopilot, clock jumps and
    time-scale excursions;
  - three subscribers that read frames and keep changing their views (sizes from 1x1 to
    480x270, camera and exposure overrides, frame rates, shared views, up to three
    subscriptions each);
  - a viewer taking snapshots (up to 640x360), probes, stats, presets lists and states;
  - a client that connects and disconnects (some without a close frame);
  - a monitor that reads `stats` (the simulated clock) every second.
Every request must get its reply (an `error` to a valid request is a failure); every frame's
header must match the view it was asked for.

Memory: the daemon's VmRSS is sampled every --rss-interval seconds. The warm-up exercises every
change kind, field, enum value, view size and snapshot size once, then makes random changes
until --warmup-minutes simulated minutes (10) have passed since the start. It ends with a
settle: the world state goes back to its initial values, the subscribers to their home views,
and the median RSS over --settle-seconds is the baseline. The measured --simulated-minutes of
random changes (30) end with the same settle, whose median is the end figure, so the two are
taken in the same state and growth means memory not given back. The random part of the warm-up
is there because the renderer's working set is reached by combinations, not by single changes:
a composite pipeline (specialized by output kind, camera in space, sun in view, night, clouds,
ground) is compiled at its first use, and which combinations a scene needs is drawn at random.
With the baseline right after the single changes, runs of seeds 2 and 1 gave +4.5 % and
+15.5 %.

The daemon gets an empty Mesa shader cache of its own (MESA_SHADER_CACHE_DIR, in the scratch
directory; --shader-cache DIR to give one). With the user's cache, most shader variants load
from it and LLVM's optimizer and code generator are first used at the first variant the cache
lacks, whenever the random changes happen to ask for one: about 11 MiB of libLLVM's code paged
in and about 20 MiB more anonymous memory, once per process. After the baseline that failed
runs at +13 %, and whether it did depended on what earlier runs had left in the cache. With an
empty cache the first compile comes at start-up, as on a fresh machine (docs/PERFORMANCE.md,
"Soak: where the memory went").

Exit status 0 when RSS growth < --max-growth-percent (5), no validation message, no refused
or unanswered request, no bad frame and the daemon alive and exiting 0 on SIGTERM; 1
otherwise; 2 for a bad command line or a daemon that does not start. The last line is a
one-line summary with the figures.
"""

import argparse
import asyncio
import base64
import datetime
import json
import math
import os
import random
import re
import statistics
import struct
import sys
import tempfile
import time
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "e2e"))
import serve_harness as H  # noqa: E402

# ------------------------------------------------------------------------------------------
# Constants

VALIDATION_PREFIX = "skyd: vulkan validation"
HOME_VIEWS = [  # one per subscriber: where it returns for the baseline and end measurements
    {"width": 96, "height": 54, "fps": 10},
    {"width": 320, "height": 180, "fps": 5, "camera": {"yaw_deg": 90, "pitch_deg": 5}},
    {"width": 480, "height": 270, "fps": 3, "exposure": {"mode": "manual", "ev100": 13}},
]
STREAM_SIZES = [(1, 1), (16, 9), (64, 36), (96, 54), (160, 90), (256, 144), (320, 180),
                (400, 225), (480, 270), (37, 211)]
SNAPSHOT_SIZES = [(1, 1), (64, 36), (160, 90), (320, 180), (640, 360), (333, 97)]
MAX_STREAM = (480, 270)
MAX_SNAPSHOT = (640, 360)
WEATHER_PRESETS = ["clear", "fair_cumulus", "scattered", "broken", "overcast", "storm"]
ATMOSPHERE_PRESETS = ["earth", "mars"]

# The 14 weather parameters the autopilot and transitions drive, and the angles the ephemeris
# drives (PROTOCOL.md, set): a patch naming them must switch those off in the same patch.
WEATHER_PARAMS = [f"clouds.{layer}.{name}" for layer in ("low", "high")
                  for name in ("coverage", "type", "density", "bottom_km", "thickness_km")] + [
    "clouds.precipitation", "weather.humidity", "weather.wind.speed_m_s",
    "weather.wind.direction_deg"]
EPHEMERIS_ANGLES = ["sun.azimuth_deg", "sun.elevation_deg", "moon.azimuth_deg",
                    "moon.elevation_deg"]
RADII = ["atmosphere.bottom_radius_km", "atmosphere.top_radius_km"]
MAX_ATMOSPHERE_THICKNESS_KM = 1000.0
CLOCK_FIELDS = ["clock.utc", "clock.time_scale"]  # changed only as clock excursions (below)

# Bounds the soak keeps to (unless --uncapped) on fields whose whole range is valid but whose
# top end costs more than a soak on two CPU cores can carry: a 4096x4096 transmittance LUT is
# 28 s of lavapipe time per rebuild, a 512^3 froxel volume 2 GiB. Twice the default sizes and
# step counts still change every buffer's size.
COST_CAPS = {
    "render.transmittance_lut": [512, 128],
    "render.multiscattering_lut": [64, 64],
    "render.skyview_lut": [384, 216],
    "render.aerial_perspective_lut": [64, 64, 64],
    "clouds.quality.primary_steps": 128,
    "clouds.quality.light_steps": 12,
}
UTC_DRAW_RANGE = (-2177452800.0, 4070908800.0)  # 1901..2099: room for the clock to run on


# ------------------------------------------------------------------------------------------
# The field table


class Field:
    def __init__(self, path, kind, lo=None, hi=None, names=None, read_only=False):
        self.path, self.kind, self.lo, self.hi = path, kind, lo, hi
        self.names, self.read_only = names, read_only


def read_field_table(path):
    """The world state's fields from protocol/world_fields.c: path, type, range, enum names."""
    with open(path) as f:
        text = f.read()
    defines = {m.group(1): float(m.group(2)) for m in
               re.finditer(r"^#define (\w+) (-?[0-9.eE+-]+)\s*$", text, re.M)}
    enums = {m.group(1): re.findall(r'"([^"]*)"', m.group(2)) for m in
             re.finditer(r"static const char \*const (\w+)\[\] = \{([^}]*)\};", text)}

    def number(token):
        return defines[token] if token in defines else float(token)

    fields = []
    row = re.compile(r"\b(NUMBER|RGB|INT_PAIR|INT_TRIPLE|INT|TIME|ENUM|RO_NUMBER|RO_TIME)\(\s*"
                     r'"([a-z0-9_.]+)"\s*,\s*([\w.\[\]]+)\s*,\s*([-+\w.]+)\s*'
                     r"(?:,\s*([-+\w.]+)\s*)?,")
    for m in row.finditer(text):
        kind, fpath, _member, a, b = m.groups()
        if kind == "ENUM":
            fields.append(Field(fpath, kind, names=enums[a]))
        elif kind.startswith("RO_"):
            fields.append(Field(fpath, kind[3:], number(a), number(b), read_only=True))
        else:
            fields.append(Field(fpath, kind, number(a), number(b)))
    return fields


def leaves(tree, prefix=""):
    """Dotted paths of a state tree's leaves (arrays are leaves)."""
    out = {}
    for k, v in tree.items():
        p = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(leaves(v, p + "."))
        else:
            out[p] = v
    return out


def put(tree, path, value):
    parts = path.split(".")
    for p in parts[:-1]:
        tree = tree.setdefault(p, {})
    tree[parts[-1]] = value


def nested(flat):
    tree = {}
    for path, value in flat.items():
        put(tree, path, value)
    return tree


# ------------------------------------------------------------------------------------------
# Random valid values


class Draw:
    def __init__(self, rng, fields, uncapped):
        self.rng = rng
        self.fields = {f.path: f for f in fields if not f.read_only}
        self.uncapped = uncapped
        self.map_uploaded = False

    def number(self, lo, hi):
        r = self.rng.random()
        if r < 0.08:
            return lo
        if r < 0.16:
            return hi
        if r < 0.4 and lo >= 0 and hi > 0 and hi / max(lo, 1e-3) > 1e3:
            low = math.log(max(lo, 1e-3))  # wide ranges: log-uniform as often as not
            return min(hi, max(lo, math.exp(self.rng.uniform(low, math.log(hi)))))
        return self.rng.uniform(lo, hi)

    def integer(self, lo, hi):
        r = self.rng.random()
        if r < 0.1:
            return int(lo)
        if r < 0.2:
            return int(hi)
        return self.rng.randint(int(lo), int(hi))

    def value(self, f):
        cap = None if self.uncapped else COST_CAPS.get(f.path)
        if f.kind == "NUMBER":
            return self.number(f.lo, f.hi)
        if f.kind == "RGB":
            if self.rng.random() < 0.2:
                return self.number(f.lo, f.hi)  # one number sets all three channels
            return [self.number(f.lo, f.hi) for _ in range(3)]
        if f.kind == "INT":
            return self.integer(f.lo, min(f.hi, cap) if cap else f.hi)
        if f.kind in ("INT_PAIR", "INT_TRIPLE"):
            n = 2 if f.kind == "INT_PAIR" else 3
            return [self.integer(f.lo, min(f.hi, cap[i]) if cap else f.hi) for i in range(n)]
        if f.kind == "ENUM":
            names = list(f.names)
            if f.path == "weather.map_source" and not self.map_uploaded:
                names.remove("client")
            return self.rng.choice(names)
        if f.kind == "TIME":
            return iso_utc(self.rng.uniform(*UTC_DRAW_RANGE))
        raise ValueError(f"no draw for {f.kind} ({f.path})")

    def radii(self):
        bottom = self.number(100.0, 100000.0)
        return {RADII[0]: bottom,
                RADII[1]: bottom + self.rng.uniform(0.1, MAX_ATMOSPHERE_THICKNESS_KM)}

    def make_valid(self, flat):
        """Completes a flat patch so that it is valid whatever the state it meets."""
        for p in CLOCK_FIELDS:
            flat.pop(p, None)
        if any(p in flat for p in RADII):
            flat.update(self.radii())
        if any(p in flat for p in EPHEMERIS_ANGLES):
            flat["clock.sky_bodies"] = "manual"
        if any(p in flat for p in WEATHER_PARAMS):
            flat["weather.autopilot"] = "off"
        if flat.get("weather.map_source") == "client" and not self.map_uploaded:
            flat["weather.map_source"] = "procedural"
        return flat

    def patch(self, paths):
        return self.make_valid({p: self.value(self.fields[p]) for p in paths})

    def random_patch(self):
        """One to six fields, or a whole group of them."""
        candidates = [p for p in self.fields if p not in CLOCK_FIELDS]
        if self.rng.random() < 0.2:
            group = self.rng.choice(sorted({p.rsplit(".", 1)[0] for p in candidates}))
            paths = [p for p in candidates if p.rsplit(".", 1)[0] == group]
        else:
            paths = self.rng.sample(candidates, self.rng.randint(1, 6))
        return self.patch(paths)

    def camera(self):
        cam = {}
        for name, lo, hi in (("altitude_km", 0, 100000), ("yaw_deg", -360, 360),
                             ("pitch_deg", -90, 90), ("fov_deg", 1, 170)):
            if self.rng.random() < 0.5:
                cam[name] = self.number(lo, hi)
        return cam

    def exposure(self):
        exp = {}
        if self.rng.random() < 0.5:
            exp["mode"] = self.rng.choice(["auto", "manual"])
        if self.rng.random() < 0.5:
            exp["ev100"] = self.number(-10, 25)
        if self.rng.random() < 0.3:
            exp["compensation_ev"] = self.number(-10, 10)
        return exp

    def view(self, sizes, largest, size=None):
        if size is None:
            if self.rng.random() < 0.3:
                size = (self.rng.randint(1, largest[0]), self.rng.randint(1, largest[1]))
            else:
                size = self.rng.choice(sizes)
        v = {"width": size[0], "height": size[1]}
        if self.rng.random() < 0.7:
            v["fps"] = round(self.rng.uniform(0.5, 12), 2)
        if self.rng.random() < 0.5:
            v["camera"] = self.camera()
        if self.rng.random() < 0.4:
            v["exposure"] = self.exposure()
        if self.rng.random() < 0.2:
            v["format"] = "png"
        return v

    def probe(self):
        q = self.rng.choice(["transmittance", "luminance", "illuminance"])
        m = {"type": "probe", "quantity": q}
        if q in ("transmittance", "luminance"):
            m["altitude_km"] = self.number(0, 100000)
        if q == "transmittance":
            m["mu"] = self.number(-1, 1)
        if q == "luminance":
            m["view_zenith_deg"] = self.number(0, 180)
            m["view_azimuth_deg"] = self.number(-360, 360)
        if q in ("luminance", "illuminance"):
            m["sun_zenith_deg"] = self.number(0, 180)
        return m

    def weather_map(self, fmt=None, size=None):
        """A set_weather_map message: blocky random weather, rgba8 or PNG."""
        fmt = fmt or self.rng.choice(["rgba8", "png"])
        if size is None:
            side = self.rng.choice([1, 2, 7, 64, 128, 256, 333, 512])
            size = (side, self.rng.choice([side, max(1, side // 2), 512]))
        w, h = size
        block = max(1, min(w, h) // 8)
        gw, gh = -(-w // block), -(-h // block)
        grid = [[bytes(self.rng.randrange(256) for _ in range(4)) for _ in range(gw)]
                for _ in range(gh)]
        rows = []
        for y in range(h):
            cells = grid[y // block]
            rows.append(b"".join(cells[x // block] for x in range(w)))
        if fmt == "rgba8":
            data = b"".join(rows)
            m = {"type": "set_weather_map", "format": "rgba8", "width": w, "height": h}
        else:
            data = H.encode_png(w, h, rows)
            m = {"type": "set_weather_map", "format": "png"}
            if self.rng.random() < 0.5:
                m.update(width=w, height=h)
        m["data"] = base64.b64encode(data).decode()
        return m


def iso_utc(t):
    moment = datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc) + \
        datetime.timedelta(seconds=int(t))
    return moment.strftime("%Y-%m-%dT%H:%M:%SZ")


# ------------------------------------------------------------------------------------------
# Bookkeeping


class Soak:
    def __init__(self, args):
        self.args = args
        self.failures = []
        self.sent = {}
        self.acked = {}
        self.replies = {}
        self.fields_set = set()
        self.enum_values_set = set()
        self.phase = "warmup"
        self.done = False
        self.home_generation = 0
        self.at_home = {}
        self.warm = set()
        self.clock_epoch = 0
        self.sim_s = 0.0
        self.last_sim = None
        self.rss = []          # (real s since start, simulated s, KiB, phase)
        self.settle = {}       # label -> [KiB]
        self.render_fps = []
        self.frames = {}       # client name -> subscription frames
        self.snapshots = 0
        self.max_frame_gap = {}
        self.t0 = time.monotonic()
        self.daemon = None

    def fail(self, what):
        self.failures.append(what)
        if len(self.failures) <= 20:
            print(f"soak: FAIL {what}", flush=True)

    def log(self, text):
        if self.args.verbose:
            print(f"soak: [{time.monotonic() - self.t0:7.1f} s] {text}", flush=True)

    def count(self, table, kind):
        table[kind] = table.get(kind, 0) + 1

    def elapsed(self):
        return time.monotonic() - self.t0


def memory_kib(pid):
    """VmRSS and its parts (RssAnon, RssFile, RssShmem) from /proc/PID/status, KiB."""
    out = {}
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                key = line.split(":", 1)[0]
                if key in ("VmRSS", "RssAnon", "RssFile", "RssShmem", "VmHWM"):
                    out[key] = int(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return out


def rss_kib(pid):
    return memory_kib(pid).get("VmRSS")


class SoakClient(H.Client):
    """The harness client, checking every frame's header against the view it was asked for
    and keeping no frames or events (a long run would pile them up)."""

    soak = None

    def setup(self, soak):
        self.soak = soak
        self.sub_views = {}       # subscription -> (width, height)
        self.last_frame_number = None
        self.last_frame_at = {}
        self.subscription_frames = 0
        self.event_count = 0
        self.decode_every = 25

    async def _dispatch(self, timeout):
        item = await super()._dispatch(timeout)
        if item[0] == "frame":
            self.frames.clear()
            self.subscription_frames += 1
            self.soak.frames[self.name] = self.soak.frames.get(self.name, 0) + 1
            sub = item[1].get("subscription")
            size = self.sub_views.get(sub)
            if size is None:
                self.soak.fail(f"{self.name}: frame for subscription {sub} it never had")
            else:
                self.check_frame(item[1], item[2], size, f"subscription {sub}")
            now = time.monotonic()
            if sub in self.last_frame_at:
                gap = now - self.last_frame_at[sub]
                self.soak.max_frame_gap[self.name] = max(
                    gap, self.soak.max_frame_gap.get(self.name, 0))
            self.last_frame_at[sub] = now
        elif item[0] == "event":
            self.events.clear()
            self.event_count += 1
        return item

    def check_frame(self, msg, binary, size, what):
        if not isinstance(binary, bytes) or len(binary) < 48:
            self.soak.fail(f"{self.name}: {what}: no binary frame after {H.short(msg)}")
            return
        (magic, version, fmt, number, _revision, sim_time, w, h, length,
         reserved) = H.HEADER.unpack_from(binary)
        problems = []
        if (magic, version, fmt, reserved) != (b"SKYF", 1, 1, 0):
            problems.append(f"header {magic!r} v{version} format {fmt} reserved {reserved}")
        if number != msg.get("frame_number"):
            problems.append(f"frame_number {number} vs message {msg.get('frame_number')}")
        if self.last_frame_number is not None and number <= self.last_frame_number:
            problems.append(f"frame_number {number} after {self.last_frame_number}")
        self.last_frame_number = number
        if (w, h) != tuple(size):
            problems.append(f"{w}x{h}, asked {size[0]}x{size[1]}")
        if length != len(binary) - 48 or binary[48:56] != H.PNG_SIGNATURE:
            problems.append(f"payload {length} bytes of {len(binary) - 48}, not a PNG")
        if not math.isfinite(sim_time):
            problems.append(f"simulation_time_s {sim_time}")
        if not problems and w * h <= 160 * 90 and number % self.decode_every == 0:
            try:
                pw, ph, _channels, _rows = H.decode_png(binary[48:])
                if (pw, ph) != (w, h):
                    problems.append(f"PNG is {pw}x{ph}")
            except (ValueError, zlib.error, struct.error) as e:
                problems.append(f"PNG does not decode: {e}")
        if problems:
            self.soak.fail(f"{self.name}: {what}: " + "; ".join(problems))

    async def ask(self, kind, msg, expect, timeout=None):
        """One request and its reply; a reply other than `expect` is a failure."""
        msg = dict(msg)
        msg["id"] = self.new_id()
        soak = self.soak
        soak.count(soak.sent, kind)
        await self.send(msg)
        r = await self.reply(timeout or soak.args.reply_timeout)
        judged = self.judge(kind, msg, r, expect)
        if judged is None:
            await dump_failure(soak, kind, msg, r)
        return judged

    def judge(self, kind, msg, r, expect):
        soak = self.soak
        rtype = r.get("type")
        label = rtype if rtype != "error" else f"error:{r.get('code')}"
        soak.count(soak.replies, label)
        if r.get("id") != msg["id"]:
            soak.fail(f"{self.name}: {kind}: reply id {r.get('id')!r}, sent {msg['id']!r}")
            return None
        if rtype != expect:
            shown = {k: (v if k != "data" else f"<{len(v)} chars>") for k, v in msg.items()}
            soak.fail(f"{self.name}: {kind} {H.short(shown, 300)} answered {H.short(r, 400)}")
            return None
        soak.count(soak.acked, kind)
        return r

    async def subscribe(self, view):
        r = await self.ask("subscribe", {"type": "subscribe", "view": view}, "subscribed")
        if r:
            self.sub_views[r["subscription"]] = (view["width"], view["height"])
            return r["subscription"]
        return None

    async def unsubscribe(self, sub):
        r = await self.ask("unsubscribe", {"type": "unsubscribe", "subscription": sub}, "ack")
        self.last_frame_at.pop(sub, None)
        return r

    async def idle(self, seconds):
        end = time.monotonic() + seconds
        while not self.soak.done and time.monotonic() < end:
            await self.pump(min(0.5, end - time.monotonic()))
            if self.stray:
                for r in self.stray:
                    self.soak.fail(f"{self.name}: reply nobody asked for: {H.short(r)}")
                self.stray.clear()


async def dump_failure(soak, kind, msg, reply):
    """The request, its reply and the world state then, for the first few failures, in
    failure-N.json in the scratch directory (read on a connection of its own)."""
    n = len(soak.failures)
    if n > 5 or soak.daemon.proc.poll() is not None:
        return
    record = {"kind": kind, "request": {k: v for k, v in msg.items() if k != "data"},
              "reply": {k: v for k, v in reply.items() if k != "_binary"},
              "real_s": soak.elapsed(), "phase": soak.phase}
    try:
        c = await H.Client.connect(soak.daemon.url(), "dump")
        record["state"] = (await c.get_state())["state"]
        await c.close()
    except Exception as e:  # noqa: BLE001 - the dump is a help, not a check
        record["state_error"] = repr(e)
    path = os.path.join(soak.args.scratch, f"failure-{n}.json")
    with open(path, "w") as f:
        json.dump(record, f, indent=1)
    print(f"soak: request, reply and state written to {path}", flush=True)


async def connect(soak, name):
    c = await SoakClient.connect(soak.daemon.url(), name)
    c.setup(soak)
    return c


# ------------------------------------------------------------------------------------------
# The controller


class Controller:
    def __init__(self, soak, client, draw, reference):
        self.soak, self.c, self.draw, self.reference = soak, client, draw, reference
        self.window = soak.args.window
        self.pending = []  # (kind, msg) in the order sent

    async def send(self, kind, msg, expect="ack"):
        while len(self.pending) >= self.window:
            await self.collect()
        msg = dict(msg)
        msg["id"] = self.c.new_id()
        self.soak.count(self.soak.sent, kind)
        if msg["type"] == "set":
            flat = leaves(msg["patch"])
            self.soak.fields_set.update(flat)
            for p, v in flat.items():
                if isinstance(v, str):
                    self.soak.enum_values_set.add(f"{p}={v}")
            self.soak.log(f"{kind}: {json.dumps(msg['patch'])}")
        else:
            self.soak.log(f"{kind}: {H.short({k: v for k, v in msg.items() if k != 'data'})}")
        await self.c.send(msg)
        self.pending.append((kind, msg, expect))

    async def match(self, reply):
        """Judges `reply` as the answer to the oldest request in flight."""
        kind, msg, expect = self.pending.pop(0)
        if self.c.judge(kind, msg, reply, expect) is None:
            await dump_failure(self.soak, kind, msg, reply)

    async def collect(self):
        await self.match(await self.c.reply(self.soak.args.reply_timeout))

    async def drain(self):
        while self.pending:
            await self.collect()

    async def wait(self, seconds):
        """Reads for `seconds`: events, and the replies to requests in flight, in order (a
        reply read here and not matched would leave collect() waiting for it)."""
        end = time.monotonic() + seconds
        while True:
            remaining = end - time.monotonic()
            if remaining <= 0:
                return
            try:
                item = await self.c._dispatch(remaining)
            except asyncio.TimeoutError:
                return
            if item[0] != "reply":
                continue
            if not self.pending:
                self.soak.fail(f"controller: reply nobody asked for: {H.short(item[1])}")
                continue
            await self.match(item[1])

    async def set(self, flat, kind="set"):
        await self.send(kind, {"type": "set", "patch": nested(flat)})

    async def preset(self, kind, name, transition_s=None):
        m = {"type": "apply_preset", "kind": kind, "name": name}
        label = f"preset:{kind}"
        if transition_s is not None:
            m["transition_s"] = transition_s
            label += "+transition"
        await self.send(label, m)

    async def weather_map(self, fmt=None, size=None):
        m = self.draw.weather_map(fmt, size)
        await self.send(f"weather_map:{m['format']}", m)
        self.draw.map_uploaded = True

    async def clock_excursion(self, rng):
        """A clock jump or a time-scale excursion. The monitor leaves the simulated time
        across it out of the soak's count (clock_epoch is odd meanwhile)."""
        await self.drain()
        self.soak.clock_epoch += 1
        try:
            if rng.random() < 0.6:
                await self.set({"clock.utc": self.draw.value(self.draw.fields["clock.utc"])},
                               "set:clock")
            else:
                scale = self.draw.number(0, 100000)
                await self.set({"clock.time_scale": scale}, "set:clock")
                await self.drain()
                await self.wait(rng.uniform(0.2, 1.5))
                await self.set({"clock.time_scale": self.soak.args.time_scale}, "set:clock")
            await self.drain()
            await self.wait(1.2)  # the next stats sample shows the clock after it
        finally:
            self.soak.clock_epoch += 1

    async def coverage(self, rng):
        """Every kind of change once, every field, every enum value, the cost-capped sizes at
        their largest, before the baseline."""
        d = self.draw
        for kind, names in (("weather", WEATHER_PRESETS), ("atmosphere", ATMOSPHERE_PRESETS)):
            for name in names:
                await self.preset(kind, name)
        await self.preset("weather", "storm", 600)
        await self.weather_map("rgba8", (512, 512))
        await self.weather_map("png", (333, 77))
        groups = sorted({p.rsplit(".", 1)[0] for p in d.fields if p not in CLOCK_FIELDS})
        for g in groups:
            await self.set(d.patch([p for p in d.fields if p.rsplit(".", 1)[0] == g
                                    and p not in CLOCK_FIELDS]))
        for f in d.fields.values():
            if f.kind == "ENUM":
                for name in f.names:
                    await self.set(d.make_valid({f.path: name}))
        if not d.uncapped:
            await self.set(dict(COST_CAPS))  # the largest buffers the random draws can ask for
        await self.set({"weather.autopilot": "on", "weather.autopilot_seed": 7})
        await self.preset("weather", "broken", 300)
        await self.drain()
        for _ in range(2):
            await self.clock_excursion(rng)
        self.soak.clock_epoch += 1  # a pause, so that the pause is tried too
        try:
            await self.set({"clock.time_scale": 0}, "set:clock")
            await self.drain()
            await self.wait(1.0)
            await self.set({"clock.time_scale": self.soak.args.time_scale}, "set:clock")
            await self.drain()
            await self.wait(1.2)
        finally:
            self.soak.clock_epoch += 1

    async def random_change(self, rng):
        r = rng.random()
        if r < 0.62:
            await self.set(self.draw.random_patch())
        elif r < 0.72:
            transition = None
            if rng.random() < 0.6:
                transition = rng.choice([0, self.draw.number(1, 3600),
                                         self.draw.number(0, 604800)])
            await self.preset("weather", rng.choice(WEATHER_PRESETS), transition)
        elif r < 0.76:
            await self.preset("atmosphere", rng.choice(ATMOSPHERE_PRESETS))
        elif r < 0.81:
            await self.weather_map()
        elif r < 0.86:
            await self.set(self.draw.make_valid({
                "weather.autopilot": rng.choice(["on", "off"]),
                "weather.autopilot_seed": self.draw.integer(0, 2147483647)}))
        elif r < 0.90:
            await self.set(self.draw.make_valid({
                "weather.map_source": rng.choice(["client", "procedural"])}))
        elif r < 0.93:
            await self.clock_excursion(rng)
        else:
            await self.set(self.draw.patch(rng.sample(WEATHER_PARAMS, rng.randint(1, 14))))

    async def go_home(self, label):
        """The world state back to its initial values; subscribers to their home views; the
        median RSS over the settle is the `label` figure."""
        soak = self.soak
        soak.phase = "settle"
        await self.drain()
        await self.preset("weather", "clear", 0)
        await self.set(self.reference, "set:reference")
        await self.drain()
        soak.home_generation += 1
        gen = soak.home_generation
        deadline = time.monotonic() + 120
        while any(v != gen for v in soak.at_home.values()):
            if time.monotonic() > deadline:
                soak.fail(f"{label}: subscribers not back on their home views within 120 s")
                break
            await self.wait(0.2)
        await self.wait(2.0)  # the LUTs rebuilt and blended, a few frames of each view
        samples = []
        end = time.monotonic() + soak.args.settle_seconds
        while time.monotonic() < end:
            kib = rss_kib(soak.daemon.proc.pid)
            if kib:
                samples.append(kib)
            await self.wait(1.0)
        soak.settle[label] = samples
        parts = memory_kib(soak.daemon.proc.pid)
        print(f"soak: {label}: RSS median {statistics.median(samples) / 1024:.1f} MiB over "
              f"{len(samples)} samples at {soak.elapsed():.0f} s, {soak.sim_s / 60:.1f} "
              f"simulated min (now anon {parts.get('RssAnon', 0) / 1024:.1f}, file "
              f"{parts.get('RssFile', 0) / 1024:.1f}, shmem {parts.get('RssShmem', 0) / 1024:.1f}"
              f" MiB)", flush=True)

    async def random_changes(self, rng, done, deadline, late):
        """Random changes at random intervals until done(); a failure, late(), when the
        soak's elapsed real time passes `deadline` first."""
        while not done():
            if self.soak.elapsed() > deadline:
                self.soak.fail(late())
                return
            await self.random_change(rng)
            await self.wait(rng.expovariate(self.soak.args.changes_per_second))

    async def run(self):
        soak, args = self.soak, self.soak.args
        rng = random.Random(args.seed * 1000 + 1)
        await self.coverage(rng)
        await self.drain()
        soak.warm.add("controller")
        warm_until = args.warmup_minutes * 60
        await self.random_changes(
            rng, lambda: soak.sim_s >= warm_until and len(soak.warm) >= soak.warm_needed,
            warm_until / args.time_scale * 2 + 300,
            lambda: f"warm-up not done after {soak.elapsed():.0f} s: "
                    f"{sorted(soak.warm)} of {soak.warm_needed}")
        await self.go_home("baseline")
        soak.phase = "random"
        target = soak.sim_s + args.simulated_minutes * 60
        settle_sim = (args.settle_seconds + 5) * args.time_scale
        deadline = soak.elapsed() + args.expected_real_s * 2 + 120
        await self.random_changes(
            rng, lambda: soak.sim_s >= target - settle_sim, deadline,
            lambda: f"the simulated clock reached {soak.sim_s / 60:.1f} min of "
                    f"{target / 60:.1f} in {soak.elapsed():.0f} s")
        await self.go_home("end")
        while soak.sim_s < target and soak.elapsed() < deadline:
            await self.wait(0.5)
        soak.done = True


# ------------------------------------------------------------------------------------------
# The other clients


async def subscriber(soak, index, draw_seed):
    draw = Draw(random.Random(draw_seed), [], True)
    rng = draw.rng
    name = f"sub{index}"
    home = HOME_VIEWS[index]
    c = await connect(soak, name)
    subs = {}  # subscription -> view
    try:
        # Warm-up: every stream size once, one frame each, then home.
        order = STREAM_SIZES[index:] + STREAM_SIZES[:index]
        for size in order:
            view = draw.view(STREAM_SIZES, MAX_STREAM, size)
            view["fps"] = 10
            sub = await c.subscribe(view)
            if sub is None:
                continue
            seen = c.subscription_frames
            deadline = time.monotonic() + soak.args.reply_timeout
            while c.subscription_frames == seen and time.monotonic() < deadline:
                await c.pump(0.2)
            if c.subscription_frames == seen:
                soak.fail(f"{name}: no frame for {size[0]}x{size[1]} within "
                          f"{soak.args.reply_timeout:.0f} s")
            await c.unsubscribe(sub)
        sub = await c.subscribe(home)
        subs[sub] = home
        soak.warm.add(name)
        at_gen = 0
        while not soak.done:
            if soak.phase == "settle":
                if at_gen != soak.home_generation:
                    for s in [s for s, v in subs.items() if v is not home]:
                        await c.unsubscribe(s)
                        del subs[s]
                    if not subs:
                        subs[await c.subscribe(home)] = home
                    at_gen = soak.home_generation
                    soak.at_home[name] = at_gen
                await c.idle(0.5)
                continue
            await c.idle(rng.uniform(2, 8))
            if soak.done or soak.phase == "settle":
                continue
            r = rng.random()
            if r < 0.5 or len(subs) >= 3:  # a new view in place of one
                old = rng.choice(list(subs))
                view = draw.view(STREAM_SIZES, MAX_STREAM)
                new = await c.subscribe(view)
                if new is not None:
                    subs[new] = view
                await c.unsubscribe(old)
                del subs[old]
            elif r < 0.75:  # another at once, sometimes the same view as another client's
                view = (dict(rng.choice(HOME_VIEWS)) if rng.random() < 0.4
                        else draw.view(STREAM_SIZES, MAX_STREAM))
                new = await c.subscribe(view)
                if new is not None:
                    subs[new] = view
            elif len(subs) > 1:
                old = rng.choice(list(subs))
                await c.unsubscribe(old)
                del subs[old]
            if not subs:
                subs[await c.subscribe(home)] = home
    finally:
        soak.at_home.pop(name, None)
        await c.close()


async def viewer(soak, seed):
    draw = Draw(random.Random(seed), [], True)
    rng = draw.rng
    c = await connect(soak, "viewer")

    async def snapshot(size=None):
        view = draw.view(SNAPSHOT_SIZES, MAX_SNAPSHOT, size)
        r = await c.ask("snapshot", {"type": "snapshot", "view": view}, "frame")
        if r:
            soak.snapshots += 1
            c.check_frame(r, r.get("_binary"), (view["width"], view["height"]), "snapshot")

    async def other():
        k = rng.random()
        if k < 0.4:
            await c.ask("probe", draw.probe(), "probe_result")
        elif k < 0.6:
            await c.ask("stats", {"type": "stats"}, "stats")
        elif k < 0.8:
            await c.ask("list_presets", {"type": "list_presets",
                                         "kind": rng.choice(["weather", "atmosphere"])},
                        "presets")
        else:
            await c.ask("get_state", {"type": "get_state"}, "state")

    try:
        for size in SNAPSHOT_SIZES:
            await snapshot(size)
        for _ in range(6):
            await other()
        soak.warm.add("viewer")
        while not soak.done:
            if soak.phase == "settle":
                await c.idle(0.5)
                continue
            await c.idle(rng.uniform(0.5, 3))
            if soak.done or soak.phase == "settle":
                continue
            if rng.random() < 0.5:
                await snapshot()
            else:
                await other()
    finally:
        await c.close()


async def churn(soak, seed):
    rng = random.Random(seed)
    loop = asyncio.get_running_loop()
    connections = 0
    soak.warm.add("churn")
    while not soak.done:
        await asyncio.sleep(rng.uniform(1, 5))
        if soak.done or soak.phase == "settle":
            continue
        connections += 1
        soak.count(soak.sent, "connect")
        if rng.random() < 0.3:  # gone without a close frame, a subscription open
            def abrupt():
                s = H.raw_ws_connect(soak.daemon.port)
                H.raw_ws_send_text(s, json.dumps({"type": "subscribe", "id": 1,
                                                  "view": {"width": 32, "height": 18}}))
                time.sleep(0.3)
                s.close()
            try:
                await loop.run_in_executor(None, abrupt)
                soak.count(soak.acked, "connect")
            except Exception as e:  # noqa: BLE001 - reported as a failure
                soak.fail(f"churn: raw connection: {e!r}")
            continue
        try:
            c = await connect(soak, "churn")
            soak.count(soak.acked, "connect")
            if rng.random() < 0.5:
                sub = await c.subscribe({"width": rng.randint(1, 128), "height":
                                         rng.randint(1, 72)})
                if sub is not None:
                    await c.wait_frame(timeout=soak.args.reply_timeout)
            await c.close()
        except Exception as e:  # noqa: BLE001 - reported as a failure
            soak.fail(f"churn: {e!r}")
    soak.churned = connections


async def monitor(soak):
    """Stats every second (the simulated clock), RSS every --rss-interval, the daemon alive."""
    c = await connect(soak, "monitor")
    last_rss = 0.0
    try:
        while not soak.done:
            if soak.daemon.proc.poll() is not None:
                soak.fail(f"the daemon died (status {soak.daemon.proc.returncode})")
                soak.done = True
                break
            epoch = soak.clock_epoch
            r = await c.ask("stats", {"type": "stats"}, "stats")
            if r:
                sim = r.get("simulation_time_s")
                soak.render_fps.append(r.get("fps"))
                if (soak.last_sim is not None and epoch == soak.last_sim[1] and epoch % 2 == 0
                        and soak.clock_epoch == epoch and sim >= soak.last_sim[0]):
                    soak.sim_s += sim - soak.last_sim[0]
                soak.last_sim = (sim, soak.clock_epoch)
            if soak.elapsed() - last_rss >= soak.args.rss_interval:
                last_rss = soak.elapsed()
                kib = rss_kib(soak.daemon.proc.pid)
                if kib:
                    soak.rss.append((soak.elapsed(), soak.sim_s, kib, soak.phase))
            await c.idle(1.0)
    finally:
        await c.close()


# ------------------------------------------------------------------------------------------
# The run


def reference_patch(state):
    """The initial state as a patch that can be sent back at any time: without the fields the
    simulation keeps or moves, and without the angles the ephemeris places."""
    flat = leaves(state)
    for p in list(flat):
        if p.startswith("weather.transition.") or p in CLOCK_FIELDS or \
                p in ("weather.offset_east_km", "weather.offset_north_km"):
            del flat[p]
    if flat.get("clock.sky_bodies") == "ephemeris":
        for p in EPHEMERIS_ANGLES:
            del flat[p]
    return flat


def check_schema(fields, state):
    """The field table must name exactly the leaves get_state returns (the transition's ends
    are rows of a macro the table reader skips: read-only, never drawn)."""
    table = {f.path for f in fields}
    got = {p for p in leaves(state) if not re.match(r"weather\.transition\.(from|to)\.", p)}
    missing, extra = sorted(got - table), sorted(table - got)
    if missing or extra:
        raise SystemExit(f"soak: protocol/world_fields.c and get_state disagree: not in the "
                         f"table {missing}, not in the state {extra}")


def summary_of(values):
    values = sorted(values)
    return (f"min {values[0] / 1024:.1f}, median {statistics.median(values) / 1024:.1f}, "
            f"max {values[-1] / 1024:.1f}")


async def soak_main(args, soak, fields):
    soak.daemon.start()
    pid = soak.daemon.proc.pid
    print(f"soak: daemon pid {pid} on {soak.daemon.url()}, scratch {args.scratch}", flush=True)
    ctl = await connect(soak, "controller")
    await ctl.auth()
    state = (await ctl.get_state())["state"]
    check_schema(fields, state)
    draw = Draw(random.Random(args.seed), fields, args.uncapped)
    controller = Controller(soak, ctl, draw, reference_patch(state))
    soak.warm_needed = 2 + len(HOME_VIEWS) + 1  # controller, viewer, subscribers, churn
    tasks = [asyncio.ensure_future(monitor(soak))]
    tasks += [asyncio.ensure_future(subscriber(soak, i, args.seed * 1000 + 10 + i))
              for i in range(len(HOME_VIEWS))]
    tasks.append(asyncio.ensure_future(viewer(soak, args.seed * 1000 + 20)))
    tasks.append(asyncio.ensure_future(churn(soak, args.seed * 1000 + 30)))
    main = asyncio.ensure_future(controller.run())
    everything = tasks + [main]
    try:
        while not all(t.done() for t in everything):
            await asyncio.wait(everything, return_when=asyncio.FIRST_EXCEPTION)
            for t in everything:
                if t.done() and not t.cancelled() and t.exception() and not soak.done:
                    soak.fail(f"a client stopped: {t.exception()!r}")
                    soak.done = True
            if soak.done:
                await asyncio.wait(everything, timeout=args.reply_timeout + 10)
                break
    finally:
        for t in everything:
            if not t.done():
                t.cancel()
        for t in everything:
            if t.done() and not t.cancelled() and t.exception() and \
                    not any("a client stopped" in f for f in soak.failures):
                soak.fail(f"a client stopped: {t.exception()!r}")
        await ctl.close()
    status = await soak.daemon.terminate_async()
    if status != 0:
        soak.fail(f"the daemon exited with status {status} after SIGTERM")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--skyd", default=os.path.join(ROOT, "build", "skyd"))
    p.add_argument("--simulated-minutes", type=float)
    p.add_argument("--time-scale", type=float)
    p.add_argument("--real-seconds", type=float)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--changes-per-second", type=float, default=4.0,
                   help="mean rate of the controller's changes (default 4)")
    p.add_argument("--window", type=int, default=3,
                   help="controller requests in flight at once (default 3)")
    p.add_argument("--warmup-minutes", type=float, default=10.0,
                   help="simulated minutes of random changes before the baseline (default 10)")
    p.add_argument("--settle-seconds", type=float, default=10.0)
    p.add_argument("--rss-interval", type=float, default=2.0)
    p.add_argument("--max-growth-percent", type=float, default=5.0)
    p.add_argument("--reply-timeout", type=float, default=60.0)
    p.add_argument("--no-validation", action="store_true",
                   help="without the validation layer, to tell its memory from the daemon's "
                   "(such a run cannot pass)")
    p.add_argument("--uncapped", action="store_true",
                   help="draw LUT sizes and cloud step counts from their whole ranges")
    p.add_argument("--shader-cache", help="Mesa shader cache directory for the daemon "
                   "(default: a new empty one in the scratch directory)")
    p.add_argument("--scratch", help="state, config and log directory (default: a new one "
                   "under build/)")
    p.add_argument("--rss-csv", help="write the RSS samples (real s, simulated s, KiB, phase) "
                   "to this file")
    p.add_argument("--verbose", action="store_true", help="print every change")
    args = p.parse_args()
    given = [x is not None for x in (args.simulated_minutes, args.time_scale, args.real_seconds)]
    if all(given):
        p.error("give at most two of --simulated-minutes, --time-scale, --real-seconds")
    if args.real_seconds is not None:
        if args.time_scale is None:
            args.simulated_minutes = 30.0 if args.simulated_minutes is None \
                else args.simulated_minutes
            args.time_scale = args.simulated_minutes * 60 / args.real_seconds
        else:
            args.simulated_minutes = args.time_scale * args.real_seconds / 60
    else:
        args.simulated_minutes = 30.0 if args.simulated_minutes is None \
            else args.simulated_minutes
        args.time_scale = 10.0 if args.time_scale is None else args.time_scale
    if not (0 < args.time_scale <= 100000) or args.simulated_minutes <= 0 \
            or args.warmup_minutes < 0:
        p.error("the time scale must be in (0, 100000], the simulated minutes positive and the "
                "warm-up minutes not negative")
    args.expected_real_s = args.simulated_minutes * 60 / args.time_scale
    if not os.access(args.skyd, os.X_OK):
        p.error(f"{args.skyd} is not an executable; build first (make build)")
    if args.scratch:
        os.makedirs(args.scratch, exist_ok=True)
        if os.listdir(args.scratch):
            p.error(f"--scratch {args.scratch} is not empty")
    else:
        parent = os.path.join(ROOT, "build")
        os.makedirs(parent, exist_ok=True)
        args.scratch = tempfile.mkdtemp(prefix="soak-", dir=parent)
    args.scratch = os.path.abspath(args.scratch)
    args.skyd = os.path.abspath(args.skyd)
    return args


def main():
    args = parse_args()
    fields = read_field_table(os.path.join(ROOT, "protocol", "world_fields.c"))
    if not fields:
        print("soak: no fields found in protocol/world_fields.c", file=sys.stderr)
        return 2
    soak = Soak(args)
    config = H.make_config(args.scratch, os.path.join(args.scratch, "state.json"),
                           max_clients=32, max_width=1920, max_height=1080, max_fps=30,
                           control_messages_per_second=200, max_message_bytes=65536,
                           max_upload_bytes=2097152)
    config["render"]["validation"] = not args.no_validation  # the switch --validation sets
    config["initial_state"] = {
        "clock": {"utc": "2026-06-21T05:00:00Z", "time_scale": args.time_scale,
                  "sky_bodies": "ephemeris"},
        "clouds": {"low": {"coverage": 0.35}, "high": {"coverage": 0.2}},
    }
    shader_cache = args.shader_cache or os.path.join(args.scratch, "shader-cache")
    os.makedirs(shader_cache, exist_ok=True)
    soak.daemon = H.Daemon(args.skyd, args.scratch, "skyd", config,
                           env={"MESA_SHADER_CACHE_DIR": os.path.abspath(shader_cache)})
    print(f"soak: {args.simulated_minutes:g} simulated minutes measured after a "
          f"{args.warmup_minutes:g}-minute warm-up, at time scale {args.time_scale:g} (about "
          f"{args.expected_real_s + args.warmup_minutes * 60 / args.time_scale:.0f} real s), "
          f"seed {args.seed}", flush=True)
    try:
        asyncio.run(soak_main(args, soak, fields))
    except RuntimeError as e:
        if soak.daemon.proc is None or soak.daemon.port is None:
            print(f"soak: the daemon did not start: {e}", file=sys.stderr)
            return 2
        raise
    except KeyboardInterrupt:
        soak.daemon.kill()
        raise
    finally:
        soak.daemon.kill()
    return report(args, soak)


def report(args, soak):
    if args.rss_csv:
        with open(args.rss_csv, "w") as f:
            f.write("real_s,simulated_s,rss_kib,phase\n")
            for t, sim, kib, phase in soak.rss:
                f.write(f"{t:.1f},{sim:.0f},{kib},{phase}\n")
    with open(soak.daemon.log_path, errors="replace") as f:
        log = f.read().splitlines()
    validation = [line for line in log if line.startswith(VALIDATION_PREFIX)]
    if args.no_validation:
        soak.fail("run with --no-validation")
    elif not any("validation on" in line for line in log):
        soak.fail("the daemon's log does not say 'validation on': the layer did not load, so "
                  "no validation message could have been counted")
    for line in validation[:5]:
        print(f"soak: {line}", flush=True)
    if validation:
        soak.fail(f"{len(validation)} Vulkan validation messages (log {soak.daemon.log_path})")
    if H.failed:
        soak.fail(f"{H.failed} protocol checks failed in the client")

    base = statistics.median(soak.settle["baseline"]) if soak.settle.get("baseline") else None
    end = statistics.median(soak.settle["end"]) if soak.settle.get("end") else None
    growth = (end - base) / base * 100 if base and end else float("nan")
    if not (growth < args.max_growth_percent):
        soak.fail(f"RSS growth {growth:.2f} % (limit {args.max_growth_percent:g} %)")
    all_rss = [k for _, _, k, _ in soak.rss] + soak.settle.get("baseline", []) + \
        soak.settle.get("end", [])
    peak = max(all_rss) if all_rss else 0
    random_phase = [(t, k) for t, _, k, ph in soak.rss if ph == "random"]
    if len(random_phase) >= 3:
        n = len(random_phase)
        mt = sum(t for t, _ in random_phase) / n
        mk = sum(k for _, k in random_phase) / n
        den = sum((t - mt) ** 2 for t, _ in random_phase)
        slope = sum((t - mt) * (k - mk) for t, k in random_phase) / den if den else 0.0
        print(f"soak: RSS during the random phase: {summary_of([k for _, k in random_phase])} "
              f"MiB over {n} samples, trend {slope * 60 / 1024:+.2f} MiB per real minute",
              flush=True)
    if soak.rss:
        tenths = []
        span = soak.rss[-1][0] or 1
        for i in range(10):
            part = [k for t, _, k, _ in soak.rss if i * span / 10 <= t < (i + 1) * span / 10
                    or (i == 9 and t == span)]
            if part:
                tenths.append(f"{max(part) / 1024:.0f}")
        print(f"soak: RSS series ({len(soak.rss)} samples every {args.rss_interval:g} s): "
              f"{summary_of([k for _, _, k, _ in soak.rss])} MiB; peak per tenth of the run: "
              f"{' '.join(tenths)} MiB", flush=True)
    fps = [f for f in soak.render_fps if isinstance(f, (int, float))]
    if fps:
        print(f"soak: daemon render fps (distinct views per s): median "
              f"{statistics.median(fps):.1f}, min {min(fps):.1f}; longest gap between two "
              f"frames of one subscription: " + ", ".join(
                  f"{k} {v:.1f} s" for k, v in sorted(soak.max_frame_gap.items())), flush=True)
    writable = [f for f in soak_fields(args) if not f.read_only]
    print(f"soak: fields set {len(soak.fields_set & {f.path for f in writable})} of "
          f"{len(writable)}, enum values {len(soak.enum_values_set)}; replies by type: "
          + ", ".join(f"{k} {v}" for k, v in sorted(soak.replies.items())), flush=True)
    if len(soak.failures) > 20:
        print(f"soak: ... and {len(soak.failures) - 20} more failures", flush=True)

    kinds = sorted(set(soak.sent) | set(soak.acked))
    changes = ", ".join(f"{k} {soak.acked.get(k, 0)}/{soak.sent.get(k, 0)}" for k in kinds)
    frames = ", ".join(f"{k} {v}" for k, v in sorted(soak.frames.items())
                       if k.startswith("sub"))
    verdict = "PASS" if not soak.failures else f"FAIL ({len(soak.failures)} failures)"
    print(f"soak: {verdict}: RSS baseline {fmt_mib(base)} end {fmt_mib(end)} peak "
          f"{peak / 1024:.1f} MiB, growth {growth:+.2f} %; acked/sent: {changes}; frames: "
          f"{frames}, snapshots {soak.snapshots}; simulated {soak.sim_s / 60:.1f} min in "
          f"{soak.elapsed():.0f} real s (time scale {args.time_scale:g}); validation messages "
          f"{len(validation)}; seed {args.seed}", flush=True)
    return 0 if not soak.failures else 1


def soak_fields(args):
    return read_field_table(os.path.join(ROOT, "protocol", "world_fields.c"))


def fmt_mib(kib):
    return f"{kib / 1024:.1f}" if kib else "n/a"


if __name__ == "__main__":
    sys.exit(main())
