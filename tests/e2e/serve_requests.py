"""test_serve.py's checks of frames and the other requests on the main daemon: a subscription's
frames (binary header, PNG payload, frame numbers, the revision after a set), unsubscribe, the
subscription limit, snapshots, probes, presets and stats."""

import asyncio
import json
import os
import time

from serve_harness import (FIRST_FRAME_TIMEOUT, HEADER, REPLY_TIMEOUT, Client, approx_equal,
                           bad_input, check, check_binary_frame, check_error, info, json_diff,
                           short, stable)


async def t_frames(d, ctl, viewer):
    # Make sure the revision the frames must carry is the last set's.
    r = await ctl.request({"type": "set", "id": "fs1", "patch": {"sun": {"elevation_deg": 15}}})
    check("frames: set ack", r.get("type") == "ack", short(r))
    rev = r.get("revision")
    viewer.frames.clear()
    r = await viewer.request({"type": "subscribe", "id": "sub-a",
                              "view": {"width": 160, "height": 90, "fps": 10}})
    ok = check("subscribe: subscribed", r.get("type") == "subscribed" and r.get("id") == "sub-a"
               and isinstance(r.get("subscription"), int) and r["subscription"] >= 1, short(r))
    if not ok:
        return None
    sub = r["subscription"]
    view = r.get("view", {})
    check("subscribe: normalized view", view.get("width") == 160 and view.get("height") == 90
          and view.get("fps") == 10 and view.get("format") == "png"
          and view.get("camera", {}) == {} and view.get("exposure", {}) == {}, short(view))
    try:
        m, b = await viewer.wait_frame(lambda m: m.get("subscription") == sub,
                                       FIRST_FRAME_TIMEOUT)
    except asyncio.TimeoutError:
        check("subscribe: first frame", False, f"no frame within {FIRST_FRAME_TIMEOUT} s")
        return sub
    check("subscribe: first frame", True)
    check("frame message: no id", "id" not in m, short(m))
    check_binary_frame("subscription frame", m, b, 160, 90, revision=rev)
    # Consecutive frames on the connection count up by one.
    m2, b2 = await viewer.wait_frame(lambda x: x.get("subscription") == sub)
    check("frame_number increases by one", m2.get("frame_number") == m.get("frame_number") + 1,
          f"{m.get('frame_number')} then {m2.get('frame_number')}")
    check_binary_frame("second subscription frame", m2, b2, 160, 90, decode=False)
    # A state change reaches the subscription.
    r = await ctl.request({"type": "set", "id": "fs2", "patch": {"sun": {"elevation_deg": 25}}})
    rev2 = r.get("revision")
    try:
        deadline = time.monotonic() + REPLY_TIMEOUT
        found = None
        while time.monotonic() < deadline and found is None:
            mm, bb = await viewer.wait_frame(lambda x: x.get("subscription") == sub,
                                             deadline - time.monotonic())
            if isinstance(bb, bytes) and len(bb) >= 48 and HEADER.unpack_from(bb)[4] == rev2:
                found = (mm, bb)
        check("frame after a set carries the new revision", found is not None,
              f"no frame with state_revision {rev2}")
    except asyncio.TimeoutError:
        check("frame after a set carries the new revision", False,
              f"no frame with state_revision {rev2}")
    return sub


async def t_unsubscribe(viewer, sub):
    r = await viewer.request({"type": "unsubscribe", "id": "un1", "subscription": sub})
    check("unsubscribe: ack", r.get("type") == "ack" and r.get("id") == "un1", short(r))
    n = viewer.frame_count.get(sub, 0)
    await viewer.pump(1.5)  # at fps 10, a live subscription would deliver ~15 frames
    check("unsubscribe: no frames after the ack", viewer.frame_count.get(sub, 0) == n,
          f"{viewer.frame_count.get(sub, 0) - n} frames of subscription {sub} after the ack")
    await bad_input("unsubscribe again", viewer,
                    {"type": "unsubscribe", "id": "un2", "subscription": sub}, "not_found",
                    id_="un2")


async def t_subscription_limit(d):
    c = await Client.connect(d.url(), "sub-limit")
    try:
        subs = []
        for i in range(4):
            r = await c.request({"type": "subscribe", "id": f"l{i}",
                                 "view": {"width": 16, "height": 16, "fps": 1,
                                          "camera": {"yaw_deg": 10 * i}}})
            check(f"subscription {i + 1} of 4 accepted", r.get("type") == "subscribed", short(r))
            subs.append(r.get("subscription"))
        check("subscription numbers distinct", len(set(subs)) == 4, short(subs))
        r = await c.request({"type": "subscribe", "id": "l5",
                             "view": {"width": 16, "height": 16, "fps": 1}})
        check_error("fifth subscription", r, "limit_reached", id_="l5")
    finally:
        await c.close()


async def t_snapshot(d, viewer):
    rev = (await viewer.get_state()).get("revision")
    r = await viewer.request({"type": "snapshot", "id": "snap-1",
                              "view": {"width": 96, "height": 54, "fps": 5}},
                             FIRST_FRAME_TIMEOUT)
    ok = check("snapshot: frame reply with the id", r.get("type") == "frame"
               and r.get("id") == "snap-1" and "subscription" not in r,
               short({k: v for k, v in r.items() if k != "_binary"}))
    if ok:
        check_binary_frame("snapshot frame", r, r.get("_binary"), 96, 54, revision=rev)
    r2 = await viewer.request({"type": "snapshot", "id": 77, "view": {"width": 32, "height": 20}})
    if check("snapshot 2: frame reply with the id", r2.get("type") == "frame"
             and r2.get("id") == 77, short({k: v for k, v in r2.items() if k != "_binary"})):
        check_binary_frame("snapshot 2 frame", r2, r2.get("_binary"), 32, 20, decode=False)
        if ok:  # the viewer's subscription shares the counter: only the order is fixed
            check("snapshot frame_numbers count up on the connection",
                  r2.get("frame_number", 0) > r.get("frame_number", 0),
                  f"{r.get('frame_number')} then {r2.get('frame_number')}")


async def t_probe(ctl):
    r = await ctl.request({"type": "probe", "id": "pr1", "quantity": "transmittance",
                           "altitude_km": 0, "mu": 1})
    t = r.get("transmittance")
    check("probe transmittance: reply", r.get("type") == "probe_result" and r.get("id") == "pr1"
          and r.get("quantity") == "transmittance", short(r))
    check("probe transmittance: three values in (0,1)",
          isinstance(t, list) and len(t) == 3
          and all(isinstance(x, (int, float)) and 0 < x < 1 for x in t), short(r))
    r = await ctl.request({"type": "probe", "id": "pr2", "quantity": "illuminance",
                           "sun_zenith_deg": 0})
    check("probe illuminance: sun_lux and sky_lux positive",
          r.get("type") == "probe_result" and isinstance(r.get("sun_lux"), (int, float))
          and r["sun_lux"] > 0 and isinstance(r.get("sky_lux"), (int, float))
          and r["sky_lux"] > 0, short(r))
    r = await ctl.request({"type": "probe", "id": "pr3", "quantity": "luminance",
                           "altitude_km": 0, "view_zenith_deg": 45, "view_azimuth_deg": 90,
                           "sun_zenith_deg": 30})
    lum = r.get("luminance")
    check("probe luminance: three positive values",
          r.get("type") == "probe_result" and isinstance(lum, list) and len(lum) == 3
          and all(isinstance(x, (int, float)) and x > 0 for x in lum), short(r))


async def t_presets(d, ctl, viewer, repo_config_dir):
    r = await ctl.request({"type": "list_presets", "id": "lp", "kind": "atmosphere"})
    names = r.get("names")
    check("list_presets: reply", r.get("type") == "presets" and r.get("id") == "lp"
          and r.get("kind") == "atmosphere", short(r))
    check("list_presets: earth and mars", isinstance(names, list) and "earth" in names
          and "mars" in names, short(r))
    before = await ctl.get_state()
    viewer.events.clear()
    r = await ctl.request({"type": "apply_preset", "id": "ap", "kind": "atmosphere",
                           "name": "mars"})
    ok = check("apply_preset mars: ack", r.get("type") == "ack" and r.get("id") == "ap"
               and isinstance(r.get("revision"), int) and r["revision"] > before["revision"],
               short(r))
    after = await ctl.get_state()
    atm = after.get("state", {}).get("atmosphere", {})
    check("apply_preset mars: /atmosphere changed",
          not approx_equal(atm, before.get("state", {}).get("atmosphere")), short(atm))
    mars_path = os.path.join(repo_config_dir, "atmosphere", "mars.json")
    try:
        with open(mars_path) as f:
            mars = json.load(f)["atmosphere"]
        check("apply_preset mars: /atmosphere equals config/atmosphere/mars.json",
              approx_equal(atm, mars), json_diff(mars, atm))
    except (OSError, ValueError, KeyError) as e:
        info(f"cannot read {mars_path} ({e}); checking bottom_radius_km only")
        check("apply_preset mars: bottom radius 3389.5",
              atm.get("bottom_radius_km") == 3389.5, short(atm))
    o1 = {k: v for k, v in after.get("state", {}).items() if k != "atmosphere"}
    o0 = {k: v for k, v in before.get("state", {}).items() if k != "atmosphere"}
    o0, o1 = stable(o0), stable(o1)
    check("apply_preset mars: only /atmosphere changed", approx_equal(o0, o1), json_diff(o0, o1))
    if ok:
        check("apply_preset: get_state revision equals the ack's",
              after.get("revision") == r["revision"], short(after)[:120])
        e = await viewer.wait_event(lambda e: e.get("revision") == r["revision"])
        check("apply_preset: event reaches a viewer", e is not None
              and all(p.startswith("/atmosphere/") for p in e.get("changed", []))
              and e.get("changed"), short(e))
    await bad_input("apply_preset nonexistent", ctl,
                    {"type": "apply_preset", "id": "ap2", "kind": "atmosphere",
                     "name": "nonexistent"}, "not_found", id_="ap2")
    await bad_input("apply_preset bad name", ctl,
                    {"type": "apply_preset", "id": "ap3", "kind": "atmosphere",
                     "name": "../earth"}, "bad_value", "/name", "ap3")
    r = await ctl.request({"type": "apply_preset", "id": "ap4", "kind": "atmosphere",
                           "name": "earth"})
    check("apply_preset earth: ack", r.get("type") == "ack", short(r))


async def t_stats(ctl, min_clients):
    r = await ctl.request({"type": "stats", "id": "st"})
    check("stats: reply", r.get("type") == "stats" and r.get("id") == "st", short(r))
    check("stats: fps number >= 0", isinstance(r.get("fps"), (int, float)) and r["fps"] >= 0,
          short(r))
    check(f"stats: clients >= {min_clients}", isinstance(r.get("clients"), int)
          and r["clients"] >= min_clients, short(r))
    check("stats: passes object of numbers", isinstance(r.get("passes"), dict)
          and all(isinstance(v, (int, float)) for v in r["passes"].values()), short(r))
    check("stats: lut_rebuild_progress in [0,1]",
          isinstance(r.get("lut_rebuild_progress"), (int, float))
          and 0 <= r["lut_rebuild_progress"] <= 1, short(r))
