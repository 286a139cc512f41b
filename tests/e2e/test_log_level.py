#!/usr/bin/python3
"""`skyd serve --log-level` governs the renderer's lines too (render/ logs through the sink the
host hands it, not on stderr).

Usage: /usr/bin/python3 tests/e2e/test_log_level.py PATH_TO_SKYD SCRATCH_DIR

- --log-level warning: the renderer's start-up lines ("vulkan device: ...", "cloud noise")
  are info and do not appear; a warning from render/ (fault injection armed, SKYD_FAULT set to
  a fault that never fires) does, with the daemon's "skyd: warning: " prefix.
- --log-level info: the start-up lines appear, each once, as the daemon's lines ("skyd: "), the
  cloud noise as one whole line rather than a progress rewritten with carriage returns; with an
  empty cache directory (SKYD_CACHE_DIR) the noise is generated, and the next start says it
  read the noise from there instead.
Exit 0 when every check passed.
"""

import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import Daemon, check, make_config, run_daemon_test  # noqa: E402

# Armed, but never fires within a start-up.
IDLE_FAULT = "device_lost:after_frames=1000000"


def start_up_log(skyd, scratch, name, args, env=None):
    """What a daemon started with `args` logs until it listens, and while it stops."""
    config = make_config(scratch, os.path.join(scratch, f"{name}-state.json"))
    daemon = Daemon(skyd, scratch, name, config, env=env, args=args)
    daemon.start()
    daemon.terminate()
    return daemon.log_text()


async def run(skyd, scratch):
    os.makedirs(os.path.join(scratch, "web"), exist_ok=True)

    quiet = start_up_log(skyd, scratch, "warning", ["--log-level", "warning"],
                         env={"SKYD_FAULT": IDLE_FAULT})
    check("--log-level warning: no vulkan device line", "vulkan device" not in quiet,
          quiet[-600:])
    check("--log-level warning: no cloud noise line", "cloud noise" not in quiet, quiet[-600:])
    check("--log-level warning: render/'s warning still shows, as the daemon's",
          f"skyd: warning: fault injection armed (tests only): SKYD_FAULT={IDLE_FAULT}\n"
          in quiet, quiet[-600:])

    cache = os.path.join(scratch, "cache")
    shutil.rmtree(cache, ignore_errors=True)
    shown = start_up_log(skyd, scratch, "info", ["--log-level", "info"],
                         env={"SKYD_CACHE_DIR": cache})
    lines = shown.splitlines()
    check("--log-level info: one vulkan device line",
          len([line for line in lines if line.startswith("skyd: vulkan device: ")]) == 1,
          shown[-600:])
    check("--log-level info: one whole cloud noise line",
          lines.count("skyd: cloud noise 100%") == 1 and "\r" not in shown, repr(shown[-600:]))
    check("--log-level info: no fault injection without SKYD_FAULT",
          "fault injection" not in shown, shown[-600:])

    again = start_up_log(skyd, scratch, "again", ["--log-level", "info"],
                         env={"SKYD_CACHE_DIR": cache})
    lines = again.splitlines()
    check("--log-level info, next start: one line says the noise was read from the cache",
          lines.count(f"skyd: cloud noise read from the cache in {cache}") == 1 and
          "cloud noise 100%" not in again, repr(again[-600:]))


if __name__ == "__main__":
    sys.exit(run_daemon_test(run, __doc__, 60))
