"""JSON values for the end-to-end tests (re-exported by serve_harness.py): short text of a
value for failure details, a deep comparison with a tolerance on numbers, a state tree without
the fields the running simulation moves, and the first difference between two values."""

import json
import math


def short(obj, limit=400):
    if isinstance(obj, bytes):
        text = repr(obj[:64])
    elif isinstance(obj, str):
        text = obj
    else:
        text = json.dumps(obj, default=lambda o: f"<{len(o)} bytes>" if isinstance(o, bytes)
                          else repr(o))
    return text if len(text) <= limit else text[:limit] + "..."


def approx_equal(a, b, rel=1e-6, abs_tol=1e-9):
    """Deep comparison of JSON values with a tolerance on numbers."""
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.isclose(a, b, rel_tol=rel, abs_tol=abs_tol)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(approx_equal(a[k], b[k], rel, abs_tol) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(approx_equal(x, y, rel, abs_tol) for x, y in zip(a, b))
    return a == b


# Fields the world simulation moves between two reads while the clock runs, and the clock's
# epoch (the wall instant a daemon anchored a fresh state at, so two daemons started from the
# defaults differ there): comparisons of client-visible state leave them out.
SIMULATED_FIELDS = (("clock", "utc"), ("clock", "epoch"), ("weather", "offset_east_km"),
                    ("weather", "offset_north_km"))


def stable(state):
    """A copy of a state tree without the fields the running simulation moves."""
    if not isinstance(state, dict):
        return state
    out = json.loads(json.dumps(state))
    moved = list(SIMULATED_FIELDS)
    if out.get("clock", {}).get("sky_bodies") == "ephemeris":
        moved += [(body, angle) for body in ("sun", "moon")
                  for angle in ("azimuth_deg", "elevation_deg")]
    for group, name in moved:
        if isinstance(out.get(group), dict):
            out[group].pop(name, None)
    return out


def json_diff(a, b, path=""):
    """First difference between two JSON values, as text (for failure details)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}/{k}: present in only one ({short(a.get(k))} vs {short(b.get(k))})"
            d = json_diff(a[k], b[k], f"{path}/{k}")
            if d:
                return d
        return ""
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            d = json_diff(x, y, f"{path}/{i}")
            if d:
                return d
        return ""
    return "" if approx_equal(a, b) else f"{path}: {short(a)} != {short(b)}"
