"""`skyd forecast`: GRIB2 files made here with ecCodes' tools (forecast_grib.py), an ECMWF-style
file (cloud cover 0-1, 10 m wind, tp accumulated) and a GFS-style one (cloud cover in % as tcc
on the cloud layers, 850 hPa wind, prate), decoded at places and times whose answers are
computed here from the same fields: the means over the points in the square, the coverage
grid, relative humidity, wind, precipitation rates, linear interpolation between steps, the
0..360 and -180..180 longitudes. Then the refusals: GRIB1, text, a field missing, a place
outside a limited-area grid, grids that differ, a field given twice, values in the wrong units,
a cut file, a time outside the steps; and PROTOCOL.md's example.
Usage: test_forecast_cli.py SKYD OUTDIR [PROTOCOL_MD]"""
import calendar
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import forecast_grib as fg  # noqa: E402

SKYD, OUT = sys.argv[1], sys.argv[2]
PROTOCOL_MD = sys.argv[3] if len(sys.argv) > 3 else os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "..", "protocol", "PROTOCOL.md")
os.makedirs(OUT, exist_ok=True)
failures = []
passed = 0


def check(ok, what):
    global passed
    if ok:
        passed += 1
    else:
        failures.append(what)
        print("FAIL:", what)


def near(a, b, tol=1e-12):
    return a is not None and b is not None and abs(a - b) <= tol * max(1.0, abs(b))


def run(args):
    env = dict(os.environ)
    env["LD_PRELOAD"] = os.environ.get("SKYD_DAEMON_LD_PRELOAD", "")
    p = subprocess.run([SKYD, "forecast"] + args, capture_output=True, text=True, env=env)
    return p.returncode, p.stdout, p.stderr


def decode(name, args):
    rc, out, err = run(args)
    check(rc == 0, "%s: exit %d: %s" % (name, rc, err.strip()))
    if rc != 0:
        return None
    check(len(err.strip().splitlines()) == 1, "%s: stderr is not one line: %r" % (name, err))
    return json.loads(out)


def refused(name, needle, args, status=2):
    rc, out, err = run(args)
    check(rc == status, "%s: exit %d, expected %d (%s)" % (name, rc, status, err.strip()))
    check(needle in err, "%s: stderr lacks %r: %s" % (name, needle, err.strip()))
    check(out == "", "%s: printed on stdout: %s" % (name, out[:200]))


def iso(unix_s):
    return "%04d-%02d-%02dT%02d:%02d:%02dZ" % tuple(__import__("time").gmtime(unix_s)[:6])


RUN = (20260621, 0)
RUN_UNIX = calendar.timegm((2026, 6, 21, 0, 0, 0))


# ---- the fields, functions of place and step index k ----------------------------------------
def lcc(lat, lon, k): return 0.5 + 0.002 * lat + 0.001 * lon + 0.05 * k
def mcc(lat, lon, k): return 0.3 + 0.001 * lat - 0.001 * lon + 0.1 * k
def hcc(lat, lon, k): return 0.6 - 0.002 * lat + 0.0005 * lon - 0.1 * k
def tcc(lat, lon, k): return 0.7 + 0.05 * k
def t2(lat, lon, k): return 290.0 - 0.3 * lat + 0.01 * lon + 1.5 * k    # K
def d2(lat, lon, k): return t2(lat, lon, k) - 5.0 - 0.5 * k             # K
def u10(lat, lon, k): return 3.0 + 0.02 * lon + k
def v10(lat, lon, k): return -2.0 + 0.05 * lat - 0.5 * k
def tp(lat, lon, k):                                                     # m, from the run
    return [0.0, 0.002 + 1e-5 * (lat + 90.0), 0.005 + 1e-5 * (lat + 90.0) + 2e-6 * lon][k]
def prate(lat, lon, k): return 1e-4 * (1.0 + 0.01 * lat) + 2e-5 * k      # kg m-2 s-1


FIELDS = {"tcc": tcc, "lcc": lcc, "mcc": mcc, "hcc": hcc, "2t": t2, "2d": d2, "10u": u10,
          "10v": v10, "u850": u10, "v850": v10, "prate": prate}
ECMWF_STEPS = [0, 6, 12]
GFS_STEPS = [0, 3]
WORK = os.path.join(OUT, "grib")
os.makedirs(WORK, exist_ok=True)
# ECMWF open data's grid runs from 180 W, GFS's from 0 E; both 5 degrees here.
ECMWF_GRID = fg.Grid(90, -90, 5, -180, 72, 5)
GFS_GRID = fg.Grid(90, -90, 5, 0, 72, 5)


def west_east(lon):
    """The fields are functions of longitude in -180..180 (a seam at 180)."""
    return (lon + 180.0) % 360.0 - 180.0


def field_message(style, grid, name, k, hours, scale=1.0, fn=None, tag=""):
    fn = fn or FIELDS[name]
    values = [scale * fn(lat, west_east(lon), k) for lat, lon in grid.points()]
    settings = (fg.ECMWF if style == "ecmwf" else fg.GFS)[name]
    return fg.message(WORK, "%s-%s-%d%s" % (style, name, hours, tag), grid, RUN, hours,
                      settings, values)


def tp_message(grid, k, hours, tag=""):
    values = [tp(lat, lon, k) for lat, lon in grid.points()]
    return fg.message(WORK, "ecmwf-tp-%d%s" % (hours, tag), grid, RUN, hours,
                      [("shortName", "tp")], values, accumulated_from=0)


def ecmwf_parts(skip=(), grid=ECMWF_GRID):
    parts = []
    for k, hours in enumerate(ECMWF_STEPS):
        for name in ["tcc", "lcc", "mcc", "hcc", "2t", "2d", "10u", "10v"]:
            if (name, hours) not in skip and (name, None) not in skip:
                parts.append(field_message("ecmwf", grid, name, k, hours))
        parts.append(tp_message(grid, k, hours))
    return parts


ecmwf = fg.concatenate(os.path.join(OUT, "ecmwf.grib2"), ecmwf_parts())


def prate_mean(k, hours):
    """GFS's second prate: the mean over the hours before the step (here 10 times the rate)."""
    values = [10.0 * prate(lat, west_east(lon), k) for lat, lon in GFS_GRID.points()]
    return fg.message(WORK, "gfs-prate-avg-%d" % hours, GFS_GRID, RUN, hours,
                      fg.GFS["prate"] + [("typeOfStatisticalProcessing", 0)], values,
                      accumulated_from=0)


# As GFS's files have them: tcc also on the boundary-layer cloud layer (not read), prate twice
# at +3 h, the mean before the rate at the step (which is kept).
gfs_parts, gfs_mean_parts = [], []
for k, hours in enumerate(GFS_STEPS):
    step = [field_message("gfs", GFS_GRID, name, k, hours, scale=100.0)
            for name in ["tcc", "lcc", "mcc", "hcc"]]
    step.append(fg.message(WORK, "gfs-tcc-boundary-%d" % hours, GFS_GRID, RUN, hours,
                           fg.GFS_COVER + [("typeOfLevel", "boundaryLayerCloudLayer")],
                           [100.0] * (GFS_GRID.ni * GFS_GRID.nj)))
    step += [field_message("gfs", GFS_GRID, name, k, hours)
             for name in ["2t", "2d", "u850", "v850"]]
    rate = field_message("gfs", GFS_GRID, "prate", k, hours)
    if k == 0:
        gfs_parts += step + [rate]
        gfs_mean_parts += step + [rate]
    else:
        gfs_parts += step + [prate_mean(k, hours), rate]
        gfs_mean_parts += step + [prate_mean(k, hours)]
gfs = fg.concatenate(os.path.join(OUT, "gfs.grib2"), gfs_parts)
# Only the mean at +3 h: that one is read.
gfs_mean = fg.concatenate(os.path.join(OUT, "gfs-mean.grib2"), gfs_mean_parts)


# ---- expectations ----------------------------------------------------------------------------
def mean(fn, points, k):
    values = [fn(lat, west_east(lon), k) for _, lat, lon in points]
    return sum(values) / len(values)


def lerp(a, b, w):
    return (1.0 - w) * a + w * b


def expect(j, name, grid, lat0, lon0, extent, k0, k1, w, precipitation, wind="10m",
           covers_scale=1.0):
    points = fg.inside_points(grid, lat0, lon0, extent)
    p = j["points"]
    check(p["method"] == "mean" and p["count"] == len(points),
          "%s: points %s, expected %d inside" % (name, p, len(points)))
    lats = sorted({lat for _, lat, _ in points})
    check(p["latitudes_deg"] == [lats[0], lats[-1]], "%s: latitudes %s" % (name, p))
    if not points:
        return
    at = lambda fn: lerp(mean(fn, points, k0), mean(fn, points, k1), w)  # noqa: E731
    c = j["clouds"]
    for key, fn in [("low", lcc), ("medium", mcc), ("high", hcc), ("total", tcc)]:
        check(near(c[key], at(fn)), "%s: %s cover %s, expected %r" % (name, key, c[key], at(fn)))
    t, td = at(t2) - 273.15, at(d2) - 273.15
    check(near(j["temperature_c"], t), "%s: temperature %s vs %r" % (name, j["temperature_c"], t))
    check(near(j["dew_point_c"], td), "%s: dew point %s vs %r" % (name, j["dew_point_c"], td))
    rh = fg.magnus_rh(t, td)
    check(near(j["relative_humidity"], rh, 1e-9),
          "%s: RH %s vs %r" % (name, j["relative_humidity"], rh))
    u, v = at(u10), at(v10)
    wj = j["wind"]
    check(wj["level"] == wind, "%s: wind level %s" % (name, wj["level"]))
    check(near(wj["u_m_s"], u) and near(wj["v_m_s"], v), "%s: wind %s vs %r %r" % (name, wj, u, v))
    check(near(wj["speed_m_s"], math.hypot(u, v)) and
          near(wj["direction_deg"], fg.wind_from(u, v), 1e-9), "%s: wind %s" % (name, wj))
    check(near(j["precipitation"]["rate_mm_h"], precipitation(points), 1e-9),
          "%s: precipitation %s vs %r" % (name, j["precipitation"], precipitation(points)))


def time_arg(unix_s):
    return ["--time", iso(unix_s)]


# 1. ECMWF-style, halfway between the run and +6 h, 1200 km around 45 N 6 E: nine points.
place = ["--lat", "45", "--lon", "6", "--extent-km", "1200"]
j = decode("ecmwf 03Z", [ecmwf] + place + time_arg(RUN_UNIX + 3 * 3600))
if j:
    s = j["steps"]
    check(s["before"]["index"] == 0 and s["after"]["index"] == 1 and s["weight"] == 0.5,
          "ecmwf 03Z: steps %s" % s)
    check(s["before"]["valid"] == "2026-06-21T00:00:00Z" and s["after"]["step_h"] == 6 and
          s["count"] == 3 and s["last"] == "2026-06-21T12:00:00Z", "ecmwf 03Z: steps %s" % s)
    check(j["reference_time"] == "2026-06-21T00:00:00Z" and j["time"] == "2026-06-21T03:00:00Z",
          "ecmwf 03Z: times %s %s" % (j["reference_time"], j["time"]))
    check(j["precipitation"]["source"] == "tp" and j["clouds"]["units_read"] == "(0 - 1)",
          "ecmwf 03Z: sources %s %s" % (j["precipitation"], j["clouds"]))
    # tp from 0 to 6 h: its mean rate over (0, 6 h], m to mm.
    expect(j, "ecmwf 03Z", ECMWF_GRID, 45, 6, 1200, 0, 1, 0.5,
           lambda pts: mean(tp, pts, 1) * 1000.0 / 6.0)
    p = j["points"]
    check(p["rows"] == [8, 10] and p["columns"] == [36, 38] and
          p["longitudes_deg"] == [0, 10], "ecmwf 03Z: points %s" % p)
    check(j["grid"]["global"] and j["grid"]["ni"] == 72 and j["grid"]["step_deg"] == [-5, 5],
          "ecmwf 03Z: grid %s" % j["grid"])
    # The coverage grid: 16 x 16 cells of 75 km, each the bilinear value at its centre, which
    # for fields linear in latitude and longitude is the field there.
    g = j["coverage_grid"]
    check(g["size"] == 16 and g["cell_km"] == 75 and len(g["low"]) == 16 and
          all(len(row) == 16 for row in g["low"]), "ecmwf 03Z: coverage grid shape")
    worst = 0.0
    for y in range(16):
        for x in range(16):
            north = 600.0 - (y + 0.5) * 75.0
            east = -600.0 + (x + 0.5) * 75.0
            lat = 45 + math.degrees(north / fg.EARTH_RADIUS_KM)
            lon = 6 + math.degrees(east / (fg.EARTH_RADIUS_KM * math.cos(math.radians(45))))
            for key, fn in [("low", lcc), ("medium", mcc), ("high", hcc)]:
                want = lerp(fn(lat, lon, 0), fn(lat, lon, 1), 0.5)
                worst = max(worst, abs(g[key][y][x] - want))
            want = mean(tp, [(0, lat, lon)], 1) * 1000.0 / 6.0
            worst = max(worst, abs(g["precipitation_mm_h"][y][x] - want))
    check(worst < 1e-9, "ecmwf 03Z: coverage grid off by %g" % worst)
    check(g["low"][0][0] > g["low"][15][0] and g["low"][0][15] > g["low"][0][0],
          "ecmwf 03Z: the grid's first row is north, its first column west")

# 2. At a step (given as seconds since 1970): exactly that step's fields; tp's rate over (0, 6].
j = decode("ecmwf +6 h", [ecmwf] + place + ["--time", str(RUN_UNIX + 6 * 3600)])
if j:
    check(j["steps"]["before"]["index"] == 1 and j["steps"]["after"]["index"] == 1 and
          j["steps"]["weight"] == 0, "ecmwf +6 h: steps %s" % j["steps"])
    expect(j, "ecmwf +6 h", ECMWF_GRID, 45, 6, 1200, 1, 1, 0.0,
           lambda pts: mean(tp, pts, 1) * 1000.0 / 6.0)

# 3. Between +6 h and +12 h, a quarter of the way: tp's rate over (6, 12].
j = decode("ecmwf 07:30Z", [ecmwf] + place + time_arg(RUN_UNIX + 7.5 * 3600))
if j:
    check(j["steps"]["weight"] == 0.25, "ecmwf 07:30Z: weight %s" % j["steps"])
    expect(j, "ecmwf 07:30Z", ECMWF_GRID, 45, 6, 1200, 1, 2, 0.25,
           lambda pts: (mean(tp, pts, 2) - mean(tp, pts, 1)) * 1000.0 / 6.0)

# 4. Across the grid's seam (175 E and 180 W), and the same place as 0..360 and -180..180.
seam = ["--lat", "0", "--extent-km", "1200"] + time_arg(RUN_UNIX + 6 * 3600)
j = decode("seam", [ecmwf, "--lon", "178"] + seam)
if j:
    check(j["points"]["columns"] == [71, 0] and j["points"]["longitudes_deg"] == [175, 180],
          "seam: points %s" % j["points"])
    expect(j, "seam", ECMWF_GRID, 0, 178, 1200, 1, 1, 0.0,
           lambda pts: mean(tp, pts, 1) * 1000.0 / 6.0)
west = decode("-2 E", [ecmwf, "--lon", "-2"] + seam)
east = decode("358 E", [ecmwf, "--lon", "358"] + seam)
if west and east:
    check(west["clouds"] == east["clouds"] and west["points"] == east["points"] and
          west["wind"] == east["wind"], "-2 E and 358 E differ")
    expect(west, "-2 E", ECMWF_GRID, 0, -2, 1200, 1, 1, 0.0,
           lambda pts: mean(tp, pts, 1) * 1000.0 / 6.0)

# 5. A square smaller than the grid's cells: the four points around, bilinear.
j = decode("bilinear", [ecmwf, "--lat", "46", "--lon", "7", "--extent-km", "10"] +
           time_arg(RUN_UNIX + 12 * 3600))
if j:
    check(j["points"]["method"] == "bilinear" and j["points"]["count"] == 4 and
          j["points"]["latitudes_deg"] == [45, 50] and j["points"]["longitudes_deg"] == [5, 10],
          "bilinear: points %s" % j["points"])
    check(near(j["clouds"]["low"], lcc(46, 7, 2), 1e-12) and
          near(j["temperature_c"], t2(46, 7, 2) - 273.15, 1e-12),
          "bilinear: %s %s" % (j["clouds"], j["temperature_c"]))

# 6. GFS-style: cover in %, tcc on the cloud layers, 850 hPa wind, prate; 0..360 longitudes.
gfs_place = ["--lat", "45", "--lon", "6", "--extent-km", "1200"]
j = decode("gfs 01Z", [gfs] + gfs_place + time_arg(RUN_UNIX + 3600))
if j:
    check(j["clouds"]["units_read"] == "%" and j["precipitation"]["source"] == "prate",
          "gfs: %s %s" % (j["clouds"], j["precipitation"]))
    check(j["points"]["columns"] == [0, 2] and j["points"]["longitudes_deg"] == [0, 10],
          "gfs: points %s" % j["points"])
    w = 1.0 / 3.0
    expect(j, "gfs 01Z", GFS_GRID, 45, 6, 1200, 0, 1, w,
           lambda pts: lerp(mean(prate, pts, 0), mean(prate, pts, 1), w) * 3600.0,
           wind="850hPa")
j = decode("gfs, prate as a mean", [gfs_mean] + gfs_place + time_arg(RUN_UNIX + 3 * 3600))
if j:
    want = mean(prate, fg.inside_points(GFS_GRID, 45, 6, 1200), 1) * 10.0 * 3600.0
    check(near(j["precipitation"]["rate_mm_h"], want, 1e-9),
          "gfs, prate as a mean: %s vs %r" % (j["precipitation"], want))
j = decode("gfs -174 E", [gfs, "--lat", "-30", "--lon", "-174", "--extent-km", "900"] +
           time_arg(RUN_UNIX))
if j:
    check(j["points"]["columns"] == [37, 38] and j["points"]["longitudes_deg"] == [-175, -170],
          "gfs -174 E: points %s" % j["points"])
    expect(j, "gfs -174 E", GFS_GRID, -30, -174, 900, 0, 0, 0.0,
           lambda pts: mean(prate, pts, 0) * 3600.0, wind="850hPa")

# 7. PROTOCOL.md's example: its command on the ECMWF-style file prints exactly its JSON.
def fenced(text, tag):
    start = text.index("```" + tag + "\n") + len(tag) + 4
    return text[start:text.index("```", start)]


with open(PROTOCOL_MD) as f:
    protocol = f.read()
command = fenced(protocol, "text forecast-command").split()
documented = json.loads(fenced(protocol, "json forecast"))
check(command[:3] == ["skyd", "forecast", "ecmwf.grib2"], "PROTOCOL.md command %s" % command)
j = decode("PROTOCOL.md example", [ecmwf] + command[3:])
check(j == documented, "PROTOCOL.md example differs: %s" % json.dumps(j))

# ---- refusals ---------------------------------------------------------------------------------
at_6 = time_arg(RUN_UNIX + 6 * 3600)
refused("after the last step", "2026-06-21T13:00:00Z is outside the forecast: its 3 steps cover "
        "2026-06-21T00:00:00Z to 2026-06-21T12:00:00Z",
        [ecmwf] + place + time_arg(RUN_UNIX + 13 * 3600))
refused("before the first step", "is outside the forecast",
        [ecmwf] + place + time_arg(RUN_UNIX - 1))

grib1 = fg.message(WORK, "grib1", None, RUN, 0, [("shortName", "2t")],
                   [280.0] * (16 * 31), sample=fg.GRIB1_SAMPLE, ieee=False)
refused("GRIB1", "message 1 is GRIB edition 1; only GRIB2 is read", [grib1] + place + at_6)
# A GRIB2 file with a GRIB1 message after its first messages is refused as well.
mixed = fg.concatenate(os.path.join(OUT, "mixed.grib2"), ecmwf_parts()[:3] + [grib1])
refused("GRIB1 inside", "message 4 is GRIB edition 1", [mixed] + place + at_6)

text = os.path.join(OUT, "text.grib2")
with open(text, "w") as f:
    f.write("This is a text file, not a forecast.\n" * 20)
refused("text", "holds no GRIB message: not a GRIB file", [text] + place + at_6)

cut = os.path.join(OUT, "cut.grib2")
with open(ecmwf, "rb") as f:
    data = f.read()
with open(cut, "wb") as f:
    f.write(data[: len(data) // 2 + 7])
refused("cut short", "is damaged or cut short", [cut] + place + at_6)

no_hcc = fg.concatenate(os.path.join(OUT, "no-hcc.grib2"), ecmwf_parts(skip={("hcc", None)}))
refused("no hcc", "no hcc (high cloud cover) in the file", [no_hcc] + place + at_6)
hole = fg.concatenate(os.path.join(OUT, "hcc-hole.grib2"), ecmwf_parts(skip={("hcc", 6)}))
refused("hcc missing at +6 h", "hcc (high cloud cover) is missing at the step valid "
        "2026-06-21T06:00:00Z (+6 h)", [hole] + place + at_6)
no_wind = fg.concatenate(os.path.join(OUT, "no-wind.grib2"), ecmwf_parts(skip={("10v", None)}))
refused("no wind", "no 10v (10 m wind towards north) in the file, nor u and v at 850 hPa",
        [no_wind] + place + at_6)

# A limited-area grid (the sample's own: 60 N to the equator, 0 to 30 E), one step.
lam = fg.Grid(60, 0, 2, 0, 16, 2)
lam_parts = [fg.message(WORK, "lam-" + name, lam, RUN, 0, fg.ECMWF[name],
                        [FIELDS[name](lat, lon, 0) for lat, lon in lam.points()])
             for name in ["lcc", "mcc", "hcc", "2t", "2d", "10u", "10v"]]
lam_parts.append(fg.message(WORK, "lam-prate", lam, RUN, 0, fg.GFS["prate"],
                            [prate(lat, lon, 0) for lat, lon in lam.points()]))
lam_file = fg.concatenate(os.path.join(OUT, "lam.grib2"), lam_parts)
j = decode("limited area", [lam_file, "--lat", "30", "--lon", "15", "--extent-km", "300"] +
           time_arg(RUN_UNIX))
if j:
    check(j["grid"]["global"] is False and j["clouds"]["total"] is None,
          "limited area: %s %s" % (j["grid"], j["clouds"]))
    expect_points = fg.inside_points(lam, 30, 15, 300)
    check(near(j["clouds"]["low"], mean(lcc, expect_points, 0)), "limited area: low cover")
refused("outside the limited area", "45.0000, 40.0000 is outside the grid (latitudes 0..60, "
        "longitudes 0..30 east)",
        [lam_file, "--lat", "45", "--lon", "40"] + time_arg(RUN_UNIX))
refused("square beyond the limited area", "the 600 km square around 45.0000, 1.0000 reaches "
        "beyond the grid", [lam_file, "--lat", "45", "--lon", "1", "--extent-km", "600"] +
        time_arg(RUN_UNIX))
refused("one step only", "is not the forecast's one step, valid 2026-06-21T00:00:00Z",
        [lam_file, "--lat", "30", "--lon", "15"] + time_arg(RUN_UNIX + 60))

# Grids that differ: the limited area's hcc among the global fields.
odd = fg.concatenate(os.path.join(OUT, "odd-grid.grib2"),
                     ecmwf_parts()[:3] + [fg.message(WORK, "lam-hcc-6", lam, RUN, 6,
                                                     fg.ECMWF["hcc"], [0.5] * (16 * 31))])
refused("grids differ", "message 4 (hcc) is on a grid of regular_ll 16 x 31 points",
        [odd] + place + at_6)
twice = fg.concatenate(os.path.join(OUT, "twice.grib2"), ecmwf_parts() + ecmwf_parts()[:2])
refused("twice", "message %d gives tcc valid at 2026-06-21T00:00:00Z (+0 h) again, after "
        "message 1" % (len(ecmwf_parts()) + 1), [twice] + place + at_6)
percent_as_fraction = fg.message(WORK, "ecmwf-lcc-percent", ECMWF_GRID, RUN, 0, fg.ECMWF["lcc"],
                                 [100.0 * lcc(lat, lon, 0) for lat, lon in ECMWF_GRID.points()])
wrong = fg.concatenate(os.path.join(OUT, "wrong-units.grib2"), [percent_as_fraction])
refused("cover in % labelled 0-1", "(0 - 1) at", [wrong] + place + at_6)
refused("missing file", "No such file or directory",
        [os.path.join(OUT, "absent.grib2")] + place + at_6)
refused("no --time", "--time is needed", [ecmwf] + place)
refused("bad --time", "--time \"noon\" is neither ISO 8601 nor seconds since 1970",
        [ecmwf] + place + ["--time", "noon"])

print("%d passed, %d failed" % (passed, len(failures)))
sys.exit(1 if failures else 0)
