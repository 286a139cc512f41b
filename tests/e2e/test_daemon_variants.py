#!/usr/bin/python3
"""A serving daemon compiles no shader after start-up, whatever views its clients ask for.

The composite pass has a pipeline per combination of output kind, camera in space, sun or moon
in view, night sky, clouds and ground (render/sky/composite_variants.h). lavapipe compiles
each at its first dispatch and keeps it, so before the daemon made them all at start-up, a
view that needed a new combination stalled its stream for the compile, and a daemon whose
clients kept finding new ones grew for hours (the cluster soak's node A: heaptrack put the
growth in those compiles).

The daemon runs with an empty Mesa shader cache of its own (MESA_SHADER_CACHE_DIR), which
llvmpipe writes every compiled variant to. Once it listens, snapshots cover the combinations:
sRGB and linear (PNG16) output, a panorama (sun, ground and sky in one view), a view straight
up, a camera at 150 km, by day and by night, with and without clouds; then probes, client
weather maps of power-of-two sizes, of other sizes and of one of each on either axis (llvmpipe
samples a repeating texture by other code for each axis whose size is not a power of two), a
night whose moon lights the clouds, towering clouds (cumulonimbus in the weather map) by
moonlight and by day, and a new noise seed (start-up read its noise from the noise cache and ran
each noise pass once for this). The cache must hold as many entries after them as before, and
every snapshot and probe must be answered.

Usage: /usr/bin/python3 tests/e2e/test_daemon_variants.py PATH_TO_SKYD SCRATCH_DIR
"""

import asyncio
import base64
import glob
import os
import shutil
import struct
import sys
import time

import serve_harness
from serve_harness import Client, Daemon, check, info, make_config, run_daemon_test, short

VIEWS = {
    "panorama": {"projection": "equirectangular", "width": 96, "height": 48},
    "zenith": {"camera": {"pitch_deg": 80, "fov_deg": 30}, "width": 48, "height": 27},
    "space": {"camera": {"altitude_km": 150, "pitch_deg": -30}, "width": 48, "height": 27},
}
FORMATS = ["png", "png16"]
SUN_ELEVATIONS = [35.0, -20.0]
LOW_COVERAGES = [0.6, 0.0]
SNAPSHOT_TIMEOUT_S = 60.0
NEW_SEED = 918273  # a noise seed no other test uses
SETTLE_S = 3.0  # Mesa writes its cache from a thread of its own: the count must hold this long


def forget_noise_seed(seed):
    """Removes the noise cache's files of `seed` (their header's seed, bytes 12-15), so that
    the daemon generates it."""
    noise_cache = os.environ.get("SKYD_CACHE_DIR", "")
    for path in glob.glob(os.path.join(noise_cache, "cloud-noise-*.bin")) if noise_cache else []:
        with open(path, "rb") as f:
            header = f.read(16)
        if len(header) == 16 and struct.unpack_from("<I", header, 12)[0] == seed:
            os.remove(path)


def cache_entries(cache_dir):
    return sum(len(files) for _, _, files in os.walk(cache_dir))


async def settled_entries(cache_dir, limit_s=60.0):
    """The cache's entry count once it has held for SETTLE_S (or after limit_s)."""
    deadline = time.monotonic() + limit_s
    count, since = cache_entries(cache_dir), time.monotonic()
    while time.monotonic() < deadline and time.monotonic() - since < SETTLE_S:
        await asyncio.sleep(0.25)
        now = cache_entries(cache_dir)
        if now != count:
            count, since = now, time.monotonic()
    return count


def weather_map(side_x, side_y):
    """A client weather map (rgba8) of cumulus in every other texel."""
    texels = b"".join(bytes((200 if i % 2 else 0, 0, 170, 0)) for i in range(side_x * side_y))
    return {"type": "set_weather_map", "format": "rgba8", "width": side_x, "height": side_y,
            "data": base64.b64encode(texels).decode()}


def extra_requests():
    """(what, message, expected reply type): the requests beyond the views that run passes of
    their own or bind other images."""
    snap = {"type": "snapshot", "view": {"width": 40, "height": 30}}
    probes = [{"type": "probe", "quantity": "transmittance", "altitude_km": 1, "mu": 0.3},
              {"type": "probe", "quantity": "luminance", "altitude_km": 2,
               "view_zenith_deg": 60, "view_azimuth_deg": 20, "sun_zenith_deg": 70},
              {"type": "probe", "quantity": "illuminance", "sun_zenith_deg": 40}]
    out = [(f"probe {p['quantity']}", p, "probe_result") for p in probes]
    for w, h in ((64, 64), (7, 5), (7, 512), (512, 5)):
        out += [(f"weather map {w}x{h}", weather_map(w, h), "ack"),
                (f"weather map {w}x{h}: snapshot", snap, "frame")]
    out += [("procedural map", {"type": "set", "patch": {
        "weather": {"map_source": "procedural"}}}, "ack"),
        ("moonlit clouds", {"type": "set", "patch": {
            "sun": {"elevation_deg": -30}, "moon": {"elevation_deg": 40},
            "clouds": {"low": {"coverage": 0.6}}}}, "ack"),
        ("moonlit clouds: snapshot", snap, "frame"),
        # The marches' TOWERING variants: a weather map that may hold cumulonimbus.
        ("towering clouds by moonlight", {"type": "set", "patch": {
            "clouds": {"low": {"type": 1.0}}}}, "ack"),
        ("towering clouds by moonlight: snapshot", snap, "frame"),
        ("towering clouds by day", {"type": "set", "patch": {"sun": {"elevation_deg": 35}}},
         "ack"),
        ("towering clouds by day: snapshot", snap, "frame"),
        ("no towering clouds", {"type": "set", "patch": {"clouds": {"low": {"type": 0.3}}}},
         "ack"),
        # Generated by the noise passes, which start-up ran once even when it read its own
        # seed's noise from the cache (forget_noise_seed keeps this one from being read).
        ("another noise seed", {"type": "set", "patch": {"clouds": {"noise_seed": NEW_SEED}}},
         "ack"),
        ("another noise seed: snapshot", snap, "frame")]
    return out


async def run(skyd, scratch):
    cache = os.path.join(scratch, "shader-cache")
    shutil.rmtree(cache, ignore_errors=True)
    os.makedirs(cache)
    config = make_config(scratch, os.path.join(scratch, "state.json"))
    d = Daemon(skyd, scratch, "variants", config,
               env={"MESA_SHADER_CACHE_DIR": cache, "MESA_SHADER_CACHE_DISABLE": "false"},
               ready_timeout=serve_harness.EMPTY_SHADER_CACHE_READY_TIMEOUT)
    for name in glob.glob(os.path.join(scratch, "state.*")):
        os.remove(name)  # a run before this one left NEW_SEED in its world
    forget_noise_seed(NEW_SEED)
    t = time.monotonic()
    d.start()
    info(f"listening after {time.monotonic() - t:.1f} s")
    started = d.log_text()
    try:
        at_start = await settled_entries(cache)
        check("the daemon's start-up wrote its compiled shaders to the cache", at_start > 0,
              f"{at_start} entries in {cache}")
        ctl = await Client.connect(d.url(), "variants-controller")
        await ctl.auth()
        answered = asked = 0
        seen = at_start
        slowest = (0.0, "")
        for sun in SUN_ELEVATIONS:
            for coverage in LOW_COVERAGES:
                r = await ctl.request({"type": "set", "patch": {
                    "sun": {"elevation_deg": sun}, "clouds": {"low": {"coverage": coverage}}}})
                check(f"sun {sun}, low coverage {coverage}: set", r.get("type") == "ack",
                      short(r))
                for view_name, view in VIEWS.items():
                    for fmt in FORMATS:
                        what = f"sun {sun}, coverage {coverage}, {view_name}, {fmt}"
                        start = time.monotonic()
                        r = await ctl.request({"type": "snapshot", "id": f"s{asked}",
                                               "view": dict(view, format=fmt)},
                                              SNAPSHOT_TIMEOUT_S)
                        took = time.monotonic() - start
                        now = cache_entries(cache)
                        if now != seen:
                            info(f"{what}: {now - seen} new shader cache entries, {took:.2f} s")
                            seen = now
                        slowest = max(slowest, (took, what))
                        asked += 1
                        answered += check(f"{what}: a frame", r.get("type") == "frame",
                                          short(r))
        for what, message, reply_type in extra_requests():
            r = await ctl.request(dict(message, id=f"x{asked}"), SNAPSHOT_TIMEOUT_S)
            asked += 1
            answered += check(f"{what}: answered", r.get("type") == reply_type, short(r))
            now = cache_entries(cache)
            if now != seen:
                info(f"{what}: {now - seen} new shader cache entries")
                seen = now
        check("the new noise seed was generated, not read",
              d.log_text().count("cloud noise 100%") == 1 + ("cloud noise 100%" in started),
              d.log_text()[-600:])
        after = await settled_entries(cache)
        info(f"{answered} of {asked} requests answered; slowest snapshot {slowest[0]:.2f} s "
             f"({slowest[1]})")
        check("no shader compiled after start-up: the cache holds as many entries as when "
              "the daemon began to listen", after == at_start,
              f"{at_start} entries at start-up, {after} after the snapshots")
        info(f"shader cache entries: {at_start} at start-up, {after} after {asked} snapshots")
        await ctl.close()
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 600))
