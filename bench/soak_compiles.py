"""bench/soak.py's watch on the daemons' Mesa shader caches: llvmpipe writes every variant it
compiles there, and a variant first compiled after start-up keeps its code (LLVM's allocations
and lavapipe's) for the life of the process, which the RSS slope then measures. Each entry that
appears after a daemon listens is reported with the requests sent in the seconds before it
(every client's, kept by SoakClient.send), so that the request that needed it can be found and
the variant made at start-up instead (ctest daemon_variants holds what is found)."""

import asyncio
import collections
import os
import time

POLL_S = 1.0
RECENT_S = 15.0     # Mesa writes its cache from a thread of its own, after the compile
RECENT_MAX = 64


class RecentRequests:
    """The requests every soak client sent in the last RECENT_S seconds."""

    def __init__(self):
        self.items = collections.deque(maxlen=RECENT_MAX)

    def add(self, client, text):
        self.items.append((time.monotonic(), client, text))

    def since(self, seconds):
        now = time.monotonic()
        return [(now - t, c, m) for t, c, m in self.items if now - t <= seconds]


def cache_files(cache_dir):
    found = set()
    for root, _, files in os.walk(cache_dir):
        found.update(os.path.join(root, f) for f in files if f != "index")
    return found


class CacheWatch:
    """One daemon's shader cache: the entries it held when the daemon listened, and each one
    written after."""

    def __init__(self, label, cache_dir):
        self.label, self.cache_dir = label, cache_dir
        self.known = None
        self.events = []  # (real s, phase, new entries, [(age, client, request)])

    def mark_ready(self):
        """The daemon listens (again, after a restart): what is there now came with start-up."""
        self.known = cache_files(self.cache_dir)

    async def run(self, soak):
        while not soak.done:
            await asyncio.sleep(POLL_S)
            if self.known is None or soak.restarting:
                continue
            now = cache_files(self.cache_dir)
            new = now - self.known
            if not new:
                continue
            self.known = now
            recent = soak.recent.since(RECENT_S)
            self.events.append((soak.elapsed(), soak.phase, len(new), recent))
            print(f"soak: {self.label}shader cache: {len(new)} new entries at "
                  f"{soak.elapsed():.0f} s ({soak.phase}), after:", flush=True)
            for age, client, text in recent:
                print(f"soak:   -{age:4.1f} s {client}: {text}", flush=True)

    def summary(self):
        after = sum(n for _, phase, n, _ in self.events if phase == "random")
        total = sum(n for _, _, n, _ in self.events)
        return f"{self.label}{total} after start-up ({after} in the measured stretch)"
