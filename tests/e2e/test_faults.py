#!/usr/bin/python3
"""Faults on the real daemon: kill -9 during state writes, and a state directory that cannot
be written.

Usage: /usr/bin/python3 tests/e2e/test_faults.py PATH_TO_SKYD SCRATCH_DIR

1. Three rounds: a controller sends `set` after `set` (each waiting for its ack) while the
   daemon is killed with SIGKILL at a random moment; after each restart the state is the last
   acknowledged one (or the one whose ack was in flight), its values those of that revision,
   and no temporary file is left.
2. The state directory replaced by a plain file (what a vanished or unwritable directory looks
   like even to root): a `set` is refused with an `internal` error naming the write, the state
   and revision stay, frames still come; once the directory is back, a `set` succeeds.

Bounded loops and timeouts throughout; prints "N passed, M failed".
"""

import asyncio
import glob
import os
import random
import shutil
import signal
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (Client, Daemon, check, check_unchanged, info,  # noqa: E402
                           make_config, run_daemon_test, short)

ROUNDS = 3


def elevation_of(revision):
    """The sun elevation the test sets at a revision: distinct per revision."""
    return round(-5.0 + (revision % 90) * 0.5, 3)


async def writer(ctl, acked, sent):
    """set after set until the connection dies; records (revision, value) pairs."""
    while True:
        revision = (acked[-1][0] if acked else (await ctl.get_state())["revision"]) + 1
        value = elevation_of(revision)
        sent.append((revision, value))
        r = await ctl.request({"type": "set", "id": revision,
                               "patch": {"sun": {"elevation_deg": value}}})
        if r.get("type") != "ack":
            raise RuntimeError(f"set answered {short(r)}")
        acked.append((r["revision"], value))


async def kill_rounds(d, state_file, rng):
    for k in range(ROUNDS):
        ctl = await Client.connect(d.url(), f"controller-{k}")
        await ctl.auth()
        acked, sent = [], []
        task = asyncio.ensure_future(writer(ctl, acked, sent))
        await asyncio.sleep(rng.uniform(0.5, 1.5))
        os.kill(d.proc.pid, signal.SIGKILL)
        d.proc.wait(10)
        try:
            await asyncio.wait_for(task, 10)
        except Exception:  # noqa: BLE001 - the connection dies with the daemon
            pass
        await ctl.close()
        last = acked[-1] if acked else None
        d.start()
        c = await Client.connect(d.url(), f"after-kill-{k}")
        try:
            s = await c.get_state()
        finally:
            await c.close()
        revision = s.get("revision")
        elevation = s.get("state", {}).get("sun", {}).get("elevation_deg")
        info(f"kill -9 round {k + 1}: {len(acked)} sets acknowledged (last {last}), restored "
             f"revision {revision}, sun elevation {elevation}")
        check(f"kill -9 round {k + 1}: writes were under way", len(acked) >= 3,
              f"{len(acked)} acknowledged")
        in_flight = sent[-1] if sent else None
        ok = last is not None and (revision, elevation) in (last, in_flight)
        check(f"kill -9 round {k + 1}: the last acknowledged state is restored", ok,
              f"acknowledged {last}, in flight {in_flight}, restored ({revision}, {elevation})")
        leftovers = [p for p in glob.glob(state_file[:-len(".json")] + "*") if p != state_file]
        check(f"kill -9 round {k + 1}: no temporary state files left", not leftovers,
              short(leftovers))


async def unwritable(d, state_dir):
    ctl = await Client.connect(d.url(), "controller-rw")
    await ctl.auth()
    try:
        before = await ctl.get_state()
        aside = state_dir + ".aside"
        os.rename(state_dir, aside)
        with open(state_dir, "w") as f:
            f.write("not a directory\n")
        r = await ctl.request({"type": "set", "id": "rw",
                               "patch": {"sun": {"elevation_deg": 33.3}}})
        check("unwritable: set refused with internal", r.get("type") == "error"
              and r.get("code") == "internal" and r.get("id") == "rw", short(r))
        check("unwritable: the error says the state cannot be saved",
              "cannot be saved" in r.get("message", "") and "not applied" in r.get("message", ""),
              short(r))
        await check_unchanged("unwritable", ctl, before)  # revision, and state but the clock
        r = await ctl.request({"type": "snapshot", "id": "snap",
                               "view": {"width": 32, "height": 18}}, 60)
        check("unwritable: the daemon still renders", r.get("type") == "frame"
              and isinstance(r.get("_binary"), bytes), short(r))
        os.unlink(state_dir)
        os.rename(aside, state_dir)
        r = await ctl.request({"type": "set", "id": "rw2",
                               "patch": {"sun": {"elevation_deg": 34.7}}})  # off the writer grid
        check("unwritable: writable again, set acknowledged", r.get("type") == "ack"
              and r.get("revision") == before.get("revision") + 1, short(r))
    finally:
        await ctl.close()
        if os.path.isfile(state_dir):
            os.unlink(state_dir)
        if os.path.isdir(state_dir + ".aside"):
            os.rename(state_dir + ".aside", state_dir)


async def run(skyd, scratch):
    state_dir = os.path.join(scratch, "state")
    shutil.rmtree(state_dir, ignore_errors=True)
    for p in glob.glob(state_dir + "*"):
        os.unlink(p) if os.path.isfile(p) else shutil.rmtree(p)
    state_file = os.path.join(state_dir, "faults-state.json")
    d = Daemon(skyd, scratch, "faults", make_config(scratch, state_file))
    d.start()
    try:
        seed = int(os.environ.get("SKYD_FAULTS_SEED", time.time()))
        info(f"seed {seed} (SKYD_FAULTS_SEED repeats it)")
        await kill_rounds(d, state_file, random.Random(seed))
        await unwritable(d, state_dir)
        status = await d.terminate_async()
        check("daemon exits 0 after SIGTERM", status == 0, f"status {status}")
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 400))
