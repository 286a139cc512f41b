#!/usr/bin/python3
"""Soak: the real daemon, with clients attached, under random valid changes for a stretch of
simulated time (300 minutes, 30 real ones, by default), with the Vulkan validation layer on.

Usage: /usr/bin/python3 bench/soak.py [--simulated-minutes 300] [--time-scale 10] [--seed 1] ...
       make soak SOAK_ARGS="--simulated-minutes 1200"   (two real hours)

Any two of --simulated-minutes, --time-scale and --real-seconds set the third (default: 300
simulated minutes at a time scale of 10, about 30 real minutes: long enough for the RSS slope,
which needs at least four 60-s blocks after its 120-s skip). The real seconds and the
simulated minutes are those measured, after the warm-up's --warmup-minutes (10).

The daemon (`skyd serve`, validation on, a scratch state directory) gets these clients:
  - a controller that sends random valid changes: `set` patches drawn from the world state's
    JSON Schema as `skyd schema` prints it (checked against what `get_state` returns) within
    each field's type, range, enum or array length, never a readOnly field; weather and
    atmosphere presets, weather transitions, `set_weather_map` uploads (rgba8 and PNG, 1x1 to
    512x512), the autopilot, clock jumps and time-scale excursions;
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
is there because the renderer's working set is reached by combinations, not by single changes.
It was first needed for the composite pipelines (specialized by output kind, camera in space,
sun in view, night, clouds, ground), each compiled at its first use: with the baseline right
after the single changes, runs of seeds 2 and 1 gave +4.5 % and +15.5 %, and in cluster runs
node A kept finding new combinations for hours. The daemon now makes and dispatches all of
them at start-up (ctest daemon_variants).

The daemon gets an empty Mesa shader cache of its own (MESA_SHADER_CACHE_DIR, in the scratch
directory; --shader-cache DIR to give one; with --no-rss-verdict, which judges no memory, the
user's). With the user's cache, most shader variants load
from it and LLVM's optimizer and code generator are first used at the first variant the cache
lacks, whenever the random changes happen to ask for one: about 11 MiB of libLLVM's code paged
in and about 20 MiB more anonymous memory, once per process. After the baseline that failed
runs at +13 %, and whether it did depended on what earlier runs had left in the cache. With an
empty cache the first compile comes at start-up, as on a fresh machine (docs/PERFORMANCE.md,
"Soak: where the memory went").

Memory is judged by its slope, not by the growth between the two settles (which is still
printed): a least-squares fit of VmRSS against real time over the measured random changes
after their first --slope-skip-s (120 s: RSS climbing back from the settle's reference state
to the random changes' working set), on block means of --slope-block-s (60 s) with the residuals' remaining autocorrelation taken into
account by an effective sample size (bench/soak_slope.py), in MiB per real and per simulated
hour with its 95 % interval, for VmRSS and its parts RssAnon, RssFile and RssShmem. A leak is
an interval wholly above zero whose upper end reaches --max-slope (1 MiB per real hour): an
interval that holds zero passes (a short run gives a wide one; the figure says how wide), and
so does a significantly positive slope known to be below the bound. Beside it, each daemon's C
heap from its /metrics (the heap in use and the free space glibc keeps) is sampled and its
slopes printed, unjudged, to tell a leak from the allocator's retention (bench/soak_heap.py).

Faults (bench/soak_faults.py; --no-faults for none), drawn from the seed and printed at the
start: a kill -9 of the daemon during the warm-up with changes in flight and a restart on its
state file (--kills; every client reconnects; when RSS is judged the coverage pass runs again,
so that the measured process is warmed as the first was), a full disk under the state file
(--disk-full; SKYD_FAULT_DIR, server/base/test_faults.h) and the wall clock stepped back
(--clock-back) in the measured stretch. A ledger of every acknowledged change
(bench/soak_ledger.py) is checked against the daemon's state after each fault and at the end,
and against the state file after the full disk. --cluster (bench/soak_cluster.py): a real
redis-server with AUTH and two nodes sharing a world, both soaked (each node's slope), the
ledger checked on both, and redis-server killed -9 and restarted (--redis-restarts).

Exit status 0 when the RSS slope passes (not judged with --no-rss-verdict), every fault did
what it should (changes refused on the full disk or while Redis was away, the clock step
logged by the daemon, the simulated clock never going back), the ledger holds, no
validation message, no refused or unanswered request, no bad frame, no subscription left
without a frame for longer than --reply-timeout (a client subscribes and never reads all along)
and the daemon alive and exiting 0 on SIGTERM; 1 otherwise; 2 for a bad command line or a daemon that does not start. The last line is a
one-line summary with the figures.

The code: bench/soak.py (the run, the command line and the report), soak_schema.py (the
fields of `skyd schema`), soak_fields.py (constants, random valid values), soak_bookkeeping.py
(the record, memory, the checking client), soak_controller.py (the controller) and
soak_clients.py (the other clients).
"""

import argparse
import asyncio
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# 30 real minutes at the default time scale of 10
DEFAULT_SIMULATED_MINUTES = 300.0
sys.path.insert(0, os.path.join(ROOT, "tests", "e2e"))
import serve_harness as H  # noqa: E402
from soak_bookkeeping import Soak, connect  # noqa: E402
from soak_clients import (churn, monitor, resilient, stalled_reader,  # noqa: E402
                          subscriber, viewer)
from soak_controller import Controller  # noqa: E402
from soak_cluster import Cluster, node_b_client, node_b_memory  # noqa: E402
from soak_compiles import CacheWatch  # noqa: E402
from soak_faults import FaultPlan  # noqa: E402
from soak_heap import heap_sampler, heap_slopes, write_csv as write_heap_csv  # noqa: E402
from soak_fields import (CLOCK_FIELDS, EPHEMERIS_ANGLES, HOME_VIEWS,  # noqa: E402
                         VALIDATION_PREFIX, Draw, weather_params)
from soak_ledger import Ledger  # noqa: E402
from soak_slope import fit_slope, measured_stretch  # noqa: E402
from soak_schema import (check_state, leaves, load_schema, schema_fields,  # noqa: E402
                         without_read_only)


# ------------------------------------------------------------------------------------------
# The run


# Writable fields the simulation moves on its own (the wind drifts the weather map): sent back
# as they were at the start they would move the map, not restore the state.
MOVED_BY_SIMULATION = ["weather.offset_east_km", "weather.offset_north_km"]


def reference_patch(state, fields):
    """The initial state as a patch that can be sent back at any time: without the schema's
    readOnly fields (the daemon refuses them), the clock, the fields the simulation moves,
    and the angles the ephemeris places."""
    flat = without_read_only(leaves(state), fields)
    for p in CLOCK_FIELDS + MOVED_BY_SIMULATION:
        flat.pop(p, None)
    if flat.get("clock.sky_bodies") == "ephemeris":
        for p in EPHEMERIS_ANGLES:
            flat.pop(p, None)
    return flat


def ledger_exclusions(fields):
    """Pointer prefixes of the fields the simulation moves without a revision: not checked
    against the ledger (bench/soak_ledger.py)."""
    paths = CLOCK_FIELDS + MOVED_BY_SIMULATION + EPHEMERIS_ANGLES + weather_params(fields)
    return ["/clock/", "/weather/transition/"] + ["/" + p.replace(".", "/") for p in paths]


def summary_of(values):
    values = sorted(values)
    return (f"min {values[0] / 1024:.1f}, median {statistics.median(values) / 1024:.1f}, "
            f"max {values[-1] / 1024:.1f}")


async def soak_main(args, soak, fields):
    soak.daemon.start()
    for watch in soak.compile_watches:  # node B listened before node A started
        watch.mark_ready()
    pid = soak.daemon.proc.pid
    print(f"soak: daemon pid {pid} on {soak.daemon.url()}, scratch {args.scratch}", flush=True)
    ctl = await connect(soak, "controller")
    await ctl.auth()
    state = (await ctl.get_state())["state"]
    check_state(fields, state)
    soak.ledger = Ledger(ledger_exclusions(fields),
                         ["/" + f.path.replace(".", "/") for f in fields if f.read_only])
    draw = Draw(random.Random(args.seed), fields, args.uncapped)
    controller = Controller(soak, ctl, draw, reference_patch(state, fields))
    soak.warm_needed = 2 + len(HOME_VIEWS) + 1  # controller, viewer, subscribers, churn
    tasks = [asyncio.ensure_future(resilient(soak, "monitor", lambda again: monitor(soak)))]
    tasks += [asyncio.ensure_future(resilient(
        soak, f"sub{i}", lambda again, i=i: subscriber(soak, i, args.seed * 1000 + 10 + i,
                                                       again)))
        for i in range(len(HOME_VIEWS))]
    tasks.append(asyncio.ensure_future(resilient(
        soak, "viewer", lambda again: viewer(soak, args.seed * 1000 + 20, again))))
    if soak.cluster is not None:
        tasks.append(asyncio.ensure_future(node_b_client(soak, soak.cluster,
                                                         args.seed * 1000 + 60)))
        tasks.append(asyncio.ensure_future(node_b_memory(soak, soak.cluster)))
        tasks.append(asyncio.ensure_future(heap_sampler(soak, soak.cluster.node_b,
                                                        soak.heap_b)))
    tasks.append(asyncio.ensure_future(heap_sampler(soak, soak.daemon, soak.heap)))
    tasks += [asyncio.ensure_future(watch.run(soak)) for watch in soak.compile_watches]
    tasks.append(asyncio.ensure_future(churn(soak, args.seed * 1000 + 30)))
    tasks.append(asyncio.ensure_future(stalled_reader(soak)))
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
        await controller.c.close()
    status = await soak.daemon.terminate_async()
    if status != 0:
        soak.fail(f"the daemon exited with status {status} after SIGTERM")
    if soak.cluster is not None:
        status = await soak.cluster.node_b.terminate_async()
        if status != 0:
            soak.fail(f"node B exited with status {status} after SIGTERM")


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
    p.add_argument("--max-slope", type=float, default=1.0,
                   help="MiB per real hour: RSS fails when the 95 %% interval of its slope "
                        "lies wholly above 0 and reaches this bound (default 1)")
    p.add_argument("--slope-skip-s", type=float, default=120.0,
                   help="real seconds at the start of the measured stretch left out of the "
                        "slope: RSS climbing back from the settle to the random changes' "
                        "working set (default 120)")
    p.add_argument("--slope-block-s", type=float, default=60.0,
                   help="real seconds per block mean of the slope fit (default 60)")
    p.add_argument("--no-rss-verdict", action="store_true",
                   help="report RSS without judging it (a run of a minute or two is too short "
                        "to tell a leak from the allocator's warm-up; make test's short soak)")
    p.add_argument("--reply-timeout", type=float, default=60.0)
    p.add_argument("--no-validation", action="store_true",
                   help="without the validation layer, to tell its memory from the daemon's "
                   "(such a run cannot pass)")
    p.add_argument("--uncapped", action="store_true",
                   help="draw LUT sizes and cloud step counts from their whole ranges")
    p.add_argument("--shader-cache", help="Mesa shader cache directory for the daemon "
                   "(default: a new empty one in the scratch directory; with "
                   "--no-rss-verdict, the user's)")
    p.add_argument("--scratch", help="state, config and log directory (default: a new one "
                   "under build/)")
    p.add_argument("--rss-csv", help="write the RSS samples (real s, simulated s, KiB, phase) "
                   "to this file, and the C heap's to F.heap.csv")
    p.add_argument("--no-faults", action="store_true",
                   help="no kill -9, full disk or clock step (bench/soak_faults.py)")
    p.add_argument("--kills", type=int, default=1,
                   help="kill -9 and restarts of the daemon during the warm-up (default 1)")
    p.add_argument("--disk-full", type=int, default=1,
                   help="full disks under the state file in the measured stretch (default 1)")
    p.add_argument("--clock-back", type=int, default=1,
                   help="wall-clock steps back in the measured stretch (default 1)")
    p.add_argument("--cluster", action="store_true",
                   help="a real redis-server (with AUTH) and two nodes sharing a world; both "
                        "soaked, each with its slope (bench/soak_cluster.py)")
    p.add_argument("--redis-restarts", type=int, default=1,
                   help="with --cluster: redis-server kill -9 and restarts (default 1)")
    p.add_argument("--verbose", action="store_true", help="print every change")
    args = p.parse_args()
    given = [x is not None for x in (args.simulated_minutes, args.time_scale, args.real_seconds)]
    if all(given):
        p.error("give at most two of --simulated-minutes, --time-scale, --real-seconds")
    if args.real_seconds is not None:
        if args.time_scale is None:
            args.simulated_minutes = DEFAULT_SIMULATED_MINUTES if args.simulated_minutes is None \
                else args.simulated_minutes
            args.time_scale = args.simulated_minutes * 60 / args.real_seconds
        else:
            args.simulated_minutes = args.time_scale * args.real_seconds / 60
    else:
        args.simulated_minutes = DEFAULT_SIMULATED_MINUTES if args.simulated_minutes is None \
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
    try:
        fields = schema_fields(load_schema(args.skyd))
    except (OSError, ValueError, subprocess.SubprocessError) as e:
        print(f"soak: `{args.skyd} schema state` gave no schema: {e}", file=sys.stderr)
        return 2
    if not [f for f in fields if not f.read_only]:
        print(f"soak: `{args.skyd} schema state` names no writable field", file=sys.stderr)
        return 2
    soak = Soak(args)
    soak.schema_fields = fields
    soak.state_file = os.path.join(args.scratch, "state.json")
    if args.no_faults:
        args.kills = args.disk_full = args.clock_back = args.redis_restarts = 0
    if args.cluster:
        args.disk_full = 0  # a node of a shared world writes no state file
        soak.cluster = Cluster(soak, args)
    soak.faults = FaultPlan(args, os.path.join(args.scratch, "faults"))
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
    env = {"SKYD_FAULT_DIR": soak.faults.dir}
    # The empty cache is for the RSS verdict; a run without one takes the user's, so that its
    # two starts load the variants rather than compile them (make test's short soak).
    if args.shader_cache or not args.no_rss_verdict:
        shader_cache = args.shader_cache or os.path.join(args.scratch, "shader-cache")
        os.makedirs(shader_cache, exist_ok=True)
        env["MESA_SHADER_CACHE_DIR"] = os.path.abspath(shader_cache)
    soak.daemon = H.Daemon(args.skyd, args.scratch, "skyd", config, env=env,
                           ready_timeout=H.EMPTY_SHADER_CACHE_READY_TIMEOUT)
    if not args.no_rss_verdict:  # the user's cache holds every variant already
        soak.compile_watch = CacheWatch("node A " if soak.cluster else "",
                                        env["MESA_SHADER_CACHE_DIR"])
        soak.compile_watches.append(soak.compile_watch)
    print(f"soak: {args.simulated_minutes:g} simulated minutes measured after a "
          f"{args.warmup_minutes:g}-minute warm-up, at time scale {args.time_scale:g} (about "
          f"{args.expected_real_s + args.warmup_minutes * 60 / args.time_scale:.0f} real s), "
          f"seed {args.seed}", flush=True)
    print(f"soak: faults (seed {args.seed}): {soak.faults.describe()}", flush=True)
    if soak.cluster is not None:
        config["cluster"] = soak.cluster.section()
        config_b = json.loads(json.dumps(config))
        config_b["state_file"] = os.path.join(args.scratch, "state-b.json")
        cache_b = os.path.join(args.scratch, "shader-cache-b")
        os.makedirs(cache_b, exist_ok=True)
        os.makedirs(os.path.join(args.scratch, "faults-b"), exist_ok=True)
        env_b = {"MESA_SHADER_CACHE_DIR": cache_b,
                 "SKYD_FAULT_DIR": os.path.join(args.scratch, "faults-b")}
        soak.compile_watches.append(CacheWatch("node B ", cache_b))
        try:
            soak.cluster.start_redis()
        except (OSError, RuntimeError, subprocess.SubprocessError) as e:
            print(f"soak: redis-server did not start: {e}", file=sys.stderr)
            return 2
        soak.daemon.config = config
    try:
        if soak.cluster is not None:
            soak.cluster.start_node_b(config_b, env_b)
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
        if soak.cluster is not None:
            soak.cluster.stop()
    return report(args, soak)


def report(args, soak):
    if args.rss_csv:
        with open(args.rss_csv, "w") as f:
            f.write("real_s,simulated_s,rss_kib,phase,anon_kib,file_kib,shmem_kib,pid\n")
            for t, sim, kib, phase, anon, file_, shmem, pid in soak.rss:
                f.write(f"{t:.1f},{sim:.0f},{kib},{phase},{anon},{file_},{shmem},{pid}\n")
        if soak.cluster is not None:
            with open(args.rss_csv + ".node-b.csv", "w") as f:
                f.write("real_s,simulated_s,rss_kib,phase,anon_kib,file_kib,shmem_kib,pid\n")
                for t, sim, kib, phase, anon, file_, shmem, pid in soak.cluster.rss_b:
                    f.write(f"{t:.1f},{sim:.0f},{kib},{phase},{anon},{file_},{shmem},{pid}\n")
        write_heap_csv(args.rss_csv + ".heap.csv", soak.heap)
        if soak.cluster is not None:
            write_heap_csv(args.rss_csv + ".node-b.heap.csv", soak.heap_b)
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
    steps = sum("the wall clock stepped back" in line for line in log)
    if steps < soak.clock_steps:
        soak.fail(f"{soak.clock_steps} wall-clock steps back made, the daemon logged {steps}: "
                  f"the fault did not reach it")
    undone = [str(f) for f in soak.faults.faults if not f.done]
    if undone and not soak.failures:
        soak.fail(f"faults never done: {'; '.join(undone)}")
    ledger = soak.ledger
    if ledger is not None:
        print(f"soak: faults: {soak.restarts} kill -9 and restarts (reconnections: "
              + (", ".join(f"{k} {v}" for k, v in sorted(soak.reconnects.items())) or "none")
              + f"), {soak.disk_refused} changes refused on a full disk, {soak.clock_steps} "
              f"wall-clock steps back (the daemon logged {steps}), "
              + (f"{soak.cluster.redis_restarts} redis-server kill -9 and restarts "
                 f"({soak.cluster.redis_refused} changes refused as unavailable), "
                 if soak.cluster else "")
              + f"ledger: {ledger.entries} "
              f"acknowledged changes, {ledger.checks} checks, {ledger.checked} fields compared",
              flush=True)

    base = statistics.median(soak.settle["baseline"]) if soak.settle.get("baseline") else None
    end = statistics.median(soak.settle["end"]) if soak.settle.get("end") else None
    growth = (end - base) / base * 100 if base and end else float("nan")
    slope = leak_slope(args, soak, soak.rss, "node A " if soak.cluster else "")
    heap_slopes(args, soak.heap, "node A " if soak.cluster else "")
    if soak.cluster is not None:
        slope = "node A " + slope + ", node B " + leak_slope(args, soak, soak.cluster.rss_b,
                                                             "node B ")
        heap_slopes(args, soak.heap_b, "node B ")
    # A daemon held up by the client that never reads would starve the others' streams.
    for name, gap in sorted(soak.max_frame_gap.items()):
        if gap > args.reply_timeout:
            soak.fail(f"{name}: {gap:.1f} s between two frames of one subscription (limit "
                      f"--reply-timeout {args.reply_timeout:g} s)")
    all_rss = [r[2] for r in soak.rss] + soak.settle.get("baseline", []) + \
        soak.settle.get("end", [])
    peak = max(all_rss) if all_rss else 0
    random_phase = [r[2] for r in soak.rss if r[3] == "random"]
    if random_phase:
        print(f"soak: RSS during the random phase: {summary_of(random_phase)} MiB over "
              f"{len(random_phase)} samples", flush=True)
    if soak.rss:
        tenths = []
        span = soak.rss[-1][0] or 1
        for i in range(10):
            part = [r[2] for r in soak.rss if i * span / 10 <= r[0] < (i + 1) * span / 10
                    or (i == 9 and r[0] == span)]
            if part:
                tenths.append(f"{max(part) / 1024:.0f}")
        print(f"soak: RSS series ({len(soak.rss)} samples every {args.rss_interval:g} s): "
              f"{summary_of([r[2] for r in soak.rss])} MiB; peak per tenth of the run: "
              f"{' '.join(tenths)} MiB", flush=True)
    fps = [f for f in soak.render_fps if isinstance(f, (int, float))]
    if fps:
        print(f"soak: daemon render fps (distinct views per s): median "
              f"{statistics.median(fps):.1f}, min {min(fps):.1f}; longest gap between two "
              f"frames of one subscription: " + ", ".join(
                  f"{k} {v:.1f} s" for k, v in sorted(soak.max_frame_gap.items())), flush=True)
    if soak.compile_watches:
        print("soak: shader cache entries written: "
              + ", ".join(w.summary() for w in soak.compile_watches), flush=True)
    writable = [f for f in soak.schema_fields if not f.read_only]
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
    print(f"soak: {verdict}: RSS slope {slope}; baseline {fmt_mib(base)} end {fmt_mib(end)} "
          f"peak {peak / 1024:.1f} MiB, growth {growth:+.2f} %; acked/sent: {changes}; frames: "
          f"{frames}, snapshots {soak.snapshots}; simulated {soak.sim_s / 60:.1f} min in "
          f"{soak.elapsed():.0f} real s (time scale {args.time_scale:g}); validation messages "
          f"{len(validation)}; seed {args.seed}", flush=True)
    return 0 if not soak.failures else 1


MEMORY_PARTS = (("VmRSS", 2), ("RssAnon", 4), ("RssFile", 5), ("RssShmem", 6))


def leak_slope(args, soak, rows, node=""):
    """The slopes of VmRSS and its parts over the measured random changes (bench/soak_slope.py),
    printed in MiB per real and per simulated hour with their 95 % intervals; the verdict on
    VmRSS's. Returns the one-line figure for the summary."""
    measured = measured_stretch(rows, args.slope_skip_s)
    real_s = measured[-1][0] - measured[0][0] if len(measured) > 1 else 0.0
    sim_s = measured[-1][1] - measured[0][1] if len(measured) > 1 else 0.0
    sim_per_real = sim_s / real_s if real_s > 0 else args.time_scale
    figure = "n/a"
    for name, col in MEMORY_PARTS:
        fit = fit_slope([(r[0], r[col], r[7]) for r in measured], args.slope_block_s)
        if fit is None:
            print(f"soak: {node}{name} slope: too few samples ({len(measured)} over {real_s:.0f} s; "
                  f"{args.slope_block_s:g}-s blocks, at least 4 needed)", flush=True)
            if name == "VmRSS" and not args.no_rss_verdict:
                soak.fail(f"{node}the measured stretch ({real_s:.0f} s) is too short for a "
                          f"slope")
            continue
        per_h = 3600 / 1024  # KiB/s -> MiB/h
        real = (fit["slope"] * per_h, fit["low"] * per_h, fit["high"] * per_h)
        sim = tuple(x / sim_per_real for x in real)
        text = (f"{real[0]:+.2f} MiB per real hour [{real[1]:+.2f}, {real[2]:+.2f}], "
                f"{sim[0]:+.3f} MiB per simulated hour [{sim[1]:+.3f}, {sim[2]:+.3f}]")
        print(f"soak: {node}{name} slope: {text} (95 %, {fit['n']} blocks of "
              f"{args.slope_block_s:g} s, residual lag-1 autocorrelation {fit['r1']:+.2f}, "
              f"n_eff {fit['n_eff']:.1f}, t {fit['t']:.2f})", flush=True)
        if name != "VmRSS":
            continue
        figure = f"{real[0]:+.2f} MiB/real h [{real[1]:+.2f}, {real[2]:+.2f}]"
        # A leak: the whole interval above zero and not all of it below the bound.
        if not args.no_rss_verdict and real[1] > 0 and not (real[2] < args.max_slope):
            soak.fail(f"{node}VmRSS grows: {real[0]:+.2f} MiB per real hour, 95 % interval "
                      f"[{real[1]:+.2f}, {real[2]:+.2f}] lies above 0 and reaches "
                      f"--max-slope {args.max_slope:g} MiB per real hour")
    return figure


def fmt_mib(kib):
    return f"{kib / 1024:.1f}" if kib else "n/a"


if __name__ == "__main__":
    sys.exit(main())
