#!/usr/bin/python3
"""No pipeline is compiled while frames render.

lavapipe (Mesa 22.3) defers compiling a pipeline whose `if` conditions or loop ends can be
computed from uniform-buffer or push-constant values alone, and compiles it at dispatch with
those values inlined. When the first inlined variant is less than half the code, it does so
again at every later dispatch and never frees the old code: the daemon grew by megabytes a
second, and which pipelines did depended on the state at their first dispatch (the soak found
it). The passes therefore read their parameters from storage buffers (SKY_PARAMETER_BLOCK in
shaders/include/sky_shared.h).

This test renders time-lapses through day, night with the moon and stars, a weather transition
into rain, an environment map, a camera above the atmosphere, Mars, and every luminance probe,
with Gallium's trace driver recording the driver calls (GALLIUM_TRACE). A pipeline compiled
when it is created follows the driver's capability queries (get_param) and is bound only when a
command buffer runs, even when that is at once; a compile at dispatch follows the reading of
the inlined values and is bound at once. There must be none, and the traces must show
dispatches. The build before this test's fix had 1 to 9 per scene.

It also renders one scene at view sizes with and without powers of two, into an empty Mesa
shader cache (MESA_SHADER_CACHE_DIR): llvmpipe keys a compute pipeline's compiled code on
whether each bound image's width and height are powers of two, and writes each new variant to
that cache. Images of a view's size are therefore made with extents that never are
(gpu_image_create_view_sized in render/vk/vk_resources.h), and the sizes after the first must add
nothing to the cache. Before that, 96x54 then 128x64, 64x32, 127x64 and 128x65 took it from 23
to 40 entries: each new combination a hitch of several compiles, and code kept for good.

Usage: test_pipeline_compiles.py SKYD OUTPUT_DIR
"""

import os
import re
import subprocess
import sys

CALL = re.compile(r"<call no='\d+' class='\w+' method='(\w+)'>")
PTR = re.compile(r"<ptr>(0x[0-9a-f]+)</ptr>")

SCENES = {
    "lapse": ["render", "--width", "96", "--height", "54", "--frames", "7", "--step-s", "10800",
              "--time", "2026-06-19T03:00:00Z", "--lat", "48.1", "--lon", "11.6",
              "--weather", "fair_cumulus", "--weather-to", "storm"],
    "panorama": ["render", "--width", "128", "--height", "64", "--frames", "3", "--step-s",
                 "21600", "--time", "2026-03-20T00:00:00Z", "--lat", "-33.9", "--lon", "151.2",
                 "--weather", "broken", "--projection", "equirectangular", "--format", "png16"],
    "space": ["render", "--width", "64", "--height", "36", "--set", "camera.altitude_km=150",
              "--set", "camera.pitch_deg=-30", "--sun-elevation", "20", "--weather", "overcast"],
    "mars": ["render", "--width", "64", "--height", "36", "--preset", "mars",
             "--sun-elevation", "3"],
    "probe_luminance": ["probe", "luminance", "--altitude", "2", "--view-zenith", "80",
                        "--view-azimuth", "30", "--sun-zenith", "60"],
    "probe_transmittance": ["probe", "transmittance", "--altitude", "0", "--mu", "0.1"],
    "probe_illuminance": ["probe", "illuminance", "--sun-zenith", "95"],
}


def dispatch_compiles(trace_path):
    """Counts (compiles at dispatch, compute states created, dispatches) in a trace."""
    events = []  # (method, pointer): create, bind, launch, query (get_param), other
    method, lines = None, []
    with open(trace_path, errors="replace") as f:
        for line in f:
            m = CALL.search(line)
            if m:
                method, lines = m.group(1), []
                continue
            if method is None:
                continue
            if "</call>" not in line:
                lines.append(line)
                continue
            text = "".join(lines)
            if method == "create_compute_state":
                ret = re.search(r"<ret><ptr>(0x[0-9a-f]+)</ptr></ret>", text)
                events.append(("create", ret.group(1) if ret else None))
            elif method == "bind_compute_state":
                ptrs = PTR.findall(text)
                events.append(("bind", ptrs[1] if len(ptrs) > 1 else None))
            elif method == "launch_grid":
                events.append(("launch", None))
            elif method == "get_param":
                events.append(("query", None))
            else:
                events.append(("other", None))
            method = None
    compiles = sum(1 for before, a, b in zip(events, events[1:], events[2:])
                   if a[0] == "create" and b == ("bind", a[1]) and before[0] != "query")
    creates = sum(1 for e in events if e[0] == "create")
    launches = sum(1 for e in events if e[0] == "launch")
    return compiles, creates, launches


# The first size has no power of two; each later one brings a new combination.
VIEW_SIZES = ["96x54", "128x64", "64x32", "127x64", "128x65", "256x128"]


def cache_entries(cache_dir):
    return sum(len(files) for _, _, files in os.walk(cache_dir))


def view_size_variants(skyd, out_dir, env):
    """Renders clouds at VIEW_SIZES (perspective, then the last as a panorama) into an empty
    shader cache; returns a failure count."""
    cache = os.path.join(out_dir, "view-size-shader-cache")
    subprocess.run(["rm", "-rf", cache], check=True)
    os.makedirs(cache)
    env = dict(env, MESA_SHADER_CACHE_DIR=cache)
    env.pop("MESA_SHADER_CACHE_DISABLE", None)
    counts = []
    for k, size in enumerate(VIEW_SIZES):
        w, h = size.split("x")
        cmd = [skyd, "render", "--width", w, "--height", h, "--weather", "broken",
               "--sun-elevation", "25", "--out", os.path.join(out_dir, f"size-{size}.png")]
        if k == len(VIEW_SIZES) - 1:
            cmd += ["--projection", "equirectangular"]
        run = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, timeout=600)
        if run.returncode != 0:
            print(f"FAIL view sizes: skyd exited {run.returncode} at {size}\n"
                  f"{run.stderr[-2000:]}")
            return 1
        counts.append(cache_entries(cache))
    figures = ", ".join(f"{s} {n}" for s, n in zip(VIEW_SIZES, counts))
    ok = counts[0] > 0 and counts[-1] == counts[0]
    print(f"{'ok  ' if ok else 'FAIL'} view sizes: shader cache entries after each render: "
          f"{figures} (no new variant after the first size)")
    if counts[0] == 0:
        print("FAIL view sizes: nothing in the shader cache, so nothing could be counted")
    return 0 if ok else 1


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, out_dir = sys.argv[1], sys.argv[2]
    os.makedirs(out_dir, exist_ok=True)
    failures = 0
    base_env = dict(os.environ)
    preload = base_env.pop("SKYD_DAEMON_LD_PRELOAD", "")  # the sanitizer build's, for skyd only
    if preload:
        base_env["LD_PRELOAD"] = preload
    for name, args in SCENES.items():
        trace = os.path.join(out_dir, f"{name}.trace.xml")
        cmd = [skyd] + args
        if args[0] == "render":
            pattern = "%d" if "--frames" in args else ""
            cmd += ["--out", os.path.join(out_dir, f"{name}{pattern}.png"), "--validation"]
        env = dict(base_env, GALLIUM_TRACE=trace)
        run = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, timeout=600)
        if run.returncode != 0:
            print(f"FAIL {name}: skyd exited {run.returncode}\n{run.stderr[-2000:]}")
            failures += 1
            continue
        if not os.path.exists(trace):
            print(f"FAIL {name}: no trace written (GALLIUM_TRACE needs a Gallium driver such "
                  "as lavapipe)")
            failures += 1
            continue
        compiles, creates, launches = dispatch_compiles(trace)
        os.remove(trace)  # megabytes each; the figures are in the log
        ok = compiles == 0 and creates > 0 and launches > 0
        print(f"{'ok  ' if ok else 'FAIL'} {name}: {compiles} compiles at dispatch, {creates} "
              f"compute states created, {launches} dispatches")
        failures += not ok
    print(f"{len(SCENES) - failures} of {len(SCENES)} scenes without a compile at dispatch")
    failures += view_size_variants(skyd, out_dir, base_env)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
