"""Support for tests/e2e/test_serve.py: check bookkeeping (the passed/failed counters live
here), the binary frame check, the daemon under test (started on a free port, stopped with
SIGTERM), a WebSocket client wrapper on Debian's python3-websockets 10.4, and the error and
bad-input checks. It re-exports the PNG decoder and encoder (png_codec.py), the JSON comparison
helpers (serve_json.py) and the raw-socket helpers for what the library will not send
(serve_raw.py), so that every name is still importable from here."""

import asyncio
import json
import math
import os
import queue
import re
import signal
import struct
import subprocess
import sys
import threading
import time
import zlib

try:
    import websockets
    import websockets.exceptions
except ImportError:  # pragma: no cover - environment problem, not a test result
    print("test_serve.py: the websockets package is missing; run with /usr/bin/python3 "
          "(Debian python3-websockets)", file=sys.stderr)
    sys.exit(1)

from png_codec import PNG_SIGNATURE, decode_png, decode_png_full, encode_png  # noqa: E402,F401
from serve_json import (SIMULATED_FIELDS, approx_equal, json_diff, short,  # noqa: E402,F401
                        stable)
from serve_raw import (http_get_raw, raw_handshake_status, raw_ws_connect,  # noqa: E402,F401
                       raw_ws_send_text)

TOKEN = "e2e-controller-token"
ALLOWED_ORIGIN = "http://example.test"
REPLY_TIMEOUT = 10.0      # a control reply (set waits for the next render tick)
FIRST_FRAME_TIMEOUT = 30.0  # the first frame of a run (LUTs are built at start)
READY_TIMEOUT = 60.0      # the "listening" line
# ... when the daemon has an empty Mesa shader cache of its own (MESA_SHADER_CACHE_DIR): it
# compiles every variant before it listens, 34 s on two quiet cores and several times that
# under the sanitizers on a loaded machine.
EMPTY_SHADER_CACHE_READY_TIMEOUT = 240.0
EXIT_TIMEOUT = 20.0       # exit after SIGTERM
# The frames a daemon renders before it listens (renderer_host.c's warm_up_frames), and again
# in each renderer it rebuilds; SKYD_FAULT counts them with the rest. Its log says how many
# ("start-up frames: N"), and start_up_frames reads that back.
WARM_UP_FRAMES = 12

CAPABILITIES = ["hello", "auth", "get_state", "set", "subscribe", "unsubscribe", "snapshot",
                "probe", "list_presets", "apply_preset", "stats", "set_weather_map", "describe",
                "apply_observation", "png", "jpeg"]

HEADER = struct.Struct("<4sHHQQdIIII")
assert HEADER.size == 48

# ------------------------------------------------------------------------------------------
# Check bookkeeping

passed = 0
failed = 0
VERBOSE = os.environ.get("SKYD_TEST_VERBOSE") == "1"  # also print the checks that pass


def check(name, cond, detail=""):
    """Records one check; prints a line when it fails. Returns cond."""
    global passed, failed
    if cond:
        passed += 1
        if VERBOSE:
            print(f"ok   {name}", flush=True)
    else:
        failed += 1
        print(f"FAIL {name}: {detail}", flush=True)
    return bool(cond)


def info(text):
    print(f"info: {text}", flush=True)


# ------------------------------------------------------------------------------------------
# Binary frames (header + PNG)


def check_binary_frame(name, text_msg, binary, width, height, revision=None, decode=True,
                       fmt_expected=1):
    """Checks a binary frame (header + PNG) against the frame message that announced it:
    format 1 is an 8-bit RGBA PNG, 2 a 16-bit linear RGB one."""
    if not check(f"{name}: binary message", isinstance(binary, bytes),
                 f"expected a binary message after {short(text_msg)}, got {short(binary)}"):
        return None
    if not check(f"{name}: at least 48 bytes", len(binary) >= 48, f"length {len(binary)}"):
        return None
    (magic, version, fmt, frame_number, state_revision, sim_time, w, h, payload_length,
     reserved) = HEADER.unpack_from(binary)
    check(f"{name}: magic", magic == b"SKYF", repr(magic))
    check(f"{name}: header_version", version == 1, str(version))
    check(f"{name}: format", fmt == fmt_expected, f"{fmt}, expected {fmt_expected}")
    check(f"{name}: reserved", reserved == 0, str(reserved))
    check(f"{name}: frame_number matches the frame message",
          frame_number == text_msg.get("frame_number"),
          f"header {frame_number}, message {short(text_msg)}")
    check(f"{name}: simulation_time_s finite", math.isfinite(sim_time), str(sim_time))
    check(f"{name}: width/height", (w, h) == (width, height),
          f"header {w}x{h}, requested {width}x{height}")
    check(f"{name}: payload_length", payload_length == len(binary) - 48,
          f"payload_length {payload_length}, message length {len(binary)}")
    if revision is not None:
        check(f"{name}: state_revision", state_revision == revision,
              f"header {state_revision}, expected {revision}")
    if decode:
        try:
            png = decode_png_full(binary[48:])
        except (ValueError, zlib.error, struct.error) as e:
            check(f"{name}: PNG decodes", False, str(e))
            return state_revision
        check(f"{name}: PNG decodes", True)
        pw, ph, channels, rows = png["width"], png["height"], png["channels"], png["rows"]
        check(f"{name}: PNG IHDR size", (pw, ph) == (width, height), f"{pw}x{ph}")
        shape = (4, 8) if fmt_expected == 1 else (3, 16)
        check(f"{name}: PNG is {'RGBA8' if fmt_expected == 1 else 'RGB16'}",
              (channels, png["depth"]) == shape, f"{channels} channels of {png['depth']} bits")
        channels = channels * png["depth"] // 8  # bytes per pixel
        pixels = set()
        for row in rows:
            for i in range(0, len(row), channels):
                pixels.add(row[i:i + channels])
                if len(pixels) > 1:
                    break
            if len(pixels) > 1:
                break
        check(f"{name}: image not constant", len(pixels) > 1,
              f"every pixel is {pixels!r}")
    return state_revision


# ------------------------------------------------------------------------------------------
# The daemon


def daemon_environment():
    """The daemon's environment. Under the sanitizer build the preloads meant for the daemon
    arrive as SKYD_DAEMON_LD_PRELOAD, so that they do not also instrument this interpreter."""
    env = dict(os.environ)
    preload = env.pop("SKYD_DAEMON_LD_PRELOAD", "")
    if preload:
        env["LD_PRELOAD"] = preload
    return env


def stop_process(proc, sig=signal.SIGTERM, timeout=EXIT_TIMEOUT):
    """Sends `sig` to a running process and waits `timeout` s for it, then kills it. Returns
    the exit status (None if it had to be killed, or when there is no process)."""
    if proc is None or proc.poll() is not None:
        return proc.poll() if proc else None
    proc.send_signal(sig)
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        return None


class Daemon:
    def __init__(self, skyd, scratch, name, config, env=None, args=None,
                 ready_timeout=READY_TIMEOUT):
        self.skyd = skyd
        self.ready_timeout = ready_timeout  # s until the "listening" line
        self.args = list(args or [])  # after `serve --config FILE`
        self.scratch = scratch
        self.name = name
        self.config = config
        self.env = dict(env or {})  # added to the daemon's environment
        self.config_path = os.path.join(scratch, f"{name}.json")
        self.log_path = os.path.join(scratch, f"{name}.log")
        self.proc = None
        self.port = None
        self.lines = queue.Queue()
        self.log_offset = 0

    def start(self):
        with open(self.config_path, "w") as f:
            json.dump(self.config, f, indent=2)
        self.lines = queue.Queue()  # a fresh one per start: the old reader thread ends with None
        self.log_offset = os.path.getsize(self.log_path) if os.path.exists(self.log_path) else 0
        log = open(self.log_path, "ab")
        env = daemon_environment()
        env.update(self.env)
        self.proc = subprocess.Popen([self.skyd, "serve", "--config", self.config_path,
                                      *self.args],
                                     stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=log, cwd=self.scratch, env=env)
        log.close()
        threading.Thread(target=self._read_stdout, args=(self.proc, self.lines),
                         daemon=True).start()
        deadline = time.monotonic() + self.ready_timeout
        while True:
            remaining = deadline - time.monotonic()
            try:
                line = self.lines.get(timeout=max(0.01, remaining))
            except queue.Empty:
                line = None
            if line is None:
                try:
                    code = self.proc.wait(timeout=1)
                    why = f"exited with status {code} before printing the listening line"
                except subprocess.TimeoutExpired:
                    why = f"no listening line within {self.ready_timeout:.0f} s"
                    self.kill()  # no test can use it, and nothing else would stop it
                raise RuntimeError(f"{self.name}: {why}; log {self.log_path}: "
                                   f"{self.log_tail()}")
            m = re.fullmatch(r"skyd: listening on http://127\.0\.0\.1:(\d+)/", line.rstrip("\n"))
            if m:
                self.port = int(m.group(1))
                return
            info(f"{self.name}: unexpected stdout line before the listening line: {line!r}")

    def _read_stdout(self, proc, lines):
        for raw in proc.stdout:
            lines.put(raw.decode("utf-8", "replace"))
        lines.put(None)

    def log_text(self):
        """What the daemon has logged since its last start."""
        try:
            with open(self.log_path, "rb") as f:
                f.seek(self.log_offset)
                return f.read().decode("utf-8", "replace")
        except OSError:
            return ""

    async def wait_exit(self, timeout):
        """The exit status once the daemon exits by itself, or None after timeout seconds."""
        def wait():
            try:
                return self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                return None
        return await asyncio.get_running_loop().run_in_executor(None, wait)

    def log_tail(self, n=600):
        try:
            with open(self.log_path, "rb") as f:
                f.seek(self.log_offset)
                return f.read().decode("utf-8", "replace")[-n:]
        except OSError:
            return "(no log)"

    def url(self):
        return f"ws://127.0.0.1:{self.port}/"

    def terminate(self):
        """SIGTERM; returns the exit status (None if it had to be killed)."""
        return stop_process(self.proc)

    async def terminate_async(self):
        return await asyncio.get_running_loop().run_in_executor(None, self.terminate)

    def kill(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def start_up_frames(log_text):
    """The warm-up frames the daemon's log says it rendered before listening (None: no line)."""
    m = re.search(r"start-up frames: (\d+) and a probe", log_text)
    return int(m.group(1)) if m else None


def make_config(scratch, state_file, **limits):
    lim = {"max_message_bytes": 16384, "max_clients": 16, "max_width": 1000, "max_height": 800,
           "max_fps": 60, "control_messages_per_second": 1000, "max_upload_bytes": 1500000}
    lim.update(limits)
    return {
        "listen": {"address": "127.0.0.1", "port": 0},
        "web_root": os.path.join(scratch, "web"),
        "state_file": state_file,
        "render": {"device": "", "validation": False},
        "limits": lim,
        "controller_token": TOKEN,
        "allowed_origins": [ALLOWED_ORIGIN],
    }


# ------------------------------------------------------------------------------------------
# A client: replies, events and frames sorted out of one message stream


class Client:
    def __init__(self, ws, name):
        self.ws = ws
        self.name = name
        self.pending = []     # messages read ahead and pushed back
        self.events = []
        self.frames = []      # (frame message, binary, arrival time), subscription frames only
        self.frame_count = {}  # subscription -> frames received
        self.stray = []       # replies that arrived while nobody waited for one
        self.hello = None
        self.next_id = 1000
        self.url = None
        self.connect_kwargs = {}
        self.controller = False

    @classmethod
    async def connect(cls, url, name, read_hello=True, **kwargs):
        kwargs.setdefault("open_timeout", 10)
        kwargs.setdefault("close_timeout", 5)
        kwargs.setdefault("ping_interval", None)
        kwargs.setdefault("max_size", 1 << 24)
        ws = await websockets.connect(url, **kwargs)
        c = cls(ws, name)
        c.url, c.connect_kwargs = url, kwargs
        if read_hello:
            c.hello = await c.raw(REPLY_TIMEOUT)
            if isinstance(c.hello, (bytes, str)) or c.hello.get("type") != "hello":
                raise RuntimeError(f"{name}: first message is not hello: {short(c.hello)}")
        return c

    async def auth(self):
        r = await self.request({"type": "auth", "id": "auth", "token": TOKEN})
        if r.get("type") != "ack" or r.get("role") != "controller":
            raise RuntimeError(f"{self.name}: auth answered with {short(r)}")
        self.controller = True
        return r

    async def reopen(self):
        """A fresh connection in place of a closed one (so later checks still run)."""
        info(f"{self.name}: connection closed ({self.ws.close_code} {self.ws.close_reason!r}); "
             f"reconnecting for the remaining checks")
        fresh = await Client.connect(self.url, self.name, **self.connect_kwargs)
        self.ws, self.hello, self.pending = fresh.ws, fresh.hello, []
        if self.controller:
            await self.auth()

    def new_id(self):
        self.next_id += 1
        return self.next_id

    async def raw(self, timeout):
        """One message: a dict for JSON text, str for non-JSON text, bytes for binary."""
        if self.pending:
            return self.pending.pop(0)
        try:
            m = await asyncio.wait_for(self.ws.recv(), timeout)
        except asyncio.TimeoutError:
            raise asyncio.TimeoutError(f"{self.name}: nothing received within {timeout:.1f} s")
        if isinstance(m, bytes):
            return m
        try:
            return json.loads(m)
        except ValueError:
            return m

    async def _dispatch(self, timeout):
        """Reads one item; stores events and subscription frames. Returns ("reply", msg),
        ("event", msg) or ("frame", msg, binary)."""
        m = await self.raw(timeout)
        if isinstance(m, bytes):
            check(f"{self.name}: binary message announced by a frame message", False,
                  f"binary message of {len(m)} bytes without a preceding frame message")
            return ("junk", m)
        if not isinstance(m, dict):
            check(f"{self.name}: server text is a JSON object", False, short(m))
            return ("junk", m)
        if m.get("type") == "event":
            self.events.append(m)
            return ("event", m)
        if m.get("type") == "frame":
            # The binary follows its frame message at once, but the caller's time may be
            # nearly spent: waiting only that long would leave the binary to be read
            # alone next time, unpaired from the frame message already taken.
            b = await self.raw(max(timeout, REPLY_TIMEOUT))
            if not isinstance(b, bytes):
                check(f"{self.name}: frame message immediately followed by a binary message",
                      False, f"after {short(m)} came {short(b)}")
                self.pending.insert(0, b)
                b = None
            if "subscription" in m:
                self.frames.append((m, b, time.monotonic()))
                if len(self.frames) > 64:
                    del self.frames[:-64]
                sub = m.get("subscription")
                self.frame_count[sub] = self.frame_count.get(sub, 0) + 1
                return ("frame", m, b)
            m = dict(m)
            m["_binary"] = b
            return ("reply", m)
        return ("reply", m)

    async def send(self, obj):
        await self.ws.send(obj if isinstance(obj, (str, bytes)) else json.dumps(obj))

    async def reply(self, timeout=REPLY_TIMEOUT):
        """The next reply (skipping events and subscription frames)."""
        deadline = time.monotonic() + timeout
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise asyncio.TimeoutError(f"{self.name}: no reply within {timeout} s")
            item = await self._dispatch(remaining)
            if item[0] == "reply":
                return item[1]

    async def request(self, obj, timeout=REPLY_TIMEOUT):
        await self.send(obj)
        return await self.reply(timeout)

    async def get_state(self):
        i = self.new_id()
        r = await self.request({"type": "get_state", "id": i})
        if r.get("type") != "state" or r.get("id") != i:
            raise RuntimeError(f"{self.name}: get_state answered with {short(r)}")
        return r

    async def wait_frame(self, pred=lambda m: True, timeout=REPLY_TIMEOUT):
        deadline = time.monotonic() + timeout
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise asyncio.TimeoutError(f"{self.name}: no matching frame within {timeout} s")
            item = await self._dispatch(remaining)
            if item[0] == "frame" and pred(item[1]):
                return item[1], item[2]
            if item[0] == "reply":
                self.stray.append(item[1])

    async def wait_event(self, pred, timeout=REPLY_TIMEOUT):
        for e in self.events:
            if pred(e):
                return e
        deadline = time.monotonic() + timeout
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            try:
                item = await self._dispatch(remaining)
            except asyncio.TimeoutError:
                return None
            if item[0] == "event" and pred(item[1]):
                return item[1]
            if item[0] == "reply":
                self.stray.append(item[1])

    async def pump(self, duration):
        """Reads (and sorts) everything that arrives during `duration` seconds."""
        deadline = time.monotonic() + duration
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return
            try:
                item = await self._dispatch(remaining)
            except asyncio.TimeoutError:
                return
            if item[0] == "reply":
                self.stray.append(item[1])

    async def close(self):
        try:
            await asyncio.wait_for(self.ws.close(), 6)
        except Exception:
            pass


def error_fields(msg):
    return msg.get("fields") if isinstance(msg.get("fields"), list) else []


def check_error(name, msg, code, pointer=None, id_=None):
    """Checks an `error` reply: code, the field entry for `pointer`, the echoed id."""
    ok = check(f"{name}: error reply", msg.get("type") == "error", short(msg))
    if not ok:
        return False
    ok &= check(f"{name}: code {code}", msg.get("code") == code, short(msg))
    check(f"{name}: message is text", isinstance(msg.get("message"), str), short(msg))
    check(f"{name}: fields is a list", isinstance(msg.get("fields"), list), short(msg))
    if id_ is not None:
        check(f"{name}: id echoed", msg.get("id") == id_, f"sent id {id_!r}: {short(msg)}")
    fields = error_fields(msg)
    if fields:
        check(f"{name}: top-level code is the first field's",
              msg.get("code") == fields[0].get("code"), short(msg))
        check(f"{name}: field entries have pointer/reason/code",
              all(isinstance(f, dict) and isinstance(f.get("pointer"), str)
                  and isinstance(f.get("reason"), str) and isinstance(f.get("code"), str)
                  for f in fields), short(msg))
    if pointer is not None:
        match = [f for f in fields if isinstance(f, dict) and f.get("pointer") == pointer]
        ok &= check(f"{name}: field entry {pointer}", bool(match), short(msg))
        if match:
            check(f"{name}: field entry {pointer} code {code}", match[0].get("code") == code,
                  short(msg))
    return ok


async def check_unchanged(name, client, before):
    """get_state on the same connection: it still answers, nothing changed."""
    try:
        after = await client.get_state()
    except Exception as e:  # noqa: BLE001 - any failure here is the check failing
        check(f"{name}: connection still answers get_state", False, repr(e))
        return
    check(f"{name}: connection still answers get_state", True)
    check(f"{name}: revision unchanged", after.get("revision") == before.get("revision"),
          f"before {before.get('revision')}, after {after.get('revision')}")
    a, b = stable(after.get("state")), stable(before.get("state"))
    check(f"{name}: state unchanged", approx_equal(a, b), json_diff(b, a))


async def bad_input(name, client, payload, code, pointer=None, id_=None, raw_frame=None):
    """Sends one bad message; expects `error` `code`; then the state must be unchanged."""
    before = await client.get_state()
    if raw_frame is not None:
        opcode, data = raw_frame
        await client.ws.write_frame(True, opcode, data)
    else:
        await client.send(payload)
    try:
        r = await client.reply()
    except asyncio.TimeoutError:
        check(f"{name}: reply", False, "no reply within the timeout")
        await client.close()  # a late reply would be taken for the next request's
        await client.reopen()
        return
    except websockets.exceptions.ConnectionClosed as e:
        check(f"{name}: connection stays open", False, f"closed: {e}")
        await client.reopen()
        return
    check_error(name, r, code, pointer, id_)
    await check_unchanged(name, client, before)


# ------------------------------------------------------------------------------------------
# Test sections


def run_daemon_test(run, doc, timeout_s):
    """The main() of a test script taking PATH_TO_SKYD SCRATCH_DIR: runs `run(skyd, scratch)`
    within timeout_s, prints "N passed, M failed" and returns the exit status."""
    if len(sys.argv) != 3:
        print(doc, file=sys.stderr)
        return 2
    skyd, scratch = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    os.makedirs(scratch, exist_ok=True)
    try:
        asyncio.run(asyncio.wait_for(run(skyd, scratch), timeout_s))
    except asyncio.TimeoutError:
        check(f"whole run within {timeout_s} s", False, "timed out")
    return summary()


def summary(started=None):
    """Prints "N passed, M failed" (with the seconds since `started`, a time.monotonic()
    reading, when given) and returns the exit status: 0 when nothing failed."""
    took = f" in {time.monotonic() - started:.1f} s" if started is not None else ""
    print(f"{passed} passed, {failed} failed{took}")
    return 0 if failed == 0 else 1
