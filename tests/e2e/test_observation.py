#!/usr/bin/python3
"""apply_observation and POST /api/weather/metar with the real daemon on loopback (Debian's
python3-websockets, urllib).

Usage: /usr/bin/python3 tests/e2e/test_observation.py PATH_TO_SKYD SCRATCH_DIR

A controller's METAR becomes one revision: the reply carries it with the decoded report, the
patch applied and the groups left unmapped; the state shows the sky of the report (FEW040: a
fair cumulus layer at 1.2 km, weather.source "metar") and a viewer hears of it. A middle-étage
group beside a low one is reported unmapped. A report the decoder refuses (a bad cloud group,
NIL, none at all) is a bad_value at /metar naming the group, and a viewer's is forbidden; the
state is untouched each time. Over HTTP: the report as text or as {"metar": ...} with the
bearer token; without it 401; a refused report 422 with the decoder's message; GET 405 with
Allow: POST. weather.source survives a restart (it is persisted with the state).
Exit 0 when every check passed.
"""

import asyncio
import json
import os
import sys
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (TOKEN, Client, Daemon, bad_input, check, check_unchanged,  # noqa: E402
                           info, make_config, run_daemon_test, short)

FAIR = "METAR LFLY 211200Z 18008KT 9999 FEW040 22/10 Q1018"
LAYERED = "METAR LFLY 211230Z 18008KT 9999 SCT030 BKN100 12/05 Q1010"
BAD = "METAR EGLL 281150Z 24010KT 9999 BKN0X0 12/09 Q1005"
FOG = "METAR EGLL 280650Z 00000KT 0200 FG OVC005 08/08 Q1025"


def http(port, method, path, body=None, headers=None):
    """(status, headers, parsed JSON or None) for every status."""
    data = body.encode() if isinstance(body, str) else body
    request = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, method=method,
                                     headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=30) as r:
            status, hdrs, raw = r.status, dict(r.headers.items()), r.read()
    except urllib.error.HTTPError as e:
        status, hdrs, raw = e.code, dict(e.headers.items()), e.read()
    try:
        parsed = json.loads(raw)
    except ValueError:
        parsed = None
    return status, {k.lower(): v for k, v in hdrs.items()}, parsed


async def call(port, method, path, body=None, headers=None):
    return await asyncio.get_running_loop().run_in_executor(
        None, lambda: http(port, method, path, body, headers))


async def check_ws(ctl, viewer):
    before = await ctl.get_state()
    r = await ctl.request({"type": "apply_observation", "id": "o1", "metar": FAIR})
    check("FEW040: an observation reply", r.get("type") == "observation" and r.get("id") == "o1",
          short(r))
    check("FEW040: a new revision", r.get("revision") == before.get("revision", 0) + 1, short(r))
    report = r.get("report") or {}
    check("FEW040: the decoded report", report.get("station") == "LFLY"
          and [c.get("amount") for c in report.get("clouds", [])] == ["FEW"], short(report))
    patch = r.get("patch") or {}
    check("FEW040: the patch applied", patch.get("weather", {}).get("source") == "metar"
          and abs(patch.get("clouds", {}).get("low", {}).get("coverage", -1) - 0.1875) < 1e-12,
          short(patch))
    check("FEW040: nothing unmapped", r.get("unmapped") == [], short(r))
    state = (await ctl.get_state()).get("state", {})
    low = state.get("clouds", {}).get("low", {})
    check("FEW040: fair cumulus at 1.2 km in the state",
          abs(low.get("coverage", -1) - 0.1875) < 1e-12
          and abs(low.get("bottom_km", -1) - 1.2192) < 1e-9
          and abs(low.get("type", -1) - 2 / 3) < 1e-12, short(low))
    check("FEW040: weather.source metar", state.get("weather", {}).get("source") == "metar",
          short(state.get("weather")))
    event = await viewer.wait_event(lambda e: e.get("revision") == r.get("revision"))
    check("FEW040: the viewer hears of it", event is not None
          and "/weather/source" in (event or {}).get("changed", []), short(event))

    r = await ctl.request({"type": "apply_observation", "id": "o2", "metar": LAYERED})
    mid = ((r.get("patch") or {}).get("clouds") or {}).get("mid") or {}
    check("BKN100 beside SCT030: the middle layer takes it (altostratus), nothing unmapped",
          r.get("unmapped") == [] and mid.get("coverage") == 0.75 and mid.get("type") == 0
          and abs(mid.get("bottom_km", 0) - 3.048) < 1e-9, short(r))

    await bad_input("bad cloud group", ctl,
                    {"type": "apply_observation", "id": "b1", "metar": BAD}, "bad_value",
                    "/metar", "b1")
    state_before = await ctl.get_state()
    r = await ctl.request({"type": "apply_observation", "id": "b2", "metar": BAD})
    message = r.get("message", "")
    check("bad cloud group: the message names the group, its index and offset",
          'group 6 "BKN0X0" (offset 32)' in message, short(r))
    await check_unchanged("bad cloud group, again", ctl, state_before)
    await bad_input("NIL report", ctl, {"type": "apply_observation", "id": "b3",
                                        "metar": "METAR EGLL 281150Z NIL"}, "bad_value",
                    "/metar", "b3")
    await bad_input("no report", ctl, {"type": "apply_observation", "id": "b4"},
                    "missing_field", "/metar", "b4")
    await bad_input("empty report", ctl, {"type": "apply_observation", "id": "b5", "metar": ""},
                    "out_of_range", "/metar", "b5")
    await bad_input("a viewer", viewer, {"type": "apply_observation", "id": "v1", "metar": FOG},
                    "forbidden", None, "v1")


async def check_http(port, ctl):
    bearer = {"Authorization": f"Bearer {TOKEN}"}
    status, _, body = await call(port, "POST", "/api/weather/metar", FOG + "\n", bearer)
    check("HTTP text: 200 with revision, report, patch, unmapped",
          status == 200 and body is not None
          and {"revision", "report", "patch", "unmapped"} <= set(body), f"{status} {body}")
    state = (await ctl.get_state()).get("state", {})
    low = state.get("clouds", {}).get("low", {})
    check("HTTP text: overcast stratus at 150 m and fog",
          low.get("coverage") == 1 and low.get("type") == 0
          and state.get("atmosphere", {}).get("fog", {}).get("density_per_km", 0) > 10,
          short(state.get("clouds")))
    status, _, body = await call(port, "POST", "/api/weather/metar", json.dumps({"metar": FAIR}),
                                 dict(bearer, **{"Content-Type": "application/json"}))
    check("HTTP JSON: 200", status == 200 and (body or {}).get("report", {}).get("station")
          == "LFLY", f"{status} {body}")
    before = await ctl.get_state()
    status, _, body = await call(port, "POST", "/api/weather/metar", FOG)
    check("HTTP without the token: 401", status == 401
          and (body or {}).get("code") == "auth_failed", f"{status} {body}")
    status, _, body = await call(port, "POST", "/api/weather/metar", BAD, bearer)
    fields = (body or {}).get("fields") or [{}]
    check("HTTP refused report: 422 bad_value at /metar naming the group",
          status == 422 and (body or {}).get("code") == "bad_value"
          and fields[0].get("pointer") == "/metar" and "BKN0X0" in fields[0].get("reason", ""),
          f"{status} {body}")
    status, _, body = await call(port, "POST", "/api/weather/metar",
                                 json.dumps({"metar": FAIR, "station": "x"}), bearer)
    check("HTTP JSON with another member: refused", status >= 400
          and (body or {}).get("code") == "unknown_field", f"{status} {body}")
    status, headers, _ = await call(port, "GET", "/api/weather/metar")
    check("HTTP GET: 405 Allow: POST", status == 405 and headers.get("allow") == "POST",
          f"{status} {headers}")
    await check_unchanged("HTTP refusals", ctl, before)


async def run(skyd, scratch):
    state_file = os.path.join(scratch, "state.json")
    for stale in (state_file, state_file + ".token"):
        if os.path.exists(stale):
            os.remove(stale)
    config = make_config(scratch, state_file)
    daemon = Daemon(skyd, scratch, "observation", config)
    daemon.start()
    try:
        ctl = await Client.connect(daemon.url(), "controller")
        await ctl.auth()
        viewer = await Client.connect(daemon.url(), "viewer")
        await check_ws(ctl, viewer)
        await check_http(daemon.port, ctl)
        await ctl.close()
        await viewer.close()
    finally:
        status = daemon.terminate()
        check("daemon exits 0 on SIGTERM", status == 0, f"status {status}")
    daemon = Daemon(skyd, scratch, "observation-restart", config)
    daemon.start()
    try:
        c = await Client.connect(daemon.url(), "after restart")
        state = (await c.get_state()).get("state", {})
        check("restart: weather.source is still metar",
              state.get("weather", {}).get("source") == "metar", short(state.get("weather")))
        await c.close()
    finally:
        status = daemon.terminate()
        check("restarted daemon exits 0", status == 0, f"status {status}")
        info(f"log tail: {daemon.log_tail(300)}")


if __name__ == "__main__":
    started = time.monotonic()
    sys.exit(run_daemon_test(run, __doc__, 240))
