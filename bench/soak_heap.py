"""bench/soak.py's heap figures: each daemon's C heap from its /metrics (skyd_heap_in_use_bytes
and skyd_heap_free_bytes, glibc's mallinfo2), sampled every HEAP_INTERVAL_S beside the RSS, and
their slopes over the measured stretch as the RSS's are fitted (bench/soak_slope.py). They say
what an RSS slope is made of: a heap in use that grows is a leak or a growing cache; free space
that grows while the heap in use stays flat is the allocator's retention (fragmentation). The
figures are printed, not judged: the verdict stays the RSS slope's."""

import asyncio
import re
import urllib.request

from soak_slope import fit_slope, measured_stretch

HEAP_INTERVAL_S = 10.0
_METRIC = re.compile(r"^(skyd_heap_in_use_bytes|skyd_heap_free_bytes) (\S+)$", re.M)


def read_heap(http_url, timeout=5.0):
    """(in use, free) in KiB from the daemon's /metrics; None when it cannot be read or the
    daemon publishes no heap figures (not glibc)."""
    try:
        with urllib.request.urlopen(http_url + "/metrics", timeout=timeout) as r:
            text = r.read().decode()
    except (OSError, ValueError):
        return None
    values = {name: float(value) for name, value in _METRIC.findall(text)}
    if len(values) != 2:
        return None
    return (values["skyd_heap_in_use_bytes"] / 1024, values["skyd_heap_free_bytes"] / 1024)


def http_of(ws_url):
    """ws://host:port/ -> http://host:port (the daemon serves HTTP on its WebSocket port)."""
    return "http" + ws_url[len("ws"):].rstrip("/")


async def heap_sampler(soak, daemon, rows):
    """Appends (real s, simulated s, in use KiB, phase, free KiB, pid) to rows until the soak
    is done; a daemon being restarted is skipped."""
    loop = asyncio.get_running_loop()
    while not soak.done:
        proc = daemon.proc
        if proc is not None and proc.poll() is None and daemon.port is not None:
            heap = await loop.run_in_executor(None, read_heap, http_of(daemon.url()))
            if heap is not None:
                rows.append((soak.elapsed(), soak.sim_s, heap[0], soak.phase, heap[1], proc.pid))
        await asyncio.sleep(HEAP_INTERVAL_S)


def heap_slopes(args, rows, node=""):
    """Prints the slopes of the heap in use and of its free space over the measured random
    changes (after --slope-skip-s, as the RSS's), MiB per real hour with 95 % intervals."""
    measured = measured_stretch(rows, args.slope_skip_s)
    if not measured:
        print(f"soak: {node}heap: no samples from /metrics in the measured stretch", flush=True)
        return
    per_h = 3600 / 1024  # KiB/s -> MiB/h
    parts = []
    for name, col in (("in use", 2), ("free", 4)):
        fit = fit_slope([(r[0], r[col], r[5]) for r in measured], args.slope_block_s)
        values = [r[col] / 1024 for r in measured]
        level = f"{min(values):.1f}-{max(values):.1f} MiB"
        if fit is None:
            parts.append(f"{name} {level}, too few blocks for a slope")
            continue
        parts.append(f"{name} {level}, slope {fit['slope'] * per_h:+.2f} MiB per real hour "
                     f"[{fit['low'] * per_h:+.2f}, {fit['high'] * per_h:+.2f}]")
    print(f"soak: {node}C heap ({len(measured)} samples every {HEAP_INTERVAL_S:g} s): "
          + "; ".join(parts), flush=True)


def write_csv(path, rows):
    with open(path, "w") as f:
        f.write("real_s,simulated_s,heap_in_use_kib,phase,heap_free_kib,pid\n")
        for t, sim, in_use, phase, free, pid in rows:
            f.write(f"{t:.1f},{sim:.0f},{in_use:.0f},{phase},{free:.0f},{pid}\n")
