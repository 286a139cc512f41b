"""`skyd render --metar` and `--forecast`: the observed or forecast sky in the image. Each frame
looks straight at the sun (49 x 37 pixels, odd, so the centre pixel's ray meets the disc) in
16-bit linear light; the sun's disc shows as a centre pixel far brighter than the ring 4 pixels
around it, and a clear sky is blue (b/r of the median pixel 2.5 to 3.2; under cloud or fog
below 1.3).
 - FEW040 at noon: fair weather, the disc visible and the sky blue;
 - OVC005 with FG in 200 m: the disc gone behind the stratus and the sky grey;
 - a refused report (a bad cloud group, NIL) exits 2 naming the group and writes no image;
 - a GRIB2 forecast (made with ecCodes' tools, forecast_grib.py) clear at +0 h and overcast at
   +6 h: clear at the run's time, overcast at +6 h, and a time-lapse across it sees the disc
   go as the weather comes.
Usage: test_observation_render.py SKYD OUTDIR"""
import os
import struct
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import forecast_grib as fg  # noqa: E402
from png_codec import decode_png_full  # noqa: E402

SKYD, OUT = sys.argv[1], sys.argv[2]
os.makedirs(OUT, exist_ok=True)
failures = []
passed = 0
VIEW = ["--width", "49", "--height", "37", "--format", "png16",
        "--set", "sun.elevation_deg=50", "--set", "sun.azimuth_deg=90",
        "--set", "camera.yaw_deg=90", "--set", "camera.pitch_deg=50",
        "--set", "camera.fov_deg=30", "--set", "camera.altitude_km=0.002"]
FULL_SCALE_KEY = "Luminance full scale cd/m2"


def check(ok, what):
    global passed
    if ok:
        passed += 1
    else:
        failures.append(what)
        print("FAIL:", what)


def render(name, args):
    env = dict(os.environ)
    env["LD_PRELOAD"] = os.environ.get("SKYD_DAEMON_LD_PRELOAD", "")
    path = os.path.join(OUT, name + ".png")
    if os.path.exists(path):
        os.remove(path)
    p = subprocess.run([SKYD, "render"] + VIEW + args + ["--out", path], capture_output=True,
                       text=True, env=env)
    return p.returncode, p.stderr, path


def measure(path):
    """(centre / ring luminance, b/r of the median pixel, the median luminance cd/m2)."""
    with open(path, "rb") as f:
        png = decode_png_full(f.read())
    scale = float(png["text"][FULL_SCALE_KEY])
    w, h, c = png["width"], png["height"], png["channels"]

    def rgb(x, y):
        return [v / 65535.0 * scale
                for v in struct.unpack(">HHH", png["rows"][y][x * c * 2:x * c * 2 + 6])]

    def lum(v):
        return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]

    cx, cy = w // 2, h // 2
    ring = [lum(rgb(cx + dx, cy + dy)) for dx in range(-4, 5) for dy in range(-4, 5)
            if max(abs(dx), abs(dy)) == 4]
    pixels = sorted((rgb(x, y) for y in range(h) for x in range(w)), key=lum)
    median = pixels[len(pixels) // 2]
    return (lum(rgb(cx, cy)) / (sum(ring) / len(ring)), median[2] / max(median[0], 1e-9),
            lum(median))


def looks(name, args, sun_visible, blue):
    rc, err, path = render(name, args)
    check(rc == 0, "%s: exit %d: %s" % (name, rc, err.strip()))
    if rc != 0:
        return None
    disc, blueness, median = measure(path)
    print("%s: centre/ring %.3g, median b/r %.3f, median %.4g cd/m2" % (name, disc, blueness,
                                                                        median))
    if sun_visible:
        check(disc > 10.0, "%s: the sun's disc is visible (centre/ring %.3g > 10)" % (name, disc))
    else:
        check(disc < 1.5, "%s: no sun disc (centre/ring %.3g < 1.5)" % (name, disc))
    if blue:
        check(blueness > 1.5, "%s: the sky is blue (b/r %.3f > 1.5)" % (name, blueness))
    else:
        check(blueness < 1.3, "%s: the sky is grey (b/r %.3f < 1.3)" % (name, blueness))
    return err


err = looks("fair", ["--metar", "METAR LFLY 211200Z 18008KT 9999 FEW040 22/10 Q1018"], True, True)
check(err is not None and "FEW 1219 m" in err, "fair: the report's summary on stderr")
looks("fog", ["--metar", "METAR EGLL 210650Z 00000KT 0200 FG OVC005 08/08 Q1025"], False, False)

# Refusals: exit 2, the group named, no image.
for name, text, needle in [
        ("bad group", "METAR EGLL 281150Z 24010KT 9999 BKN0X0 12/09 Q1005", '"BKN0X0"'),
        ("nil", "METAR EGLL 281150Z NIL", "NIL")]:
    rc, err, path = render("refused", ["--metar", text])
    check(rc == 2, "%s: exit %d, expected 2" % (name, rc))
    check(needle in err, "%s: stderr names %s: %s" % (name, needle, err.strip()))
    check(not os.path.exists(path), "%s: no image written" % name)

# A forecast: clear at +0 h, overcast (and wet) at +6 h, at every grid point.
WORK = os.path.join(OUT, "grib")
os.makedirs(WORK, exist_ok=True)
GRID = fg.Grid(90, -90, 5, -180, 72, 5)
RUN = (20260621, 0)
FIELDS = [{"tcc": 0.0, "lcc": 0.0, "mcc": 0.0, "hcc": 0.0, "2t": 293.0, "2d": 283.0,
           "10u": 3.0, "10v": 0.0},
          {"tcc": 1.0, "lcc": 1.0, "mcc": 0.8, "hcc": 0.0, "2t": 289.0, "2d": 288.0,
           "10u": 6.0, "10v": 2.0}]
parts = []
for k, hours in enumerate([0, 6]):
    for name, value in FIELDS[k].items():
        parts.append(fg.message(WORK, "%s-%d" % (name, hours), GRID, RUN, hours, fg.ECMWF[name],
                                [value] * (GRID.ni * GRID.nj)))
    parts.append(fg.message(WORK, "tp-%d" % hours, GRID, RUN, hours, [("shortName", "tp")],
                            [0.002 * k] * (GRID.ni * GRID.nj), accumulated_from=0))
grib = fg.concatenate(os.path.join(OUT, "front.grib2"), parts)
at_run = ["--set", "clock.utc=2026-06-21T00:00:00Z", "--forecast", grib]
err = looks("forecast +0 h", at_run, True, True)
check(err is not None and "--forecast: 2026-06-21T00:00:00Z" in err,
      "forecast: the sample's summary on stderr: %s" % (err or "").strip())
err = looks("forecast +6 h", ["--set", "clock.utc=2026-06-21T06:00:00Z", "--forecast", grib],
            False, False)
check(err is not None and "unmapped" not in err,
      "forecast +6 h: the medium cover goes to the middle layer, nothing unmapped: %s"
      % (err or "").strip())
rc, err, _ = render("outside", ["--set", "clock.utc=2026-06-22T00:00:00Z", "--forecast", grib])
check(rc == 2 and "--forecast" in err, "a time after the last step: exit %d: %s" % (rc, err))

# The time-lapse: 0, 3 and 6 h; the disc fades as the cloud comes (half cover at +3 h).
env = dict(os.environ)
env["LD_PRELOAD"] = os.environ.get("SKYD_DAEMON_LD_PRELOAD", "")
pattern = os.path.join(OUT, "lapse-%d.png")
p = subprocess.run([SKYD, "render"] + VIEW + at_run + ["--frames", "3", "--step-s", "10800",
                                                        "--out", pattern],
                   capture_output=True, text=True, env=env)
check(p.returncode == 0, "lapse: exit %d: %s" % (p.returncode, p.stderr.strip()))
if p.returncode == 0:
    discs = [measure(pattern % i)[0] for i in range(3)]
    print("lapse: centre/ring %s" % ", ".join("%.3g" % d for d in discs))
    check(discs[0] > 10.0 and discs[2] < 1.5, "lapse: clear first, overcast last: %s" % discs)

print("%d checks passed, %d failed" % (passed, len(failures)))
sys.exit(1 if failures else 0)
