"""bench/soak.py's faults: drawn from the seed at the start (and printed), done by the
controller at their moments, each followed by a check of the ledger (bench/soak_ledger.py).

  kill     kill -9 of the daemon during the warm-up's random changes (after the n-th, with
           requests in flight), and a restart on the same state file; every client reconnects.
           During the warm-up, not the measured stretch: a new process starts its memory curve
           again (when RSS is judged, the controller runs the coverage pass and the
           warm-up's random changes again after it).
  disk     a full disk under the state file (SKYD_FAULT_DIR/state_write, server/base/
           test_faults.h: every write fails with ENOSPC) for the next few changes: each must be
           acknowledged (a change that changed nothing writes nothing) or refused with error
           `internal` naming the state that cannot be saved, at least one refused; when space
           returns, the state and the state file must hold every acknowledged change.
  clock    the wall clock stepped back (SKYD_FAULT_DIR/wall_clock_offset) for a few seconds,
           then set right: the monitor fails on a simulated clock that goes back or jumps ahead,
           and the daemon must log the step.
  redis    (--cluster) redis-server killed and started again on its port and data.

The faults other than kill fall at random fractions of the measured stretch's simulated time.
No two overlap: the controller does them one at a time, between its changes."""

import os
import random

FAULT_FLAG = "state_write"
CLOCK_FILE = "wall_clock_offset"


class Fault:
    def __init__(self, kind, phase, at, **params):
        self.kind, self.phase, self.at, self.params = kind, phase, at, params
        self.done = False

    def __str__(self):
        where = (f"after warm-up change {self.at}" if self.phase == "warmup"
                 else f"at {self.at * 100:.0f} % of the measured stretch")
        extra = "".join(f", {k} {v:g}" if isinstance(v, float) else f", {k} {v}"
                        for k, v in self.params.items())
        return f"{self.kind} {where}{extra}"


class FaultPlan:
    def __init__(self, args, directory):
        self.dir = directory
        os.makedirs(directory, exist_ok=True)
        rng = random.Random(args.seed * 1000 + 40)
        self.faults = []
        at = sorted(rng.randint(2, 8) for _ in range(args.kills))
        self.faults += [Fault("kill", "warmup", n) for n in at]
        measured = [("disk", {"changes": rng.randint(3, 8)}) for _ in range(args.disk_full)]
        measured += [("clock", {"step_s": -round(rng.uniform(60, 7200), 1),
                                "hold_s": round(rng.uniform(2, 5), 1)})
                     for _ in range(args.clock_back)]
        if getattr(args, "cluster", False):
            measured += [("redis", {}) for _ in range(args.redis_restarts)]
        rng.shuffle(measured)
        # Evenly spread fractions with some jitter, so that none falls on another.
        n = len(measured)
        for i, (kind, params) in enumerate(measured):
            frac = (i + 0.25 + rng.uniform(0, 0.5)) / n * 0.8 + 0.05
            self.faults.append(Fault(kind, "random", round(frac, 3), **params))
        self.refused = 0

    def describe(self):
        return "; ".join(str(f) for f in self.faults) or "none"

    def due(self, phase, position):
        """The faults of `phase` due at `position` (warm-up change count or measured fraction),
        in order; marked done."""
        out = []
        for f in self.faults:
            if not f.done and f.phase == phase and position >= f.at:
                f.done = True
                out.append(f)
        return out

    def pending(self, phase):
        return [f for f in self.faults if f.phase == phase and not f.done]

    def path(self, name):
        return os.path.join(self.dir, name)

    def set_disk_full(self, on):
        if on:
            open(self.path(FAULT_FLAG), "w").close()
        elif os.path.exists(self.path(FAULT_FLAG)):
            os.unlink(self.path(FAULT_FLAG))

    def set_clock_offset(self, seconds):
        if seconds:
            with open(self.path(CLOCK_FILE) + ".new", "w") as f:
                f.write(f"{seconds}\n")
            os.replace(self.path(CLOCK_FILE) + ".new", self.path(CLOCK_FILE))
        elif os.path.exists(self.path(CLOCK_FILE)):
            os.unlink(self.path(CLOCK_FILE))
