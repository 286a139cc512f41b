#!/usr/bin/python3
"""Browser test of the web client (clients/web) in headless Chromium.

Usage: /usr/bin/python3 tests/e2e/test_web.py PATH_TO_SKYD WEB_ROOT OUTPUT_DIR

Starts `skyd serve` on a free loopback port with WEB_ROOT as its web root, starts Debian's
chromedriver and drives Chromium (--headless=new) through the WebDriver HTTP API (standard
library only). Checks that the page loads from skyd, a frame appears on the canvas (not
blank), the session becomes controller through the token field, moving the time-of-day
control raises the state revision and changes the image (with the sun and moon switched to the
server's ephemeris, whose sun sliders turn read-only), the simulated clock runs live in the page,
an invalid latitude shows the server's error next to the latitude field, a weather preset
applied over a transition shows its progress to the end, the layout fits a narrow window, the page
reconnects by itself when the daemon restarts, another client's change reaches the page's
controls through the event's values without a get_state (the running clock comes as
simulation events), and the browser logged no errors (CSP
violations included). Screenshots go to OUTPUT_DIR.

Exit status 0 when every check passed, 1 otherwise (also when chromium or chromedriver is
missing: scripts/install-deps.sh installs them).
"""

import asyncio
import base64
import json
import os
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness  # noqa: E402
from serve_harness import (TOKEN, Client, Daemon, check, info, make_config,  # noqa: E402
                           stop_process)

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
FRAME_TIMEOUT = 40.0
STEP_TIMEOUT = 15.0

# Runs in the page: statistics of the canvas pixels (mean, spread, mean per channel).
CANVAS_STATS_JS = """
const canvas = document.getElementById('view');
const ctx = canvas.getContext('2d');
const data = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
let sum = 0, sum2 = 0, n = 0;
for (let i = 0; i < data.length; i += 4) {
  const v = (data[i] + data[i + 1] + data[i + 2]) / 3;
  sum += v; sum2 += v * v; n++;
}
const mean = sum / n;
return {width: canvas.width, height: canvas.height, mean: mean,
        stddev: Math.sqrt(Math.max(0, sum2 / n - mean * mean)),
        rgb: [0, 1, 2].map(c => { let s = 0; for (let i = c; i < data.length; i += 4) s += data[i];
                                  return s / n; })};
"""


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class WebDriver:
    """The few W3C WebDriver commands the test needs, over chromedriver's HTTP API."""

    def __init__(self, log_path):
        self.port = free_port()
        self.log = open(log_path, "ab")
        self.proc = subprocess.Popen([CHROMEDRIVER, f"--port={self.port}"],
                                     stdout=self.log, stderr=self.log,
                                     stdin=subprocess.DEVNULL)
        self.base = f"http://127.0.0.1:{self.port}"
        self.session = None
        deadline = time.monotonic() + 15
        while True:
            try:
                self.call("GET", "/status")
                break
            except (urllib.error.URLError, ConnectionError):
                if time.monotonic() > deadline:
                    raise RuntimeError("chromedriver did not answer within 15 s")
                time.sleep(0.1)

    def call(self, method, path, body=None):
        data = json.dumps(body).encode() if body is not None else None
        req = urllib.request.Request(self.base + path, data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(req, timeout=60) as r:
                return json.loads(r.read().decode()).get("value")
        except urllib.error.HTTPError as e:
            raise RuntimeError(f"WebDriver {method} {path}: {e.code} "
                               f"{e.read().decode(errors='replace')[:400]}") from None

    def start(self, width, height, prefs=None):
        args = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--no-first-run", "--disable-extensions", f"--window-size={width},{height}"]
        options = {"binary": CHROMIUM, "args": args}
        if prefs:
            options["prefs"] = prefs
        caps = {"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": options,
            "goog:loggingPrefs": {"browser": "ALL"},
        }}}
        value = self.call("POST", "/session", caps)
        self.session = value["sessionId"]

    def s(self, path):
        return f"/session/{self.session}{path}"

    def get(self, url):
        self.call("POST", self.s("/url"), {"url": url})

    def js(self, script, *args):
        return self.call("POST", self.s("/execute/sync"), {"script": script, "args": list(args)})

    def find(self, css):
        value = self.call("POST", self.s("/element"), {"using": "css selector", "value": css})
        return next(iter(value.values()))

    def click(self, css):
        self.call("POST", self.s(f"/element/{self.find(css)}/click"), {})

    def clear(self, css):
        self.call("POST", self.s(f"/element/{self.find(css)}/clear"), {})

    def type(self, css, text):
        self.call("POST", self.s(f"/element/{self.find(css)}/value"), {"text": text})

    def text(self, css):
        return self.js("const e = document.querySelector(arguments[0]);"
                       "return e ? e.textContent : null;", css)

    def screenshot(self, path):
        png = base64.b64decode(self.call("GET", self.s("/screenshot")))
        with open(path, "wb") as f:
            f.write(png)
        return png

    def set_window(self, width, height):
        self.call("POST", self.s("/window/rect"), {"width": width, "height": height})

    def browser_log(self):
        try:
            return self.call("POST", self.s("/se/log"), {"type": "browser"}) or []
        except RuntimeError as e:
            info(f"browser log unavailable: {e}")
            return None

    def quit(self):
        try:
            if self.session:
                self.call("DELETE", self.s(""))
        except (RuntimeError, urllib.error.URLError, ConnectionError):
            pass
        stop_process(self.proc, timeout=10)
        self.log.close()


def wait_for(what, fn, timeout=STEP_TIMEOUT, interval=0.1):
    """Polls fn until it returns a true value; returns it, or None after the timeout."""
    deadline = time.monotonic() + timeout
    while True:
        value = fn()
        if value:
            return value
        if time.monotonic() > deadline:
            info(f"timed out after {timeout:.0f} s waiting for {what}")
            return None
        time.sleep(interval)


def number(text):
    try:
        return int(text)
    except (TypeError, ValueError):
        return None


def image_differs(a, b):
    """Whether two canvas statistics describe visibly different images."""
    return (abs(a["mean"] - b["mean"]) > 2.0
            or max(abs(x - y) for x, y in zip(a["rgb"], b["rgb"])) > 2.0)


def time_field(wd):
    return wd.js("return document.getElementById('time').value;") or ""


def move_time_slider(wd, minutes, events, what):
    """Puts the time-of-day slider at `minutes` and dispatches `events` on it; checks (as
    `what`) that the state revision rises, and returns the new one."""
    before = number(wd.text("#revision")) or 0
    wd.js(f"const s = document.getElementById('time-of-day'); s.focus(); s.value = '{minutes}';"
          + "".join(f"s.dispatchEvent(new Event('{e}'));" for e in events))
    raised = wait_for("revision after the time change",
                      lambda: (number(wd.text("#revision")) or 0) > before)
    check(what, raised, f"before {before}, after {wd.text('#revision')}")
    return number(wd.text("#revision")) or 0


def run_checks(wd, daemon, out):
    port = daemon.port
    # Small frames (the page's size and fps query parameters) so that lavapipe and the
    # sanitizer build keep up.
    url = f"http://127.0.0.1:{port}/?size=320x180&fps=10"
    t0 = time.monotonic()
    wd.get(url)
    check("page title", wd.js("return document.title;") == "skyd live view",
          wd.js("return document.title;"))
    connected = wait_for("connection", lambda: wd.text("#connection") == "connected")
    check("page connects to skyd over WebSocket", connected, wd.text("#connection"))
    check("hello shows the viewer role",
          wait_for("role", lambda: wd.text("#role") == "viewer"), wd.text("#role"))

    frames = wait_for("first frame", lambda: (number(wd.text("#frame-count")) or 0) > 0,
                      timeout=FRAME_TIMEOUT)
    check("a frame is drawn", frames, f"frames {wd.text('#frame-count')}")
    info(f"first frame after {time.monotonic() - t0:.1f} s")
    first = wd.js(CANVAS_STATS_JS)
    check("canvas has the view's size", (first["width"], first["height"]) == (320, 180),
          json.dumps(first))
    check("canvas is not blank (pixels vary)", first["stddev"] > 2.0, json.dumps(first))
    check("canvas is not black", first["mean"] > 10.0, json.dumps(first))
    check("daytime sky is bluer than red", first["rgb"][2] > first["rgb"][0], json.dumps(first))
    wd.screenshot(os.path.join(out, "web-initial.png"))

    presets = wait_for("atmosphere presets", lambda: wd.js(
        "return [...document.getElementById('atmosphere-preset').options].map(o => o.value);"))
    check("atmosphere presets listed from the server",
          presets and "earth" in presets and "mars" in presets, str(presets))
    check("weather presets: the server's list or its error beside the picker",
          wait_for("weather presets", lambda: wd.js(
              "return document.getElementById('weather-preset').options.length > 0 ||"
              " document.querySelector('[data-error-for=\"preset:weather\"]').textContent"
              ".length > 0;")), "")

    stats_seen = wait_for("stats", lambda: (wd.text("#server-fps") or "–") != "–")
    check("server stats are shown", stats_seen, wd.text("#server-fps"))
    check("per-pass legend lists passes",
          wait_for("pass legend", lambda: wd.js(
              "return document.querySelectorAll('#pass-legend li').length;") > 0), "")

    # A viewer's set is refused next to the control (forbidden), before becoming controller:
    # the page disables the control for a viewer, and a script's change still reaches the server.
    wd.js("const s = document.getElementById('humidity'); s.value = '0.9';"
          "s.dispatchEvent(new Event('change'));")
    forbidden = wait_for("forbidden", lambda: "forbidden" in (wd.text(
        '[data-error-for="weather.humidity"]') or ""))
    check("viewer's change shows forbidden next to the control", forbidden,
          wd.text('[data-error-for="weather.humidity"]'))

    wd.type("#token", TOKEN)
    wd.click("#auth")
    check("token field makes the session controller",
          wait_for("controller", lambda: wd.text("#role") == "controller"), wd.text("#role"))

    # The server's ephemeris places the sun: its sliders turn read-only, and noon's frame is
    # the reference for the time change below.
    revision_before = number(wd.text("#revision"))
    wd.js("const s = document.getElementById('sky-bodies'); s.value = 'ephemeris';"
          "s.dispatchEvent(new Event('change'));")
    check("ephemeris mode makes the sun sliders read-only",
          wait_for("sun sliders disabled", lambda: wd.js(
              "return document.getElementById('sun-elevation').disabled;")),
          wd.text("#sun-mode-note"))
    ephemeris_revision = number(wd.text("#revision")) or 0
    check("the mode switch raises the revision", ephemeris_revision > (revision_before or 0),
          f"{revision_before} -> {ephemeris_revision}")
    wait_for("a frame in ephemeris mode",
             lambda: (number(wd.text("#frame-revision")) or 0) >= ephemeris_revision,
             timeout=FRAME_TIMEOUT)
    time.sleep(0.5)
    first = wd.js(CANVAS_STATS_JS)

    # The simulated clock runs (time_scale 1) and the page shows it live.
    clock_before = wd.text("#sim-clock")
    ticked = wait_for("the clock ticks", lambda: wd.text("#sim-clock") != clock_before)
    check("the simulated clock runs live", ticked and
          (wd.text("#sim-clock") or "").startswith("2026-06-21 12:"),
          f"{clock_before} -> {wd.text('#sim-clock')}")

    # Move the time of day from noon to 17:30 UTC: the server moves the sun. First as while
    # dragging (input events only): the throttled send must carry the slider's time, though
    # the frames arriving before it fires show the running clock in the time field.
    frame_revision_before = number(wd.text("#frame-revision"))
    dragged_revision = move_time_slider(wd, "1050", ["input"],
                                        "time slider, while dragged, raises the state revision")
    wait_for("a frame of the dragged time",
             lambda: (number(wd.text("#frame-revision")) or 0) >= dragged_revision,
             timeout=FRAME_TIMEOUT)
    check("the time sent while dragging is the slider's (17:30)",
          wait_for("time field at 17:30", lambda: time_field(wd).startswith("17:30")),
          time_field(wd))
    # Then the release (change): the final value, sent at once.
    new_revision = move_time_slider(wd, "1050", ["change"],
                                    "time control raises the state revision")
    shown = wait_for("a frame of the new revision",
                     lambda: (number(wd.text("#frame-revision")) or 0) >= new_revision,
                     timeout=FRAME_TIMEOUT)
    check("a frame of the new revision is drawn", shown,
          f"frame revision {frame_revision_before} -> {wd.text('#frame-revision')}, "
          f"state {new_revision}")
    time.sleep(0.5)  # the PNG decode of that frame completes before it is counted
    after = wd.js(CANVAS_STATS_JS)
    check("time control changes the image", image_differs(first, after),
          f"noon {json.dumps(first)}, 17:30 {json.dumps(after)}")
    check("the late-afternoon sky is darker than noon's", after["mean"] < first["mean"],
          f"noon mean {first['mean']:.1f}, 17:30 mean {after['mean']:.1f}")
    check("time input shows 17:30", time_field(wd).startswith("17:30"), time_field(wd))
    wd.screenshot(os.path.join(out, "web-time-changed.png"))

    # An invalid latitude: the server's out_of_range appears next to the latitude field.
    revision_before = number(wd.text("#revision"))
    wd.clear("#latitude")
    wd.type("#latitude", "123\ue004")  # then Tab: the change event
    slot = '[data-error-for="location.latitude_deg"]'
    error = wait_for("latitude error", lambda: wd.text(slot))
    check("invalid latitude shows the server's error next to the field",
          error and "out_of_range" in error, f"slot text {error!r}")
    check("the error names the range", error and "90" in error, f"slot text {error!r}")
    check("the field is marked invalid",
          wd.js("return document.getElementById('latitude').getAttribute('aria-invalid');")
          == "true", "")
    check("general error line stays empty", wd.text("#error") == "", wd.text("#error"))
    check("invalid value leaves the revision", number(wd.text("#revision")) == revision_before,
          f"{revision_before} -> {wd.text('#revision')}")
    wd.screenshot(os.path.join(out, "web-error.png"))

    # A valid value clears it.
    wd.clear("#latitude")
    wd.type("#latitude", "46\ue004")
    check("a valid value clears the error", wait_for("error cleared", lambda: wd.text(slot) == ""),
          wd.text(slot))

    check_transition(wd, out)
    check_event_values(wd, daemon)

    # Narrow window: one column, nothing wider than the viewport.
    wd.set_window(420, 900)
    time.sleep(0.5)
    overflow = wd.js("return document.documentElement.scrollWidth - window.innerWidth;")
    check("narrow window: no horizontal overflow", overflow is not None and overflow <= 0,
          f"overflow {overflow}px")
    columns = wd.js("return getComputedStyle(document.querySelector('.layout'))"
                    ".gridTemplateColumns.split(' ').length;")
    check("narrow window: one column", columns == 1, f"{columns} columns")
    wd.screenshot(os.path.join(out, "web-narrow.png"))

    check_console(wd, "browser console has no errors")
    check_reconnect(wd, daemon)
    check_console(wd, "browser console: no errors but refused reconnection attempts",
                  allow="ERR_CONNECTION_REFUSED")


def check_transition(wd, out_dir):
    """The storm preset over 150 simulated seconds with the clock at 30x real time: the
    revision rises, the progress shows part of the way, then the end with the storm's cover."""
    wd.js("const s = document.getElementById('time-scale'); s.value = '30';"
          "s.dispatchEvent(new Event('change'));")
    wait_for("time scale", lambda: wd.js(
        "return document.getElementById('time-scale').value;") == "30")
    revision_before = number(wd.text("#revision")) or 0
    wd.js("document.getElementById('weather-preset').value = 'storm';"
          "document.getElementById('weather-transition').value = '150';")
    wd.click('button[data-apply-kind="weather"]')
    check("a weather preset with a transition raises the revision",
          wait_for("revision", lambda: (number(wd.text("#revision")) or 0) > revision_before),
          f"{revision_before} -> {wd.text('#revision')}")
    text = "#weather-transition-text"
    partway = wait_for("progress part of the way", lambda: "% of 150 s" in wd.text(text)
                       and 0 < wd.js("return document.getElementById("
                                     "'weather-transition-progress').value;") < 1)
    check("the transition's progress is shown part of the way", partway, wd.text(text))
    done = wait_for("transition done", lambda: wd.text(text).startswith("done"))
    check("the transition reaches its end", done, wd.text(text))
    check("the storm's low cloud cover is reached",
          wait_for("coverage", lambda: wd.js(
              "return document.getElementById('low-coverage').value;") == "0.85"),
          wd.js("return document.getElementById('low-coverage').value;"))
    check("no error beside the weather preset",
          wd.text('[data-error-for="preset:weather"]') == "",
          wd.text('[data-error-for="preset:weather"]'))
    wd.screenshot(os.path.join(out_dir, "web-storm.png"))


# Runs in the page: records the type of every message the page sends from now on.
RECORD_SENT_JS = """
window.sentTypes = [];
const send = WebSocket.prototype.send;
WebSocket.prototype.send = function (data) {
  try { window.sentTypes.push(JSON.parse(data).type); } catch (e) { window.sentTypes.push('?'); }
  return send.call(this, data);
};
"""


async def set_from_another_client(url, patch):
    """A second controller sets `patch`; returns the ack."""
    other = await Client.connect(url, "other")
    try:
        await other.request({"type": "hello", "client": "test_web.py"})
        await other.auth()
        return await other.request({"type": "set", "patch": patch})
    finally:
        await other.close()


def check_event_values(wd, daemon):
    """With the clock running, the page keeps its state from events alone: another client's
    change reaches the control through the event's values, the revision follows, and the
    clock's own changes come as simulation events (its hello asks for them), so the page
    sends no get_state at all."""
    wd.js(RECORD_SENT_JS)
    ack = asyncio.run(set_from_another_client(daemon.url(), {"weather": {"humidity": 0.37}}))
    check("another client's set is acknowledged", ack.get("type") == "ack", json.dumps(ack))
    shown = wait_for("humidity from the event", lambda: wd.js(
        "return document.getElementById('humidity').value;") == "0.37")
    check("another client's change shows in the page's control", shown,
          wd.js("return document.getElementById('humidity').value;"))
    check("the page's revision follows the event",
          wait_for("revision", lambda: number(wd.text("#revision")) == ack.get("revision")),
          f"{wd.text('#revision')} vs {ack.get('revision')}")
    time.sleep(2.5)  # long enough for two polls, had the page kept polling the running clock
    sent = wd.js("return window.sentTypes;") or []
    check("no get_state after the event, the clock running", "get_state" not in sent,
          json.dumps(sent))


def check_console(wd, name, allow=None):
    """No SEVERE entries in the browser log since the last read (it is drained by reading)."""
    log = wd.browser_log()
    if log is None:
        return
    severe = [e for e in log if e.get("level") == "SEVERE"
              and not (allow and allow in e.get("message", ""))]
    check(name, not severe, json.dumps(severe)[:800])


def check_reconnect(wd, daemon):
    """The daemon restarts on the same port: the page notices, reconnects by itself, takes the
    controller role again with the token it kept and receives frames again."""
    frames_before = number(wd.text("#frame-count")) or 0
    daemon.terminate()
    closed = wait_for("closed", lambda: (wd.text("#connection") or "").startswith("closed"))
    check("connection loss is shown", closed, wd.text("#connection"))
    daemon.start()
    check("the page reconnects by itself",
          wait_for("reconnect", lambda: wd.text("#connection") == "connected", timeout=30),
          wd.text("#connection"))
    check("the controller role is restored",
          wait_for("role", lambda: wd.text("#role") == "controller"), wd.text("#role"))
    check("frames resume after the reconnection",
          wait_for("frames", lambda: (number(wd.text("#frame-count")) or 0) > frames_before,
                   timeout=FRAME_TIMEOUT), f"{frames_before} -> {wd.text('#frame-count')}")


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, web_root, out = (os.path.abspath(p) for p in sys.argv[1:4])
    if not (os.access(CHROMIUM, os.X_OK) and os.access(CHROMEDRIVER, os.X_OK)):
        print("test_web.py: chromium and chromium-driver are needed "
              "(scripts/install-deps.sh installs them)", file=sys.stderr)
        return 1
    os.makedirs(out, exist_ok=True)
    for name in os.listdir(out):
        path = os.path.join(out, name)
        if os.path.isfile(path):
            os.unlink(path)
    config = make_config(out, os.path.join(out, "state.json"))
    config["web_root"] = os.path.abspath(web_root)
    config["allowed_origins"] = []
    config["listen"]["port"] = free_port()  # fixed, so that a restart keeps it
    daemon = Daemon(skyd, out, "skyd", config)
    wd = None
    started = time.monotonic()
    try:
        daemon.start()
        info(f"skyd on port {daemon.port}")
        wd = WebDriver(os.path.join(out, "chromedriver.log"))
        wd.start(1280, 720)
        run_checks(wd, daemon, out)
    except Exception as e:  # noqa: BLE001 - any failure is a failed check
        check("browser test ran", False, f"{type(e).__name__}: {e}")
    finally:
        if wd is not None:
            wd.quit()
        status = daemon.terminate()
        check("skyd exits 0 on SIGTERM", status == 0, f"status {status}; {daemon.log_tail()}")
    return serve_harness.summary(started)


if __name__ == "__main__":
    sys.exit(main())
