"""test_serve.py's checks of the daemon's life and limits: an unknown config member refused at
startup, SIGTERM (close 1001, exit status 0) and the state persisting across a restart of the
main daemon, and the rate limit and client limit on the limits daemon."""

import asyncio
import glob
import json
import os
import subprocess

from serve_harness import (FIRST_FRAME_TIMEOUT, TOKEN, Client, approx_equal, check,
                           check_unchanged, info, json_diff, make_config, short, stable,
                           websockets)


async def t_sigterm_restart(d, ctl):
    r = await ctl.request({"type": "set", "id": "rs",
                           "patch": {"sun": {"elevation_deg": 12.25, "azimuth_deg": 77},
                                     "camera": {"fov_deg": 55}}})
    check("restart: set ack", r.get("type") == "ack", short(r))
    saved = await ctl.get_state()
    # Written before the ack, not only at shutdown.
    state_file = d.config["state_file"]
    seen = b""
    for _ in range(40):
        try:
            with open(state_file, "rb") as f:
                seen = f.read()
            if b"12.25" in seen and b"55" in seen:
                break
        except OSError:
            pass
        await asyncio.sleep(0.1)
    check("state file written within 4 s of a change (before shutdown)",
          b"12.25" in seen and b"55" in seen, f"state file holds {seen[:200]!r}")
    # A subscribed client: the close frame must get through while frames stream.
    watcher = await Client.connect(d.url(), "watcher")
    r = await watcher.request({"type": "subscribe", "id": "w",
                               "view": {"width": 64, "height": 36, "fps": 30}})
    check("restart: watcher subscribed", r.get("type") == "subscribed", short(r))
    await watcher.wait_frame(timeout=FIRST_FRAME_TIMEOUT)
    status = await d.terminate_async()
    closes = []
    for c in (watcher, ctl):
        try:
            while True:
                await c.raw(10)
        except websockets.exceptions.ConnectionClosed as e:
            closes.append((c.name, e.rcvd.code if e.rcvd else None,
                           e.rcvd.reason if e.rcvd else None))
        except asyncio.TimeoutError:
            closes.append((c.name, "still open after 10 s", None))
    for name, code, reason in closes:
        check(f"SIGTERM: {name} closed with 1001", code == 1001, f"code {code!r}")
        check(f"SIGTERM: {name} close reason", reason == "skyd shutting down", repr(reason))
    check("SIGTERM: exit status 0", status == 0, f"exit status {status}; log: {d.log_tail(300)}")
    try:
        with open(state_file) as f:
            json.load(f)
        check("state file written and valid JSON", True)
    except (OSError, ValueError) as e:
        check("state file written and valid JSON", False, repr(e))
    leftovers = [p for p in glob.glob(state_file + "*") if p != state_file]
    check("no temporary state files left", not leftovers, short(leftovers))

    d.start()
    check("restart: the client weather map restored", "restored the client weather map (512x512)"
          in d.log_tail(4000), d.log_tail(600))
    c = await Client.connect(d.url(), "after-restart")
    try:
        s = await c.get_state()
        check("restart: revision restored", s.get("revision") == saved.get("revision"),
              f"before {saved.get('revision')}, after {s.get('revision')}")
        check("restart: state restored",
              approx_equal(stable(s.get("state")), stable(saved.get("state"))),
              json_diff(stable(saved.get("state")), stable(s.get("state"))))
        # The restored revision keeps counting up.
        await c.request({"type": "auth", "id": 1, "token": TOKEN})
        r = await c.request({"type": "set", "id": 2, "patch": {"sun": {"azimuth_deg": 78}}})
        check("restart: revision keeps counting up", r.get("type") == "ack"
              and isinstance(r.get("revision"), int) and r["revision"] > saved["revision"],
              short(r))
    finally:
        await c.close()
    status = await d.terminate_async()
    check("SIGTERM after restart: exit status 0", status == 0, f"exit status {status}")


async def t_rate_limit(d):
    c = await Client.connect(d.url(), "rate")
    try:
        cps = d.config["limits"]["control_messages_per_second"]
        await asyncio.sleep(1.2)  # a full bucket
        before = await c.get_state()
        for i in range(30):
            await c.send({"type": "get_state", "id": i})
        replies = []
        try:
            for _ in range(30):
                replies.append(await c.reply())
        except asyncio.TimeoutError:
            pass
        states = [r for r in replies if r.get("type") == "state"]
        limited = [r for r in replies if r.get("type") == "error"
                   and r.get("code") == "rate_limited"]
        others = [r for r in replies if r not in states and r not in limited]
        info(f"rate limit burst of 30 (limit {cps}/s): {len(states)} state, "
             f"{len(limited)} rate_limited")
        check("rate limit: every message answered", len(replies) == 30, f"{len(replies)} replies")
        check("rate limit: some rate_limited errors", len(limited) >= 1,
              f"{len(states)} state, {len(limited)} rate_limited")
        check("rate limit: no more than the burst (+1 s refill) succeed",
              len(states) <= 2 * cps + 1, f"{len(states)} state replies")
        check("rate limit: burst-1 messages succeed", len(states) >= cps - 1,
              f"{len(states)} state replies")
        check("rate limit: no other replies", not others, short(others))
        ids = [r.get("id") for r in states]
        check("rate limit: replies in order", ids == sorted(ids), short(ids))
        await asyncio.sleep(1.5)
        await check_unchanged("rate limit: after the burst", c, before)
    finally:
        await c.close()


async def t_max_clients(d):
    a = await Client.connect(d.url(), "mc-a")
    b = await Client.connect(d.url(), "mc-b")
    try:
        msgs = []
        close = None
        try:
            ws = await websockets.connect(d.url(), open_timeout=10, close_timeout=5,
                                          ping_interval=None)
            try:
                while True:
                    m = await asyncio.wait_for(ws.recv(), 10)
                    msgs.append(json.loads(m) if isinstance(m, str) else m)
            except websockets.exceptions.ConnectionClosed as e:
                close = (e.rcvd.code, e.rcvd.reason) if e.rcvd else (None, None)
            except asyncio.TimeoutError:
                close = ("still open after 10 s", None)
            finally:
                await ws.close()
        except websockets.exceptions.InvalidStatusCode as e:
            close = (f"handshake refused with HTTP {e.status_code}", None)
        errs = [m for m in msgs if isinstance(m, dict) and m.get("type") == "error"]
        check("max_clients: third connection gets error limit_reached",
              any(m.get("code") == "limit_reached" for m in errs), short(msgs))
        if any(isinstance(m, dict) and m.get("type") == "hello" for m in msgs):
            info(f"max_clients: the refused connection got a hello first: {short(msgs)}")
        check("max_clients: then close 1008", close is not None and close[0] == 1008,
              f"close {close!r}")
        check("max_clients: close reason", close is not None and close[1] == "too many clients",
              f"close {close!r}")
        s = await a.get_state()
        check("max_clients: existing clients unaffected", s.get("type") == "state", short(s))
        await b.close()
        got = None
        for _ in range(20):  # the server notices the close within a moment
            try:
                got = await Client.connect(d.url(), "mc-c")
                break
            except Exception:  # noqa: BLE001 - refused again: the slot is not free yet
                await asyncio.sleep(0.25)
        check("max_clients: a slot frees when a client leaves", got is not None,
              "no hello on a new connection after one closed")
        if got:
            await got.close()
    finally:
        await a.close()
        await b.close()


def t_bad_config(skyd, scratch):
    """An unknown config member is a startup error: exit status 2, no listening line."""
    cfg = make_config(scratch, os.path.join(scratch, "bad-state.json"))
    cfg["bogus_member"] = 1
    path = os.path.join(scratch, "bad-config.json")
    with open(path, "w") as f:
        json.dump(cfg, f)
    try:
        p = subprocess.run([skyd, "serve", "--config", path], stdin=subprocess.DEVNULL,
                           capture_output=True, timeout=30, cwd=scratch)
    except subprocess.TimeoutExpired as e:
        check("unknown config member: exit status 2", False,
              f"still running after 30 s; stdout {e.stdout!r}")
        return
    check("unknown config member: exit status 2", p.returncode == 2,
          f"exit status {p.returncode}; stderr {p.stderr[-300:]!r}")
    check("unknown config member: no listening line", b"listening" not in p.stdout,
          repr(p.stdout[-200:]))
    check("unknown config member: stderr names it", b"bogus_member" in p.stderr,
          repr(p.stderr[-300:]))
