"""bench/soak.py's constants and its draws of random valid values: patches of the world
state (from the fields of `skyd schema`, bench/soak_schema.py), views, probes and weather
maps."""

import base64
import datetime
import math
import os
import sys

_E2E = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "e2e")
if _E2E not in sys.path:  # bench/soak.py puts it there; this for an import on its own
    sys.path.insert(0, _E2E)
import serve_harness as H  # noqa: E402

# ------------------------------------------------------------------------------------------
# Constants

VALIDATION_PREFIX = "skyd: vulkan validation"
HOME_VIEWS = [  # one per subscriber: where it returns for the baseline and end measurements
    {"width": 96, "height": 54, "fps": 10},
    {"width": 320, "height": 180, "fps": 5, "camera": {"yaw_deg": 90, "pitch_deg": 5}},
    {"width": 480, "height": 270, "fps": 3, "exposure": {"mode": "manual", "ev100": 13}},
]
STREAM_SIZES = [(1, 1), (16, 9), (64, 36), (96, 54), (160, 90), (256, 144), (320, 180),
                (400, 225), (480, 270), (37, 211)]
SNAPSHOT_SIZES = [(1, 1), (64, 36), (160, 90), (320, 180), (640, 360), (333, 97)]
MAX_STREAM = (480, 270)
MAX_SNAPSHOT = (640, 360)
WEATHER_PRESETS = ["clear", "fair_cumulus", "scattered", "broken", "overcast", "storm",
                   "altocumulus", "warm_front"]
ATMOSPHERE_PRESETS = ["earth", "mars"]

# Rules of `set` (PROTOCOL.md) between fields, which a per-field schema cannot state: the
# angles the ephemeris drives (a patch naming them must switch it off in the same patch), the
# two radii (the top above the bottom by at most 1000 km). The weather parameters the autopilot
# and transitions drive come from the schema: weather_params().
EPHEMERIS_ANGLES = ["sun.azimuth_deg", "sun.elevation_deg", "moon.azimuth_deg",
                    "moon.elevation_deg"]
RADII = ["atmosphere.bottom_radius_km", "atmosphere.top_radius_km"]
MAX_ATMOSPHERE_THICKNESS_KM = 1000.0
CLOCK_FIELDS = ["clock.utc", "clock.time_scale"]  # changed only as clock excursions (below)
TRANSITION_END = "weather.transition.from."

# Soak-side choices, keyed by path. Bounds the soak keeps to (unless --uncapped) on fields whose
# whole range is valid but whose top end costs more than a soak on two CPU cores can carry: a
# 4096x4096 transmittance LUT is 28 s of lavapipe time per rebuild, a 512^3 froxel volume
# 2 GiB. Twice the default sizes and step counts still change every buffer's size. An array's
# cap is per element.
COST_CAPS = {
    "render.transmittance_lut": [512, 128],
    "render.multiscattering_lut": [64, 64],
    "render.skyview_lut": [384, 216],
    "render.aerial_perspective_lut": [64, 64, 64],
    "clouds.quality.primary_steps": 128,
    "clouds.quality.light_steps": 12,
}
# The schema gives a date-time no bounds (the daemon takes 1900..2100): drawn within 1901..2099,
# room for the clock to run on after a jump.
DATE_TIME_DRAW_RANGE = (-2177452800.0, 4070908800.0)
UNBOUNDED_DRAW_RANGE = (-1e6, 1e6)  # a number or integer the schema leaves unbounded


def weather_params(fields):
    """The weather parameters the autopilot and transitions drive: the fields a transition's
    ends stand for (weather.transition.from.<path>, read-only rows of the schema)."""
    paths = {f.path for f in fields}
    return [f.path[len(TRANSITION_END):] for f in fields if f.path.startswith(TRANSITION_END)
            and f.path[len(TRANSITION_END):] in paths]


# ------------------------------------------------------------------------------------------
# Random valid values


class Draw:
    def __init__(self, rng, fields, uncapped):
        self.rng = rng
        self.fields = {f.path: f for f in fields if not f.read_only}
        self.weather = [p for p in weather_params(fields) if p in self.fields]
        self.uncapped = uncapped
        self.map_uploaded = False

    def number(self, lo, hi):
        r = self.rng.random()
        if r < 0.08:
            return lo
        if r < 0.16:
            return hi
        if r < 0.4 and lo >= 0 and hi > 0 and hi / max(lo, 1e-3) > 1e3:
            low = math.log(max(lo, 1e-3))  # wide ranges: log-uniform as often as not
            return min(hi, max(lo, math.exp(self.rng.uniform(low, math.log(hi)))))
        return self.rng.uniform(lo, hi)

    def integer(self, lo, hi):
        r = self.rng.random()
        if r < 0.1:
            return int(lo)
        if r < 0.2:
            return int(hi)
        return self.rng.randint(int(lo), int(hi))

    def value(self, f):
        cap = None if self.uncapped else COST_CAPS.get(f.path)
        return self.node(f.schema, cap)

    def node(self, s, cap=None):
        """A random value valid under the schema node `s`; `cap` bounds an integer from above
        (a list: per array element)."""
        if "const" in s:
            return s["const"]
        if "enum" in s:
            return self.rng.choice(list(s["enum"]))
        if "oneOf" in s:
            return self.node(self.rng.choice(s["oneOf"]), cap)
        kind = s.get("type")
        if kind in ("number", "integer"):
            lo = s.get("minimum", s.get("exclusiveMinimum", UNBOUNDED_DRAW_RANGE[0]))
            hi = s.get("maximum", s.get("exclusiveMaximum", UNBOUNDED_DRAW_RANGE[1]))
            if kind == "integer":
                lo += "exclusiveMinimum" in s and "minimum" not in s
                hi -= "exclusiveMaximum" in s and "maximum" not in s
                return self.integer(lo, min(hi, cap) if cap is not None else hi)
            v = self.number(lo, hi)
            if ("exclusiveMinimum" in s and v <= lo) or ("exclusiveMaximum" in s and v >= hi):
                v = (lo + hi) / 2
            return v
        if kind == "array":
            lo = s.get("minItems", 0)
            n = self.rng.randint(lo, s.get("maxItems", lo + 3))
            caps = cap if isinstance(cap, list) else [cap] * n
            return [self.node(s.get("items", {}), caps[i] if i < len(caps) else None)
                    for i in range(n)]
        if kind == "boolean":
            return self.rng.random() < 0.5
        if kind == "string" and s.get("format") == "date-time":
            return iso_utc(self.rng.uniform(*DATE_TIME_DRAW_RANGE))
        raise ValueError(f"no draw for the schema node {s}")

    def radii(self):
        bottom, top = self.fields[RADII[0]].schema, self.fields[RADII[1]].schema
        b = self.number(bottom["minimum"], bottom["maximum"])
        t = b + self.rng.uniform(0.1, MAX_ATMOSPHERE_THICKNESS_KM)
        return {RADII[0]: b, RADII[1]: min(max(t, top["minimum"]), top["maximum"])}

    def make_valid(self, flat):
        """Completes a flat patch so that it is valid whatever the state it meets."""
        for p in CLOCK_FIELDS:
            flat.pop(p, None)
        if any(p in flat for p in RADII):
            flat.update(self.radii())
        if any(p in flat for p in EPHEMERIS_ANGLES):
            flat["clock.sky_bodies"] = "manual"
        if any(p in flat for p in self.weather):
            flat["weather.autopilot"] = "off"
        if flat.get("weather.map_source") == "client" and not self.map_uploaded:
            flat["weather.map_source"] = "procedural"
        # The soak's daemon has no forecast folder: following one (and its map) is refused.
        if flat.get("weather.source") == "forecast":
            flat["weather.source"] = "client"
        if flat.get("weather.map_source") == "forecast":
            flat["weather.map_source"] = "procedural"
        return flat

    def patch(self, paths):
        return self.make_valid({p: self.value(self.fields[p]) for p in paths})

    def random_patch(self):
        """One to six fields, or a whole group of them."""
        candidates = [p for p in self.fields if p not in CLOCK_FIELDS]
        if self.rng.random() < 0.2:
            group = self.rng.choice(sorted({p.rsplit(".", 1)[0] for p in candidates}))
            paths = [p for p in candidates if p.rsplit(".", 1)[0] == group]
        else:
            paths = self.rng.sample(candidates, min(len(candidates), self.rng.randint(1, 6)))
        return self.patch(paths)

    def camera(self):
        cam = {}
        for name, lo, hi in (("altitude_km", 0, 100000), ("yaw_deg", -360, 360),
                             ("pitch_deg", -90, 90), ("fov_deg", 1, 170)):
            if self.rng.random() < 0.5:
                cam[name] = self.number(lo, hi)
        return cam

    def exposure(self):
        exp = {}
        if self.rng.random() < 0.5:
            exp["mode"] = self.rng.choice(["auto", "manual"])
        if self.rng.random() < 0.5:
            exp["ev100"] = self.number(-10, 25)
        if self.rng.random() < 0.3:
            exp["compensation_ev"] = self.number(-10, 10)
        return exp

    def view(self, sizes, largest, size=None):
        if size is None:
            if self.rng.random() < 0.3:
                size = (self.rng.randint(1, largest[0]), self.rng.randint(1, largest[1]))
            else:
                size = self.rng.choice(sizes)
        v = {"width": size[0], "height": size[1]}
        if self.rng.random() < 0.7:
            v["fps"] = round(self.rng.uniform(0.5, 12), 2)
        if self.rng.random() < 0.5:
            v["camera"] = self.camera()
        if self.rng.random() < 0.4:
            v["exposure"] = self.exposure()
        if self.rng.random() < 0.2:
            v["format"] = "png"
        return v

    def probe(self):
        q = self.rng.choice(["transmittance", "luminance", "illuminance"])
        m = {"type": "probe", "quantity": q}
        if q in ("transmittance", "luminance"):
            m["altitude_km"] = self.number(0, 100000)
        if q == "transmittance":
            m["mu"] = self.number(-1, 1)
        if q == "luminance":
            m["view_zenith_deg"] = self.number(0, 180)
            m["view_azimuth_deg"] = self.number(-360, 360)
        if q in ("luminance", "illuminance"):
            m["sun_zenith_deg"] = self.number(0, 180)
        return m

    def weather_map(self, fmt=None, size=None):
        """A set_weather_map message: blocky random weather, rgba8 or PNG."""
        fmt = fmt or self.rng.choice(["rgba8", "png"])
        if size is None:
            side = self.rng.choice([1, 2, 7, 64, 128, 256, 333, 512])
            size = (side, self.rng.choice([side, max(1, side // 2), 512]))
        w, h = size
        block = max(1, min(w, h) // 8)
        gw, gh = -(-w // block), -(-h // block)
        grid = [[bytes(self.rng.randrange(256) for _ in range(4)) for _ in range(gw)]
                for _ in range(gh)]
        rows = []
        for y in range(h):
            cells = grid[y // block]
            rows.append(b"".join(cells[x // block] for x in range(w)))
        if fmt == "rgba8":
            data = b"".join(rows)
            m = {"type": "set_weather_map", "format": "rgba8", "width": w, "height": h}
        else:
            data = H.encode_png(w, h, rows)
            m = {"type": "set_weather_map", "format": "png"}
            if self.rng.random() < 0.5:
                m.update(width=w, height=h)
        m["data"] = base64.b64encode(data).decode()
        return m


def iso_utc(t):
    moment = datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc) + \
        datetime.timedelta(seconds=int(t))
    return moment.strftime("%Y-%m-%dT%H:%M:%SZ")
