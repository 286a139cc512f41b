#!/usr/bin/python3
"""End-to-end test of `skyd serve` with a real WebSocket client.

Usage: /usr/bin/python3 tests/e2e/test_serve.py PATH_TO_SKYD SCRATCH_DIR

Starts the daemon itself (config JSON in SCRATCH_DIR, port 0), talks to it with Debian's
python3-websockets 10.4 (asyncio API), and checks the contract in protocol/PROTOCOL.md:
hello, roles, get/set round trips and events, every class of bad input (each followed by a
get_state showing the world state and revision unchanged on the same connection), frames and
their binary header and PNG payload, snapshots, probes, presets, stats, unsubscribe, a client
that never reads, origin checks, rate and client limits, SIGTERM (close 1001, exit status 0)
and state persistence across a restart.

Prints one line per failed check ("FAIL name: details"), a few "info:" lines and measured
figures, and a final "N passed, M failed" line; exits 0 when every check passed, 1 otherwise.
SKYD_TEST_VERBOSE=1 also prints the checks that pass. Standard library + websockets only
(Linux: the slow-reader check reads /proc/net/tcp to see when the daemon is backpressured).
The daemon's stderr goes to SCRATCH_DIR/<name>.log.

The checks live in serve_protocol.py, serve_requests.py, serve_jpeg.py, serve_envmap.py,
serve_world.py, serve_connections.py, serve_weather_map.py and serve_lifecycle.py; this file
runs them in order, each group as a section, on the main daemon and then on the limits daemon.
"""

import asyncio
import glob
import os
import re
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness  # noqa: E402  (the counters live there)
from serve_harness import *  # noqa: E402,F401,F403
from serve_connections import (INDEX_HTML, SECRET, t_http, t_not_reading,  # noqa: E402
                               t_origin, t_slow_reader)
from serve_envmap import t_envmap  # noqa: E402
from serve_jpeg import t_bandwidth, t_jpeg  # noqa: E402
from serve_lifecycle import (t_bad_config, t_max_clients, t_rate_limit,  # noqa: E402
                             t_sigterm_restart)
from serve_protocol import (t_bad_inputs, t_describe, t_hello, t_roles,  # noqa: E402
                            t_set_and_event)
from serve_requests import (t_frames, t_presets, t_probe, t_snapshot,  # noqa: E402
                            t_stats, t_subscription_limit, t_unsubscribe)
from serve_weather_map import t_weather_map  # noqa: E402
from serve_world import t_world_sim  # noqa: E402

# ------------------------------------------------------------------------------------------


async def section(name, coro, clients=()):
    """Runs one group of checks; an exception is a failed check, not a crash. Clients the
    group left closed are reconnected so that later groups still run."""
    try:
        await coro
    except Exception as e:  # noqa: BLE001
        tb = traceback.format_exception_only(type(e), e)[-1].strip()
        check(f"{name}: ran to completion", False, tb)
    for c in clients:
        if c.ws.closed:
            try:
                await c.reopen()
            except Exception as e:  # noqa: BLE001
                info(f"{c.name}: cannot reconnect: {e!r}")


async def main_checks(d, repo_config_dir):
    """Everything on the main daemon; returns the default state it started with."""
    ctl = await Client.connect(d.url(), "controller")
    viewer = await Client.connect(d.url(), "viewer")
    both = (ctl, viewer)
    defaults = await ctl.get_state()
    await section("hello/auth", t_hello(d, ctl), both)
    await section("describe", t_describe(d, viewer), both)
    await section("set/event", t_set_and_event(d, ctl, viewer), both)
    await section("bad inputs", t_bad_inputs(d), both)
    await section("roles", t_roles(d), both)
    sub = None
    try:
        sub = await t_frames(d, ctl, viewer)
    except Exception as e:  # noqa: BLE001
        check("frames: ran to completion", False,
              traceback.format_exception_only(type(e), e)[-1].strip())
    await section("snapshot", t_snapshot(d, viewer), both)
    await section("jpeg", t_jpeg(d, viewer), both)
    await section("bandwidth", t_bandwidth(d), both)
    if sub is not None and not viewer.ws.closed:
        await section("unsubscribe", t_unsubscribe(viewer, sub), both)
    await section("subscription limit", t_subscription_limit(d), both)
    await section("probe", t_probe(ctl), both)
    await section("environment map", t_envmap(d, ctl, viewer), both)
    await section("presets", t_presets(d, ctl, viewer, repo_config_dir), both)
    await section("stats", t_stats(ctl, 2), both)
    await section("world simulation", t_world_sim(ctl, repo_config_dir), both)
    await section("origin", t_origin(d), both)
    await section("http", t_http(d), both)
    await section("slow reader", t_slow_reader(d), both)
    await section("not reading", t_not_reading(d), both)
    check("no unexpected replies on the viewer", not viewer.stray, short(viewer.stray))
    await section("weather map", t_weather_map(d, ctl, viewer), both)
    check("no unexpected replies on the viewer after the weather map", not viewer.stray,
          short(viewer.stray))
    await viewer.close()
    await section("SIGTERM/restart", t_sigterm_restart(d, ctl))
    return defaults


async def run(skyd, scratch):
    repo_config_dir = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "config")
    os.makedirs(os.path.join(scratch, "web"), exist_ok=True)
    with open(os.path.join(scratch, "web", "index.html"), "wb") as f:
        f.write(INDEX_HTML)
    with open(os.path.join(scratch, "secret.txt"), "wb") as f:
        f.write(SECRET)
    daemons = []
    await asyncio.get_running_loop().run_in_executor(None, t_bad_config, skyd, scratch)
    try:
        # --- main daemon
        state_file = os.path.join(scratch, "main-state.json")
        for p in glob.glob(state_file[:-len(".json")] + "*"):  # the weather map too
            os.unlink(p)
        d = Daemon(skyd, scratch, "main", make_config(scratch, state_file))
        daemons.append(d)
        try:
            d.start()
            check("main daemon starts", True)
        except Exception as e:  # noqa: BLE001
            check("main daemon starts", False, str(e))
            d = None
        defaults = None
        if d is not None:
            info(f"main daemon on port {d.port}")
            try:
                defaults = await main_checks(d, repo_config_dir)
            except Exception as e:  # noqa: BLE001
                check("main daemon checks ran", False,
                      traceback.format_exception_only(type(e), e)[-1].strip())

        # --- limits daemon: rate limit, max clients, corrupt state file
        state_file2 = os.path.join(scratch, "limits-state.json")
        for p in glob.glob(state_file2[:-len(".json")] + "*"):
            os.unlink(p)
        with open(state_file2, "w") as f:
            f.write('{"revision": 3, "state": {"sun": ')  # truncated: corrupt
        d2 = Daemon(skyd, scratch, "limits",
                    make_config(scratch, state_file2, max_clients=2,
                                control_messages_per_second=5))
        daemons.append(d2)
        try:
            d2.start()
            check("limits daemon starts despite a corrupt state file", True)
        except Exception as e:  # noqa: BLE001
            check("limits daemon starts despite a corrupt state file", False, str(e))
            d2 = None
        if d2 is not None:
            info(f"limits daemon on port {d2.port}")
            moved = glob.glob(state_file2 + ".corrupt-*")
            check("corrupt state file moved aside to .corrupt-<time>", len(moved) == 1
                  and re.fullmatch(r".*\.corrupt-\d+", moved[0]) is not None, short(moved))
            if defaults is not None:
                c = await Client.connect(d2.url(), "defaults")
                s = await c.get_state()
                check("corrupt state file: starts from defaults",
                      approx_equal(stable(s.get("state")), stable(defaults.get("state"))),
                      json_diff(stable(defaults.get("state")), stable(s.get("state"))))
                await c.close()
            await asyncio.sleep(0.3)
            await section("rate limit", t_rate_limit(d2))
            await asyncio.sleep(0.3)
            await section("max clients", t_max_clients(d2))
            status = await d2.terminate_async()
            check("limits daemon: SIGTERM exit status 0", status == 0, f"exit status {status}")
    finally:
        for dm in daemons:
            dm.kill()


def main():
    if len(sys.argv) != 3:
        print("usage: /usr/bin/python3 tests/e2e/test_serve.py PATH_TO_SKYD SCRATCH_DIR",
              file=sys.stderr)
        return 2
    skyd = os.path.abspath(sys.argv[1])
    scratch = os.path.abspath(sys.argv[2])
    os.makedirs(scratch, exist_ok=True)
    start = time.monotonic()
    try:
        asyncio.run(asyncio.wait_for(run(skyd, scratch), 180))
    except asyncio.TimeoutError:
        check("whole run within 180 s", False, "timed out")
    except Exception as e:  # noqa: BLE001
        check("test harness", False, "".join(traceback.format_exception(e))[-1500:])
    info(f"run took {time.monotonic() - start:.1f} s")
    passed, failed = serve_harness.passed, serve_harness.failed
    print(f"{passed} passed, {failed} failed", flush=True)
    return 0 if failed == 0 and passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
