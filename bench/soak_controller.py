"""bench/soak.py's controller: random valid changes (set patches, presets, weather
transitions and maps, the autopilot, clock excursions) with a window of requests in flight, the
coverage pass of the warm-up, and the settles that take the baseline and end RSS figures."""

import asyncio
import json
import os
import random
import statistics
import sys
import time

_E2E = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "e2e")
if _E2E not in sys.path:  # bench/soak.py puts it there; this for an import on its own
    sys.path.insert(0, _E2E)
import serve_harness as H  # noqa: E402
from soak_bookkeeping import dump_failure, memory_kib, rss_kib  # noqa: E402
from soak_fields import (ATMOSPHERE_PRESETS, CLOCK_FIELDS, COST_CAPS,  # noqa: E402
                         WEATHER_PRESETS)
from soak_schema import leaves, nested  # noqa: E402

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
            read_only = sorted(p for p in flat if p not in self.draw.fields)
            if read_only:  # a soak bug, not the daemon's: the daemon would refuse the patch
                self.soak.fail(f"controller: {kind} names fields the schema does not let a "
                               f"set change: {read_only}")
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
                scale = self.draw.value(self.draw.fields["clock.time_scale"])
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
            if f.enum:
                for name in f.enum:
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
            await self.set(self.draw.patch(["weather.autopilot", "weather.autopilot_seed"]))
        elif r < 0.90:
            await self.set(self.draw.patch(["weather.map_source"]))
        elif r < 0.93:
            await self.clock_excursion(rng)
        else:
            weather = self.draw.weather
            await self.set(self.draw.patch(rng.sample(weather, rng.randint(1, len(weather)))))

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
