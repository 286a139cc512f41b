#!/usr/bin/python3
"""The controller token of `skyd serve`, with the real daemon on loopback.

Usage: /usr/bin/python3 tests/e2e/test_control_token.py SKYD SKYCTL WEB_ROOT OUTPUT_DIR

With an empty controller_token the first start prints "skyd: control at URL#token=TOKEN" once,
after the listening line, and keeps the token in <state_file>.token (mode 0600, at least 128
bits); auth with it makes a controller whose set is accepted, skyctl --token-file takes it, and
the web client opened at that URL in headless Chromium becomes controller and drops the
fragment from its address. A restart prints the same token; a token file others may read is
replaced by a new one. Without a state file the token is printed and kept nowhere. A configured
token is never printed or logged, and works; read_only refuses every auth. Exit status 0 when
every check passed.
"""

import asyncio
import glob
import os
import re
import shutil
import stat
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness  # noqa: E402
from serve_harness import (Client, Daemon, check, daemon_environment, info,  # noqa: E402
                           make_config)
from test_web import CHROMEDRIVER, CHROMIUM, WebDriver, check_console, wait_for  # noqa: E402

CONTROL = re.compile(r"skyd: control at http://127\.0\.0\.1:(\d+)/#token=([0-9A-Za-z._~-]+)")
CONFIGURED = "configured-token-never-printed-4b1d"


def next_line(daemon, timeout=10):
    """The daemon's next stdout line, or None."""
    try:
        line = daemon.lines.get(timeout=timeout)
    except Exception:  # noqa: BLE001 - queue.Empty
        return None
    return line.rstrip("\n") if line is not None else None


def rest_of_stdout(daemon):
    """Every stdout line left once the daemon has exited."""
    lines = []
    while True:
        line = daemon.lines.get(timeout=10)
        if line is None:
            return lines
        lines.append(line.rstrip("\n"))


DAEMONS = []  # killed at the end, whatever happened


def started(daemon, name):
    DAEMONS.append(daemon)
    try:
        daemon.start()
        return check(f"{name}: starts", True)
    except Exception as e:  # noqa: BLE001
        return check(f"{name}: starts", False, str(e))


async def auth(daemon, token, name):
    """auth with token on a fresh connection: the reply, and the client (to close)."""
    c = await Client.connect(daemon.url(), name)
    return await c.request({"type": "auth", "id": "a", "token": token}), c


async def becomes_controller(daemon, token, name):
    r, c = await auth(daemon, token, name)
    ok = check(f"{name}: auth makes a controller",
               r.get("type") == "ack" and r.get("role") == "controller", str(r))
    if ok:
        r = await c.request({"type": "set", "id": "s", "patch": {"camera": {"fov_deg": 61}}})
        check(f"{name}: the controller's set is accepted", r.get("type") == "ack", str(r))
    await c.close()


def stop(daemon, name):
    status = daemon.terminate()
    check(f"{name}: exits 0 on SIGTERM", status == 0, f"status {status}")
    return rest_of_stdout(daemon)


def skyctl_with_file(skyctl, daemon, token_file):
    env = daemon_environment()
    env.pop("SKYD_TOKEN", None)
    p = subprocess.run([skyctl, "--url", daemon.url(), "--timeout", "30", "--token-file",
                        token_file, "set", "camera.fov_deg=62"],
                       stdin=subprocess.DEVNULL, capture_output=True, timeout=60, env=env)
    check("skyctl --token-file with the daemon's token file",
          p.returncode == 0 and p.stdout.startswith(b"revision "),
          f"exit {p.returncode}: {p.stdout!r} {p.stderr!r}")


def web_client(url, out):
    """The printed URL in Chromium: controller, and no token left in the address."""
    if not (os.access(CHROMIUM, os.X_OK) and os.access(CHROMEDRIVER, os.X_OK)):
        check("chromium and chromedriver are installed", False,
              "scripts/install-deps.sh installs them")
        return
    wd = WebDriver(os.path.join(out, "chromedriver.log"))
    try:
        wd.start(1280, 720)
        wd.get(url)
        check("web: the page at the printed URL becomes controller",
              wait_for("controller", lambda: wd.text("#role") == "controller"), wd.text("#role"))
        href = wd.js("return location.href;")
        check("web: the fragment is gone from location.href",
              "#" not in href and "token" not in href, href)
        check("web: the token is kept in sessionStorage as a typed one is",
              wd.js("return sessionStorage.getItem('skyd-controller-token');")
              == url.split("#token=")[1], "")
        check("web: the token field stays empty", wd.js(
            "return document.getElementById('token').value;") == "", "")
        check_console(wd, "web: browser console has no errors")
        wd.get(url.split("#")[0])  # the tab's sessionStorage outlives the page
        check("web: still controller when opened again without the fragment",
              wait_for("controller again", lambda: wd.text("#role") == "controller"),
              wd.text("#role"))
    finally:
        wd.quit()


def mode_of(path):
    return stat.S_IMODE(os.stat(path).st_mode)


async def run(skyd, skyctl, web_root, out):
    state = os.path.join(out, "var", "state.json")  # var/ is made by the daemon
    token_file = state + ".token"
    config = make_config(out, state)
    config.update({"controller_token": "", "web_root": web_root, "allowed_origins": []})

    # --- first start: a token made, kept and printed once
    d = Daemon(skyd, out, "generated", config)
    if not started(d, "first start"):
        return
    line = next_line(d)
    m = CONTROL.fullmatch(line or "")
    check("first start: the control line follows the listening line", m, repr(line))
    token = m.group(2) if m else ""
    check("first start: the control URL has the listening port",
          m and int(m.group(1)) == d.port, repr(line))
    check("first start: the token has at least 128 bits",
          re.fullmatch(r"[0-9a-f]{32,}", token) and len(token) * 4 >= 128, token)
    check("first start: the token file exists", os.path.isfile(token_file), token_file)
    if os.path.isfile(token_file):
        check("first start: the token file is 0600", mode_of(token_file) == 0o600,
              oct(mode_of(token_file)))
        with open(token_file) as f:
            check("first start: the token file holds the token", f.read() == token + "\n", "")
    check("first start: the log names the token file but not the token",
          token_file in d.log_text() and token not in d.log_text(), d.log_tail())
    await becomes_controller(d, token, "generated token")
    r, c = await auth(d, "not-the-token", "wrong token")
    check("a wrong token is refused", r.get("code") == "auth_failed", str(r))
    await c.close()
    skyctl_with_file(skyctl, d, token_file)
    if m:
        web_client(line.split("control at ", 1)[1], out)
    rest = stop(d, "first start")
    check("first start: the control line printed exactly once",
          not [x for x in rest if "control at" in x], str(rest))

    # --- restart: the same token
    if not started(d, "restart"):
        return
    line = next_line(d)
    m = CONTROL.fullmatch(line or "")
    check("restart: the same token is printed", m and m.group(2) == token, repr(line))
    await becomes_controller(d, token, "restored token")
    stop(d, "restart")
    leftovers = [p for p in glob.glob(state + "*") if p not in (state, token_file)]
    check("no temporary files left", not leftovers, str(leftovers))

    # --- a token file others may read: replaced
    os.chmod(token_file, 0o644)
    if not started(d, "exposed token file"):
        return
    m = CONTROL.fullmatch(next_line(d) or "")
    new_token = m.group(2) if m else ""
    check("exposed token file: a new token is printed", m and new_token != token, new_token)
    check("exposed token file: 0600 again with the new token", mode_of(token_file) == 0o600
          and open(token_file).read() == new_token + "\n", oct(mode_of(token_file)))
    check("exposed token file: the log says why",
          "0644" in d.log_text() and "replaced" in d.log_text(), d.log_tail())
    r, c = await auth(d, token, "old token")
    check("exposed token file: the old token is refused", r.get("code") == "auth_failed", str(r))
    await c.close()
    stop(d, "exposed token file")

    # --- no state file: printed, kept nowhere
    before = set(glob.glob(os.path.join(out, "**", "*.token"), recursive=True))
    d = Daemon(skyd, out, "stateless", dict(config, state_file=""))
    if started(d, "no state file"):
        m = CONTROL.fullmatch(next_line(d) or "")
        check("no state file: a token is printed", m, "")
        if m:
            await becomes_controller(d, m.group(2), "process token")
        stop(d, "no state file")
        after = set(glob.glob(os.path.join(out, "**", "*.token"), recursive=True))
        check("no state file: no token file written", after == before, str(after - before))

    # --- a configured token: used, never printed or logged
    state2 = os.path.join(out, "configured", "state.json")
    d = Daemon(skyd, out, "configured", dict(config, controller_token=CONFIGURED,
                                             state_file=state2))
    if started(d, "configured token"):
        await becomes_controller(d, CONFIGURED, "configured token")
        rest = stop(d, "configured token")
        check("configured token: nothing on stdout after the listening line", not rest, str(rest))
        check("configured token: not in the log", CONFIGURED not in d.log_text(), "")
        check("configured token: no token file", not os.path.exists(state2 + ".token"), "")

    # --- read_only: nobody controls, even with a token configured
    state3 = os.path.join(out, "read-only", "state.json")
    d = Daemon(skyd, out, "read_only", dict(config, read_only=True, state_file=state3,
                                            controller_token=CONFIGURED))
    if started(d, "read_only"):
        for name, tried in (("configured token", CONFIGURED), ("another token", "x")):
            r, c = await auth(d, tried, f"read-only {name}")
            check(f"read_only: auth with the {name} refused",
                  r.get("code") == "auth_failed" and "read-only" in r.get("message", ""), str(r))
            r = await c.request({"type": "set", "id": "s", "patch": {"camera": {"fov_deg": 50}}})
            check(f"read_only: set forbidden after the {name}", r.get("code") == "forbidden",
                  str(r))
            await c.close()
        rest = stop(d, "read_only")
        check("read_only: no control line", not rest, str(rest))
        check("read_only: the log says so", "read-only" in d.log_text(), d.log_tail())
        check("read_only: no token file", not os.path.exists(state3 + ".token"), "")


def main():
    if len(sys.argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, skyctl, web_root, out = (os.path.abspath(p) for p in sys.argv[1:5])
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    started_at = time.monotonic()
    try:
        asyncio.run(asyncio.wait_for(run(skyd, skyctl, web_root, out), 150))
    except Exception as e:  # noqa: BLE001 - a timeout or a crash is a failed check
        check("test ran to completion", False, f"{type(e).__name__}: {e}")
    finally:
        for d in DAEMONS:
            d.kill()
    info(f"took {time.monotonic() - started_at:.1f} s")
    print(f"{serve_harness.passed} passed, {serve_harness.failed} failed")
    return 0 if serve_harness.failed == 0 and serve_harness.passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
