"""bench/soak.py's bookkeeping: the Soak record of what was sent, answered and measured, the
daemon's memory from /proc, and SoakClient, the harness client that checks every frame header
and judges every reply (a failure's request, reply and state dumped to failure-N.json)."""

import json
import math
import os
import struct
import sys
import time
import zlib

_E2E = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "e2e")
if _E2E not in sys.path:  # bench/soak.py puts it there; this for an import on its own
    sys.path.insert(0, _E2E)
import serve_harness as H  # noqa: E402
from soak_compiles import RecentRequests  # noqa: E402

# ------------------------------------------------------------------------------------------
# Bookkeeping


class Soak:
    def __init__(self, args):
        self.args = args
        self.schema_fields = []  # soak_schema.Field of `skyd schema state`
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
        self.rss = []          # (real s since start, simulated s, VmRSS KiB, phase, RssAnon,
        #                        RssFile, RssShmem KiB, daemon pid)
        self.settle = {}       # label -> [KiB]
        self.heap = []         # (real s, simulated s, C heap in use KiB, phase, its free KiB,
        #                        pid) from /metrics (bench/soak_heap.py)
        self.heap_b = []       # the same for node B in --cluster
        self.render_fps = []
        self.frames = {}       # client name -> subscription frames
        self.snapshots = 0
        self.max_frame_gap = {}
        self.t0 = time.monotonic()
        self.daemon = None
        self.state_file = None
        self.faults = None       # soak_faults.FaultPlan
        self.ledger = None       # soak_ledger.Ledger
        self.cluster = None
        self.restarting = False  # a kill -9 and restart under way
        self.generation = 0      # daemon starts since the first
        self.restarts = 0
        self.reconnects = {}     # client name -> reconnections after a restart
        self.disk_refused = 0
        self.clock_steps = 0
        self.recent = RecentRequests()  # every client's requests of the last seconds
        self.compile_watches = []       # soak_compiles.CacheWatch per daemon
        self.compile_watch = None       # the one of the daemon the clients use

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

    async def send(self, obj):
        if self.soak is not None and isinstance(obj, dict):
            self.soak.recent.add(self.name, H.short({k: v for k, v in obj.items()
                                                     if k not in ("data", "id")}))
        await super().send(obj)

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
            if self.name == "controller" and self.soak.ledger is not None:
                self.soak.ledger.on_event(item[1])
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
