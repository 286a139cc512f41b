#!/usr/bin/python3
"""A render thread that stops ticking, on the real daemon: SKYD_FAULT=stall (render/vk/
fault_injection.h) makes one queue submission finish STALL_S seconds late, so the render
thread really waits in it, as on a device that stalls on a frame and recovers.

Usage: /usr/bin/python3 tests/e2e/test_render_stall.py PATH_TO_SKYD SCRATCH_DIR

1. /healthz answers 200 while frames flow, 503 ("the render thread has not ticked for ...")
   once the stalled tick is older than 5 s, and 200 again when the submission finishes.
2. With limits.max_queued_http_requests = 2, two GET /api/state wait for the stalled render
   loop; a third is answered at once with 503, Retry-After and an `unavailable` error naming
   the cap; the two waiting ones are answered 200 with the state once the loop runs again.
   /metrics counts the refusal.
3. A cap of 0 in the configuration is refused at start with an error naming the field.

Bounded waits throughout; prints "N passed, M failed".
"""

import asyncio
import concurrent.futures
import json
import os
import shutil
import subprocess
import sys
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (WARM_UP_FRAMES, Client, Daemon, check, info,  # noqa: E402
                           make_config, run_daemon_test, short)

STALL_S = 14          # the late submission; /healthz's limit is 5 s
AFTER_FRAMES = WARM_UP_FRAMES + 6  # the start-up's warm-up frames, then the subscription's
QUEUE_CAP = 2


def http(port, path, timeout=60):
    """GET: (status, headers, body text, seconds taken); status 0 when nothing answered."""
    t0 = time.monotonic()
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=timeout) as r:
            return r.status, dict(r.headers), r.read().decode(), time.monotonic() - t0
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read().decode(), time.monotonic() - t0
    except OSError as e:
        return 0, {}, repr(e), time.monotonic() - t0


def health(port):
    status, _, body, _ = http(port, "/healthz", timeout=5)
    try:
        return status, json.loads(body)
    except ValueError:
        return status, {"body": body}


async def wait_health(port, want_status, timeout):
    """Polls /healthz every 0.2 s until it answers want_status; (status, body, seconds)."""
    loop = asyncio.get_running_loop()
    t0 = time.monotonic()
    status, body = 0, {}
    while time.monotonic() - t0 < timeout:
        status, body = await loop.run_in_executor(None, health, port)
        if status == want_status:
            break
        await asyncio.sleep(0.2)
    return status, body, time.monotonic() - t0


def metric(port, line_start):
    _, _, text, _ = http(port, "/metrics", timeout=10)
    for line in text.splitlines():
        if line.startswith(line_start + " "):
            return float(line.split()[1])
    return 0.0


async def stalled(skyd, scratch):
    state_dir = os.path.join(scratch, "stall")
    shutil.rmtree(state_dir, ignore_errors=True)
    os.makedirs(state_dir)
    config = make_config(scratch, os.path.join(state_dir, "state.json"),
                         max_queued_http_requests=QUEUE_CAP)
    fault = f"stall:after_frames={AFTER_FRAMES}:seconds={STALL_S}"
    d = Daemon(skyd, scratch, "stall", config, env={"SKYD_FAULT": fault})
    d.start()
    info(f"SKYD_FAULT={fault}, listening on port {d.port}")
    loop = asyncio.get_running_loop()
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=4)
    try:
        status, body = await loop.run_in_executor(None, health, d.port)
        check("/healthz: 200 while the render thread ticks", status == 200
              and body.get("status") == "ok", f"{status} {short(body)}")
        viewer = await Client.connect(d.url(), "viewer")
        r = await viewer.request({"type": "subscribe", "id": "s",
                                  "view": {"width": 32, "height": 18, "fps": 20}})
        check("subscribed", r.get("type") == "subscribed", short(r))

        # 1. The stall: /healthz goes 503 once the tick is 5 s old.
        status, body, waited = await wait_health(d.port, 503, 60)
        info(f"/healthz answered 503 after {waited:.1f} s: {short(body)}")
        check("/healthz: 503 when the render thread stops ticking", status == 503
              and body.get("status") == "unavailable", f"{status} {short(body)}")
        check("/healthz: the reason says the render thread has not ticked",
              "render thread has not ticked for" in body.get("reason", "")
              and body.get("last_tick_age_s", 0) > 5, short(body))
        stall_said = "fault injection: a submission stalls" in d.log_text()
        check("the daemon's log says the submission stalls (the fault, not something else)",
              stall_said, d.log_tail())

        # 2. The queue: two requests wait for the stalled loop, a third is refused at once.
        waiting = [loop.run_in_executor(pool, http, d.port, "/api/state", 120)
                   for _ in range(QUEUE_CAP)]
        await asyncio.sleep(0.5)
        status, headers, text, took = await loop.run_in_executor(pool, http, d.port,
                                                                 "/api/state", 30)
        try:
            error = json.loads(text)
        except ValueError:
            error = {"body": text}
        headers = {k.lower(): v for k, v in headers.items()}
        check(f"queue: request {QUEUE_CAP + 1} answered 503 at once", status == 503
              and took < 3.0, f"{status} after {took:.1f} s: {text[:200]}")
        check("queue: with Retry-After", headers.get("retry-after") == "1", short(headers))
        check("queue: an `unavailable` error naming the cap",
              error.get("type") == "error" and error.get("code") == "unavailable"
              and "limits.max_queued_http_requests" in error.get("message", "")
              and f"at most {QUEUE_CAP}" in error.get("message", ""), short(error))
        still, _, _ = await wait_health(d.port, 503, 0.1)
        check("queue: refused while the render loop was still stalled", still == 503,
              str(still))
        answers = await asyncio.gather(*waiting)
        for i, (status, _, text, took) in enumerate(answers):
            ok = status == 200
            try:
                ok = ok and json.loads(text).get("revision") is not None
            except ValueError:
                ok = False
            check(f"queue: waiting request {i + 1} answered 200 with the state once the loop "
                  "runs", ok, f"{status} after {took:.1f} s: {text[:160]}")
        check("queue: /metrics counts the refusal",
              metric(d.port, 'skyd_errors_total{code="unavailable"}') >= 1)

        # The stall ends: /healthz is ok again, frames flow.
        status, body, waited = await wait_health(d.port, 200, 60)
        check("/healthz: 200 again once the render thread ticks", status == 200
              and body.get("status") == "ok", f"{status} {short(body)}")
        sub = r.get("subscription")
        await viewer.pump(0.5)
        before = viewer.frame_count.get(sub, 0)
        await viewer.pump(2.0)
        after = viewer.frame_count.get(sub, 0)
        check("frames flow again after the stall", after - before >= 5,
              f"{after - before} frames in 2 s")
        await viewer.close()
        code = await d.terminate_async()
        check("the daemon stops cleanly", code == 0, f"exit {code}: {d.log_tail()}")
    finally:
        pool.shutdown(wait=False)
        d.kill()


def bad_cap(skyd, scratch):
    config = make_config(scratch, os.path.join(scratch, "bad-cap-state.json"),
                         max_queued_http_requests=0)
    path = os.path.join(scratch, "bad-cap.json")
    with open(path, "w") as f:
        json.dump(config, f)
    p = subprocess.run([skyd, "serve", "--config", path], cwd=scratch, capture_output=True,
                       stdin=subprocess.DEVNULL, timeout=60)
    err = p.stderr.decode("utf-8", "replace")
    check("a cap of 0 is refused at start, naming the field", p.returncode != 0
          and "/limits/max_queued_http_requests" in err, f"exit {p.returncode}: {err[-300:]}")


async def run(skyd, scratch):
    bad_cap(skyd, scratch)
    await stalled(skyd, scratch)


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 240))
