#!/usr/bin/python3
"""Many skyd nodes, one world, on Redis: real redis-server, haproxy and skyd processes on free
loopback ports, started and stopped by this test (by their process ids).

Usage: /usr/bin/python3 tests/e2e/test_cluster.py PATH_TO_SKYD SCRATCH_DIR

Redis runs with config/redis.conf's users (scripts/redis-conf.sh gives them passwords): nobody
is let in without AUTH, the nodes log in as "skyd", whose password node 1 and node 3 give in
the URL (percent-encoded) and node 2 in a password file.

1. Bad cluster configs fail at start with an error naming the field: a world name with a
   space, a URL that is not redis://HOST:PORT, a Redis nobody listens on, a world without
   its Redis; a wrong password (in the URL or the file), none at all, a password file open to
   others, missing, or given beside a password in the URL. No error holds the password.
   The user "skyd" reaches only the world's keys and the commands skyd sends.
2. Redis, two nodes and haproxy (three servers; the third starts later). A change through one
   node reaches a viewer of the other with the same revision within 200 ms.
3. Controllers on both nodes send changes at once: every change is acknowledged with its own
   revision, the revisions have no gap, and both nodes tell the same order of events and end
   in the same state.
4. The same view on both nodes, with the clock paused, gives the same image (within a
   converged render's noise); with the clock running, the nodes' simulated clocks (from the
   epoch in the shared state) differ by under 50 ms.
5. Redis killed with -9: a change is refused with `unavailable` naming the cluster, frames go
   on; restarted on its append-only file it holds every acknowledged change; the nodes
   reconnect, a change through each reaches the other.
6. Two clients through haproxy (least connections: one per node); the node of one is killed
   with -9: that client reconnects through haproxy and finds the same state and revision.
7. A third node joins late and starts from the current state; a change through it reaches
   the others.
8. That node, stopped while the world moves on by more changes than the stream keeps, takes
   the snapshot when it runs again.
9. The password is in no node's log or output, nor in /metrics, /healthz, describe or stats.

Prints "N passed, M failed".
"""

import asyncio
import json
import os
import signal
import sys
import time
import urllib.error
import urllib.parse
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cluster_harness import (SKYD_PASSWORD, Haproxy, Redis, cluster_section,  # noqa: E402
                             free_port, resp, resp_pipeline, run_bad_config, start_node,
                             write_secret)
from serve_harness import (FIRST_FRAME_TIMEOUT, HEADER, TOKEN, Client, check, decode_png, info,  # noqa: E402
                           json_diff, run_daemon_test, short, stable)

WORLD = "e2e-world_1"
# Paused clock, no autopilot: the state only changes through the test's changes.
PAUSED = {"clock": {"utc": "2026-06-21T07:30:00Z", "time_scale": 0},
          "weather": {"autopilot": "off"},
          "clouds": {"low": {"coverage": 0.5}}}
PROPAGATION_LIMIT_S = 0.2


def humidity_of(i, node):
    """A distinct humidity per change."""
    return round(0.05 + 0.002 * i + (0.4 if node == 2 else 0.0), 4)


async def connect(url, name, simulation_events=False):
    c = await Client.connect(url, name)
    await c.request({"type": "hello", "id": f"{name}-hello", "client": name, "protocol": 1,
                     "simulation_events": simulation_events})
    return c


async def controller(url, name):
    c = await connect(url, name)
    await c.auth()
    return c


def state_changes(client):
    return [(e.get("revision"), e.get("by"), e.get("values", {}).get("/weather/humidity"))
            for e in client.events if e.get("event") == "state_changed"]


async def wait_revision(client, revision, timeout):
    return await client.wait_event(lambda e: e.get("event") == "state_changed"
                                   and e.get("revision", 0) >= revision, timeout)


def password_forms(password=SKYD_PASSWORD):
    """The password as it may leak: as it is and percent-encoded."""
    return {password, urllib.parse.quote(password, safe="")}


async def bad_configs(skyd, scratch, redis):
    nobody = free_port()
    port = redis.port
    leaky = write_secret(os.path.join(scratch, "leaky-password"), SKYD_PASSWORD, 0o644)
    wrong = write_secret(os.path.join(scratch, "wrong-password"), "not-" + SKYD_PASSWORD)
    cases = [
        ("bad world name", {"redis": f"redis://127.0.0.1:{nobody}", "world": "bad world"},
         "/cluster/world", "not a letter"),
        ("bad URL", {"redis": "http://127.0.0.1:6379", "world": "w"}, "/cluster/redis",
         "redis://[USER[:PASSWORD]@]HOST:PORT"),
        ("no port", {"redis": "redis://127.0.0.1", "world": "w"}, "/cluster/redis", "port"),
        ("world without redis", {"world": "w"}, "/cluster/redis", "needs its Redis"),
        ("unreachable Redis", {"redis": f"redis://127.0.0.1:{nobody}", "world": "w"},
         "/cluster/redis", "cannot reach"),
        ("wrong password in the URL", cluster_section(port, "w", password="not-" + SKYD_PASSWORD),
         "/cluster/redis", 'Redis refused AUTH as user "skyd": Redis answered: WRONGPASS'),
        ("wrong password in the file", cluster_section(port, "w", "file", password_file=wrong),
         "/cluster/redis", 'Redis refused AUTH as user "skyd": Redis answered: WRONGPASS'),
        ("no password", {"redis": f"redis://127.0.0.1:{port}", "world": "w"},
         "/cluster/redis", "Redis asks for a user and password (NOAUTH"),
        ("a user without a password", {"redis": f"redis://skyd@127.0.0.1:{port}", "world": "w"},
         "/cluster/redis", "WRONGPASS invalid username-password pair or user is disabled. (no "
         "password was given)"),
        ("password file open to others", cluster_section(port, "w", "file", password_file=leaky),
         "/cluster/redis_password_file", "open to group or others (mode 0644)"),
        ("password file missing",
         cluster_section(port, "w", "file", password_file=os.path.join(scratch, "nowhere")),
         "/cluster/redis_password_file", "does not exist"),
        ("password twice", dict(cluster_section(port, "w"), redis_password_file=wrong),
         "/cluster/redis_password_file", "give it once"),
        ("rediss", {"redis": f"rediss://skyd:{SKYD_PASSWORD}@127.0.0.1:{port}", "world": "w"},
         "/cluster/redis", "stunnel"),
    ]
    for name, cluster, pointer, words in cases:
        t0 = time.monotonic()
        code, err, out = await asyncio.get_running_loop().run_in_executor(
            None, run_bad_config, skyd, scratch, "bad-" + name.replace(" ", "-"), cluster)
        check(f"bad config ({name}): skyd exits with an error", code not in (0, None),
              f"exit {code}")
        check(f"bad config ({name}): the error names {pointer} and says why",
              pointer in err and words in err, err[-400:])
        check(f"bad config ({name}): at once", time.monotonic() - t0 < 20,
              f"{time.monotonic() - t0:.1f} s")
        secrets = password_forms() | password_forms("not-" + SKYD_PASSWORD)
        check(f"bad config ({name}): the password is in no output",
              not any(p in err or p in out for p in secrets), err[-400:])


def skyd_user_limits(redis):
    """config/redis.conf's user "skyd": the world's keys and skyd's commands, nothing else."""
    skyd = ("skyd", SKYD_PASSWORD)
    key = f"skyd:{{{WORLD}}}:rev"
    check("ACL: the user skyd reads the world's keys",
          resp(redis.port, "EXISTS", key, auth=skyd) in (0, 1))
    for args, words in [(["GET", "other:key"], "NOPERM"), (["SET", "skyd-not-a-world", "1"],
                                                           "NOPERM"),
                        (["KEYS", "*"], "NOPERM"), (["CONFIG", "GET", "*"], "NOPERM"),
                        (["FLUSHALL"], "NOPERM"), (["PUBLISH", "c", "m"], "NOPERM"),
                        (["EVAL", "return redis.call('FLUSHALL')", "0"], "can't run"),
                        (["EVAL", "return redis.call('GET', 'other')", "0"], "can't access")]:
        try:
            reply = resp(redis.port, *args, auth=skyd)
            refused = False
        except RuntimeError as e:
            reply, refused = str(e), words in str(e)
        check(f"ACL: the user skyd may not {' '.join(args[:2])}", refused, short(reply))
    try:
        reply = resp(redis.port, "GET", key, auth=None)
    except RuntimeError as e:
        reply = str(e)
    check("ACL: without AUTH nothing is read",
          "NOAUTH" in str(reply), short(reply))


async def propagation(n1, n2):
    ctl = await controller(n1.url(), "ctl-prop")
    viewer = await connect(n2.url(), "viewer-prop")
    worst = 0.0
    for i in range(5):
        value = humidity_of(i, 1)
        r = await ctl.request({"type": "set", "id": f"p{i}",
                               "patch": {"weather": {"humidity": value}}})
        t_ack = time.monotonic()
        if not check(f"propagation {i}: acknowledged", r.get("type") == "ack", short(r)):
            continue
        e = await wait_revision(viewer, r["revision"], 5.0)
        t_event = time.monotonic()
        ok = check(f"propagation {i}: the other node tells revision {r['revision']}",
                   e is not None and e.get("revision") == r["revision"]
                   and e.get("values", {}).get("/weather/humidity") == value, short(e))
        if ok:
            worst = max(worst, t_event - t_ack)
    info(f"propagation: slowest event on the other node {worst * 1000:.1f} ms after the ack")
    check(f"propagation: within {PROPAGATION_LIMIT_S * 1000:.0f} ms",
          worst < PROPAGATION_LIMIT_S, f"{worst * 1000:.1f} ms")
    s1, s2 = await ctl.get_state(), await viewer.get_state()
    check("propagation: both nodes at the same revision and state",
          s1["revision"] == s2["revision"] and s1["state"] == s2["state"],
          f"{s1['revision']} vs {s2['revision']}")
    await ctl.close()
    await viewer.close()
    return s1["revision"]


async def concurrent(n1, n2, count=15):
    v1, v2 = await connect(n1.url(), "viewer-1"), await connect(n2.url(), "viewer-2")
    c1, c2 = await controller(n1.url(), "ctl-1"), await controller(n2.url(), "ctl-2")
    start = (await v1.get_state())["revision"]

    async def fire(c, node):
        for i in range(count):
            await c.send({"type": "set", "id": f"n{node}-{i}",
                          "patch": {"weather": {"humidity": humidity_of(i, node)}}})
        replies = []
        while len(replies) < count:
            replies.append(await c.reply(15.0))
        return replies

    r1, r2 = await asyncio.gather(fire(c1, 1), fire(c2, 2))
    acks = [r for r in r1 + r2 if r.get("type") == "ack"]
    check("concurrent: every change acknowledged", len(acks) == 2 * count,
          [short(r) for r in r1 + r2 if r.get("type") != "ack"][:3])
    revisions = sorted(r["revision"] for r in acks)
    check("concurrent: one revision per change, no gap",
          revisions == list(range(start + 1, start + 1 + 2 * count)), revisions)
    end = start + 2 * count
    await wait_revision(v1, end, 5.0)
    await wait_revision(v2, end, 5.0)
    o1 = [c for c in state_changes(v1) if c[0] > start]
    o2 = [c for c in state_changes(v2) if c[0] > start]
    check("concurrent: both nodes tell every change", len(o1) == 2 * count and
          len(o2) == 2 * count, f"{len(o1)}, {len(o2)}")
    check("concurrent: in one order everywhere", o1 == o2, f"{o1[:4]} vs {o2[:4]}")
    by = [c[1] for c in o1]
    info(f"concurrent: order of senders {''.join('1' if b == 'ctl-1' else '2' for b in by)}")
    s1, s2 = await v1.get_state(), await v2.get_state()
    check("concurrent: the same final state on both nodes",
          s1["revision"] == s2["revision"] == end and s1["state"] == s2["state"],
          f"{s1['revision']} vs {s2['revision']}: {json_diff(s1['state'], s2['state'])}")
    if o1:
        check("concurrent: the final humidity is the last revision's",
              s1["state"]["weather"]["humidity"] == o1[-1][2],
              f"{s1['state']['weather']['humidity']} vs {o1[-1]}")
    for c in (v1, v2, c1, c2):
        await c.close()


def mean_abs_difference(a, b):
    """Per channel, of 255, between two binary frames (header, then PNG)."""
    wa, ha, ca, rows_a = decode_png(a[HEADER.size:])
    wb, hb, cb, rows_b = decode_png(b[HEADER.size:])
    if (wa, ha, ca) != (wb, hb, cb):
        return None
    total = 0
    for ra, rb in zip(rows_a, rows_b):
        total += sum(abs(x - y) for x, y in zip(ra, rb))
    return total / (wa * ha * ca)


async def same_view(n1, n2):
    """The same view on both nodes, the clock paused: the same picture. A node renders a few
    frames first so that temporal reprojection has converged."""
    view = {"width": 96, "height": 64,
            "camera": {"yaw_deg": 90, "pitch_deg": 15, "fov_deg": 70},
            "exposure": {"mode": "manual", "ev100": 12}}
    images = []
    for node in (n1, n2):
        v = await connect(node.url(), f"viewer-view-{node.name}")
        r = await v.request({"type": "subscribe", "id": "warm", "view": dict(view, fps=10)})
        if r.get("type") == "subscribed":
            for _ in range(12):
                await v.wait_frame(timeout=FIRST_FRAME_TIMEOUT)
            await v.request({"type": "unsubscribe", "subscription": r["subscription"]})
        s = await v.request({"type": "snapshot", "id": "same", "view": view},
                            FIRST_FRAME_TIMEOUT)
        if not check(f"same view: {node.name} renders the snapshot", s.get("type") == "frame",
                     short(s)):
            s = {}
        images.append(s.get("_binary"))
        await v.close()
    if not check("same view: both nodes render a snapshot", all(images)):
        return
    diff = mean_abs_difference(images[0], images[1])
    info(f"same view: mean absolute difference {diff} (of 255)")
    check("same view, clock paused: images differ by at most a converged render's noise",
          diff is not None and diff < 2.0, f"{diff}")


async def simulated_offset(client, samples=8):
    """The node's simulated time minus the wall time, s, from the `stats` reply with the
    shortest round trip (its simulation_time_s is the clock at the tick that answered, a
    wall instant between sending and receiving)."""
    best = None
    for i in range(samples):
        t0 = time.time()
        r = await client.request({"type": "stats", "id": f"clock{i}"})
        t1 = time.time()
        if r.get("type") != "stats":
            raise RuntimeError(f"stats answered with {short(r)}")
        rtt = t1 - t0
        if best is None or rtt < best[0]:
            best = (rtt, r["simulation_time_s"] - (t0 + t1) / 2)
        await asyncio.sleep(0.05)
    return best


async def clock_running(n1, n2):
    """The clock running: both nodes compute the same simulated instant from the epoch in
    the shared state, although they started at different times."""
    ctl = await controller(n1.url(), "ctl-clock")
    viewer = await connect(n2.url(), "viewer-clock")
    r = await ctl.request({"type": "set", "id": "run", "patch": {"clock": {"time_scale": 1}}})
    check("clock: set running", r.get("type") == "ack", short(r))
    await wait_revision(viewer, r.get("revision", 0), 5.0)
    await asyncio.sleep(1.0)
    (rtt1, off1), (rtt2, off2) = await simulated_offset(ctl), await simulated_offset(viewer)
    info(f"clock: simulated minus wall time {off1:.4f} s on node 1 (rtt {rtt1 * 1000:.1f} ms), "
         f"{off2:.4f} s on node 2 (rtt {rtt2 * 1000:.1f} ms)")
    check("clock running: the two nodes' simulated clocks differ by under 50 ms",
          abs(off1 - off2) < 0.050, f"{(off1 - off2) * 1000:.1f} ms")
    r = await ctl.request({"type": "set", "id": "pause", "patch": {"clock": {"time_scale": 0}}})
    check("clock: paused again", r.get("type") == "ack", short(r))
    await wait_revision(viewer, r.get("revision", 0), 5.0)
    await ctl.close()
    await viewer.close()


def http_patch_state(node, patch):
    """PATCH /api/state as the controller: (HTTP status, decoded body)."""
    req = urllib.request.Request(f"http://127.0.0.1:{node.port}/api/state",
                                 data=json.dumps(patch).encode(), method="PATCH",
                                 headers={"Authorization": f"Bearer {TOKEN}",
                                          "Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"{}")


def metric(node, name):
    """A sample's value from the node's /metrics, or None."""
    with urllib.request.urlopen(f"http://127.0.0.1:{node.port}/metrics", timeout=5) as r:
        for line in r.read().decode().splitlines():
            if line.startswith(name + " "):
                return float(line.split()[1])
    return None


async def redis_faults(n1, n2, redis):
    ctl1 = await controller(n1.url(), "ctl-f1")
    ctl2 = await controller(n2.url(), "ctl-f2")
    viewer = await connect(n1.url(), "viewer-f")
    r = await ctl1.request({"type": "set", "id": "f0", "patch": {"weather": {"humidity": 0.31}}})
    check("faults: a change before the fault is acknowledged", r.get("type") == "ack", short(r))
    acked = r.get("revision")
    sub = await viewer.request({"type": "subscribe", "id": "f-sub",
                                "view": {"width": 32, "height": 16, "fps": 10}})
    check("faults: viewer subscribed", sub.get("type") == "subscribed", short(sub))
    await viewer.wait_frame(timeout=FIRST_FRAME_TIMEOUT)

    redis.stop(signal.SIGKILL)
    info("faults: redis-server killed with -9")
    r = await ctl1.request({"type": "set", "id": "f1", "patch": {"weather": {"humidity": 0.32}}})
    message = r.get("message", "")
    check("faults: with Redis gone a change is refused as unavailable",
          r.get("type") == "error" and r.get("code") == "unavailable", short(r))
    check("faults: the refusal names the cluster, not the password",
          f"redis://skyd:***@127.0.0.1:{redis.port}" in message and WORLD in message
          and not any(p in message for p in password_forms()), message)
    before = viewer.frame_count.get(sub.get("subscription"), 0)
    await viewer.pump(1.5)
    after = viewer.frame_count.get(sub.get("subscription"), 0)
    check("faults: frames go on while Redis is away", after - before >= 5,
          f"{after - before} frames in 1.5 s")
    status, body = await asyncio.get_running_loop().run_in_executor(
        None, http_patch_state, n2, {"weather": {"humidity": 0.35}})
    check("faults: PATCH /api/state is refused with 503 unavailable",
          status == 503 and body.get("code") == "unavailable", f"{status} {body}")
    check("faults: /metrics says the stream reader is not connected",
          metric(n1, "skyd_cluster_connected") == 0, str(metric(n1, "skyd_cluster_connected")))
    s = await viewer.get_state()
    check("faults: the node keeps the last state", s["revision"] == acked
          and s["state"]["weather"]["humidity"] == 0.31, f"{s['revision']}")

    redis.start()
    rev = resp(redis.port, "GET", f"skyd:{{{WORLD}}}:rev")
    check("faults: Redis restarted on its append-only file keeps every acknowledged change",
          rev is not None and int(rev) == acked, f"{rev} vs {acked}")
    # The nodes reconnect with back-off (at most 2 s between tries).
    t0 = time.monotonic()
    r = None
    while time.monotonic() - t0 < 15:
        r = await ctl2.request({"type": "set", "id": "f2",
                                "patch": {"weather": {"humidity": 0.33}}})
        if r.get("type") == "ack":
            break
        await asyncio.sleep(0.2)
    check("faults: after Redis is back a change through the other node is acknowledged",
          r is not None and r.get("type") == "ack", short(r))
    info(f"faults: node 2 accepted a change {time.monotonic() - t0:.2f} s after the restart")
    if r and r.get("type") == "ack":
        e = await wait_revision(viewer, r["revision"], 10.0)
        check("faults: node 1 caught up from the stream", e is not None
              and e.get("values", {}).get("/weather/humidity") == 0.33, short(e))
        r = await ctl1.request({"type": "set", "id": "f3",
                                "patch": {"weather": {"humidity": 0.34}}})
        check("faults: node 1 takes changes again", r.get("type") == "ack", short(r))
        check("faults: /metrics counts the reconnection",
              metric(n1, "skyd_cluster_connected") == 1
              and metric(n1, "skyd_cluster_connections_total") == 2,
              f"{metric(n1, 'skyd_cluster_connected')}, "
              f"{metric(n1, 'skyd_cluster_connections_total')}")
    for c in (ctl1, ctl2, viewer):
        await c.close()


async def killed_node(n1, n2, lb):
    a = await connect(lb.url(), "lb-a")
    b = await connect(lb.url(), "lb-b")
    s_before = await a.get_state()
    n1.kill()
    info("kill -9: node 1 killed")
    # The client that was on node 1 finds its connection closed.
    closed = []
    for c in (a, b):
        try:
            await c.get_state()
        except Exception:  # noqa: BLE001 - a closed connection is what is looked for
            closed.append(c)
    check("kill -9: exactly one of two haproxy clients was on the killed node",
          len(closed) == 1, f"{len(closed)} closed")
    if not closed:
        return
    t0 = time.monotonic()
    fresh = None
    while time.monotonic() - t0 < 15 and fresh is None:
        try:
            fresh = await connect(lb.url(), "lb-again")
        except Exception:  # noqa: BLE001 - haproxy may still try the dead node
            await asyncio.sleep(0.2)
    if not check("kill -9: the client reconnects through haproxy", fresh is not None):
        return
    info(f"kill -9: reconnected in {time.monotonic() - t0:.2f} s")
    s_after = await fresh.get_state()
    check("kill -9: the same revision on the other node", s_after["revision"] ==
          s_before["revision"], f"{s_before['revision']} vs {s_after['revision']}")
    check("kill -9: the same state", stable(s_after["state"]) == stable(s_before["state"]))
    for c in (fresh, a, b):
        await c.close()


async def late_joiner(skyd, scratch, redis, n2, port3):
    c2 = await controller(n2.url(), "ctl-late")
    r = await c2.request({"type": "set", "id": "l0", "patch": {"weather": {"humidity": 0.61}}})
    check("late joiner: a change before it starts", r.get("type") == "ack", short(r))
    n3 = start_node(skyd, scratch, "node3", redis.port, WORLD, port=port3,
                    initial_state=dict(PAUSED, weather={"humidity": 0.99, "autopilot": "off"}))
    v3 = await connect(n3.url(), "viewer-late")
    s2, s3 = await c2.get_state(), await v3.get_state()
    check("late joiner: starts from the current state and revision",
          s3["revision"] == s2["revision"] and s3["state"] == s2["state"],
          f"{s3['revision']} vs {s2['revision']}, humidity {s3['state']['weather']['humidity']}")
    c3 = await controller(n3.url(), "ctl-3")
    r = await c3.request({"type": "set", "id": "l1", "patch": {"weather": {"humidity": 0.62}}})
    if check("late joiner: takes changes", r.get("type") == "ack", short(r)):
        e = await wait_revision(c2, r["revision"], 5.0)
        check("late joiner: its change reaches the others", e is not None, "")
    for c in (c2, v3, c3):
        await c.close()
    return n3


async def trimmed_stream(node, redis, extra=1100):
    """A node stopped (SIGSTOP) while the world moves on by more changes than the stream keeps
    (about 1000): once it runs again it finds its place trimmed away and takes the snapshot.
    The changes are written straight into Redis as a node's script writes them."""
    viewer = await connect(node.url(), "viewer-trim")
    before = await viewer.get_state()
    keys = {k: f"skyd:{{{WORLD}}}:{k}" for k in ("rev", "state", "stream")}
    state = json.loads(resp(redis.port, "GET", keys["state"]))
    revision = int(resp(redis.port, "GET", keys["rev"]))
    node.proc.send_signal(signal.SIGSTOP)
    t0 = time.monotonic()
    try:
        commands = []
        for i in range(extra):
            revision += 1
            state["revision"] = revision
            state["weather"]["humidity"] = round(0.2 + 0.0005 * (i % 1000), 4)
            text = json.dumps(state)
            commands.append(["XADD", keys["stream"], "MAXLEN", "~", "1000", "*", "rev",
                             revision, "state", text, "by", "ctl-direct", "changed",
                             "/weather/humidity"])
            commands.append(["SET", keys["state"], text])
            commands.append(["SET", keys["rev"], revision])
        # One fsync per write would take most of a minute: these writes are the test's, not
        # acknowledged changes.
        resp(redis.port, "CONFIG", "SET", "appendfsync", "everysec")
        replies = resp_pipeline(redis.port, commands)
        resp(redis.port, "CONFIG", "SET", "appendfsync", "always")
        info(f"trimmed stream: {extra} changes written in {time.monotonic() - t0:.2f} s")
        check("trimmed stream: changes written while the node is stopped",
              all(r is not None for r in replies), "")
        oldest = resp(redis.port, "XRANGE", keys["stream"], "-", "+", "COUNT", "1")
        check("trimmed stream: the stream no longer holds the node's place",
              oldest and int(oldest[0][1][1]) > before["revision"] + 1, short(oldest))
    finally:
        node.proc.send_signal(signal.SIGCONT)
    t0 = time.monotonic()
    e = await wait_revision(viewer, revision, 10.0)
    info(f"trimmed stream: caught up {time.monotonic() - t0:.2f} s after it ran again")
    s = await viewer.get_state()
    check("trimmed stream: the node catches up from the snapshot",
          s["revision"] == revision
          and s["state"]["weather"]["humidity"] == state["weather"]["humidity"],
          f"revision {s['revision']} of {revision}")
    check("trimmed stream: its clients hear of it", e is not None
          and "/weather/humidity" in e.get("changed", []), short(e))
    check("trimmed stream: the node said so", "catching up from the snapshot" in
          node.log_text(), node.log_tail())
    await viewer.close()


def http_text(node, path):
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{node.port}{path}", timeout=10) as r:
            return r.read().decode("utf-8", "replace")
    except urllib.error.HTTPError as e:
        return e.read().decode("utf-8", "replace")


async def password_outputs(nodes):
    """What a node says to operators and clients, while it runs."""
    texts = []
    for n in nodes:
        if n.proc is None or n.proc.poll() is not None:
            continue
        texts += [http_text(n, "/metrics"), http_text(n, "/healthz"),
                  http_text(n, "/api/state")]
        c = await connect(n.url(), f"viewer-secrets-{n.name}")
        for kind in ("describe", "stats", "get_state"):
            texts.append(json.dumps(await c.request({"type": kind, "id": kind})))
        await c.close()
    return texts


def password_nowhere(nodes, outputs):
    """After the nodes stopped: their logs, stdout lines and what they answered hold no form
    of the password."""
    texts = list(outputs)
    for n in nodes:
        texts.append(n.log_text())
        while not n.lines.empty():
            texts.append(n.lines.get_nowait() or "")
    leaks = [t[:120] for t in texts if any(p in t for p in password_forms())]
    check("secrets: the password is in no log line, stdout line, /metrics, /healthz, "
          "describe or stats", not leaks and len(texts) > 10, short(leaks))
    said = "".join(n.log_text() for n in nodes)
    check("secrets: every node's log names the cluster with the password redacted",
          all("redis://skyd:***@127.0.0.1" in n.log_text() for n in nodes), said[-300:])


async def run(skyd, scratch):
    redis = Redis(scratch, free_port())
    nodes = []
    lb = None
    outputs = []
    try:
        redis.start()
        await bad_configs(skyd, scratch, redis)
        skyd_user_limits(redis)
        ports = [free_port() for _ in range(3)]
        n1 = start_node(skyd, scratch, "node1", redis.port, WORLD, ports[0], PAUSED)
        nodes.append(n1)
        n2 = start_node(skyd, scratch, "node2", redis.port, WORLD, ports[1], PAUSED,
                        password_in="file")
        nodes.append(n2)
        lb = Haproxy(scratch, free_port(), ports)
        lb.start()
        await propagation(n1, n2)
        await concurrent(n1, n2)
        await same_view(n1, n2)
        await clock_running(n1, n2)
        await redis_faults(n1, n2, redis)
        await killed_node(n1, n2, lb)
        nodes.append(await late_joiner(skyd, scratch, redis, n2, ports[2]))
        await trimmed_stream(nodes[-1], redis)
        outputs = await password_outputs(nodes)
    finally:
        if lb:
            lb.stop()
        for n in nodes:
            status = n.terminate()
            if n.proc and n.proc.returncode not in (0, -9):
                check(f"{n.name} stops cleanly", status == 0, f"exit {status}: {n.log_tail()}")
        redis.stop()
    password_nowhere(nodes, outputs)


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 240))
