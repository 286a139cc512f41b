"""bench/soak.py's view of the world state: the fields of the JSON Schema that `skyd schema`
prints (paths, types, ranges, enums, array lengths, read-only rows), and helpers for flat and
nested state trees. Nothing here knows a field by name: a field added to the schema reaches
the soak's draws with no change to the soak."""

import json
import subprocess


class Field:
    """One leaf of the schema: `path` (dotted), `schema` (its node) and what the draws use."""

    def __init__(self, path, schema):
        self.path, self.schema = path, schema
        self.read_only = bool(schema.get("readOnly"))
        self.default = schema.get("default")
        self.enum = schema.get("enum")


def load_schema(skyd):
    """The world state's JSON Schema, as the daemon under test prints it."""
    out = subprocess.run([skyd, "schema", "state"], check=True, capture_output=True,
                         text=True, timeout=60).stdout
    return json.loads(out)


def schema_fields(schema, prefix=""):
    """The schema's leaves in its order: every node without "properties" is a field (arrays
    and oneOf of a number or an array are leaves, as in get_state's state)."""
    out = []
    for name, node in schema.get("properties", {}).items():
        path = f"{prefix}{name}"
        if "properties" in node:
            out += schema_fields(node, path + ".")
        else:
            out.append(Field(path, node))
    return out


def leaves(tree, prefix=""):
    """Dotted paths of a state tree's leaves (arrays are leaves)."""
    out = {}
    for k, v in tree.items():
        p = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(leaves(v, p + "."))
        else:
            out[p] = v
    return out


def put(tree, path, value):
    parts = path.split(".")
    for p in parts[:-1]:
        tree = tree.setdefault(p, {})
    tree[parts[-1]] = value


def nested(flat):
    tree = {}
    for path, value in flat.items():
        put(tree, path, value)
    return tree


def without_read_only(flat, fields):
    """`flat` less the paths the schema marks readOnly (the daemon refuses them in a set)."""
    ro = {f.path for f in fields if f.read_only}
    return {p: v for p, v in flat.items() if p not in ro}


def check_state(fields, state):
    """The schema must name every leaf get_state returns, and get_state return every writable
    field of the schema; a mismatch means the daemon and its schema disagree."""
    table = {f.path for f in fields}
    got = set(leaves(state))
    missing = sorted(got - table)
    extra = sorted({f.path for f in fields if not f.read_only} - got)
    if missing or extra:
        raise SystemExit(f"soak: `skyd schema` and get_state disagree: not in the schema "
                         f"{missing}, not in the state {extra}")
