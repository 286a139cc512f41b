"""bench/soak.py's ledger: every change the daemon acknowledged (its revision and the values it
set, from the `state_changed` event of that revision, or from the `set` patch when the event
never came), checked against the daemon's state after each restart, after a full disk and at
the end: the state must hold, for each field, the last acknowledged value, unless a later
change overwrote it (one that may have been committed though its ack was lost in a kill -9:
its values are accepted too, and the state read then becomes the ledger's reference for
those fields). Fields the simulation moves (the clock, the ephemeris' angles, the weather
parameters that transitions and the autopilot drive, anything a `simulation` event named)
are not checked: their values move without a revision."""

import math


def flatten(pointer, value, out):
    """A JSON value at `pointer` as its leaves (arrays are leaves)."""
    if isinstance(value, dict):
        for k, v in value.items():
            flatten(f"{pointer}/{k}", v, out)
    else:
        out[pointer] = value
    return out


def at(tree, pointer):
    node = tree
    for part in pointer.strip("/").split("/"):
        if not isinstance(node, dict) or part not in node:
            raise KeyError(pointer)
        node = node[part]
    return node


def same(a, b):
    """Equal values; a number stands for an array of it (a `set` patch may give one number
    for a colour's three channels, the state holds the array)."""
    if isinstance(a, bool) or isinstance(b, bool):
        return type(a) is type(b) and a == b
    if isinstance(a, list) and isinstance(b, (int, float)):
        a, b = b, a
    if isinstance(a, (int, float)) and isinstance(b, list):
        return len(b) > 0 and all(same(a, x) for x in b)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


# In-flight requests whose fields the soak cannot name: what they may have touched.
UNNAMED_PREFIXES = {"preset:weather": ("/weather", "/clouds"),
                    "preset:atmosphere": ("/atmosphere",),
                    "weather_map": ("/weather",)}


class Ledger:
    def __init__(self, excluded_prefixes, derived=()):
        self.excluded = tuple(excluded_prefixes)  # pointer prefixes the simulation moves
        # readOnly pointers the daemon derives from other fields (weather.anchor from the
        # offsets and the clock): a change in flight at a kill may have moved them, with no
        # patch or event of their own to say so.
        self.derived = frozenset(derived)
        self.events = {}        # revision -> {leaf pointer: value} of state_changed events
        self.patches = {}       # revision -> {leaf pointer: value} of acked set patches
        self.acked = set()      # acknowledged revisions whose event has not been folded in
        self.kinds = {}         # revision -> kind, for those
        self.max_acked = 0
        self.expected = {}      # leaf pointer -> (revision, value): the reference
        self.sim_moved = set()  # pointers named by simulation events
        self.entries = 0        # acknowledged changes that changed something
        self.checked = 0        # fields compared, over all checks
        self.checks = 0

    def on_event(self, msg):
        if msg.get("event") == "state_changed" and isinstance(msg.get("revision"), int):
            values = {}
            for p, v in (msg.get("values") or {}).items():
                flatten(p, v, values)
            self.events[msg["revision"]] = values
        elif msg.get("event") == "simulation":
            self.sim_moved.update(msg.get("changed") or [])

    def on_ack(self, revision, kind, msg):
        """An ack of `msg` (a controller request of `kind`) at `revision`."""
        if not isinstance(revision, int) or revision <= self.max_acked:
            return  # a change that changed nothing keeps the revision (and sends no event)
        self.acked.add(revision)
        self.max_acked = revision
        self.entries += 1
        self.kinds[revision] = kind
        if msg.get("type") == "set":
            self.patches[revision] = flatten("", msg["patch"], {})

    def _ignored(self, pointer):
        return pointer.startswith(self.excluded) or any(
            pointer == s or pointer.startswith(s + "/") or s.startswith(pointer + "/")
            for s in self.sim_moved)

    def _fold(self):
        """Acknowledged revisions into self.expected, in order: the event's values, or the
        patch's until the event comes (an event that never comes: a kill -9)."""
        for r in sorted(self.acked):
            values = self.events.pop(r, None)
            source = values if values is not None else self.patches.get(r, {})
            for p, v in source.items():
                if p not in self.expected or self.expected[p][0] <= r:
                    self.expected[p] = (r, v)
            if values is not None:
                self.acked.discard(r)
                self.patches.pop(r, None)
                self.kinds.pop(r, None)

    def check(self, label, state, revision, in_flight=()):
        """Failures (strings) of the state read at `revision` against the ledger.
        in_flight: (kind, msg) requests sent and never answered (a kill -9)."""
        self._fold()
        self.checks += 1
        failures = []
        if not isinstance(revision, int) or revision < self.max_acked:
            failures.append(f"{label}: revision {revision} below the last acknowledged "
                            f"{self.max_acked}: acknowledged changes lost")
        # Changes committed but never acknowledged: seen as events above the last ack, or
        # requests in flight.
        alternatives = {}
        for r, values in self.events.items():
            if r > self.max_acked:
                for p, v in values.items():
                    alternatives.setdefault(p, []).append(v)
        # Acknowledged changes whose event never came: a preset's or a map's fields unknown.
        unnamed = tuple(x for r in self.acked if r not in self.patches
                        for x in next((v for k, v in UNNAMED_PREFIXES.items()
                                       if self.kinds.get(r, "").startswith(k)), ("/",)))
        for kind, msg in in_flight:
            if msg.get("type") == "set":
                for p, v in flatten("", msg["patch"], {}).items():
                    alternatives.setdefault(p, []).append(v)
            else:
                unnamed += next((v for k, v in UNNAMED_PREFIXES.items() if kind.startswith(k)),
                                ("/",))
        rebased = 0
        for p, (r, v) in sorted(self.expected.items()):
            if self._ignored(p):
                continue
            try:
                actual = at(state, p)
            except KeyError:
                failures.append(f"{label}: {p} (revision {r}) is missing from the state")
                continue
            if same(actual, v):
                self.checked += 1
                continue
            if any(same(actual, a) for a in alternatives.get(p, [])) or \
                    p.startswith(unnamed) or (in_flight and p in self.derived):
                self.expected[p] = (revision, actual)  # a change whose ack was lost
                rebased += 1
                continue
            failures.append(f"{label}: {p} is {actual!r}, acknowledged {v!r} at revision {r}")
        self.events = {r: v for r, v in self.events.items() if r > (revision or 0)}
        if in_flight or unnamed:  # after a restart: what is lost is lost; the state rules
            for r in list(self.acked):
                self.acked.discard(r)
                self.patches.pop(r, None)
                self.kinds.pop(r, None)
        if isinstance(revision, int) and revision > self.max_acked:
            self.max_acked = revision  # committed before the kill, unacknowledged
        return failures, rebased
