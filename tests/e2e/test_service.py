#!/usr/bin/python3
"""skyd as a service: the sd_notify protocol, SIGHUP reloads, log levels, the systemd unit.

Usage: /usr/bin/python3 tests/e2e/test_service.py PATH_TO_SKYD SCRATCH_DIR UNIT_FILE BINDIR

- sd_notify: the test is the service manager (a datagram socket in NOTIFY_SOCKET, a 0.6 s
  WATCHDOG_USEC): READY=1 after the listening line, WATCHDOG=1 pings, RELOADING=1 then READY=1
  around a SIGHUP, STOPPING=1 at SIGTERM.
- SIGHUP with a changed configuration and presets while a controller streams frames: one log
  line names every change (limits, token, origins, presets added, broken and removed, fields
  that wait for a restart) and no token; the client keeps its connection and role; new
  connections see the new limits, token and origins, over WebSocket and HTTP. A configuration
  that does not load changes nothing; read_only then refuses every auth.
- Simulation events: a client whose hello asks hears the running clock about once a second;
  others hear nothing.
- Logging: each connection is logged (opened and closed), an auth failure and a refused change
  are logged, tokens never are; --log-level warning hides the connections; --log-level error
  hides the renderer's "vulkan device" line, which the default level shows; a bad level exits 2.
- The unit this build installs (config/skyd.service with the build's paths: UNIT_FILE) runs
  BINDIR/skyd as the system user skyd and passes `systemd-analyze verify` (with the skyd
  of this build in place of the installed one).
Exit 0 when every check passed.
"""

import asyncio
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_harness import (ALLOWED_ORIGIN, TOKEN, Client, Daemon, check, info,  # noqa: E402
                           make_config, raw_handshake_status, run_daemon_test, short)

SOURCE_CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "config")
NEW_TOKEN = "reloaded-controller-token-0123456789"
UNIT_FILE = None
BINDIR = None


class NotifyListener:
    """A datagram socket standing for systemd's notification socket."""

    def __init__(self, path):
        if os.path.exists(path):
            os.remove(path)
        self.path = path
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(path)
        self.sock.settimeout(0.2)
        self.messages = []  # (monotonic time, {key: value})
        self.running = True
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self):
        while self.running:
            try:
                data = self.sock.recv(4096)
            except socket.timeout:
                continue
            except OSError:
                return
            fields = dict(line.split("=", 1) for line in data.decode().split("\n") if "=" in line)
            self.messages.append((time.monotonic(), fields))

    def wait(self, key, after=0.0, timeout=10.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for at, fields in list(self.messages):
                if at >= after and key in fields:
                    return at, fields
            time.sleep(0.05)
        return None, None

    def close(self):
        self.running = False
        self.thread.join()
        self.sock.close()


async def check_notify(skyd, scratch):
    listener = NotifyListener(os.path.join(scratch, "notify.sock"))
    config = make_config(scratch, os.path.join(scratch, "notify-state.json"))
    daemon = Daemon(skyd, scratch, "notify", config,
                    env={"NOTIFY_SOCKET": listener.path, "WATCHDOG_USEC": "600000"})
    try:
        started = time.monotonic()
        daemon.start()
        listening = time.monotonic()
        at, ready = listener.wait("READY", timeout=10)
        check("notify: READY=1", ready is not None and ready.get("READY") == "1", short(ready))
        check("notify: READY after the listening line", at is not None and at >= started)
        check("notify: STATUS names the URL",
              ready is not None and f":{daemon.port}/" in ready.get("STATUS", ""), short(ready))
        time.sleep(1.5)
        pings = [at for at, f in listener.messages if f.get("WATCHDOG") == "1" and at > listening]
        check("notify: watchdog pings at half the interval (>= 3 in 1.5 s)", len(pings) >= 3,
              f"{len(pings)} pings")
        hup = time.monotonic()
        daemon.proc.send_signal(signal.SIGHUP)
        at_reloading, reloading = listener.wait("RELOADING", after=hup)
        at_ready, _ = listener.wait("READY", after=at_reloading or hup)
        check("notify: RELOADING=1 then READY=1 at SIGHUP", reloading is not None and
              at_ready is not None and at_ready >= at_reloading)
        check("notify: RELOADING carries MONOTONIC_USEC",
              reloading is not None and reloading.get("MONOTONIC_USEC", "").isdigit())
        stop = time.monotonic()
        status = daemon.terminate()
        _, stopping = listener.wait("STOPPING", after=stop)
        check("notify: STOPPING=1 at SIGTERM", stopping is not None)
        check("notify: exit 0", status == 0, f"status {status}")
    finally:
        daemon.kill()
        listener.close()


def http_patch(port, token, patch):
    request = urllib.request.Request(f"http://127.0.0.1:{port}/api/state",
                                     data=json.dumps(patch).encode(), method="PATCH",
                                     headers={"Authorization": f"Bearer {token}"})
    try:
        with urllib.request.urlopen(request, timeout=30) as r:
            return r.status
    except urllib.error.HTTPError as e:
        return e.code


async def wait_log(daemon, pattern, timeout=10.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = re.search(pattern, daemon.log_text())
        if m:
            return m
        await asyncio.sleep(0.1)
    return None


async def check_reload(skyd, scratch):
    config_dir = os.path.join(scratch, "config")
    shutil.rmtree(config_dir, ignore_errors=True)
    for kind in ("atmosphere", "weather"):
        os.makedirs(os.path.join(config_dir, kind))
        for name in ("earth.json", "mars.json") if kind == "atmosphere" else \
                ("clear.json", "overcast.json"):
            shutil.copy(os.path.join(SOURCE_CONFIG, kind, name), os.path.join(config_dir, kind))
    config = make_config(scratch, os.path.join(scratch, "reload-state.json"))
    daemon = Daemon(skyd, scratch, "reload", config, env={"SKYD_CONFIG_DIR": config_dir})
    daemon.start()
    try:
        controller = await Client.connect(daemon.url(), "controller")
        await controller.auth()
        sub = await controller.request({"type": "subscribe", "id": 1,
                                        "view": {"width": 64, "height": 36, "fps": 10}})
        check("reload: subscribed", sub.get("type") == "subscribed", short(sub))
        await controller.wait_frame(timeout=30)
        bad = await controller.request({"type": "auth", "id": 2, "token": "not-the-token"})
        check("a wrong token is refused", bad.get("code") == "auth_failed", short(bad))
        refused = await controller.request({"type": "set", "id": 3,
                                            "patch": {"atmosphere": {"mie": {"g": 5}}}})
        check("an out-of-range set is refused", refused.get("code") == "out_of_range")
        check("log: the connection", await wait_log(
            daemon, r"skyd: connection \d+ from 127\.0\.0\.1") is not None, daemon.log_tail())
        check("log: the auth failure", await wait_log(
            daemon, r"auth.*(refused|failed)") is not None, daemon.log_tail())
        check("log: the refused change", await wait_log(
            daemon, r"refused.*(/patch/atmosphere/mie/g|mie)") is not None, daemon.log_tail())

        changed = dict(config)
        changed["limits"] = dict(config["limits"], max_width=500, max_clients=9)
        changed["controller_token"] = NEW_TOKEN
        changed["allowed_origins"] = [ALLOWED_ORIGIN, "http://other.test"]
        changed["listen"] = dict(config["listen"], port=1)
        with open(daemon.config_path, "w") as f:
            json.dump(changed, f)
        shutil.copy(os.path.join(SOURCE_CONFIG, "weather", "clear.json"),
                    os.path.join(config_dir, "weather", "sunny_test.json"))
        with open(os.path.join(config_dir, "weather", "broken_test.json"), "w") as f:
            f.write('{"weather": {"coverage": ')
        os.remove(os.path.join(config_dir, "atmosphere", "mars.json"))
        daemon.proc.send_signal(signal.SIGHUP)
        line = await wait_log(daemon, r"skyd: reloaded the configuration: (.*)")
        text = line.group(1) if line else ""
        check("reload: one log line", line is not None, daemon.log_tail())
        for what in ("limits.max_width 1000 -> 500", "limits.max_clients 16 -> 9",
                     "controller token changed", "allowed_origins", "sunny_test added",
                     "broken_test does not apply", "atmosphere preset mars removed",
                     "not applied until a restart: listen"):
            check(f"reload line says {what!r}", what in text, text)

        await controller.pump(0.5)
        before = controller.frame_count.get(sub["subscription"], 0)
        await controller.pump(1.5)
        check("reload: the streaming client keeps its frames",
              controller.frame_count.get(sub["subscription"], 0) > before)
        r = await controller.request({"type": "set", "id": 4,
                                      "patch": {"sun": {"illuminance_lux": 101000}}})
        check("reload: the controller keeps its role", r.get("type") == "ack", short(r))

        fresh = await Client.connect(daemon.url(), "fresh")
        check("reload: hello announces the new limits",
              fresh.hello.get("limits", {}).get("max_width") == 500, short(fresh.hello))
        old = await fresh.request({"type": "auth", "id": 5, "token": TOKEN})
        check("reload: the old token is refused", old.get("code") == "auth_failed", short(old))
        new = await fresh.request({"type": "auth", "id": 6, "token": NEW_TOKEN})
        check("reload: the new token works", new.get("role") == "controller", short(new))
        wide = await fresh.request({"type": "subscribe", "id": 7,
                                    "view": {"width": 600, "height": 36, "fps": 5}})
        check("reload: the new max_width applies", wide.get("code") == "out_of_range",
              short(wide))
        check("reload: the new origin is let in",
              "101" in (raw_handshake_status(daemon.port, "http://other.test") or ""))
        check("reload: HTTP takes the new token", http_patch(daemon.port, NEW_TOKEN, {
            "sun": {"illuminance_lux": 102000}}) == 200 and
            http_patch(daemon.port, TOKEN, {"sun": {"illuminance_lux": 103000}}) == 401)

        with open(daemon.config_path, "w") as f:
            f.write('{"limits": ')
        daemon.proc.send_signal(signal.SIGHUP)
        check("reload: a broken configuration is reported",
              await wait_log(daemon, r"reload failed: the running configuration stays")
              is not None, daemon.log_tail())
        again = await fresh.request({"type": "auth", "id": 8, "token": NEW_TOKEN})
        check("reload: ... and changes nothing", again.get("role") == "controller", short(again))

        with open(daemon.config_path, "w") as f:
            json.dump(dict(changed, read_only=True), f)
        offset = len(daemon.log_text())
        daemon.proc.send_signal(signal.SIGHUP)
        await wait_log(daemon, r"read_only false -> true")
        check("reload: read_only is logged", "read_only false -> true" in daemon.log_text()[offset:])
        ro = await fresh.request({"type": "auth", "id": 9, "token": NEW_TOKEN})
        check("reload: read_only refuses auth", ro.get("code") == "auth_failed" and
              "read-only" in ro.get("message", ""), short(ro))
        await fresh.close()
        await controller.close()
        check("log: the connection's close",
              await wait_log(daemon, r"connection \d+ from 127\.0\.0\.1 closed") is not None)
    finally:
        status = daemon.terminate()
        check("reload: exit 0", status == 0, f"status {status}")
    log = daemon.log_text()
    check("log: no token in the log", TOKEN not in log and NEW_TOKEN not in log)


async def check_simulation_events(skyd, scratch):
    """A client whose hello asks for simulation events hears the running clock and the sun
    once a second, without a revision; a client that did not ask hears nothing."""
    config = make_config(scratch, os.path.join(scratch, "sim-state.json"))
    config["initial_state"] = {"clock": {"utc": "2026-06-21T18:00:00Z", "time_scale": 60,
                                         "sky_bodies": "ephemeris"}}
    for stale in (config["state_file"],):
        if os.path.exists(stale):
            os.remove(stale)
    daemon = Daemon(skyd, scratch, "simulation", config)
    daemon.start()
    try:
        wants = await Client.connect(daemon.url(), "wants")
        await wants.request({"type": "hello", "id": 1, "client": "sim", "simulation_events": True})
        plain = await Client.connect(daemon.url(), "plain")
        await plain.request({"type": "hello", "id": 1, "client": "plain"})
        start = (await wants.get_state())
        await asyncio.gather(wants.pump(3.2), plain.pump(3.2))
        sims = [e for e in wants.events if e.get("event") == "simulation"]
        check("simulation events: about one a second", 2 <= len(sims) <= 4, str(len(sims)))
        check("simulation events: none to a client that did not ask",
              not [e for e in plain.events if e.get("event") == "simulation"],
              short(plain.events))
        if sims:
            last = sims[-1]
            values = last.get("values", {})
            check("simulation events: the clock, the sun, their values",
                  {"/clock/utc", "/sun/elevation_deg"} <= set(last.get("changed", [])) and
                  set(last.get("changed", [])) == set(values), short(last))
            check("simulation events: the revision stays",
                  all(e.get("revision") == start["revision"] for e in sims), short(sims))
            times = [e.get("simulation_time_s", 0) for e in sims]
            check("simulation events: simulated time runs at 60x",
                  all(40 < b - a < 100 for a, b in zip(times, times[1:])), str(times))
            now = await wants.get_state()
            check("simulation events: their values are the state's",
                  abs(now["state"]["sun"]["elevation_deg"] - values.get("/sun/elevation_deg", 1e9))
                  < 1.0, f"{now['state']['sun']['elevation_deg']} vs {short(values)}")
        await wants.close()
        await plain.close()
    finally:
        daemon.terminate()


async def check_log_level(skyd, scratch):
    bad = subprocess.run([skyd, "serve", "--log-level", "loud"], capture_output=True, text=True,
                         timeout=30)
    check("--log-level loud: exit 2 naming the levels", bad.returncode == 2 and
          "error, warning, info or debug" in bad.stderr, f"{bad.returncode} {bad.stderr!r}")
    config = make_config(scratch, os.path.join(scratch, "quiet-state.json"))
    daemon = Daemon(skyd, scratch, "quiet", config, args=["--log-level", "warning"])
    daemon.start()
    try:
        client = await Client.connect(daemon.url(), "quiet")
        await client.get_state()
        await client.close()
        await asyncio.sleep(0.3)
    finally:
        daemon.terminate()
    log = daemon.log_text()
    check("--log-level warning: no connection lines", "connection" not in log, log[-400:])
    shown = start_up_log(skyd, scratch, "default-level", [])
    check("default log level: the renderer's vulkan device line", "vulkan device" in shown,
          shown[-400:])
    hidden = start_up_log(skyd, scratch, "error-level", ["--log-level", "error"])
    check("--log-level error: no vulkan device line from the renderer",
          "vulkan device" not in hidden, hidden[-400:])


def start_up_log(skyd, scratch, name, args):
    """What a daemon started with `args` logs until it listens, and while it stops."""
    config = make_config(scratch, os.path.join(scratch, f"{name}-state.json"))
    daemon = Daemon(skyd, scratch, name, config, args=args)
    daemon.start()
    daemon.terminate()
    return daemon.log_text()


def check_unit(skyd):
    analyze = shutil.which("systemd-analyze")
    if not analyze:
        check("systemd-analyze is installed (scripts/install-deps.sh)", False)
        return
    text = open(UNIT_FILE).read()
    check("unit: Type=notify, watchdog, reload, state directory, hardening",
          all(s in text for s in ("Type=notify", "WatchdogSec=", "ExecReload=", "StateDirectory=",
                                  "ProtectSystem=strict", "NoNewPrivileges=yes")))
    installed = os.path.join(BINDIR, "skyd")
    check("unit: runs the installed skyd as the user skyd",
          f"\nExecStart={installed} serve " in text and "\nUser=skyd\n" in text, installed)
    unit = os.path.join(os.path.dirname(os.path.abspath(skyd)), "skyd-verify.service")
    with open(unit, "w") as f:
        f.write(text.replace(f"ExecStart={installed} ", f"ExecStart={os.path.abspath(skyd)} "))
    r = subprocess.run([analyze, "verify", "--man=no", unit], capture_output=True, text=True,
                       timeout=60)
    problems = [line for line in (r.stdout + r.stderr).splitlines()
                if "skyd-verify.service" in line]
    check("unit: systemd-analyze verify finds nothing", r.returncode == 0 and not problems,
          f"{r.returncode} {problems}")


async def run(skyd, scratch):
    check_unit(skyd)
    await check_notify(skyd, scratch)
    await check_reload(skyd, scratch)
    await check_simulation_events(skyd, scratch)
    await check_log_level(skyd, scratch)


if __name__ == "__main__":
    if len(sys.argv) != 5:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    BINDIR = sys.argv.pop(4)
    UNIT_FILE = sys.argv.pop(3)
    sys.exit(run_daemon_test(run, __doc__, 300))
