#!/usr/bin/python3
"""Device faults on the real daemon: a lost Vulkan device and a failed device memory
allocation, provoked through SKYD_FAULT (render/vk/fault_injection.h: after N rendered frames,
the next queue submission reports VK_ERROR_DEVICE_LOST, or the next memory allocation
VK_ERROR_OUT_OF_DEVICE_MEMORY; lavapipe never does either by itself). Every daemon here runs
with the validation layer on and its log must hold no validation message, so a renderer
destroyed after a loss, or a create that failed half way, may leave no object behind.

Usage: /usr/bin/python3 tests/e2e/test_device_faults.py PATH_TO_SKYD SCRATCH_DIR

Frames are counted over the process, the start-up's warm-up frames included (W of them,
serve_harness.WARM_UP_FRAMES, again in each rebuilt renderer; each start checks the log's
count against it); where a check needs the fault to meet one request, a loop
finds the failing one instead of assuming that count.

1. A recovered loss (device_lost:after_frames=W+8), met while a subscriber streams, a
   controller sets the sun again and again and a viewer asks for snapshot after snapshot:
   the log reports it and the rebuild, frames come again (and show the last revision),
   /metrics counts the loss and /healthz is ok again, every
   set is acknowledged, every snapshot is answered (a frame, or an `internal` error saying the
   device was lost), and the revision, the state and the state file are the last
   acknowledged ones.
2. A loss the renderer cannot be rebuilt after (device_lost:after_frames=W+1:permanent: creating
   a device fails too): the snapshot that met it gets an `internal` error saying so, the
   client is closed with 1011, the daemon exits 1 within a bound, and the state file holds
   the last acknowledged state.
3. Losses that keep coming (device_lost:after_frames=W+1:times=3): two are rebuilt, the third
   within the minute stops the daemon the same way.
4. Out of device memory (out_of_memory:after_frames=W+5): a snapshot at a new size gets an
   `internal` error naming the image that could not be allocated and why; the subscriber at
   another size keeps its frames; the same snapshot then succeeds.

Bounded waits throughout; prints "N passed, M failed".
"""

import asyncio
import json
import os
import re
import shutil
import sys
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (HEADER, WARM_UP_FRAMES, Client, Daemon, check,  # noqa: E402
                           check_binary_frame, info, make_config, run_daemon_test, short,
                           stable, approx_equal, json_diff, start_up_frames)

EXIT_BOUND_S = 30.0     # a stopping daemon exits within this (it rebuilds nothing any more)
REBUILD_BOUND_S = 40.0  # a rebuild (cloud noise, warm-up frames) on a loaded 2-core machine
SUB_VIEW = {"width": 32, "height": 18, "fps": 10}


def start(skyd, scratch, name, fault):
    state_dir = os.path.join(scratch, name)
    shutil.rmtree(state_dir, ignore_errors=True)
    os.makedirs(state_dir)
    config = make_config(scratch, os.path.join(state_dir, "state.json"))
    config["render"]["validation"] = True
    d = Daemon(skyd, scratch, name, config, env={"SKYD_FAULT": fault})
    t = time.monotonic()
    try:
        d.start()
    except RuntimeError:
        if "rendering the start-up frames failed" in d.log_text():
            info(f"{name}: the fault met a start-up frame; its after_frames counts "
                 f"WARM_UP_FRAMES ({WARM_UP_FRAMES}): is that still the warm-up's count?")
        raise
    info(f"{name}: SKYD_FAULT={fault}, listening after {time.monotonic() - t:.1f} s")
    frames = start_up_frames(d.log_text())
    check(f"{name}: the start-up renders WARM_UP_FRAMES frames", frames == WARM_UP_FRAMES,
          f"the log says {frames}, serve_harness.py {WARM_UP_FRAMES}")
    return d


def http_text(port, path):
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=10) as r:
            return r.read().decode()
    except (OSError, urllib.error.URLError) as e:
        return f"(no answer: {e})"


def state_file(d):
    with open(d.config["state_file"]) as f:
        return json.load(f)


def check_log_clean(name, d):
    log = d.log_text()
    bad = [line for line in log.splitlines() if "vulkan validation" in line]
    check(f"{name}: no validation messages", not bad, short(bad))


def elevation(k):
    return round(1.0 + (k % 80) * 0.5, 2)


async def setter(ctl, acked, sent, errors, stop):
    """Sets the sun again and again until `stop` is set or the connection ends."""
    k = 0
    while not stop.is_set():
        k += 1
        value = elevation(k)
        sent.append(value)
        r = await ctl.request({"type": "set", "id": f"set-{k}",
                               "patch": {"sun": {"elevation_deg": value}}}, REBUILD_BOUND_S)
        if r.get("type") == "ack":
            acked.append((r.get("revision"), value))
        else:
            errors.append(r)
        await asyncio.sleep(0.05)


async def snapshots_until_error(name, client, width, height, limit=10):
    """Snapshots one after the other until one is answered with an error; returns the list of
    replies (the last the error, unless none came)."""
    replies = []
    for k in range(limit):
        r = await client.request({"type": "snapshot", "id": f"{name}-{k}",
                                  "view": {"width": width, "height": height}}, REBUILD_BOUND_S)
        replies.append(r)
        if r.get("type") != "frame":
            break
    return replies


def frame_revision(binary):
    return HEADER.unpack_from(binary)[4] if isinstance(binary, bytes) and len(binary) >= 48 \
        else None


async def pump_until(client, condition, timeout):
    """Reads the client's stream until condition() holds; False after timeout seconds."""
    deadline = time.monotonic() + timeout
    while not condition():
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            return False
        await client.pump(min(0.2, remaining))
    return True


async def snapshotter(viewer, replies, stop):
    """Snapshots one after the other until `stop` is set; every reply is kept."""
    k = 0
    while not stop.is_set():
        k += 1
        r = await viewer.request({"type": "snapshot", "id": f"snap-{k}",
                                  "view": {"width": 40, "height": 24}}, REBUILD_BOUND_S)
        replies.append((f"snap-{k}", r))


async def recovered(skyd, scratch):
    name = "recovered"
    d = start(skyd, scratch, name, f"device_lost:after_frames={WARM_UP_FRAMES + 8}")
    try:
        ctl = await Client.connect(d.url(), f"{name}-controller")
        await ctl.auth()
        before = await ctl.get_state()
        viewer = await Client.connect(d.url(), f"{name}-viewer")
        sub = await Client.connect(d.url(), f"{name}-subscriber")
        r = await sub.request({"type": "subscribe", "id": "sub", "view": SUB_VIEW})
        check(f"{name}: subscribed", r.get("type") == "subscribed", short(r))
        acked, sent, errors, snaps, stop = [], [], [], [], asyncio.Event()
        tasks = [asyncio.ensure_future(setter(ctl, acked, sent, errors, stop)),
                 asyncio.ensure_future(snapshotter(viewer, snaps, stop))]
        rebuilt = await pump_until(sub, lambda: "renderer rebuilt" in d.log_text(),
                                   REBUILD_BOUND_S)
        check(f"{name}: the loss is met while streaming, and the renderer rebuilt", rebuilt,
              d.log_tail())
        count_then = sum(sub.frame_count.values())
        resumed = await pump_until(sub, lambda: sum(sub.frame_count.values()) >= count_then + 5,
                                   15)
        check(f"{name}: frames come again after the rebuild", resumed,
              f"{sum(sub.frame_count.values()) - count_then} frames in 15 s")
        metrics = http_text(d.port, "/metrics")
        check(f"{name}: /metrics counts the loss",
              re.search(r"^skyd_device_losses_total 1$", metrics, re.M) is not None,
              "\n".join(line for line in metrics.splitlines() if "device_losses" in line))
        check(f"{name}: /healthz is ok again", '"status":"ok"' in http_text(d.port, "/healthz"))
        stop.set()
        await asyncio.wait_for(asyncio.gather(*tasks), REBUILD_BOUND_S)
        check(f"{name}: every set is acknowledged", not errors and len(acked) >= 5,
              f"{len(acked)} acks, errors {short(errors)}")
        # A snapshot rendered in the tick that lost the device is answered with an error
        # (which one, if any, depends on timing); every other one with its frame.
        bad = [(i, r) for i, r in snaps
               if not (r.get("type") == "frame" and r.get("id") == i) and
               not (r.get("type") == "error" and r.get("code") == "internal"
                    and r.get("id") == i and "device was lost" in r.get("message", ""))]
        check(f"{name}: every snapshot is answered, with its frame or the loss",
              snaps and not bad, short(bad or snaps))
        failed = [i for i, r in snaps if r.get("type") == "error"]
        check(f"{name}: snapshots succeed after the rebuild",
              snaps and snaps[-1][1].get("type") == "frame", short(snaps[-1:]))
        last_revision, last_value = acked[-1] if acked else (None, None)
        check(f"{name}: one revision per set", last_revision == before["revision"] + len(acked),
              f"before {before['revision']}, {len(acked)} acks, last {last_revision}")
        s = await ctl.get_state()
        check(f"{name}: the revision is the last acknowledged", s["revision"] == last_revision,
              f"state {s['revision']}, last ack {last_revision}")
        check(f"{name}: the sun is the last set",
              s["state"]["sun"]["elevation_deg"] == last_value,
              f"{s['state']['sun']['elevation_deg']} != {last_value}")
        expected = json.loads(json.dumps(before["state"]))
        expected["sun"]["elevation_deg"] = last_value
        check(f"{name}: nothing else in the state changed",
              approx_equal(stable(s["state"]), stable(expected)),
              json_diff(stable(expected), stable(s["state"])))

        def last_shown():
            return frame_revision(sub.frames[-1][1]) if sub.frames else None
        shown = await pump_until(sub, lambda: last_shown() == last_revision, 10)
        check(f"{name}: frames show the last revision", shown,
              f"last frame revision {last_shown()}, want {last_revision}")
        if sub.frames:
            m, b, _ = sub.frames[-1]
            check_binary_frame(f"{name}: a frame after the rebuild", m, b, SUB_VIEW["width"],
                               SUB_VIEW["height"], last_revision)
        info(f"{name}: {len(acked)} sets acknowledged, {len(snaps)} snapshots "
             f"({len(failed)} met the loss), {sum(sub.frame_count.values())} frames")
        log = d.log_text()
        check(f"{name}: the log reports the loss once",
              log.count("error: the Vulkan device was lost") == 1, d.log_tail())
        for c in (viewer, ctl, sub):
            await c.close()
        status = await d.terminate_async()
        check(f"{name}: SIGTERM still exits 0", status == 0, f"status {status}")
        saved = state_file(d)
        check(f"{name}: the state file holds the last acknowledged revision",
              saved.get("revision") == last_revision and
              saved["sun"]["elevation_deg"] == last_value,
              f"file revision {saved.get('revision')}, sun {saved['sun']['elevation_deg']}")
        check_log_clean(name, d)
    finally:
        d.kill()


async def check_stopped(name, d, client, expected, within=EXIT_BOUND_S):
    """The daemon stops by itself within `within` seconds: client closed with 1011, exit 1,
    the state saved as expected() says once it has exited: (last acknowledged, in flight or
    None), each a (revision, sun elevation) pair."""
    t = time.monotonic()
    status = await d.wait_exit(within)
    check(f"{name}: the daemon exits by itself within {within:.0f} s", status is not None,
          d.log_tail())
    if status is None:
        return
    info(f"{name}: exited {status} {time.monotonic() - t:.1f} s after the last check")
    check(f"{name}: exit status 1", status == 1, f"status {status}")
    try:
        await asyncio.wait_for(client.ws.wait_closed(), 10)
    except asyncio.TimeoutError:
        pass
    check(f"{name}: the client was closed with 1011", client.ws.close_code == 1011,
          f"close {client.ws.close_code} {client.ws.close_reason!r}")
    log = d.log_text()
    check(f"{name}: the log says it stops with the state saved",
          "skyd: stopped with the state saved" in log, d.log_tail())
    saved = state_file(d)
    got = (saved.get("revision"), saved.get("sun", {}).get("elevation_deg"))
    last, in_flight = expected()
    check(f"{name}: the state file holds the last acknowledged state",
          got == last or (in_flight is not None and got == in_flight),
          f"file {got}, last acknowledged {last}, in flight {in_flight}")


async def unrecoverable(skyd, scratch):
    name = "unrecoverable"
    d = start(skyd, scratch, name, f"device_lost:after_frames={WARM_UP_FRAMES + 1}:permanent")
    try:
        ctl = await Client.connect(d.url(), f"{name}-controller")
        await ctl.auth()
        last = None
        for k in range(3):
            r = await ctl.request({"type": "set", "id": k,
                                   "patch": {"sun": {"elevation_deg": 20.5 + k}}})
            check(f"{name}: set {k} acknowledged", r.get("type") == "ack", short(r))
            last = (r.get("revision"), 20.5 + k)
        replies = await snapshots_until_error(name, ctl, 40, 24)
        error = replies[-1]
        check(f"{name}: the snapshot that met the loss gets an internal error",
              error.get("type") == "error" and error.get("code") == "internal"
              and "device was lost" in error.get("message", ""), short(error))
        await check_stopped(name, d, ctl, lambda: (last, None))
        check(f"{name}: the log says the renderer could not be rebuilt",
              "the renderer could not be rebuilt" in d.log_text(), d.log_tail())
        check_log_clean(name, d)
    finally:
        d.kill()


async def repeated(skyd, scratch):
    name = "repeated"
    d = start(skyd, scratch, name, f"device_lost:after_frames={WARM_UP_FRAMES + 1}:times=3")
    try:
        ctl = await Client.connect(d.url(), f"{name}-controller")
        await ctl.auth()
        sub = await Client.connect(d.url(), f"{name}-subscriber")
        r = await sub.request({"type": "subscribe", "id": "sub", "view": SUB_VIEW})
        check(f"{name}: subscribed", r.get("type") == "subscribed", short(r))
        acked, sent, errors, stop = [], [], [], asyncio.Event()
        task = asyncio.ensure_future(setter(ctl, acked, sent, errors, stop))
        pump = asyncio.ensure_future(sub.pump(2 * REBUILD_BOUND_S + EXIT_BOUND_S))
        def expected():  # a set whose ack was under way when the daemon stopped is saved too
            last = acked[-1] if acked else None
            in_flight = (last[0] + 1, sent[-1]) if last and sent and sent[-1] != last[1] else None
            return last, in_flight
        # Two rebuilds come first.
        await check_stopped(name, d, sub, expected, 2 * REBUILD_BOUND_S + EXIT_BOUND_S)
        stop.set()
        for t in (task, pump):
            t.cancel()
        await asyncio.gather(task, pump, return_exceptions=True)
        log = d.log_text()
        check(f"{name}: two losses rebuilt, the third stops the daemon",
              log.count("renderer rebuilt") == 2 and "lost 3 times within 60 s" in log,
              d.log_tail())
        check(f"{name}: sets were acknowledged between the losses", len(acked) >= 3,
              f"{len(acked)} acks")
        check_log_clean(name, d)
    finally:
        d.kill()


async def out_of_memory(skyd, scratch):
    name = "out_of_memory"
    d = start(skyd, scratch, name, f"out_of_memory:after_frames={WARM_UP_FRAMES + 5}")
    try:
        sub = await Client.connect(d.url(), f"{name}-subscriber")
        r = await sub.request({"type": "subscribe", "id": "sub", "view": SUB_VIEW})
        check(f"{name}: subscribed", r.get("type") == "subscribed", short(r))
        # The warm-up's frames, then five of the subscription's: the fault is armed and the
        # subscription's images exist, so the next allocation is the snapshot's.
        armed = await pump_until(sub, lambda: sum(sub.frame_count.values()) >= 5, 15)
        check(f"{name}: the subscription streams", armed, f"{sub.frame_count}")
        viewer = await Client.connect(d.url(), f"{name}-viewer")
        r = await viewer.request({"type": "snapshot", "id": "big",
                                  "view": {"width": 48, "height": 30}}, REBUILD_BOUND_S)
        message = r.get("message", "")
        check(f"{name}: the snapshot that needed new images gets an internal error",
              r.get("type") == "error" and r.get("code") == "internal" and r.get("id") == "big",
              short(r))
        check(f"{name}: the error names what could not be allocated and why",
              "out of memory" in message and 'image "output" (48x30' in message
              and "VK_ERROR_OUT_OF_DEVICE_MEMORY" in message, short(r))
        count_then = sum(sub.frame_count.values())
        served = await pump_until(sub, lambda: sum(sub.frame_count.values()) >= count_then + 3,
                                  10)
        check(f"{name}: the subscriber is still served", served,
              f"{sum(sub.frame_count.values()) - count_then} frames in 10 s")
        m, b, _ = sub.frames[-1]
        check_binary_frame(f"{name}: a subscription frame after the failure", m, b,
                           SUB_VIEW["width"], SUB_VIEW["height"])
        r = await viewer.request({"type": "snapshot", "id": "again",
                                  "view": {"width": 48, "height": 30}}, REBUILD_BOUND_S)
        check(f"{name}: the same snapshot then succeeds", r.get("type") == "frame"
              and r.get("id") == "again", short(r))
        if r.get("type") == "frame":
            check_binary_frame(f"{name}: the snapshot", r, r["_binary"], 48, 30)
        log = d.log_text()
        check(f"{name}: no device loss, the failure is logged",
              "device was lost" not in log and "rendering the 48x30 view failed: out of memory"
              in log, d.log_tail())
        for c in (sub, viewer):
            await c.close()
        status = await d.terminate_async()
        check(f"{name}: SIGTERM exits 0", status == 0, f"status {status}")
        check_log_clean(name, d)
    finally:
        d.kill()


async def run(skyd, scratch):
    for scenario in (recovered, unrecoverable, repeated, out_of_memory):
        t = time.monotonic()
        await scenario(skyd, scratch)
        info(f"{scenario.__name__}: {time.monotonic() - t:.1f} s")


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 400))
