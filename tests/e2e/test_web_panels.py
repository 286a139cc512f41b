#!/usr/bin/python3
"""Browser test of the web client's panels (clients/web) in headless Chromium.

Usage: /usr/bin/python3 tests/e2e/test_web_panels.py PATH_TO_SKYD WEB_ROOT OUTPUT_DIR

With test_web.py's daemon and WebDriver: a viewer page has every controller-only control
disabled and a controller page (another tab, after auth) has them enabled; the clock buttons
pause, play at the previous scale and set the clock to now; a click on the image probes the
luminance there, beside the illuminance and the sun's and moon's positions; snapshots (PNG,
PNG16, equirectangular) are saved as downloads; a generated weather map is previewed channel by
channel, uploaded (the state's weather.map_source becomes "client") and a map the server refuses
shows its error; the panorama is drawn and a mouse drag turns it. Each panel's element
screenshot goes to OUTPUT_DIR and must not be blank.
"""

import base64
import json
import os
import re
import sys
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness  # noqa: E402
from serve_harness import (PNG_SIGNATURE, TOKEN, Daemon, check, decode_png_full,  # noqa: E402
                           encode_png, info, make_config)
from test_web import (CHROMEDRIVER, CHROMIUM, FRAME_TIMEOUT, WebDriver, free_port,  # noqa: E402
                      number, wait_for)

# Runs in the page: the pixels of canvas arguments[0] as statistics, and (arguments[1]) the
# fraction of pixels that differ from those kept under window.kept[arguments[0]].
CANVAS_JS = """
const canvas = document.getElementById(arguments[0]);
const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
window.kept = window.kept || {};
let sum = 0, sum2 = 0, differ = 0;
const kept = window.kept[arguments[0]];
for (let i = 0; i < data.length; i += 4) {
  const v = (data[i] + data[i + 1] + data[i + 2]) / 3;
  sum += v; sum2 += v * v;
  if (kept && (Math.abs(kept[i] - data[i]) + Math.abs(kept[i + 1] - data[i + 1])
               + Math.abs(kept[i + 2] - data[i + 2])) > 6) differ++;
}
if (arguments[1]) window.kept[arguments[0]] = data;
const n = data.length / 4, mean = sum / n;
return {mean: mean, stddev: Math.sqrt(Math.max(0, sum2 / n - mean * mean)),
        differ: kept ? differ / n : null};
"""


def element_screenshot(wd, css, path):
    """Saves the element's screenshot; returns the standard deviation of its pixels' grey
    levels (0 for a uniform, blank region)."""
    png = base64.b64decode(wd.call("GET", wd.s(f"/element/{wd.find(css)}/screenshot")))
    with open(path, "wb") as f:
        f.write(png)
    image = decode_png_full(png)
    c = image["channels"]
    values = [sum(row[i:i + min(c, 3)]) / min(c, 3)
              for row in image["rows"][::2] for i in range(0, len(row), 2 * c)]
    mean = sum(values) / len(values)
    return (sum((v - mean) ** 2 for v in values) / len(values)) ** 0.5


def check_screenshot(wd, css, out, name):
    spread = element_screenshot(wd, css, os.path.join(out, name))
    check(f"{name}: the panel is not blank", spread > 8.0, f"grey level spread {spread:.1f}")


def api_state(daemon):
    with urllib.request.urlopen(f"http://127.0.0.1:{daemon.port}/api/state", timeout=10) as r:
        return json.loads(r.read().decode())["state"]


def check_roles(wd, url, out):
    """Tab 1 stays a viewer, tab 2 becomes controller; returns the handles."""
    viewer_tab = wd.call("GET", wd.s("/window"))
    wd.get(url)
    check("viewer page connects", wait_for("viewer", lambda: wd.text("#role") == "viewer"),
          wd.text("#role"))
    wait_for("first frame", lambda: (number(wd.text("#frame-count")) or 0) > 0,
             timeout=FRAME_TIMEOUT)
    enabled = wd.js("return [...document.querySelectorAll('[data-path], [data-controller]')]"
                    ".filter(e => !e.disabled).map(e => e.id || e.tagName);")
    total = wd.js("return document.querySelectorAll('[data-path], [data-controller]').length;")
    check("viewer: every controller-only control is disabled", total > 25 and enabled == [],
          f"{total} controls, enabled: {enabled}")
    free = wd.js("return ['camera-yaw', 'view-size', 'snapshot-save', 'panorama-load', 'token',"
                 " 'auth', 'weather-map-file'].filter(id => document.getElementById(id).disabled);")
    check("viewer: the view, snapshot, panorama and token controls stay enabled", free == [],
          str(free))
    check_screenshot(wd, "aside", out, "web-panels-viewer-controls.png")

    controller_tab = wd.call("POST", wd.s("/window/new"), {"type": "tab"})["handle"]
    wd.call("POST", wd.s("/window"), {"handle": controller_tab})
    wd.get(url)
    wait_for("controller page", lambda: wd.text("#role") == "viewer")
    wd.type("#token", TOKEN)
    wd.click("#auth")
    check("controller page: auth makes the session controller",
          wait_for("controller", lambda: wd.text("#role") == "controller"), wd.text("#role"))
    # Still locked for other reasons: the upload until a file is read (and the sun sliders
    # were the sun in ephemeris mode).
    still = wd.js("return [...document.querySelectorAll('[data-path], [data-controller]')]"
                  ".filter(e => e.disabled).map(e => e.id + ':' + e.dataset.locks);")
    check("controller: only the upload (no file yet) stays disabled",
          still == ["weather-map-upload:no-file"], str(still))

    wd.call("POST", wd.s("/window"), {"handle": viewer_tab})
    check("the viewer tab keeps its controls disabled", wd.js(
        "return document.getElementById('clock-play').disabled"
        " && document.getElementById('humidity').disabled;"), "")
    wd.call("POST", wd.s("/window"), {"handle": controller_tab})
    return viewer_tab, controller_tab


def check_clock(wd, daemon, out):
    wd.js("const s = document.getElementById('time-scale'); s.value = '5';"
          "s.dispatchEvent(new Event('change'));")
    wait_for("scale 5", lambda: api_state(daemon)["clock"]["time_scale"] == 5)
    wd.click("#clock-pause")
    check("pause sets clock.time_scale to 0",
          wait_for("paused", lambda: api_state(daemon)["clock"]["time_scale"] == 0),
          json.dumps(api_state(daemon)["clock"]))
    check("the page shows the clock paused",
          wait_for("paused text", lambda: wd.text("#clock-state") == "paused"
                   and wd.js("return document.getElementById('time-scale').value;") == "0"),
          wd.text("#clock-state"))
    wd.click("#clock-play")
    check("play restores the previous scale (5)",
          wait_for("running", lambda: api_state(daemon)["clock"]["time_scale"] == 5),
          json.dumps(api_state(daemon)["clock"]))
    wd.click("#clock-pause")
    wait_for("paused", lambda: api_state(daemon)["clock"]["time_scale"] == 0)
    wd.click("#clock-now")

    def near_now():
        utc = api_state(daemon)["clock"]["utc"]
        t = time.mktime(time.strptime(utc[:19], "%Y-%m-%dT%H:%M:%S")) - time.timezone
        return abs(t - time.time()) < 120 and utc
    check("now sets clock.utc to the current time", wait_for("now", near_now),
          api_state(daemon)["clock"]["utc"])
    check_screenshot(wd, "#time-panel", out, "web-panels-clock.png")


def check_probe(wd, daemon, out):
    # Noon in June at 45°N with the sun placed by hand: daylight everywhere in the view.
    state = api_state(daemon)
    wd.click("#view")  # the element's centre: the camera's own direction
    check("a click on the image probes its luminance",
          wait_for("luminance", lambda: "cd/m²" in (wd.text("#probe-luminance") or "")),
          wd.text("#probe-luminance"))
    values = [float(v) for v in re.findall(r"[RGB] ([-+0-9.e]+)",
                                           wd.text("#probe-luminance") or "")]
    check("the daytime sky's luminance is positive in all three channels",
          len(values) == 3 and all(v > 0 for v in values), wd.text("#probe-luminance"))
    yaw = state["camera"]["yaw_deg"] % 360
    pixel = wd.text("#probe-pixel") or ""
    shown = float(pixel.split("azimuth ")[1].split("°")[0]) if "azimuth " in pixel else None
    check("the picked direction is the camera's at the image centre",
          shown is not None and abs((shown - yaw + 180) % 360 - 180) < 2.0,
          f"{pixel}; camera yaw {yaw}")
    check("sun and sky illuminance in lux",
          wait_for("lux", lambda: "lx" in (wd.text("#probe-sun-lux") or "")
                   and "lx" in (wd.text("#probe-sky-lux") or "")),
          f"{wd.text('#probe-sun-lux')} / {wd.text('#probe-sky-lux')}")
    sun = wd.text("#probe-sun") or ""
    check("the sun's position from the state",
          f"elevation {state['sun']['elevation_deg']:.1f}°" in sun, f"{sun}; {state['sun']}")
    check("the moon's position from the state", "azimuth" in (wd.text("#probe-moon") or ""),
          wd.text("#probe-moon"))
    check_screenshot(wd, "section.probe", out, "web-panels-probe.png")


def png_header(data):
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big"), data[24]


def jpeg_check(wd, downloads):
    """The default download format, JPEG: a .jpg file with JPEG's start and end markers."""
    before = set(os.listdir(downloads))
    wd.js("document.getElementById('snapshot-projection').value = 'perspective';"
          "document.getElementById('snapshot-format').value = 'jpeg';")
    wd.click("#snapshot-save")

    def saved():
        new = [n for n in set(os.listdir(downloads)) - before if n.endswith(".jpg")]
        return new[0] if new else None
    name = wait_for("jpeg download", saved, timeout=30)
    data = b""
    if name:
        time.sleep(0.2)
        with open(os.path.join(downloads, name), "rb") as f:
            data = f.read()
    check("snapshot jpeg is downloaded as a JPEG file",
          data[:2] == b"\xff\xd8" and data[-2:] == b"\xff\xd9" and len(data) > 1000,
          f"{name}: {len(data)} bytes")


def check_snapshots(wd, downloads, out):
    jpeg_check(wd, downloads)
    cases = [("perspective", "png", (320, 180, 8)), ("perspective", "png16", (320, 180, 16)),
             ("equirectangular", "png", (360, 180, 8))]
    for projection, fmt, expected in cases:
        before = set(os.listdir(downloads))
        wd.js(f"document.getElementById('snapshot-projection').value = '{projection}';"
              f"document.getElementById('snapshot-format').value = '{fmt}';")
        wd.click("#snapshot-save")

        def saved():
            new = [n for n in set(os.listdir(downloads)) - before
                   if n.endswith(".png") and not n.endswith(".crdownload")]
            return new[0] if new else None
        name = wait_for(f"{projection} {fmt} download", saved, timeout=30)
        data = b""
        if name:
            time.sleep(0.2)
            with open(os.path.join(downloads, name), "rb") as f:
                data = f.read()
        check(f"snapshot {projection} {fmt} is downloaded as a PNG file",
              name and data.startswith(PNG_SIGNATURE) and len(data) > 1000,
              f"{name}: {len(data)} bytes")
        check(f"snapshot {projection} {fmt}: {expected[0]} × {expected[1]}, {expected[2]}-bit",
              data and png_header(data) == expected,
              f"{name}: {png_header(data) if data else None}")
    link = wd.js("const a = document.getElementById('snapshot-link');"
                 "return [a.hidden, a.download, a.href.slice(0, 5)];")
    check("the page links the last snapshot as a blob", link[0] is False
          and link[1].endswith("-equirectangular.png") and link[2] == "blob:", str(link))
    check_screenshot(wd, "#snapshot-panel", out, "web-panels-snapshot.png")


def weather_map_png(width, height):
    """r east, g south, b falling east; a 0 (dry) on the western half, where a preview that
    premultiplied alpha would lose the other channels."""
    rows = []
    for y in range(height):
        row = bytearray()
        for x in range(width):
            row += bytes([x * 255 // (width - 1), y * 255 // (height - 1),
                          255 - x * 255 // (width - 1), 0 if x < width // 2 else 200])
        rows.append(row)
    return encode_png(width, height, rows)


def check_weather_map(wd, daemon, out):
    path = os.path.join(out, "weather-map.png")
    with open(path, "wb") as f:
        f.write(weather_map_png(16, 16))
    wd.type("#weather-map-file", path)
    check("the map file is read",
          wait_for("map read", lambda: (wd.text("#weather-map-status") or "").endswith("16 × 16")),
          wd.text("#weather-map-status"))
    texels = wd.js("return ['weather-map-low', 'weather-map-high', 'weather-map-type',"
                   " 'weather-map-precipitation'].map(id => {"
                   " const c = document.getElementById(id);"
                   " const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                   " return [c.width, d[0], d[4 * 15], d[4 * 16 * 15]]; });")
    check("the preview shows each channel as stored (alpha 0 leaves r, g, b alone)",
          texels == [[16, 0, 255, 0], [16, 0, 0, 255], [16, 255, 0, 255], [16, 0, 200, 0]],
          str(texels))
    revision = number(wd.text("#revision")) or 0
    wd.click("#weather-map-upload")
    check("upload is acknowledged with a new revision",
          wait_for("uploaded", lambda: (wd.text("#weather-map-status") or "")
                   .startswith("uploaded: revision")), wd.text("#weather-map-status"))
    acked = number((wd.text("#weather-map-status") or "").split()[-1])
    check("the ack's revision is newer", acked is not None and acked > revision,
          f"{revision} -> {acked}")
    check("the state's weather.map_source is \"client\"",
          wait_for("map source", lambda: api_state(daemon)["weather"]["map_source"] == "client"),
          api_state(daemon)["weather"]["map_source"])
    check("the page's map source follows the event", wait_for("select", lambda: wd.js(
        "return document.getElementById('weather-map-source').value;") == "client"), "")
    check_screenshot(wd, "#weather-map-panel", out, "web-panels-weather-map.png")

    # Wider than the server's 512 texels: previewed here, refused there, the error beside it.
    wide = os.path.join(out, "weather-map-wide.png")
    with open(wide, "wb") as f:
        f.write(weather_map_png(600, 2))
    wd.type("#weather-map-file", wide)
    wait_for("wide map read", lambda: "600 × 2" in (wd.text("#weather-map-status") or ""))
    wd.click("#weather-map-upload")
    error = wait_for("server error", lambda: wd.text('[data-error-for="weather-map"]'))
    check("the server's refusal shows next to the upload", error and "(" in error,
          f"{error!r}")
    wd.screenshot(os.path.join(out, "web-panels-weather-map-error.png"))


def check_observation(wd, daemon, out):
    """A METAR applied from the page: the decoded report's table (station, time, layers,
    visibility, wind, T/Td) shows while weather.source is metar; a refused report's error
    shows beside the button."""
    wd.js("document.getElementById('observation-panel').scrollIntoView();")
    wd.clear("#metar-text")
    wd.type("#metar-text", "METAR LFLY 211200Z 18008KT 9999 FEW040 22/10 Q1018")
    wd.click("#metar-apply")
    check("the report is applied with a new revision",
          wait_for("applied", lambda: (wd.text("#metar-status") or "")
                   .startswith("applied: revision")), wd.text("#metar-status"))
    table = wd.js("const t = document.getElementById('metar-report');"
                  "return t.hidden ? null : t.textContent;") or ""
    check("the decoded report is shown: station, time, layer, visibility, wind, T/Td",
          all(s in table for s in ("LFLY", "day 21, 12:00 UTC", "FEW 1219 m", "≥ 10.0 km",
                                   "from 180°, 4.1 m/s", "22 °C / 10 °C")), table)
    check("the state's weather.source is metar",
          wait_for("source", lambda: api_state(daemon)["weather"]["source"] == "metar"),
          api_state(daemon)["weather"]["source"])
    check_screenshot(wd, "#observation-panel", out, "web-panels-observation.png")
    wd.clear("#metar-text")
    wd.type("#metar-text", "METAR EGLL 281150Z 24010KT 9999 BKN0X0 12/09 Q1005")
    wd.click("#metar-apply")
    error = wait_for("metar error", lambda: wd.text('[data-error-for="metar"]'))
    check("a refused report's group shows beside the button", error and "BKN0X0" in error,
          f"{error!r}")


def drag(wd, css, dx, dy, steps=6):
    """A mouse drag through the WebDriver actions API, from the element's centre."""
    x, y = wd.js("const r = document.querySelector(arguments[0]).getBoundingClientRect();"
                 "return [Math.round(r.left + r.width / 2), Math.round(r.top + r.height / 2)];",
                 css)
    moves = [{"type": "pointerMove", "duration": 20, "origin": "viewport",
              "x": x + round(dx * i / steps), "y": y + round(dy * i / steps)}
             for i in range(1, steps + 1)]
    wd.call("POST", wd.s("/actions"), {"actions": [{
        "type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
        "actions": [{"type": "pointerMove", "duration": 0, "origin": "viewport", "x": x, "y": y},
                    {"type": "pointerDown", "button": 0}, *moves,
                    {"type": "pointerUp", "button": 0}]}]})
    wd.call("DELETE", wd.s("/actions"))


def check_panorama(wd, out):
    wd.js("document.getElementById('panorama-size').value = '512x256';")
    wd.click("#panorama-load")
    check("the panorama loads",
          wait_for("panorama", lambda: wd.text("#panorama-status") == "512 × 256", timeout=30),
          wd.text("#panorama-status") + " " + (wd.text('[data-error-for="panorama"]') or ""))
    time.sleep(0.3)
    first = wd.js(CANVAS_JS, "panorama", True)
    check("the panorama is drawn (pixels vary)", first["stddev"] > 2.0, json.dumps(first))
    check_screenshot(wd, "section.panorama", out, "web-panels-panorama.png")
    look = wd.text("#panorama-look")
    drag(wd, "#panorama", -160, 60)
    time.sleep(0.3)
    after = wd.js(CANVAS_JS, "panorama", False)
    check("a drag turns the panorama (the look changes)", wd.text("#panorama-look") != look,
          f"{look} -> {wd.text('#panorama-look')}")
    check("a drag changes the drawn pixels", after["differ"] is not None and after["differ"] > 0.2,
          json.dumps(after))
    check_screenshot(wd, "section.panorama", out, "web-panels-panorama-dragged.png")


def run_checks(wd, daemon, out, downloads):
    url = f"http://127.0.0.1:{daemon.port}/?size=320x180&fps=10"
    check_roles(wd, url, out)
    check_clock(wd, daemon, out)
    check_probe(wd, daemon, out)
    check_snapshots(wd, downloads, out)
    check_weather_map(wd, daemon, out)
    check_observation(wd, daemon, out)
    wd.js("document.getElementById('panorama').scrollIntoView();")
    check_panorama(wd, out)
    wd.screenshot(os.path.join(out, "web-panels-page.png"))
    log = wd.browser_log() or []
    severe = [e for e in log if e.get("level") == "SEVERE"]
    check("browser console has no errors", not severe, json.dumps(severe)[:800])


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, web_root, out = (os.path.abspath(p) for p in sys.argv[1:4])
    if not (os.access(CHROMIUM, os.X_OK) and os.access(CHROMEDRIVER, os.X_OK)):
        print("test_web_panels.py: chromium and chromium-driver are needed "
              "(scripts/install-deps.sh installs them)", file=sys.stderr)
        return 1
    downloads = os.path.join(out, "downloads")
    os.makedirs(downloads, exist_ok=True)
    for folder in (out, downloads):
        for name in os.listdir(folder):
            if os.path.isfile(os.path.join(folder, name)):
                os.unlink(os.path.join(folder, name))
    config = make_config(out, os.path.join(out, "state.json"))
    config["web_root"] = os.path.abspath(web_root)
    config["allowed_origins"] = []
    config["listen"]["port"] = free_port()
    daemon = Daemon(skyd, out, "skyd", config)
    wd = None
    started = time.monotonic()
    try:
        daemon.start()
        info(f"skyd on port {daemon.port}")
        wd = WebDriver(os.path.join(out, "chromedriver.log"))
        wd.start(1280, 1000, prefs={"download.default_directory": downloads,
                                    "download.prompt_for_download": False})
        run_checks(wd, daemon, out, downloads)
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
