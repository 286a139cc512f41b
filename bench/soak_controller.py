"""bench/soak.py's controller: random valid changes (set patches, presets, weather
transitions and maps, the autopilot, clock excursions) with a window of requests in flight, the
coverage pass of the warm-up, the settles that take the baseline and end RSS figures, the
faults of bench/soak_faults.py at their moments and the ledger's checks after them."""

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
from soak_bookkeeping import connect, dump_failure, memory_kib, rss_kib  # noqa: E402
from soak_fields import (ATMOSPHERE_PRESETS, CLOCK_FIELDS, COST_CAPS,  # noqa: E402
                         WEATHER_PRESETS)
from soak_schema import leaves, nested  # noqa: E402

# ------------------------------------------------------------------------------------------
# The controller


class Controller:
    def __init__(self, soak, client, draw, reference):
        self.soak, self.c, self.draw, self.reference = soak, client, draw, reference
        self.window = soak.args.window
        self.pending = []  # (kind, msg, expect) in the order sent
        self.faults = soak.faults  # soak_faults.FaultPlan, or None
        self.ledger = soak.ledger
        self.refusal = None  # "disk" or "unavailable": the refusal a fault makes valid
        self.warm_changes = 0

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
        if self.refusal and reply.get("type") == "error" and reply.get("id") == msg["id"]:
            text = str(reply.get("message"))
            if (self.refusal == "disk" and reply.get("code") == "internal"
                    and "cannot be saved" in text and "No space left on device" in text) or \
                    (self.refusal == "unavailable" and reply.get("code") == "unavailable"
                     and "redis://skyd:***@" in text):
                self.soak.count(self.soak.replies, f"error:{reply.get('code')} ({self.refusal})")
                self.faults.refused += 1
                return
        r = self.c.judge(kind, msg, reply, expect)
        if r is None:
            await dump_failure(self.soak, kind, msg, reply)
        elif r.get("type") == "ack" and self.ledger is not None:
            self.ledger.on_ack(r.get("revision"), kind, msg)

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

    async def random_changes(self, rng, done, deadline, late, before=None):
        """Random changes at random intervals until done(); a failure, late(), when the
        soak's elapsed real time passes `deadline` first. before(): a coroutine before each."""
        while not done():
            if self.soak.elapsed() > deadline:
                self.soak.fail(late())
                return
            if before is not None:
                await before()
            await self.random_change(rng)
            await self.wait(rng.expovariate(self.soak.args.changes_per_second))

    # --------------------------------------------------------------------------------------
    # Faults (bench/soak_faults.py) and the ledger's checks

    async def check_ledger(self, label, in_flight=()):
        """The daemon's state against the ledger of acknowledged changes."""
        if self.ledger is None:
            return
        await self.drain()
        await self.wait(1.0)  # the events of the last acknowledged changes
        r = await self.c.ask("get_state", {"type": "get_state"}, "state")
        if not r:
            return
        before = self.ledger.checked
        failures, rebased = self.ledger.check(label, r.get("state"), r.get("revision"),
                                              in_flight)
        for f in failures:
            self.soak.fail(f"ledger: {f}")
        print(f"soak: ledger {label}: revision {r.get('revision')} (last acknowledged "
              f"{self.ledger.max_acked}), {self.ledger.checked - before} fields as "
              f"acknowledged, {rebased} from changes whose ack was lost, {len(failures)} "
              f"wrong", flush=True)
        if self.soak.cluster is not None:  # node B follows the same world
            b = await self.soak.cluster.state_b(r.get("revision"))
            before = self.ledger.checked
            failures, _ = self.ledger.check(f"node B {label}", b.get("state"),
                                            b.get("revision"))
            for f in failures:
                self.soak.fail(f"ledger: {f}")
            print(f"soak: ledger node B {label}: revision {b.get('revision')}, "
                  f"{self.ledger.checked - before} fields as acknowledged, {len(failures)} "
                  f"wrong", flush=True)

    def check_state_file(self, label):
        """The state file itself against the ledger (what a restart would read)."""
        try:
            with open(self.soak.state_file) as f:
                saved = json.load(f)
        except (OSError, ValueError) as e:
            self.soak.fail(f"ledger: {label}: the state file cannot be read: {e}")
            return
        revision = saved.pop("revision", None)
        before = self.ledger.checked
        failures, _ = self.ledger.check(label, saved, revision)
        for f in failures:
            self.soak.fail(f"ledger: {f}")
        print(f"soak: ledger {label}: revision {revision}, {self.ledger.checked - before} "
              f"fields as acknowledged, {len(failures)} wrong", flush=True)

    async def kill_restart(self, rng):
        """kill -9 with requests in flight (one to three changes sent and not waited for), a
        restart on the same state file, and the ledger checked against what it restored."""
        soak = self.soak
        for _ in range(rng.randint(1, 3)):
            await self.set(self.draw.random_patch())
        in_flight = [(k, m) for k, m, _ in self.pending]
        self.pending = []
        old = soak.daemon.proc.pid
        loop = asyncio.get_running_loop()
        soak.restarting = True
        soak.clock_epoch += 1
        try:
            soak.daemon.proc.kill()
            await loop.run_in_executor(None, soak.daemon.proc.wait)
            t = time.monotonic()
            await loop.run_in_executor(None, soak.daemon.start)
            took = time.monotonic() - t
        finally:
            soak.generation += 1
            if soak.compile_watch is not None:  # a start reads what the last process made
                soak.compile_watch.mark_ready()
            soak.restarting = False
            soak.clock_epoch += 1
        soak.restarts += 1
        await self.c.close()
        self.c = await connect(soak, "controller")
        await self.c.auth()
        print(f"soak: fault: kill -9 of pid {old} with {len(in_flight)} requests in flight at "
              f"{soak.elapsed():.0f} s; pid {soak.daemon.proc.pid} listening after {took:.1f} s",
              flush=True)
        await self.check_ledger(f"after kill -9 #{soak.restarts}", in_flight)

    async def disk_fault(self, fault, rng):
        f, soak = self.faults, self.soak
        before = f.refused
        sent = 0
        f.set_disk_full(True)
        self.refusal = "disk"
        try:
            for _ in range(fault.params["changes"]):
                await self.random_change(rng)
                sent += 1
                await self.wait(rng.expovariate(soak.args.changes_per_second))
            await self.drain()
        finally:
            f.set_disk_full(False)
            self.refusal = None  # "disk" or "unavailable": the refusal a fault makes valid
        refused = f.refused - before
        soak.disk_refused += refused
        print(f"soak: fault: full disk for {sent} changes at {soak.elapsed():.0f} s: {refused} "
              f"refused", flush=True)
        if refused == 0:
            soak.fail("full disk: no change was refused: the fault did not reach the daemon")
        await self.check_ledger("after the full disk")
        self.check_state_file("state file after the full disk")

    async def clock_fault(self, fault):
        soak = self.soak
        print(f"soak: fault: wall clock stepped {fault.params['step_s']:+g} s for "
              f"{fault.params['hold_s']:g} s at {soak.elapsed():.0f} s", flush=True)
        self.faults.set_clock_offset(fault.params["step_s"])
        try:
            await self.wait(fault.params["hold_s"])
        finally:
            self.faults.set_clock_offset(0)
        soak.clock_steps += 1
        await self.wait(1.5)  # the monitor's next samples: the clock set right

    async def fault(self, fault, rng):
        if fault.kind == "kill":
            await self.kill_restart(rng)
        elif fault.kind == "disk":
            await self.disk_fault(fault, rng)
        elif fault.kind == "clock":
            await self.clock_fault(fault)
        elif fault.kind == "redis":
            await self.soak.cluster.restart_redis(self)

    async def run(self):
        soak, args = self.soak, self.soak.args
        rng = random.Random(args.seed * 1000 + 1)
        faults = self.faults
        await self.coverage(rng)
        await self.drain()
        soak.warm.add("controller")
        warm_until = [args.warmup_minutes * 60]

        async def warm_faults():
            self.warm_changes += 1
            for f in faults.due("warmup", self.warm_changes) if faults else []:
                await self.fault(f, rng)
                if not args.no_rss_verdict:  # the new process warmed as the first was
                    await self.coverage(rng)
                    await self.drain()
                    warm_until[0] = soak.sim_s + args.warmup_minutes * 60
        await self.random_changes(
            rng, lambda: soak.sim_s >= warm_until[0] and len(soak.warm) >= soak.warm_needed
            and not (faults and faults.pending("warmup")),
            args.warmup_minutes * 60 / args.time_scale * 4 + 600,
            lambda: f"warm-up not done after {soak.elapsed():.0f} s: "
                    f"{sorted(soak.warm)} of {soak.warm_needed}", warm_faults)
        await self.go_home("baseline")
        soak.phase = "random"
        start = soak.sim_s
        target = soak.sim_s + args.simulated_minutes * 60
        settle_sim = (args.settle_seconds + 5) * args.time_scale
        deadline = soak.elapsed() + args.expected_real_s * 2 + 120

        async def measured_faults():
            position = (soak.sim_s - start) / max(1.0, target - settle_sim - start)
            for f in faults.due("random", position) if faults else []:
                await self.fault(f, rng)
        await self.random_changes(
            rng, lambda: soak.sim_s >= target - settle_sim, deadline,
            lambda: f"the simulated clock reached {soak.sim_s / 60:.1f} min of "
                    f"{target / 60:.1f} in {soak.elapsed():.0f} s", measured_faults)
        for f in faults.due("random", 2.0) if faults else []:  # any the stretch left
            await self.fault(f, rng)
        await self.go_home("end")
        await self.check_ledger("at the end")
        while soak.sim_s < target and soak.elapsed() < deadline:
            await self.wait(0.5)
        soak.done = True
