"""bench/soak.py's other clients: the subscribers that keep changing their views, the viewer
taking snapshots, probes, stats, presets lists and states, the client that connects and
disconnects, the client that subscribes and never reads, and the monitor that reads stats (the
simulated clock, which must never go back) and samples RSS. Each reconnects after a kill -9
and restart of the daemon (resilient())."""

import asyncio
import json
import os
import random
import sys
import time

_E2E = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "e2e")
if _E2E not in sys.path:  # bench/soak.py puts it there; this for an import on its own
    sys.path.insert(0, _E2E)
import serve_harness as H  # noqa: E402
from soak_bookkeeping import connect, memory_kib  # noqa: E402
from soak_fields import (HOME_VIEWS, MAX_SNAPSHOT, MAX_STREAM, SNAPSHOT_SIZES,  # noqa: E402
                         STREAM_SIZES, Draw)

# ------------------------------------------------------------------------------------------
# The other clients


async def resilient(soak, name, run):
    """run(again) until it returns; when it stops on an exception because the daemon was
    killed and restarted (bench/soak_faults.py), again once the daemon is back, with
    again=True. Any other exception is the client's failure."""
    again = False
    while True:
        generation = soak.generation
        try:
            await run(again)
            return
        except Exception:
            if soak.done and soak.daemon.proc.poll() is not None:
                return
            if not (soak.restarting or soak.generation != generation):
                raise
        while soak.restarting:
            await asyncio.sleep(0.1)
        soak.count(soak.reconnects, name)
        again = True


async def subscriber(soak, index, draw_seed, again=False):
    draw = Draw(random.Random(draw_seed + 7919 * soak.generation), [], True)
    rng = draw.rng
    name = f"sub{index}"
    home = HOME_VIEWS[index]
    c = await connect(soak, name)
    subs = {}  # subscription -> view
    try:
        # Warm-up: every stream size once, one frame each, then home.
        order = STREAM_SIZES[index:] + STREAM_SIZES[:index]
        for size in order if not again else []:
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


async def viewer(soak, seed, again=False):
    draw = Draw(random.Random(seed + 7919 * soak.generation), [], True)
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
        for size in SNAPSHOT_SIZES if not again else []:
            await snapshot(size)
        for _ in range(6 if not again else 0):
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


def _open_stalled(port):
    s = H.raw_ws_connect(port)  # a 4 KiB receive buffer: the daemon's writes back up at once
    H.raw_ws_send_text(s, json.dumps({"type": "subscribe", "id": 1,
                                      "view": {"width": 320, "height": 180, "fps": 10}}))
    return s


async def stalled_reader(soak):
    """A client that subscribes to a stream and never reads a byte: the daemon must go on
    serving everyone else (the other clients' acks and frame gaps say whether it does)."""
    loop = asyncio.get_running_loop()
    soak.count(soak.sent, "stalled_reader")
    try:
        s = await loop.run_in_executor(None, _open_stalled, soak.daemon.port)
    except Exception as e:  # noqa: BLE001 - reported as a failure
        soak.fail(f"stalled reader: {e!r}")
        return
    soak.count(soak.acked, "stalled_reader")
    generation = soak.generation
    try:
        while not soak.done:
            await asyncio.sleep(0.5)
            if soak.generation != generation and not soak.restarting:  # the daemon restarted
                s.close()
                generation = soak.generation
                s = await loop.run_in_executor(None, _open_stalled, soak.daemon.port)
                soak.count(soak.reconnects, "stalled_reader")
    finally:
        s.close()


async def churn(soak, seed):
    rng = random.Random(seed)
    loop = asyncio.get_running_loop()
    connections = 0
    soak.warm.add("churn")
    while not soak.done:
        await asyncio.sleep(rng.uniform(1, 5))
        if soak.done or soak.phase == "settle" or soak.restarting:
            continue
        generation = soak.generation
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
                if not (soak.restarting or soak.generation != generation):
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
            if not (soak.restarting or soak.generation != generation):
                soak.fail(f"churn: {e!r}")
    soak.churned = connections


async def monitor(soak, again=False):
    """Stats every second (the simulated clock), RSS every --rss-interval, the daemon alive.
    Between two readings with no clock change of the controller's between them, the simulated
    clock must not go back, nor run ahead of the time scale (a wall clock stepped back or set
    right, bench/soak_faults.py)."""
    c = await connect(soak, "monitor")
    last_rss = 0.0
    try:
        while not soak.done:
            if soak.daemon.proc.poll() is not None and not soak.restarting:
                soak.fail(f"the daemon died (status {soak.daemon.proc.returncode})")
                soak.done = True
                break
            epoch = soak.clock_epoch
            asked = time.monotonic()
            r = await c.ask("stats", {"type": "stats"}, "stats")
            if r:
                sim = r.get("simulation_time_s")
                soak.render_fps.append(r.get("fps"))
                if (soak.last_sim is not None and epoch == soak.last_sim[1] and epoch % 2 == 0
                        and soak.clock_epoch == epoch):
                    step = sim - soak.last_sim[0]
                    real = time.monotonic() - soak.last_sim[2]
                    if step < -1e-3:
                        soak.fail(f"the simulated clock went back {-step:.3f} s")
                    elif step > soak.args.time_scale * (real + 5):
                        soak.fail(f"the simulated clock jumped {step:.0f} s ahead in {real:.1f} "
                                  f"real s at time scale {soak.args.time_scale:g}")
                    else:
                        soak.sim_s += step
                # A reading whose request overlapped a clock change may show the clock from
                # before it: it is no baseline for the next.
                soak.last_sim = (sim, epoch, asked) if soak.clock_epoch == epoch else None
            if soak.elapsed() - last_rss >= soak.args.rss_interval:
                last_rss = soak.elapsed()
                pid = soak.daemon.proc.pid
                m = memory_kib(pid)
                if m.get("VmRSS"):
                    soak.rss.append((soak.elapsed(), soak.sim_s, m["VmRSS"], soak.phase,
                                     m.get("RssAnon", 0), m.get("RssFile", 0),
                                     m.get("RssShmem", 0), pid))
            await c.idle(1.0)
    finally:
        await c.close()
