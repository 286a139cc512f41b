#!/usr/bin/python3
"""Drives clients/python/skyd_client.py against the real daemon on loopback.

Usage: /usr/bin/python3 tests/e2e/test_python_client.py PATH_TO_SKYD CLIENT_DIR OUTPUT_DIR

Checks: connect (hello, role, limits; an allowed and a refused Origin), auth (a wrong token,
the token from $SKYD_TOKEN and from a token file), get_state and set (the new revision), an
error carrying its code and field pointers, a subscription yielding frames of the asked size
whose PNGs decode (the module's decoder agrees with the tests' own), a png16 snapshot, events
with values seen by a second client (stream and callback), simulation events, replies matched
by id while frames and events interleave, and reconnection across a daemon restart on the same
port: the iterator yields frames again, the session is controller again and the revision
persisted; a client without reconnect sees its iterator fail. Exit 0 when every check passed.
"""

import asyncio
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness  # noqa: E402
from serve_harness import (ALLOWED_ORIGIN, TOKEN, Daemon, check, decode_png_full,  # noqa: E402
                           info, make_config)

skyd_client = None  # imported in main() from CLIENT_DIR
VIEW = {"width": 64, "height": 36, "fps": 10, "exposure": {"mode": "manual", "ev100": 13}}
FRAME_TIMEOUT = 30.0


async def expect_error(name, coro, code, pointer=None):
    try:
        await coro
    except skyd_client.SkydError as e:
        check(f"{name}: code {code}", e.code == code, f"{e.code}: {e}")
        check(f"{name}: message is text", isinstance(e.message, str) and e.message, repr(e))
        if pointer is not None:
            check(f"{name}: pointer {pointer}", pointer in e.pointers, str(e.pointers))
            check(f"{name}: field entries carry reason and code",
                  all(f.get("reason") and f.get("code") for f in e.fields), str(e.fields))
        return e
    except Exception as e:  # noqa: BLE001 - anything else is the check failing
        check(f"{name}: SkydError", False, f"{type(e).__name__}: {e}")
        return None
    check(f"{name}: SkydError", False, "no error")
    return None


def check_frame(name, frame, width, height, fmt=1):
    check(f"{name}: Frame", isinstance(frame, skyd_client.Frame), repr(frame))
    check(f"{name}: size {width}x{height}", (frame.width, frame.height) == (width, height),
          repr(frame))
    check(f"{name}: format {fmt}", frame.format == fmt, repr(frame))
    check(f"{name}: simulation time", frame.simulation_time_s > 1e9, repr(frame))
    image = frame.image()
    reference = decode_png_full(frame.payload)
    check(f"{name}: decoded size", (image.width, image.height) == (width, height), str(image[:4]))
    check(f"{name}: decoded like the tests' decoder",
          (image.channels, image.depth, image.rows) ==
          (reference["channels"], reference["depth"], reference["rows"]), str(image[:4]))
    check(f"{name}: not a constant image", len(set(image.rows)) > 1 or
          len(set(image.rows[0])) > 1, "every row the same")
    return image


async def basics(daemon, scratch):
    url = daemon.url()
    sky = await skyd_client.connect(url, client_name="py-test")
    check("hello: viewer", sky.role == "viewer", sky.role)
    check("hello: limits", sky.limits.get("max_width") == 1000
          and sky.limits.get("max_height") == 800, str(sky.limits))
    check("hello: server", str(sky.server).startswith("skyd"), str(sky.server))
    async with skyd_client.connect(url, origin=ALLOWED_ORIGIN, reconnect=False) as other:
        check("allowed Origin: connected", (await other.get_state())["revision"] >= 0)
    try:
        await skyd_client.connect(url, origin="http://refused.test")
        check("refused Origin: SkydConnectionError", False, "connected")
    except skyd_client.SkydConnectionError as e:
        check("refused Origin: SkydConnectionError", "403" in str(e), str(e))

    await expect_error("viewer set", sky.set({"sun": {"elevation_deg": 10}}), "forbidden")
    await expect_error("wrong token", sky.auth("wrong-token"), "auth_failed")
    os.environ.pop("SKYD_TOKEN", None)
    token_file = os.path.join(scratch, "token")
    with open(token_file, "w") as f:
        f.write(f"  {TOKEN}\t\nnot this line\n")
    check("token file", skyd_client.read_token(token_file=token_file) == TOKEN)
    os.environ["SKYD_TOKEN"] = "from-the-environment"
    check("$SKYD_TOKEN before the token file",
          skyd_client.read_token(token_file=token_file) == "from-the-environment")
    check("token before $SKYD_TOKEN", skyd_client.read_token("given") == "given")
    os.environ["SKYD_TOKEN"] = TOKEN
    check("auth from $SKYD_TOKEN", await sky.auth() == "controller", sky.role)
    os.environ.pop("SKYD_TOKEN")
    async with skyd_client.connect(url) as other:
        check("auth from a token file",
              await other.auth(token_file=token_file) == "controller", other.role)

    before = await sky.get_state()
    check("get_state: revision and state", isinstance(before.get("revision"), int)
          and "sun" in before.get("state", {}), str(before)[:200])
    revision = await sky.set({"clock": {"sky_bodies": "manual", "time_scale": 0},
                              "sun": {"elevation_deg": 12.5}})
    check("set returns the next revision", revision == before["revision"] + 1,
          f"{before['revision']} -> {revision}")
    after = await sky.get_state()
    check("get_state shows the set", after["revision"] == revision
          and after["state"]["sun"]["elevation_deg"] == 12.5, str(after["state"]["sun"]))
    await expect_error("unknown field", sky.set({"atmosphere": {"bogus": 1}}),
                       "unknown_field", "/patch/atmosphere/bogus")
    e = await expect_error("two bad fields", sky.set({"atmosphere": {"mie": {"g": 7}},
                                                       "sun": {"elevation_deg": 400}}),
                           "out_of_range", "/patch/atmosphere/mie/g")
    check("two bad fields: both pointers", e is not None and
          "/patch/sun/elevation_deg" in e.pointers, str(e and e.pointers))
    check("str() of the error names the fields", e is not None
          and "/patch/atmosphere/mie/g" in str(e) and "set" in str(e), str(e))
    reply = await sky.apply_observation("METAR LFLY 211200Z 18008KT CAVOK 22/10 Q1018")
    check("apply_observation: the next revision, the report, the patch",
          reply.get("revision") == revision + 1 and reply.get("report", {}).get("cavok") is True
          and reply.get("patch", {}).get("weather", {}).get("source") == "metar"
          and reply.get("unmapped") == [], str(reply)[:300])
    await expect_error("apply_observation of a bad group",
                       sky.apply_observation("METAR EGLL 281150Z 24010KT 9999 BKN0X0 12/09"),
                       "bad_value", "/metar")
    return sky


async def frames_and_events(sky):
    url = sky.url
    sub = await sky.subscribe(VIEW, decode=True)
    check("subscribed: a number and the normalized view", isinstance(sub.number, int)
          and sub.view.get("width") == 64 and sub.view.get("format") == "png", str(sub.view))
    numbers = []
    for i in range(3):
        frame = await sub.next(FRAME_TIMEOUT)
        numbers.append(frame.frame_number)
        check(f"subscription frame {i}: belongs to the subscription", frame.subscription is sub)
        check_frame(f"subscription frame {i}", frame, 64, 36)
    check("frame numbers rise", numbers == sorted(set(numbers)), str(numbers))

    shot = await sky.snapshot({"width": 80, "height": 40}, timeout=FRAME_TIMEOUT)
    check_frame("snapshot", shot, 80, 40)
    check("snapshot: no subscription", shot.subscription is None)
    shot16 = await sky.snapshot({"width": 48, "height": 24, "format": "png16"},
                                timeout=FRAME_TIMEOUT)
    image = check_frame("png16 snapshot", shot16, 48, 24, fmt=2)
    check("png16: 16-bit RGB with its luminance scale", (image.channels, image.depth) == (3, 16)
          and "Luminance full scale cd/m2" in image.text, str(image[:4]) + str(image.text))
    await expect_error("snapshot too wide", sky.snapshot({"width": 5000, "height": 10}),
                       "out_of_range", "/view/width")

    # A second client sees the first one's change: an event stream and a callback.
    watcher = await skyd_client.connect(url)
    seen = []
    watcher.on_event(seen.append)
    stream = watcher.events()
    wanted = None
    for step in range(3):  # requests while frames stream in: replies found by id
        wanted = await sky.set({"sun": {"elevation_deg": 20 + step}})
        state = await sky.get_state()
        check(f"interleaved request {step}: its own reply", state["revision"] == wanted
              and state["state"]["sun"]["elevation_deg"] == 20 + step, str(state)[:120])
    event = None
    while True:
        event = await stream.next(FRAME_TIMEOUT)
        if event.get("revision") == wanted:
            break
    check("event: state_changed", event.get("event") == "state_changed", str(event))
    check("event: by the sender's name", event.get("by") == "py-test", str(event))
    check("event: changed and values", "/sun/elevation_deg" in event.get("changed", [])
          and event.get("values", {}).get("/sun/elevation_deg") == 22, str(event))
    check("callback saw the same events", [e.get("revision") for e in seen][-3:] ==
          [wanted - 2, wanted - 1, wanted], str([e.get("revision") for e in seen]))
    stream.close()
    frame = await sub.next(FRAME_TIMEOUT)
    while frame.revision < wanted:
        frame = await sub.next(FRAME_TIMEOUT)
    check("a frame of the last revision arrives after the requests", frame.revision >= wanted)
    await watcher.close()

    # simulation events, asked for in hello
    async with skyd_client.connect(url, simulation_events=True) as sim:
        events = sim.events()
        await sky.set({"clock": {"time_scale": 600}})
        deadline = time.monotonic() + 15
        sim_event = None
        while time.monotonic() < deadline and sim_event is None:
            e = await events.next(15)
            if e.get("event") == "simulation":
                sim_event = e
        check("simulation event with the clock", sim_event is not None
              and "/clock/utc" in sim_event.get("values", {})
              and sim_event.get("simulation_time_s", 0) > 1e9, str(sim_event))
        await sky.set({"clock": {"time_scale": 0}})
    return sub


async def restart(daemon, sky, sub):
    url = daemon.url()
    once = await skyd_client.connect(url, reconnect=False)
    once_sub = await once.subscribe(VIEW)
    await once_sub.next(FRAME_TIMEOUT)
    events = sky.events()
    revision = await sky.set({"sun": {"elevation_deg": 33}})
    port = daemon.port
    status = await daemon.terminate_async()
    check("skyd exits 0 on SIGTERM", status == 0, f"status {status}")
    try:
        await once_sub.next(FRAME_TIMEOUT)
        while True:  # frames read before the close may still wait
            await once_sub.next(FRAME_TIMEOUT)
    except skyd_client.SkydConnectionError as e:
        check("without reconnect the iterator fails", "1001" in str(e), str(e))
    except Exception as e:  # noqa: BLE001
        check("without reconnect the iterator fails", False, f"{type(e).__name__}: {e}")
    try:
        await once.get_state()
        check("without reconnect requests fail", False, "answered")
    except skyd_client.SkydConnectionError:
        check("without reconnect requests fail", True)

    await asyncio.sleep(1.5)  # the client tries (and fails) a few times meanwhile
    stale = 0
    try:  # frames read before the close: what comes after this is from the new daemon
        while True:
            await sub.next(0.2)
            stale += 1
    except asyncio.TimeoutError:
        info(f"{stale} frames from before the restart were waiting")
    daemon.config["listen"]["port"] = port
    started = time.monotonic()
    await asyncio.get_running_loop().run_in_executor(None, daemon.start)
    check("restarted on the same port", daemon.port == port, f"{daemon.port} != {port}")
    frame = await sub.next(FRAME_TIMEOUT + 10)
    while frame.revision < revision:
        frame = await sub.next(FRAME_TIMEOUT)
    info(f"frames again {time.monotonic() - started:.1f} s after the restart: {frame!r}")
    check("frames again after the restart", frame.width == 64 and frame.subscription is sub,
          repr(frame))
    check("reconnected once", sky.reconnects == 1, str(sky.reconnects))
    check("controller again", sky.role == "controller", sky.role)
    state = await sky.get_state()
    check("the revision persisted", state["revision"] == revision
          and state["state"]["sun"]["elevation_deg"] == 33, str(state["revision"]))
    new = await sky.set({"sun": {"elevation_deg": 34}})
    check("set after the restart", new == revision + 1, f"{revision} -> {new}")
    event = await events.next(FRAME_TIMEOUT)
    while event.get("revision") != new:
        event = await events.next(FRAME_TIMEOUT)
    check("the event stream goes on", event.get("values", {}).get("/sun/elevation_deg") == 34,
          str(event))
    await sub.unsubscribe()
    try:
        await sub.next(1)
        check("unsubscribed: the iterator ends", False, "a frame")
    except StopAsyncIteration:
        check("unsubscribed: the iterator ends", True)
    await sky.close()


async def run(skyd, scratch):
    state_file = os.path.join(scratch, "state.json")
    for name in ("state.json", "state.json.token"):
        if os.path.exists(os.path.join(scratch, name)):
            os.unlink(os.path.join(scratch, name))
    daemon = Daemon(skyd, scratch, "skyd", make_config(scratch, state_file))
    try:
        await asyncio.get_running_loop().run_in_executor(None, daemon.start)
        sky = await basics(daemon, scratch)
        sub = await frames_and_events(sky)
        await restart(daemon, sky, sub)
    except Exception as e:  # noqa: BLE001 - any failure is a failed check
        check("client test ran", False, f"{type(e).__name__}: {e}")
        info(daemon.log_tail())
    finally:
        status = await daemon.terminate_async()
        check("skyd exits 0 on SIGTERM at the end", status == 0, f"status {status}")


def main():
    global skyd_client
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    skyd, client_dir, scratch = (os.path.abspath(p) for p in sys.argv[1:4])
    sys.path.insert(0, client_dir)
    import skyd_client as module  # noqa: E402
    skyd_client = module
    os.makedirs(scratch, exist_ok=True)
    started = time.monotonic()
    try:
        asyncio.run(asyncio.wait_for(run(skyd, scratch), 240))
    except asyncio.TimeoutError:
        check("whole run within 240 s", False, "timed out")
    return serve_harness.summary(started)


if __name__ == "__main__":
    sys.exit(main())
