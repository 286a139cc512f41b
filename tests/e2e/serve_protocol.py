"""test_serve.py's checks of the control protocol on the main daemon: hello and auth, describe,
set round trips and the events they make, every class of bad input (each followed by a
get_state showing the world state and revision unchanged on the same connection), and what a
viewer may not do."""

import json

from serve_harness import (CAPABILITIES, REPLY_TIMEOUT, TOKEN, Client, approx_equal, bad_input,
                           check, check_error, check_unchanged, json_diff, short, stable)


async def t_hello(d, ctl):
    h = ctl.hello
    check("hello: type", h.get("type") == "hello", short(h))
    check("hello: protocol 1", h.get("protocol") == 1, short(h))
    check("hello: server names skyd", isinstance(h.get("server"), str)
          and h["server"].startswith("skyd"), short(h))
    check("hello: role viewer", h.get("role") == "viewer", short(h))
    check("hello: no id", "id" not in h, short(h))
    caps = h.get("capabilities")
    check("hello: capabilities", isinstance(caps, list) and all(c in caps for c in CAPABILITIES),
          f"missing {[c for c in CAPABILITIES if not isinstance(caps, list) or c not in caps]}")
    lim = h.get("limits") if isinstance(h.get("limits"), dict) else {}
    for k, v in d.config["limits"].items():
        check(f"hello: limits.{k} from the config", lim.get(k) == v,
              f"config {v}, hello {lim.get(k)!r}")

    r = await ctl.request({"type": "hello", "id": "hi", "client": "test_serve.py", "protocol": 1})
    check("client hello: ack", r.get("type") == "ack" and r.get("id") == "hi"
          and isinstance(r.get("revision"), int), short(r))
    r = await ctl.request({"type": "hello", "id": "hi2", "protocol": 2})
    check_error("client hello protocol 2", r, "unsupported_protocol", id_="hi2")

    r = await ctl.request({"type": "auth", "id": "a1", "token": TOKEN})
    check("auth: ack with role controller", r.get("type") == "ack" and r.get("id") == "a1"
          and r.get("role") == "controller" and isinstance(r.get("revision"), int), short(r))
    ctl.controller = r.get("role") == "controller"

    big = 2 ** 53 - 1
    r = await ctl.request({"type": "get_state", "id": big})
    check("get_state: integer id 2^53-1 echoed", r.get("type") == "state" and r.get("id") == big,
          short(r)[:200])
    r = await ctl.request({"type": "get_state", "id": "x" * 64})
    check("get_state: 64-byte string id echoed",
          r.get("type") == "state" and r.get("id") == "x" * 64, short(r)[:200])
    r = await ctl.request({"type": "get_state", "id": "x" * 65})
    check_error("get_state: 65-byte id", r, "out_of_range", pointer="/id")


def schema_leaves(schema, prefix=""):
    """Dotted paths of the leaves of an object schema."""
    out = set()
    for name, sub in schema.get("properties", {}).items():
        path = prefix + name
        out |= schema_leaves(sub, path + ".") if "properties" in sub else {path}
    return out


def value_leaves(value, prefix=""):
    out = set()
    for name, sub in value.items():
        path = prefix + name
        out |= value_leaves(sub, path + ".") if isinstance(sub, dict) else {path}
    return out


async def t_describe(d, viewer):
    """A viewer's describe: the schemas of the state (every field get_state shows) and of the
    messages (every message type, sized by this daemon's limits), in order with its other
    replies."""
    await viewer.ws.send(json.dumps({"type": "describe", "id": "d1"}))
    await viewer.ws.send(json.dumps({"type": "get_state", "id": "d2"}))
    replies = []
    while len(replies) < 2:
        m = await viewer.raw(REPLY_TIMEOUT)
        if isinstance(m, dict) and m.get("type") != "event":
            replies.append(m)
    r, s = replies
    check("describe: replies in order", r.get("id") == "d1" and s.get("id") == "d2",
          f"{r.get('id')!r}, {s.get('id')!r}")
    check("describe: a viewer gets schema", r.get("type") == "schema", short(r)[:200])
    state, messages = r.get("state") or {}, r.get("messages") or {}
    for name, schema in (("state", state), ("messages", messages)):
        check(f"describe: {name} is a 2020-12 JSON Schema",
              schema.get("$schema") == "https://json-schema.org/draft/2020-12/schema",
              short(schema)[:200])
    shown = value_leaves(s.get("state") or {})
    described = schema_leaves(state)
    check("describe: every field of get_state's state is in the state schema",
          shown and shown <= described, f"missing {sorted(shown - described)[:5]}")
    defs = messages.get("$defs", {})
    types = [c for c in CAPABILITIES if c not in ("png", "png16", "jpeg", "equirectangular")]
    check("describe: every message type has a schema", all(t in defs for t in types),
          f"missing {[t for t in types if t not in defs]}")
    check("describe: oneOf over the message types",
          len(messages.get("oneOf", [])) == len(types), short(messages.get("oneOf")))
    view = defs.get("view", {}).get("properties", {})
    limits = d.config["limits"]
    check("describe: the view's maxima are this daemon's limits",
          view.get("width", {}).get("maximum") == limits["max_width"]
          and view.get("height", {}).get("maximum") == limits["max_height"]
          and view.get("fps", {}).get("maximum") == limits["max_fps"], short(view)[:300])
    r = await viewer.request({"type": "describe", "id": "d3", "extra": 1})
    check_error("describe with an unknown member", r, "unknown_field", pointer="/extra", id_="d3")


async def t_set_and_event(d, ctl, viewer):
    s0 = await ctl.get_state()
    st = s0.get("state", {})
    check("state: has the five groups",
          all(isinstance(st.get(k), dict) for k in
              ("atmosphere", "sun", "camera", "exposure", "render")), short(st))
    check("state: revision is an integer", isinstance(s0.get("revision"), int), short(s0)[:200])
    viewer.events.clear()
    ctl.events.clear()
    r = await ctl.request({"type": "set", "id": "s1",
                           "patch": {"sun": {"elevation_deg": 7.5, "azimuth_deg": 123}}})
    ok = check("set: ack", r.get("type") == "ack" and r.get("id") == "s1"
               and isinstance(r.get("revision"), int), short(r))
    rev = r.get("revision")
    if ok:
        check("set: ack revision greater than before", rev > s0["revision"],
              f"before {s0['revision']}, ack {rev}")
    s1 = await ctl.get_state()
    check("set: get_state revision equals the ack's", s1.get("revision") == rev,
          f"ack {rev}, state {s1.get('revision')}")
    sun = s1.get("state", {}).get("sun", {})
    check("set: values round trip", sun.get("elevation_deg") == 7.5
          and sun.get("azimuth_deg") == 123, short(sun))
    other = dict(s1.get("state", {}))
    before = dict(st)
    other.pop("sun", None)
    before.pop("sun", None)
    other, before = stable(other), stable(before)
    check("set: nothing else changed", approx_equal(other, before), json_diff(before, other))

    e = await viewer.wait_event(lambda e: e.get("revision") == rev)
    check("event: reaches a second client", e is not None,
          f"viewer saw events {short(viewer.events)}")
    if e:
        check("event: state_changed", e.get("event") == "state_changed", short(e))
        check("event: changed pointers in schema order",
              e.get("changed") == ["/sun/azimuth_deg", "/sun/elevation_deg"], short(e))
        check("event: the new values, keyed by pointer",
              e.get("values") == {"/sun/azimuth_deg": 123, "/sun/elevation_deg": 7.5}, short(e))
        check("event: by names the sender's hello client", e.get("by") == "test_serve.py",
              short(e))
        check("event: no id", "id" not in e, short(e))
    e = await ctl.wait_event(lambda e: e.get("revision") == rev)
    check("event: reaches the controller too", e is not None, short(ctl.events))

    # A single number sets the three channels of an RGB field.
    r = await ctl.request({"type": "set", "id": "s2", "patch": {"atmosphere": {"mie": {"g": 0.76}}}})
    check("set scalar RGB: ack", r.get("type") == "ack", short(r))
    s2 = await ctl.get_state()
    g = s2.get("state", {}).get("atmosphere", {}).get("mie", {}).get("g")
    check("set scalar RGB: g is [0.76]*3", approx_equal(g, [0.76, 0.76, 0.76]), short(g))

    # Valid alone, inconsistent with the current state: rejected at apply time.
    before = await ctl.get_state()
    r = await ctl.request({"type": "set", "id": "s3",
                           "patch": {"atmosphere": {"top_radius_km": 6000}}})
    # The field pointer may name the patch or the state field; only the code is checked.
    check_error("set inconsistent", r, "inconsistent", id_="s3")
    await check_unchanged("set inconsistent", ctl, before)


async def t_bad_inputs(d):
    ctl = await Client.connect(d.url(), "bad-inputs")
    await ctl.auth()
    try:
        await bad_inputs(d, ctl)
    finally:
        await ctl.close()


async def bad_inputs(d, ctl):
    await bad_input("malformed '{'", ctl, "{", "malformed_json")
    await bad_input("malformed '[1,'", ctl, "[1,", "malformed_json")
    await bad_input("malformed trailing garbage", ctl, '{"type":"get_state","id":5} x',
                    "malformed_json")
    await bad_input("not an object", ctl, "[1,2]", "not_an_object")
    await bad_input("wrong type", ctl,
                    {"type": "set", "id": "w1", "patch": {"sun": {"elevation_deg": "high"}}},
                    "wrong_type", "/patch/sun/elevation_deg", "w1")
    await bad_input("out of range", ctl,
                    {"type": "set", "id": "o1", "patch": {"sun": {"elevation_deg": 200}}},
                    "out_of_range", "/patch/sun/elevation_deg", "o1")
    await bad_input("unknown field in a patch", ctl,
                    {"type": "set", "id": "u1", "patch": {"atmosphere": {"bogus": 1}}},
                    "unknown_field", "/patch/atmosphere/bogus", "u1")
    await bad_input("unknown top-level field", ctl, {"type": "get_state", "id": "u2", "bogus": 1},
                    "unknown_field", "/bogus", "u2")
    await bad_input("unknown type", ctl, {"type": "frobnicate", "id": "t1"}, "unknown_type",
                    id_="t1")
    await bad_input("missing type", ctl, {"id": "t2"}, "missing_field", "/type", "t2")
    await bad_input("missing field", ctl, {"type": "subscribe", "id": "m1", "view": {"height": 90}},
                    "missing_field", "/view/width", "m1")
    await bad_input("member given twice", ctl, '{"type":"get_state","id":"d1","id":"d1"}',
                    "bad_value")
    # All or nothing: a valid field beside an invalid one applies neither.
    await bad_input("valid + out-of-range in one patch", ctl,
                    {"type": "set", "id": "v1",
                     "patch": {"sun": {"azimuth_deg": 31}, "camera": {"fov_deg": 500}}},
                    "out_of_range", "/patch/camera/fov_deg", "v1")
    await bad_input("valid + unknown in one patch", ctl,
                    {"type": "set", "id": "v2",
                     "patch": {"sun": {"azimuth_deg": 32}, "atmosphere": {"bogus": 1}}},
                    "unknown_field", "/patch/atmosphere/bogus", "v2")
    # Size limit: exactly max_message_bytes is parsed; one byte more is not.
    limit = d.config["limits"]["max_message_bytes"]
    head = '{"type":"get_state","id":"big"}'
    r = await ctl.request(head + " " * (limit - len(head)))
    check("message of exactly max_message_bytes: answered", r.get("type") == "state"
          and r.get("id") == "big", short(r)[:200])
    # A padded unknown member: parsing it would give unknown_field; the size check comes first.
    pad = '{"type":"get_state","id":"big2","pad":"' + "a" * limit + '"}'
    await bad_input("oversized message", ctl, pad, "message_too_large")
    await bad_input("oversized by one byte", ctl, head + " " * (limit + 1 - len(head)),
                    "message_too_large")
    await bad_input("binary message", ctl, b'{"type":"get_state","id":"b1"}', "invalid_encoding")
    # websockets' send() only sends valid text, so write the text frame (opcode 1) directly.
    await bad_input("invalid UTF-8 text", ctl, None, "invalid_encoding",
                    raw_frame=(0x1, b'{"type":"get_state","id":"\xff\xfe"}'))
    # Only the code: the NUL may be caught before the message is parsed (no id, no pointer).
    await bad_input("escaped NUL in a string", ctl,
                    '{"type":"hello","id":"n1","client":"a\\u0000b"}', "bad_value")
    # View limits.
    await bad_input("subscribe width > max_width", ctl,
                    {"type": "subscribe", "id": "vw",
                     "view": {"width": d.config["limits"]["max_width"] + 1, "height": 10}},
                    "out_of_range", "/view/width", "vw")
    await bad_input("subscribe fps > max_fps", ctl,
                    {"type": "subscribe", "id": "vf",
                     "view": {"width": 16, "height": 16,
                              "fps": d.config["limits"]["max_fps"] + 1}},
                    "out_of_range", "/view/fps", "vf")
    await bad_input("probe missing parameter", ctl,
                    {"type": "probe", "id": "p1", "quantity": "transmittance", "altitude_km": 0},
                    "missing_field", "/mu", "p1")
    await bad_input("probe parameter of another quantity", ctl,
                    {"type": "probe", "id": "p2", "quantity": "illuminance", "sun_zenith_deg": 0,
                     "mu": 1}, "unknown_field", "/mu", "p2")


async def t_roles(d):
    v = await Client.connect(d.url(), "viewer-roles")
    try:
        await bad_input("viewer set", v, {"type": "set", "id": "f1",
                                          "patch": {"sun": {"elevation_deg": 20}}},
                        "forbidden", id_="f1")
        await bad_input("viewer apply_preset", v, {"type": "apply_preset", "id": "f2",
                                                   "kind": "atmosphere", "name": "mars"},
                        "forbidden", id_="f2")
        await bad_input("wrong auth token", v, {"type": "auth", "id": "f3", "token": "nope"},
                        "auth_failed", id_="f3")
        await bad_input("set after a failed auth", v,
                        {"type": "set", "id": "f4", "patch": {"sun": {"elevation_deg": 20}}},
                        "forbidden", id_="f4")
    finally:
        await v.close()
