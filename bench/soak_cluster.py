"""bench/soak.py --cluster: a real redis-server (config/redis.conf through scripts/
redis-conf.sh: append-only, appendfsync always, the node user "skyd" with a password, AUTH in
the Redis URL, as tests/e2e/test_cluster.py starts it) on a free loopback port, and two skyd
nodes sharing one world. Node A is the daemon every soak client uses (its faults: kill -9,
the clock step; a node writes no state file, so there is no full disk); node B gets a
subscriber that changes its view and must follow every change: the ledger is checked against
both nodes. Both nodes' memory is sampled and each gets its slope. The fault `redis` kills
redis-server with -9 and starts it again on its port and data: changes are refused with
`unavailable` meanwhile, and none acknowledged before may be lost."""

import asyncio
import os
import random
import signal
import sys
import time

_E2E = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "e2e")
if _E2E not in sys.path:  # bench/soak.py puts it there; this for an import on its own
    sys.path.insert(0, _E2E)
import serve_harness as H  # noqa: E402
from cluster_harness import Redis, cluster_section, free_port  # noqa: E402
from soak_bookkeeping import SoakClient, memory_kib  # noqa: E402
from soak_fields import HOME_VIEWS, MAX_STREAM, STREAM_SIZES, Draw  # noqa: E402


class Cluster:
    def __init__(self, soak, args):
        self.soak, self.args = soak, args
        self.redis = Redis(args.scratch, free_port())
        self.world = f"soak-{args.seed}"
        self.node_b = None
        self.rss_b = []          # as soak.rss, for node B
        self.redis_restarts = 0
        self.redis_refused = 0

    def section(self):
        return cluster_section(self.redis.port, self.world)

    def start_redis(self):
        self.redis.start()
        print(f"soak: redis-server pid {self.redis.proc.pid} on 127.0.0.1:{self.redis.port} "
              f"(AUTH as skyd), world {self.world!r}", flush=True)

    def start_node_b(self, config, env):
        self.node_b = H.Daemon(self.args.skyd, self.args.scratch, "skyd-b", config, env=env,
                               ready_timeout=H.EMPTY_SHADER_CACHE_READY_TIMEOUT)
        self.node_b.start()
        print(f"soak: node B pid {self.node_b.proc.pid} on {self.node_b.url()}", flush=True)

    def stop(self):
        if self.node_b is not None:
            self.node_b.kill()
        if self.redis.proc is not None:
            self.redis.stop()

    async def state_b(self, revision, timeout=10.0):
        """Node B's state once it has `revision` (it follows Redis's stream)."""
        c = await H.Client.connect(self.node_b.url(), "ledger-b")
        try:
            deadline = time.monotonic() + timeout
            while True:
                r = await c.get_state()
                if r.get("revision", -1) >= revision or time.monotonic() > deadline:
                    return r
                await asyncio.sleep(0.2)
        finally:
            await c.close()

    async def restart_redis(self, controller):
        """redis-server killed with -9, changes sent while it is away (each refused as
        `unavailable`), started again; changes until one is acknowledged again."""
        soak = self.soak
        loop = asyncio.get_running_loop()
        rng = random.Random(self.args.seed * 1000 + 50 + self.redis_restarts)
        before = controller.faults.refused
        controller.refusal = "unavailable"
        t0 = time.monotonic()
        try:
            await loop.run_in_executor(None, self.redis.stop, signal.SIGKILL)
            for _ in range(rng.randint(2, 5)):
                await controller.random_change(rng)
                await controller.wait(0.3)
            await controller.drain()
            await loop.run_in_executor(None, self.redis.start)
            away = time.monotonic() - t0
            # The nodes reconnect with back-off (at most 2 s between tries).
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline:
                refused = controller.faults.refused
                await controller.set(controller.draw.random_patch())
                await controller.drain()
                if controller.faults.refused == refused:
                    break
                await controller.wait(0.5)
            else:
                soak.fail("redis restart: no change acknowledged within 30 s of the restart")
        finally:
            controller.refusal = None
        refused = controller.faults.refused - before
        self.redis_restarts += 1
        self.redis_refused += refused
        print(f"soak: fault: redis-server killed with -9 at {soak.elapsed():.0f} s, away "
              f"{away:.1f} s; {refused} changes refused as unavailable; taking changes again "
              f"{time.monotonic() - t0 - away:.1f} s after its restart", flush=True)
        if refused == 0:
            soak.fail("redis restart: no change was refused while Redis was away")
        await controller.check_ledger(f"after redis restart #{self.redis_restarts}")


async def node_b_client(soak, cluster, seed):
    """A subscriber on node B: a home view and, every few seconds, another."""
    rng = random.Random(seed)
    draw = Draw(rng, [], True)
    while not soak.done:
        c = await SoakClient.connect(cluster.node_b.url(), "nodeB")
        c.setup(soak)
        try:
            home = dict(HOME_VIEWS[0])
            sub = await c.subscribe(home)
            while not soak.done:
                await c.idle(rng.uniform(2, 8))
                if soak.done:
                    break
                view = draw.view(STREAM_SIZES, MAX_STREAM)
                new = await c.subscribe(view)
                if sub is not None:
                    await c.unsubscribe(sub)
                sub = new
        finally:
            await c.close()


async def node_b_memory(soak, cluster):
    while not soak.done:
        pid = cluster.node_b.proc.pid
        if cluster.node_b.proc.poll() is not None:
            soak.fail(f"node B died (status {cluster.node_b.proc.returncode})")
            return
        m = memory_kib(pid)
        if m.get("VmRSS"):
            cluster.rss_b.append((soak.elapsed(), soak.sim_s, m["VmRSS"], soak.phase,
                                  m.get("RssAnon", 0), m.get("RssFile", 0),
                                  m.get("RssShmem", 0), pid))
        await asyncio.sleep(soak.args.rss_interval)
