"""test_serve.py's checks of the world simulation on the main daemon: the clock runs at
clock.time_scale, the ephemeris moves the sun, a weather transition reaches its preset, and the
simulation's rules for set hold."""

import asyncio
import json
import os
import time

from serve_harness import bad_input, check, short


def utc_seconds(text):
    """ISO 8601 UTC text of clock.utc to seconds since 1970."""
    import datetime
    return datetime.datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


async def wait_state(ctl, pred, timeout):
    """Polls get_state until pred(state tree) holds; the last state either way."""
    deadline = time.monotonic() + timeout
    while True:
        s = (await ctl.get_state()).get("state", {})
        if pred(s) or time.monotonic() > deadline:
            return s
        await asyncio.sleep(0.1)


async def t_world_sim(ctl, repo_config_dir):
    """The daemon's clock runs at clock.time_scale, the ephemeris moves the sun, a weather
    transition progresses to the preset, and the simulation's rules for set hold."""
    r = await ctl.request({"type": "set", "id": "w1", "patch": {
        "clock": {"utc": "2026-03-20T06:00:00Z", "time_scale": 3600, "sky_bodies": "ephemeris"},
        "location": {"latitude_deg": 0, "longitude_deg": 0}}})
    check("world: set clock ack", r.get("type") == "ack", short(r))
    rev = r.get("revision")
    t_real = time.monotonic()
    s0 = (await ctl.get_state()).get("state", {})
    s1 = await wait_state(ctl, lambda s: utc_seconds(s["clock"]["utc"])
                          - utc_seconds(s0["clock"]["utc"]) > 1800, 5)
    real = time.monotonic() - t_real
    sim = utc_seconds(s1["clock"]["utc"]) - utc_seconds(s0["clock"]["utc"])
    check("world: clock advances at time_scale 3600", 1800 < sim <= 3600 * (real + 0.5),
          f"{sim:.0f} simulated s in {real:.2f} real s")
    check("world: the ephemeris raises the equinox sun after 06:00 at the equator",
          s1["sun"]["elevation_deg"] > s0["sun"]["elevation_deg"] + 5,
          f"{s0['sun']['elevation_deg']} -> {s1['sun']['elevation_deg']}")
    now = await ctl.get_state()
    check("world: the simulation does not bump the revision", now.get("revision") == rev,
          f"ack {rev}, now {now.get('revision')}")
    st = await ctl.request({"type": "stats", "id": "wst"})
    check("world: stats carry the simulated clock",
          abs(st.get("simulation_time_s", 0) - utc_seconds(now["state"]["clock"]["utc"])) < 7200,
          short(st))

    await bad_input("set a sun angle in ephemeris mode", ctl,
                    {"type": "set", "id": "w2", "patch": {"sun": {"elevation_deg": 5}}},
                    "inconsistent", "/patch/sun/elevation_deg", "w2")
    await bad_input("set a read-only transition field", ctl,
                    {"type": "set", "id": "w3",
                     "patch": {"weather": {"transition": {"progress": 0.5}}}},
                    "bad_value", "/patch/weather/transition/progress", "w3")
    await bad_input("unknown weather preset", ctl,
                    {"type": "apply_preset", "id": "w4", "kind": "weather", "name": "hail"},
                    "not_found", None, "w4")
    await bad_input("transition_s out of range", ctl,
                    {"type": "apply_preset", "id": "w5", "kind": "weather", "name": "storm",
                     "transition_s": -5}, "out_of_range", "/transition_s", "w5")

    r = await ctl.request({"type": "list_presets", "id": "w6", "kind": "weather"})
    check("world: weather presets listed", r.get("names") == sorted(
        ["altocumulus", "broken", "clear", "fair_cumulus", "overcast", "scattered", "storm",
         "warm_front"]), short(r))
    r = await ctl.request({"type": "set", "id": "w7", "patch": {"clock": {"time_scale": 600}}})
    r = await ctl.request({"type": "apply_preset", "id": "w8", "kind": "weather",
                           "name": "clear"})
    r = await ctl.request({"type": "apply_preset", "id": "w9", "kind": "weather",
                           "name": "storm", "transition_s": 1200})
    check("world: apply_preset storm with transition_s: ack", r.get("type") == "ack", short(r))
    s = (await ctl.get_state()).get("state", {})
    tr = s.get("weather", {}).get("transition", {})
    check("world: the transition is under way", tr.get("duration_s") == 1200
          and 0 <= tr.get("progress", -1) < 1 and s["clouds"]["low"]["coverage"] < 0.85, short(tr))
    with open(os.path.join(repo_config_dir, "weather", "storm.json")) as f:
        storm = json.load(f)
    mid = await wait_state(ctl, lambda s: 0.2 < s["weather"]["transition"]["progress"] < 0.8, 5)
    done = await wait_state(ctl, lambda s: s["weather"]["transition"]["progress"] == 1, 8)
    check("world: the transition passes its middle",
          0 < mid["clouds"]["low"]["coverage"] < 0.85, short(mid["clouds"]["low"]))
    check("world: the transition ends exactly at the preset",
          done["weather"]["transition"]["progress"] == 1
          and all(done["clouds"][k] == storm["clouds"][k] for k in storm["clouds"])
          and done["weather"]["humidity"] == storm["weather"]["humidity"],
          short(done["clouds"]))
    r = await ctl.request({"type": "set", "id": "w10", "patch": {
        "clock": {"time_scale": 1, "sky_bodies": "manual"}, "sun": {"elevation_deg": 45}}})
    check("world: back to manual", r.get("type") == "ack", short(r))
