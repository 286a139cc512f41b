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


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, out_dir = sys.argv[1], sys.argv[2]
    os.makedirs(out_dir, exist_ok=True)
    failures = 0
    for name, args in SCENES.items():
        trace = os.path.join(out_dir, f"{name}.trace.xml")
        cmd = [skyd] + args
        if args[0] == "render":
            pattern = "%d" if "--frames" in args else ""
            cmd += ["--out", os.path.join(out_dir, f"{name}{pattern}.png"), "--validation"]
        env = dict(os.environ, GALLIUM_TRACE=trace)
        preload = env.pop("SKYD_DAEMON_LD_PRELOAD", "")  # the sanitizer build's, for skyd only
        if preload:
            env["LD_PRELOAD"] = preload
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
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
