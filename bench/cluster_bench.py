#!/usr/bin/python3
"""Cluster benchmark (docs/SCALING.md; not a test): real redis-server, haproxy and skyd nodes
on free loopback ports, started and stopped here.

  scale:    distinct views per second delivered by 1, 2 and 3 nodes of one world (every
            client watches its own camera, so every frame is a render), interleaved round
            by round, with the nodes' CPU time per view; and once through haproxy.
  overhead: the frame rate of one node in cluster mode against one with the embedded default
            (the state file), measured in the same run, interleaved round by round, with only
            the measured node rendering.

Usage: /usr/bin/python3 bench/cluster_bench.py --skyd build/skyd [--mode scale|overhead|both]
       [--seconds 6] [--clients 12] [--rounds 4] [--nodes 1,2,3]
"""

import argparse
import asyncio
import os
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "e2e"))
from cluster_harness import Haproxy, Redis, free_port, start_node  # noqa: E402
from serve_harness import FIRST_FRAME_TIMEOUT, Client, Daemon, make_config  # noqa: E402

VIEW = {"width": 128, "height": 72, "fps": 60, "format": "jpeg",
        "exposure": {"mode": "manual", "ev100": 12}}
STATE = {"clock": {"time_scale": 0}, "weather": {"autopilot": "off"},
         "clouds": {"low": {"coverage": 0.4}}}


def cpu_seconds(pid):
    """User + system CPU time of a process (all its threads), from /proc."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


async def watch(urls, clients, seconds, warm_s=3.0, pids=()):
    """Clients spread over `urls` one after another (as haproxy's leastconn spreads fresh
    connections), each subscribing its own view: views per second over `seconds`, and the CPU
    ms per view of the processes `pids` over the same window (None without pids)."""
    conns = []
    for i in range(clients):
        c = await Client.connect(urls[i % len(urls)], f"bench-{i}")
        view = dict(VIEW, camera={"yaw_deg": (360.0 * i / clients) % 360, "pitch_deg": 10,
                                  "fov_deg": 70})
        r = await c.request({"type": "subscribe", "id": f"s{i}", "view": view},
                            FIRST_FRAME_TIMEOUT)
        if r.get("type") != "subscribed":
            raise RuntimeError(f"subscribe refused: {r}")
        conns.append(c)
    await asyncio.gather(*(c.pump(warm_s) for c in conns))
    before = sum(sum(c.frame_count.values()) for c in conns)
    cpu0 = sum(cpu_seconds(pid) for pid in pids)
    t0 = time.monotonic()
    await asyncio.gather(*(c.pump(seconds) for c in conns))
    elapsed = time.monotonic() - t0
    cpu = sum(cpu_seconds(pid) for pid in pids) - cpu0
    frames = sum(sum(c.frame_count.values()) for c in conns) - before
    for c in conns:
        await c.close()
    return frames / elapsed, (1000.0 * cpu / max(frames, 1) if pids else None)


async def change_latency(url, count=40):
    """Median and 90th percentile time from a `set` to its ack, ms (the ack waits for the
    state file's fsync, or for Redis's append-only file's)."""
    c = await Client.connect(url, "bench-ctl")
    await c.auth()
    times = []
    for i in range(count):
        t0 = time.monotonic()
        r = await c.request({"type": "set", "id": f"c{i}",
                             "patch": {"weather": {"humidity": 0.3 + 0.001 * (i % 200)}}})
        if r.get("type") != "ack":
            raise RuntimeError(f"set refused: {r}")
        times.append((time.monotonic() - t0) * 1000)
    await c.close()
    times.sort()
    return times[len(times) // 2], times[int(len(times) * 0.9)]


def stop_all(lb, nodes, redis):
    if lb:
        lb.stop()
    for n in nodes:
        n.terminate()
    if redis:
        redis.stop()


async def scale(skyd, scratch, node_counts, clients, seconds, rounds):
    """Three nodes of one world run throughout; each round measures every node count, in an
    order that alternates, so that the machine's other load falls on all of them alike."""
    redis, nodes, lb = Redis(scratch, free_port()), [], None
    results = {n: [] for n in node_counts}
    try:
        redis.start()
        ports = [free_port() for _ in range(3)]
        for i in range(max(node_counts)):
            nodes.append(start_node(skyd, scratch, f"node{i + 1}", redis.port, "bench",
                                    ports[i], STATE))
        # The same views through haproxy once, so that the figure includes the balancer.
        lb = Haproxy(scratch, free_port(), ports)
        lb.start()
        await asyncio.sleep(1.5)
        through_lb, _ = await watch([lb.url()], clients, seconds)
        print(f"scale: {len(nodes)} node(s) through haproxy: {through_lb:.1f} views/s",
              flush=True)
        for r in range(rounds):
            order = node_counts if r % 2 == 0 else list(reversed(node_counts))
            for n in order:
                rate, ms = await watch([nd.url() for nd in nodes[:n]], clients, seconds,
                                       warm_s=2.0, pids=[nd.proc.pid for nd in nodes[:n]])
                results[n].append((rate, ms))
                print(f"scale: round {r + 1}, {n} node(s): {rate:.1f} views/s, "
                      f"{ms:.2f} CPU ms per view", flush=True)
    finally:
        stop_all(lb, nodes, redis)
    base = None
    for n in node_counts:
        rates = sorted(x[0] for x in results[n])
        cpus = sorted(x[1] for x in results[n])
        median, cpu = rates[len(rates) // 2], cpus[len(cpus) // 2]
        base = base or median
        print(f"scale: {n} node(s): median {median:.1f} views/s (x{median / base:.2f}), "
              f"{cpu:.2f} CPU ms per view, over {rounds} interleaved rounds")
    return results


async def overhead(skyd, scratch, clients, seconds, rounds):
    redis, nodes = Redis(scratch, free_port()), []
    try:
        redis.start()
        embedded_config = make_config(scratch, os.path.join(scratch, "embedded-state.json"))
        embedded_config["initial_state"] = STATE
        embedded = Daemon(skyd, scratch, "embedded", embedded_config)
        embedded.start()
        nodes.append(embedded)
        cluster = start_node(skyd, scratch, "cluster", redis.port, "overhead", 0, STATE)
        nodes.append(cluster)
        for name, node in (("embedded", embedded), ("cluster", cluster)):
            median, p90 = await change_latency(node.url())
            print(f"overhead: {name}: set to ack median {median:.2f} ms, 90th percentile "
                  f"{p90:.2f} ms", flush=True)
        rates = {"embedded": [], "cluster": []}
        cpu = {"embedded": [], "cluster": []}
        for r in range(rounds):
            order = [("embedded", embedded), ("cluster", cluster)]
            if r % 2:
                order.reverse()
            for name, node in order:
                rate, ms = await watch([node.url()], clients, seconds, warm_s=2.0,
                                       pids=[node.proc.pid])
                rates[name].append(rate)
                cpu[name].append(ms)
                print(f"overhead: round {r + 1} {name}: {rate:.1f} frames/s, {ms:.2f} CPU ms "
                      f"per frame", flush=True)
        e, c = sum(rates["embedded"]), sum(rates["cluster"])
        paired = sorted(cr / er for cr, er in zip(rates["cluster"], rates["embedded"]))
        median = paired[len(paired) // 2] if len(paired) % 2 else \
            (paired[len(paired) // 2 - 1] + paired[len(paired) // 2]) / 2
        print(f"overhead: embedded {e / rounds:.1f} frames/s, cluster {c / rounds:.1f} "
              f"frames/s: cluster/embedded = {c / e:.3f} (sums), median of per-round ratios "
              f"{median:.3f}, over {rounds} interleaved rounds")
        ce, cc = sum(cpu["embedded"]) / rounds, sum(cpu["cluster"]) / rounds
        print(f"overhead: CPU per frame embedded {ce:.2f} ms, cluster {cc:.2f} ms: "
              f"cluster/embedded = {cc / ce:.3f} (frame rate ratio at full load "
              f"{ce / cc:.3f})")
        return c / e
    finally:
        stop_all(None, nodes, redis)


async def main():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--skyd", required=True)
    p.add_argument("--mode", choices=("scale", "overhead", "both"), default="both")
    p.add_argument("--seconds", type=float, default=6.0)
    p.add_argument("--clients", type=int, default=12)
    p.add_argument("--rounds", type=int, default=4)
    p.add_argument("--nodes", default="1,2,3")
    a = p.parse_args()
    scratch = tempfile.mkdtemp(prefix="skyd-cluster-bench-")
    try:
        print(f"machine: {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}", flush=True)
        if a.mode in ("scale", "both"):
            counts = [int(n) for n in a.nodes.split(",")]
            if max(counts) > 3:
                raise SystemExit("config/haproxy.cfg names three nodes")
            await scale(os.path.abspath(a.skyd), scratch, counts, a.clients, a.seconds,
                        a.rounds)
        if a.mode in ("overhead", "both"):
            await overhead(os.path.abspath(a.skyd), scratch, a.clients // 3 or 1, a.seconds,
                           a.rounds)
        print(f"load after: {os.getloadavg()[0]:.2f}")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    asyncio.run(main())
