#!/usr/bin/python3
"""The HTTP API on the daemon's port (protocol/PROTOCOL.md, "HTTP API"), with Python's urllib
beside a WebSocket client (Debian's python3-websockets).

Usage: /usr/bin/python3 tests/e2e/test_http_api.py PATH_TO_SKYD SCRATCH_DIR PROTOCOL_MD

Checks /healthz, /metrics (parsed as the Prometheus text format 0.0.4: every family typed,
counters that count what was done, a consistent histogram), GET and PATCH /api/state against
the protocol (a patch is announced to WebSocket clients; every bad input is refused with the
right status and the state untouched), /api/snapshot (decoded PNGs of the asked size and
format), /api/schema (the same as `skyd schema`), unknown endpoints and methods, the rate limit,
and runs every example of PROTOCOL.md's "HTTP API" section; and through /metrics, that a PNG and
a JPEG subscription to the same view share one render per frame. Exit 0 when every check
passed.
"""

import asyncio
import json
import os
import re
import struct
import subprocess
import sys
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (TOKEN, Client, Daemon, check, decode_png_full, info,  # noqa: E402
                           make_config, run_daemon_test, short)

RATE = 25  # control_messages_per_second: requests are paced under it, then a burst exceeds it
PACE_S = 1.5 / RATE


class Response:
    def __init__(self, status, headers, body):
        self.status, self.headers, self.body = status, headers, body

    def json(self):
        try:
            return json.loads(self.body)
        except ValueError:
            return None

    def header(self, name):
        return self.headers.get(name.lower(), "")


def http(port, method, path, body=None, headers=None):
    """One request; a Response for every status (urllib raises on 4xx/5xx)."""
    data = body.encode() if isinstance(body, str) else body
    request = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, method=method,
                                     headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=30) as r:
            return Response(r.status, {k.lower(): v for k, v in r.headers.items()}, r.read())
    except urllib.error.HTTPError as e:
        return Response(e.code, {k.lower(): v for k, v in e.headers.items()}, e.read())


async def call(port, method, path, body=None, headers=None):
    time.sleep(PACE_S)
    return await asyncio.get_running_loop().run_in_executor(
        None, lambda: http(port, method, path, body, headers))


def bearer(token=TOKEN):
    return {"Authorization": f"Bearer {token}", "Content-Type": "application/json"}


# ------------------------------------------------------------------------------------------
# The Prometheus text format

SAMPLE = re.compile(r'([a-zA-Z_:][a-zA-Z0-9_:]*)(\{([a-zA-Z_][a-zA-Z0-9_]*="(?:[^"\\\n]|\\.)*"'
                    r'(?:,[a-zA-Z_][a-zA-Z0-9_]*="(?:[^"\\\n]|\\.)*")*)?\})? '
                    r'([-+]?(?:[0-9.]+(?:[eE][-+]?[0-9]+)?|Inf|NaN))\n')


def parse_exposition(text):
    """{family: {"type": t, "help": h, "samples": {(name, labels): value}}}; raises ValueError
    on any line that is not the 0.0.4 text format."""
    families, current = {}, None
    for line in text.splitlines(keepends=True):
        if not line.endswith("\n"):
            raise ValueError(f"unterminated line {line!r}")
        if line.startswith("# HELP ") or line.startswith("# TYPE "):
            parts = line[7:].rstrip("\n").split(" ", 1)
            family = families.setdefault(parts[0], {"type": None, "help": None, "samples": {}})
            if line.startswith("# TYPE "):
                if family["type"] is not None or family["samples"]:
                    raise ValueError(f"TYPE after samples or twice: {line!r}")
                if parts[1] not in ("counter", "gauge", "histogram", "summary", "untyped"):
                    raise ValueError(f"unknown type: {line!r}")
                family["type"] = parts[1]
            else:
                family["help"] = parts[1] if len(parts) > 1 else ""
            current = parts[0]
            continue
        if line.startswith("#"):
            continue
        m = SAMPLE.fullmatch(line)
        if not m:
            raise ValueError(f"not a sample line: {line!r}")
        name, labels, value = m.group(1), m.group(3) or "", m.group(4)
        base = re.sub(r"_(bucket|sum|count)$", "", name)
        owner = name if name in families else base
        if owner not in families or owner != current:
            raise ValueError(f"sample outside its family: {line!r}")
        key = (name, labels)
        if key in families[owner]["samples"]:
            raise ValueError(f"sample twice: {line!r}")
        families[owner]["samples"][key] = float(value)
    return families


def metric(families, name, labels=""):
    base = re.sub(r"_(bucket|sum|count|total)$", "", name)
    for family in (name, base, base + "_total"):
        if family in families and (name, labels) in families[family]["samples"]:
            return families[family]["samples"][(name, labels)]
    return None


async def scrape(port):
    r = await call(port, "GET", "/metrics")
    try:
        return parse_exposition(r.body.decode()), r
    except ValueError as e:
        check("/metrics: text exposition format", False, str(e))
        return {}, r


# ------------------------------------------------------------------------------------------
# Sections


async def check_health_and_metrics(port, ws, viewer):
    r = await call(port, "GET", "/healthz")
    body = r.json() or {}
    check("/healthz: 200", r.status == 200, f"{r.status} {r.body[:200]!r}")
    check("/healthz: status ok", body.get("status") == "ok", short(body))
    check("/healthz: recent tick", 0 <= body.get("last_tick_age_s", -1) < 5, short(body))
    check("/healthz: JSON content type", r.header("content-type") == "application/json")

    families, r = await scrape(port)
    check("/metrics: 200 and version 0.0.4", r.status == 200 and
          "version=0.0.4" in r.header("content-type"), f"{r.status} {r.header('content-type')}")
    wanted = {"skyd_frames_rendered_total": "counter", "skyd_frames_sent_total": "counter",
              "skyd_frames_skipped_total": "counter", "skyd_messages_total": "counter",
              "skyd_bytes_sent_total": "counter",
              "skyd_errors_total": "counter", "skyd_device_losses_total": "counter",
              "skyd_clients": "gauge", "skyd_subscriptions": "gauge",
              "skyd_state_revision": "gauge", "skyd_lut_rebuild_progress": "gauge",
              "skyd_frame_seconds": "histogram",
              "skyd_subscription_bytes_sent_total": "counter", "skyd_subscription_fps": "gauge"}
    for name, kind in wanted.items():
        check(f"/metrics: {name} is a {kind}", families.get(name, {}).get("type") == kind,
              str(families.get(name, {}).get("type")))
        check(f"/metrics: {name} has HELP", bool(families.get(name, {}).get("help")))
    # glibc's heap (Debian's C library): what the daemon holds and the free space kept.
    for name in ("skyd_heap_in_use_bytes", "skyd_heap_free_bytes"):
        check(f"/metrics: {name} is a gauge", families.get(name, {}).get("type") == "gauge",
              str(families.get(name, {}).get("type")))
    in_use = metric(families, "skyd_heap_in_use_bytes") or 0
    check("/metrics: the heap in use is between 1 MiB and 4 GiB", 2**20 < in_use < 2**32,
          str(in_use))
    free = metric(families, "skyd_heap_free_bytes")
    check("/metrics: the heap's free space is not negative", free is not None and free >= 0,
          str(free))
    check("/metrics: skyd_clients counts the WebSocket clients",
          metric(families, "skyd_clients") == 2, str(metric(families, "skyd_clients")))

    state = await ws.get_state()
    before, _ = await scrape(port)
    get_state_label = 'type="get_state"'
    get_states = metric(before, "skyd_messages_total", get_state_label) or 0
    unknown = metric(before, "skyd_errors_total", 'code="unknown_field"') or 0
    rendered = metric(before, "skyd_frames_rendered_total") or 0
    sent = metric(before, "skyd_frames_sent_total") or 0
    bytes_sent = metric(before, "skyd_bytes_sent_total") or 0
    for _ in range(3):
        await ws.get_state()
    bad = await ws.request({"type": "get_state", "id": 5, "bogus": 1})
    check("bad message refused", bad.get("code") == "unknown_field", short(bad))
    auth_failures = metric(before, "skyd_errors_total", 'code="auth_failed"') or 0
    refused = await viewer.request({"type": "auth", "id": 8, "token": "not-the-token"})
    check("a wrong token is refused", refused.get("code") == "auth_failed", short(refused))
    sub = await viewer.request({"type": "subscribe", "id": 6,
                                "view": {"width": 64, "height": 36, "fps": 10}})
    check("subscribed", sub.get("type") == "subscribed", short(sub))
    await viewer.wait_frame(timeout=30)
    after, _ = await scrape(port)
    check("/metrics: get_state messages counted",
          metric(after, "skyd_messages_total", get_state_label) == get_states + 4,
          f"{get_states} -> {metric(after, 'skyd_messages_total', get_state_label)}")
    check("/metrics: the unknown_field error counted",
          metric(after, "skyd_errors_total", 'code="unknown_field"') == unknown + 1)
    check("/metrics: the auth_failed error counted under its own code (past the codes' gap)",
          metric(after, "skyd_errors_total", 'code="auth_failed"') == auth_failures + 1,
          str(metric(after, "skyd_errors_total", 'code="auth_failed"')))
    check("/metrics: frames rendered and sent grow",
          metric(after, "skyd_frames_rendered_total") > rendered and
          metric(after, "skyd_frames_sent_total") > sent)
    check("/metrics: bytes sent grow by at least a header per frame",
          metric(after, "skyd_bytes_sent_total") >=
          bytes_sent + 48 * (metric(after, "skyd_frames_sent_total") - sent),
          f"{bytes_sent} -> {metric(after, 'skyd_bytes_sent_total')}")
    check("/metrics: skyd_subscriptions 1", metric(after, "skyd_subscriptions") == 1,
          str(metric(after, "skyd_subscriptions")))
    label = f'subscription="{sub.get("subscription")}"'
    # Per-subscription traffic is published at each render tick: the frame just received may
    # be newer than the last tick, so look again for up to 3 s (the loop ticks at least 1 Hz).
    traffic = after
    for _ in range(30):
        if (metric(traffic, "skyd_subscription_bytes_sent_total", label) or 0) > 0:
            break
        await asyncio.sleep(0.1)
        traffic, _ = await scrape(port)
    check("/metrics: bytes sent to the subscription",
          (metric(traffic, "skyd_subscription_bytes_sent_total", label) or 0) > 0,
          str(traffic.get("skyd_subscription_bytes_sent_total")))
    check("/metrics: the subscription's frame rate",
          0 < (metric(after, "skyd_subscription_fps", label) or 0) <= 10,
          str(after.get("skyd_subscription_fps")))
    check("/metrics: skyd_state_revision is the state's",
          metric(after, "skyd_state_revision") == state["revision"])
    progress = metric(after, "skyd_lut_rebuild_progress")
    check("/metrics: LUT progress in [0, 1]", progress is not None and 0 <= progress <= 1)
    buckets = sorted(((float(labels.split('"')[1]), value)
                      for (name, labels), value in
                      after.get("skyd_frame_seconds", {}).get("samples", {}).items()
                      if name == "skyd_frame_seconds_bucket"), key=lambda b: b[0])
    counts = [value for _, value in buckets]
    total = metric(after, "skyd_frame_seconds_count")
    check("/metrics: histogram buckets cumulative, +Inf last equals count",
          len(buckets) >= 5 and counts == sorted(counts) and buckets[-1][0] == float("inf")
          and counts[-1] == total and total == metric(after, "skyd_frames_rendered_total"),
          f"{buckets} count {total}")
    check("/metrics: histogram sum positive", (metric(after, "skyd_frame_seconds_sum") or 0) > 0)
    await viewer.request({"type": "unsubscribe", "id": 7, "subscription": sub["subscription"]})


async def check_shared_render(port, viewer):
    """A PNG and a JPEG subscription to the same view: skyd_frames_rendered_total grows by one
    per frame of the pair, not by one per frame sent (nothing else renders meanwhile)."""
    view = {"width": 64, "height": 36, "fps": 8, "camera": {"yaw_deg": 200, "pitch_deg": 20}}
    before, _ = await scrape(port)
    rendered = metric(before, "skyd_frames_rendered_total") or 0
    subs = []
    for fmt in ("png", "jpeg"):
        r = await viewer.request({"type": "subscribe", "id": f"pair-{fmt}",
                                  "view": dict(view, format=fmt)})
        check(f"shared render: {fmt} subscribed", r.get("type") == "subscribed", short(r))
        subs.append(r.get("subscription"))
    await viewer.pump(3.0)
    for sub in subs:
        await viewer.request({"type": "unsubscribe", "id": f"un-{sub}", "subscription": sub})
    await viewer.pump(0.5)  # frames already in the encoder arrive
    after, _ = await scrape(port)
    counts = [viewer.frame_count.get(sub, 0) for sub in subs]
    renders = (metric(after, "skyd_frames_rendered_total") or 0) - rendered
    info(f"shared render: {counts[0]} PNG and {counts[1]} JPEG frames from {renders:.0f} renders")
    check("shared render: both subscriptions get frames", min(counts) >= 5, str(counts))
    check("shared render: one render per frame of the pair, not one per encoding",
          max(counts) <= renders <= 1.2 * max(counts) + 2 and renders < 0.75 * sum(counts),
          f"{renders:.0f} renders for {counts} frames")
    subscriptions = metric(after, "skyd_subscriptions")
    check("shared render: nothing else was subscribed", subscriptions == 0, str(subscriptions))


async def check_state(port, ws):
    r = await call(port, "GET", "/api/state")
    body = r.json() or {}
    got = await ws.get_state()
    check("GET /api/state: 200", r.status == 200, f"{r.status}")
    check("GET /api/state: revision and state members",
          set(body) == {"revision", "state"} and body.get("revision") == got["revision"],
          short(body))
    check("GET /api/state: same fields as get_state",
          set(body.get("state", {})) == set(got["state"]), short(body))

    revision = got["revision"]
    r = await call(port, "PATCH", "/api/state", json.dumps({"sun": {"illuminance_lux": 98765}}),
                   bearer())
    check("PATCH: 200 with the new revision", r.status == 200 and
          r.json() == {"revision": revision + 1}, f"{r.status} {r.body[:200]!r}")
    event = await ws.wait_event(lambda e: e.get("event") == "state_changed" and
                                e.get("revision") == revision + 1)
    check("PATCH: state_changed reaches WebSocket clients", event is not None and
          "/sun/illuminance_lux" in event.get("changed", []), short(event))
    after = await ws.get_state()
    check("PATCH: applied", after["state"]["sun"]["illuminance_lux"] == 98765)

    bad_inputs = [
        ("no token", None, {"sun": {"illuminance_lux": 1}}, 401, "auth_failed", None),
        ("wrong token", bearer("nope"), {"sun": {"illuminance_lux": 1}}, 401, "auth_failed",
         None),
        ("out of range", bearer(), {"atmosphere": {"mie": {"g": 7}}}, 422, "out_of_range",
         "/patch/atmosphere/mie/g"),
        ("unknown field", bearer(), {"sun": {"bogus": 1}}, 422, "unknown_field",
         "/patch/sun/bogus"),
        ("wrong type", bearer(), {"sun": {"illuminance_lux": "bright"}}, 422, "wrong_type",
         "/patch/sun/illuminance_lux"),
        ("not an object", bearer(), [1, 2], 422, "wrong_type", "/patch"),
        ("malformed JSON", bearer(), '{"sun": ', 400, "malformed_json", None),
        ("empty body", bearer(), "", 400, "malformed_json", None),
        ("too large", bearer(), {"x": "y" * 20000}, 413, "message_too_large", None),
        ("read-only member", bearer(), {"revision": 3}, 422, None, "/patch/revision"),
    ]
    for name, headers, body, status, code, pointer in bad_inputs:
        text = body if isinstance(body, str) else json.dumps(body)
        r = await call(port, "PATCH", "/api/state", text, headers)
        reply = r.json() or {}
        check(f"PATCH {name}: {status}", r.status == status, f"{r.status} {r.body[:300]!r}")
        check(f"PATCH {name}: error shape", reply.get("type") == "error" and
              isinstance(reply.get("message"), str) and isinstance(reply.get("fields"), list),
              short(reply))
        if code:
            check(f"PATCH {name}: code {code}", reply.get("code") == code, short(reply))
        if pointer:
            check(f"PATCH {name}: names {pointer}",
                  any(f.get("pointer") == pointer for f in reply.get("fields", [])), short(reply))
        if status == 401:
            check(f"PATCH {name}: www-authenticate", r.header("www-authenticate") == "Bearer")
    unchanged = await ws.get_state()
    check("bad patches leave the state untouched", unchanged["revision"] == revision + 1 and
          unchanged["state"]["sun"] == after["state"]["sun"], short(unchanged["state"]["sun"]))


async def check_snapshot(port):
    cases = [("perspective", "width=96&height=54&yaw_deg=90&pitch_deg=20", 96, 54, 8),
             ("png16", "width=64&height=40&format=png16", 64, 40, 16),
             ("panorama", "width=128&height=64&projection=equirectangular", 128, 64, 8)]
    images = {}
    for name, query, width, height, depth in cases:
        r = await call(port, "GET", f"/api/snapshot?{query}")
        check(f"snapshot {name}: 200 image/png", r.status == 200 and
              r.header("content-type") == "image/png", f"{r.status} {r.body[:200]!r}")
        try:
            png = decode_png_full(r.body)
            check(f"snapshot {name}: {width}x{height} {depth}-bit",
                  (png["width"], png["height"], png["depth"]) == (width, height, depth),
                  short({k: png[k] for k in ("width", "height", "depth")}))
            images[name] = r.body
        except Exception as e:  # noqa: BLE001 - a decoding failure is the check failing
            check(f"snapshot {name}: decodes", False, repr(e))
    r = await call(port, "GET", "/api/snapshot?width=96&height=54&format=jpeg&quality=60")
    body = r.body or b""
    check("snapshot jpeg: 200 image/jpeg", r.status == 200 and
          r.header("content-type") == "image/jpeg", f"{r.status} {body[:200]!r}")
    check("snapshot jpeg: SOI and EOI markers", body[:2] == b"\xff\xd8" and body[-2:] == b"\xff\xd9",
          body[:4].hex())
    # The baseline SOF0 segment carries the height and width.
    sof = body.find(b"\xff\xc0")
    check("snapshot jpeg: 96x54", sof > 0 and struct.unpack_from(">HH", body, sof + 5) == (54, 96),
          str(sof))
    r = await call(port, "GET", "/api/snapshot?width=96&height=54&yaw_deg=270&pitch_deg=20")
    check("snapshot: the camera parameters change the image",
          r.status == 200 and r.body != images.get("perspective"))
    bad = [("too high", "width=64&height=99999", 422, "out_of_range", "/view/height"),
           ("missing height", "width=64", 422, "missing_field", "/view/height"),
           ("not a number", "width=wide&height=64", 422, "wrong_type", "/view/width"),
           ("unknown format", "width=64&height=64&format=gif", 422, "bad_value", "/view/format"),
           ("quality with png", "width=64&height=64&quality=50", 422, "inconsistent",
            "/view/quality"),
           ("quality 0", "width=64&height=64&format=jpeg&quality=0", 422, "out_of_range",
            "/view/quality"),
           ("unknown parameter", "width=64&height=64&zoom=2", 422, "unknown_field", None),
           ("twice", "width=64&width=65&height=64", 422, "unknown_field", None)]
    for name, query, status, code, pointer in bad:
        r = await call(port, "GET", f"/api/snapshot?{query}")
        reply = r.json() or {}
        check(f"snapshot {name}: {status} {code}", r.status == status and
              reply.get("code") == code, f"{r.status} {r.body[:300]!r}")
        if pointer:
            check(f"snapshot {name}: names {pointer}",
                  any(f.get("pointer") == pointer for f in reply.get("fields", [])), short(reply))


async def check_schema_and_routes(port, skyd):
    r = await call(port, "GET", "/api/schema")
    schema = r.json() or {}
    printed = json.loads(subprocess.run([skyd, "schema"], capture_output=True, check=True,
                                        timeout=30).stdout)
    check("/api/schema: 200, the same as `skyd schema`", r.status == 200 and schema == printed)
    latitude = schema.get("properties", {}).get("location", {}).get("properties", {}) \
        .get("latitude_deg", {})
    check("/api/schema: a field has its type, range, unit and description",
          latitude.get("type") == "number" and latitude.get("minimum") == -90 and
          latitude.get("maximum") == 90 and latitude.get("x-unit") == "deg" and
          bool(latitude.get("description")), short(latitude))
    for method, path, status in [("GET", "/api/nothing", 404), ("GET", "/api", 404),
                                 ("POST", "/api/state", 405), ("DELETE", "/healthz", 405),
                                 ("PATCH", "/api/snapshot", 405)]:
        r = await call(port, method, path, "{}" if method != "GET" else None)
        reply = r.json() or {}
        check(f"{method} {path}: {status}", r.status == status and reply.get("type") == "error",
              f"{r.status} {r.body[:200]!r}")
        if status == 405:
            check(f"{method} {path}: allow header", r.header("allow") in ("GET", "GET, PATCH"))


async def check_rate_limit(port, ws):
    def burst():
        return [http(port, "GET", "/api/state").status for _ in range(RATE * 2)]
    statuses = await asyncio.get_running_loop().run_in_executor(None, burst)
    check("a burst past the rate limit gets 429", 429 in statuses and statuses[0] == 200,
          str(statuses))
    r = http(port, "GET", "/healthz")
    check("/healthz is not rate-limited", r.status == 200, str(r.status))
    r = http(port, "GET", "/api/state")
    check("the limited request has the protocol's error", r.status != 429 or
          (r.json() or {}).get("code") == "rate_limited", r.body[:200])
    await asyncio.sleep(1.2)
    r = await call(port, "GET", "/api/state")
    check("after a second, requests pass again", r.status == 200, str(r.status))
    await ws.get_state()


async def check_protocol_examples(port, protocol_md):
    text = open(protocol_md, encoding="utf-8").read()
    section = text.split("## HTTP API", 1)[-1].split("\n## ", 1)[0]
    pairs = re.findall(r"```http request\n(.*?)```\s*```http response\n(.*?)```", section, re.S)
    check("PROTOCOL.md: HTTP examples found for every endpoint",
          {p[0].split()[1].split("?")[0] for p in pairs} ==
          {"/healthz", "/metrics", "/api/state", "/api/snapshot", "/api/schema",
           "/api/weather/metar", "/api/weather/forecast"},
          str([p[0].split("\n")[0] for p in pairs]))
    for request, response in pairs:
        head, _, body = request.partition("\n\n")
        lines = head.strip().split("\n")
        method, path = lines[0].split()
        headers = dict(line.split(": ", 1) for line in lines[1:])
        headers = {k: v.replace("TOKEN", TOKEN) for k, v in headers.items()}
        status_line, _, expected = response.partition("\n")
        status, content_type = status_line.split()
        r = await call(port, method, path, body.strip() or None, headers)
        name = f"PROTOCOL.md example {lines[0]} ({status})"
        check(f"{name}: status and type", r.status == int(status) and
              r.header("content-type").startswith(content_type),
              f"{r.status} {r.header('content-type')} {r.body[:200]!r}")
        if content_type == "application/json" and expected.strip():
            shown, got = json.loads(expected), r.json() or {}
            check(f"{name}: members", set(shown) <= set(got), f"{set(shown)} vs {set(got)}")
        elif content_type == "text/plain":
            families = parse_exposition(r.body.decode())
            shown = re.findall(r"^# TYPE (\S+) (\S+)$", expected, re.M)
            check(f"{name}: families", all(families.get(n, {}).get("type") == t
                                           for n, t in shown), str(shown))


PROTOCOL_MD = None


async def run(skyd, scratch):
    protocol_md = PROTOCOL_MD
    state_file = os.path.join(scratch, "state.json")
    for stale in (state_file, state_file + ".token"):
        if os.path.exists(stale):
            os.remove(stale)
    config = make_config(scratch, state_file, control_messages_per_second=RATE)
    daemon = Daemon(skyd, scratch, "http_api", config)
    daemon.start()
    try:
        ws = await Client.connect(daemon.url(), "controller")
        await ws.auth()
        viewer = await Client.connect(daemon.url(), "viewer")
        await check_health_and_metrics(daemon.port, ws, viewer)
        await check_shared_render(daemon.port, viewer)
        await check_state(daemon.port, ws)
        await check_snapshot(daemon.port)
        await check_schema_and_routes(daemon.port, skyd)
        await check_protocol_examples(daemon.port, protocol_md)
        await check_rate_limit(daemon.port, ws)
        r = http(daemon.port, "GET", "/healthz")
        check("still healthy after everything", r.status == 200, r.body[:200])
        await ws.close()
        await viewer.close()
    finally:
        status = daemon.terminate()
        check("daemon exits 0 on SIGTERM", status == 0, f"status {status}")
        info(f"log tail: {daemon.log_tail(300)}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    PROTOCOL_MD = sys.argv.pop(3)
    sys.exit(run_daemon_test(run, __doc__, 240))
