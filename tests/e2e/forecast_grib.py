"""GRIB2 files with known fields for the `skyd forecast` tests, made with ecCodes' own tools
from the GRIB2 sample it ships (regular_ll_sfc_grib2.tmpl): grib_filter sets the grid, the
run, the step, the parameter and every value, packed as 64-bit IEEE floats so that the values
read back exactly. No network."""
import math
import os
import subprocess

SAMPLES = "/usr/share/eccodes/samples"
GRIB2_SAMPLE = "regular_ll_sfc_grib2.tmpl"
GRIB1_SAMPLE = "regular_ll_sfc_grib1.tmpl"


def samples_dir():
    """The samples folder ecCodes names (codes_info -s), else Debian's."""
    try:
        out = subprocess.run(["codes_info", "-s"], capture_output=True, text=True, check=True,
                             env=tool_env()).stdout.strip()
        if out and os.path.exists(os.path.join(out, GRIB2_SAMPLE)):
            return out
    except (OSError, subprocess.CalledProcessError):
        pass
    return SAMPLES


def tool_env():
    """ecCodes' tools run without the sanitizer build's preloads."""
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    return env


class Grid:
    """A regular lat/lon grid: lat_first..lat_last (step dlat), lon_first + i * dlon."""

    def __init__(self, lat_first, lat_last, dlat, lon_first, ni, dlon):
        self.lat_first, self.lat_last, self.dlat = lat_first, lat_last, dlat
        self.lon_first, self.ni, self.dlon = lon_first, ni, dlon
        self.nj = int(round(abs(lat_last - lat_first) / dlat)) + 1

    def lats(self):
        sign = -1 if self.lat_last < self.lat_first else 1
        return [self.lat_first + sign * j * self.dlat for j in range(self.nj)]

    def lons(self):
        return [self.lon_first + i * self.dlon for i in range(self.ni)]

    def points(self):
        """(lat, lon) in scan order: rows from lat_first, i fastest."""
        return [(lat, lon) for lat in self.lats() for lon in self.lons()]

    def settings(self):
        return [("Ni", self.ni), ("Nj", self.nj), ("numberOfDataPoints", self.ni * self.nj),
                ("latitudeOfFirstGridPointInDegrees", self.lat_first),
                ("latitudeOfLastGridPointInDegrees", self.lat_last),
                ("longitudeOfFirstGridPointInDegrees", self.lon_first),
                ("longitudeOfLastGridPointInDegrees", self.lon_first + (self.ni - 1) * self.dlon),
                ("iDirectionIncrementInDegrees", self.dlon),
                ("jDirectionIncrementInDegrees", self.dlat)]


# What each field is in ecCodes' terms: settings after the grid and the run.
ECMWF = {
    "tcc": [("shortName", "tcc")], "lcc": [("shortName", "lcc")],
    "mcc": [("shortName", "mcc")], "hcc": [("shortName", "hcc")],
    "2t": [("shortName", "2t")], "2d": [("shortName", "2d")],
    "10u": [("shortName", "10u")], "10v": [("shortName", "10v")],
}
# GFS: cloud covers in % as tcc on the cloud layers, wind at 850 hPa.
GFS_COVER = [("centre", "kwbc"), ("discipline", 0), ("parameterCategory", 6),
             ("parameterNumber", 1)]
GFS = {
    "tcc": GFS_COVER + [("typeOfLevel", "entireAtmosphere")],
    "lcc": GFS_COVER + [("typeOfLevel", "lowCloudLayer")],
    "mcc": GFS_COVER + [("typeOfLevel", "middleCloudLayer")],
    "hcc": GFS_COVER + [("typeOfLevel", "highCloudLayer")],
    "2t": [("centre", "kwbc"), ("shortName", "2t")],
    "2d": [("centre", "kwbc"), ("shortName", "2d")],
    "u850": [("centre", "kwbc"), ("shortName", "u"), ("typeOfLevel", "isobaricInhPa"),
             ("level", 850)],
    "v850": [("centre", "kwbc"), ("shortName", "v"), ("typeOfLevel", "isobaricInhPa"),
             ("level", 850)],
    "prate": [("centre", "kwbc"), ("shortName", "prate")],
}


def rule(key, value):
    if isinstance(value, str):
        return 'set %s = "%s";' % (key, value)
    return "set %s = %r;" % (key, value)


def message(workdir, name, grid, run, step, field_settings, values, sample=GRIB2_SAMPLE,
            accumulated_from=None, ieee=True):
    """One message file: run = (dataDate, dataTime), step in hours (an accumulation from
    accumulated_from to step when given); values in scan order. grid None keeps the sample's
    (60 N to the equator, 0 to 30 E, every 2 degrees)."""
    rules = []
    if accumulated_from is not None:
        rules.append(rule("productDefinitionTemplateNumber", 8))
    if grid is not None:
        rules += [rule(k, v) for k, v in grid.settings()]
    rules += [rule("dataDate", run[0]), rule("dataTime", run[1])]
    rules += [rule(k, v) for k, v in field_settings]
    if accumulated_from is not None:
        rules.append(rule("stepRange", "%d-%d" % (accumulated_from, step)))
    else:
        rules.append(rule("step", step))
    if ieee:
        rules.append('set packingType = "grid_ieee"; set precision = 2;')
    rules.append("set values = {%s};" % ",".join(repr(float(v)) for v in values))
    rules.append("write;")
    path = os.path.join(workdir, name + ".grib")
    with open(path + ".rules", "w") as f:
        f.write("\n".join(rules) + "\n")
    subprocess.run(["grib_filter", "-o", path, path + ".rules",
                    os.path.join(samples_dir(), sample)], check=True, env=tool_env(),
                   capture_output=True)
    return path


def concatenate(path, parts):
    """A GRIB file is its messages one after the other."""
    with open(path, "wb") as out:
        for part in parts:
            with open(part, "rb") as f:
                out.write(f.read())
    return path


EARTH_RADIUS_KM = 6371.0


def inside_points(grid, lat0, lon0, extent_km):
    """The grid points within the square of side extent_km around (lat0, lon0) on the local
    east/north plane (equirectangular), as (index, lat, lon) in scan order."""
    half = math.degrees(0.5 * extent_km / EARTH_RADIUS_KM)
    half_lon = half / math.cos(math.radians(lat0))
    out = []
    for index, (lat, lon) in enumerate(grid.points()):
        dlon = (lon - lon0 + 540.0) % 360.0 - 180.0
        if abs(lat - lat0) <= half and abs(dlon) <= half_lon:
            out.append((index, lat, lon))
    return out


def magnus_rh(t, td):
    """Magnus over water, Alduchov & Eskridge (1996): a = 17.625, b = 243.04 C."""
    a, b = 17.625, 243.04
    return min(1.0, math.exp(a * td / (b + td) - a * t / (b + t)))


def wind_from(u, v):
    """The direction the wind blows from, degrees north through east."""
    return math.degrees(math.atan2(-u, -v)) % 360.0 if (u or v) else 0.0
