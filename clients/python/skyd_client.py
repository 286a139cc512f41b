"""A small asyncio client for skyd's WebSocket protocol (protocol/PROTOCOL.md), on the standard
library and Debian's python3-websockets (10.4, its asyncio API).

    import asyncio, skyd_client

    async def main():
        async with skyd_client.connect("ws://127.0.0.1:8080/") as sky:
            print(sky.role, sky.limits["max_width"])
            await sky.auth()                      # $SKYD_TOKEN, or auth(token=...), token_file=
            revision = await sky.set({"sun": {"elevation_deg": 5}})
            sub = await sky.subscribe({"width": 320, "height": 180, "fps": 5})
            async for frame in sub:               # Frame: header fields and the PNG payload
                print(frame.frame_number, frame.revision, frame.width, frame.height)

    asyncio.run(main())

One task reads the connection and sorts what arrives: replies go to the request with the same
`id` (every request gets one), `event` messages to every events() stream and on_event()
callback, frames to their subscription, so nothing interleaved with a reply is lost. When the
connection drops (a daemon restart, say) the client reconnects with back-off, repeats its
hello, re-authenticates and re-subscribes; subscriptions and event streams go on where they
were. A request in flight when the connection dropped raises SkydConnectionError: it may or
may not have been applied.
"""

import asyncio
import collections
import json
import logging
import os
import struct

import websockets
import websockets.exceptions

from skyd_png import decode_png

__all__ = ["Client", "Frame", "SkydError", "SkydConnectionError", "connect", "read_token",
           "parse_frame"]

DEFAULT_URL = "ws://127.0.0.1:8080/"
HEADER = struct.Struct("<4sHHQQdIIII")  # the 48-byte binary frame header
FORMATS = {1: "png", 2: "png16"}
log = logging.getLogger("skyd_client")


class SkydError(Exception):
    """An `error` reply: code (stable), message (for people), fields (the server's entries:
    pointer, reason, code) and pointers (the JSON Pointers alone)."""

    def __init__(self, reply, request_type=None):
        self.reply = reply
        self.code = reply.get("code")
        self.message = reply.get("message", "")
        self.fields = [f for f in reply.get("fields") or [] if isinstance(f, dict)]
        self.pointers = [f.get("pointer") for f in self.fields]
        self.request_type = request_type
        if self.fields:
            text = "; ".join(f"{f.get('pointer')}: {f.get('reason')} [{f.get('code')}]"
                             for f in self.fields)
        else:
            text = f"{self.message} [{self.code}]"
        super().__init__(f"{request_type}: {text}" if request_type else text)


class SkydConnectionError(ConnectionError):
    """The connection failed or dropped (and, with reconnect, could not be made again)."""


def read_token(token=None, token_file=None):
    """The controller token as skyctl finds it: token, else $SKYD_TOKEN, else the first line
    of token_file (blanks trimmed; `skyd serve` keeps its own in <state_file>.token)."""
    token = token or os.environ.get("SKYD_TOKEN")
    if token:
        return token
    if token_file:
        with open(token_file, encoding="utf-8") as f:
            line = f.readline().strip(" \t\r\n")
        if not line:
            raise ValueError(f"{token_file}: no token on its first line")
        return line
    raise ValueError("no controller token: pass token=, set $SKYD_TOKEN or give token_file=")


class Frame:
    """One rendered frame: the binary header's fields, the PNG payload, and what it belongs to
    (subscription, a Subscription, or None for a snapshot)."""

    __slots__ = ("format", "frame_number", "revision", "simulation_time_s", "width", "height",
                 "payload", "subscription", "_image")

    def __init__(self, fmt, frame_number, revision, simulation_time_s, width, height, payload,
                 subscription=None):
        self.format = fmt
        self.frame_number = frame_number
        self.revision = revision
        self.simulation_time_s = simulation_time_s
        self.width = width
        self.height = height
        self.payload = payload
        self.subscription = subscription
        self._image = None

    @property
    def format_name(self):
        return FORMATS.get(self.format, str(self.format))

    def image(self):
        """The payload decoded (skyd_png.PngImage: width, height, channels, depth, rows, text);
        decoded once, on the first call."""
        if self._image is None:
            self._image = decode_png(self.payload)
        return self._image

    def __repr__(self):
        return (f"Frame({self.format_name} #{self.frame_number} revision {self.revision} "
                f"{self.width}x{self.height} t={self.simulation_time_s:.3f} "
                f"{len(self.payload)} bytes)")


def parse_frame(binary, subscription=None):
    """A Frame from a binary message; ValueError when the header is not a valid one."""
    if len(binary) < HEADER.size:
        raise ValueError(f"binary message of {len(binary)} bytes, shorter than the header")
    (magic, version, fmt, number, revision, sim_time, width, height, length,
     reserved) = HEADER.unpack_from(binary)
    if magic != b"SKYF" or version != 1 or reserved != 0:
        raise ValueError(f"bad frame header {bytes(binary[:16])!r}")
    if length != len(binary) - HEADER.size:
        raise ValueError(f"payload_length {length} in a message of {len(binary)} bytes")
    return Frame(fmt, number, revision, sim_time, width, height, bytes(binary[HEADER.size:]),
                 subscription)


class _Stream:
    """An async iterator over items pushed by the reader: at most `keep` wait (the oldest
    are dropped and counted); ends when closed, raises the error it was failed with."""

    def __init__(self, keep):
        self._items = collections.deque(maxlen=keep)
        self._wake = asyncio.Event()
        self._error = None
        self._closed = False
        self.dropped = 0

    def _push(self, item):
        if len(self._items) == self._items.maxlen:
            self.dropped += 1
        self._items.append(item)
        self._wake.set()

    def _end(self, error=None):
        self._error = self._error or error
        self._closed = True
        self._wake.set()

    async def next(self, timeout=None):
        """The next item; asyncio.TimeoutError after timeout seconds (None: no limit)."""
        while not self._items:
            if self._error is not None:
                raise self._error
            if self._closed:
                raise StopAsyncIteration
            self._wake.clear()
            await asyncio.wait_for(self._wake.wait(), timeout)
        return self._items.popleft()

    def __aiter__(self):
        return self

    async def __anext__(self):
        return await self.next()


class Subscription(_Stream):
    """Frames of one subscribed view. `number` is the server's number for it on the current
    connection (it changes when the client reconnects); `view` the normalized view."""

    def __init__(self, client, view, keep, decode):
        super().__init__(keep)
        self.client = client
        self.request_view = view
        self.view = None
        self.number = None
        self.decode = decode

    async def next(self, timeout=None):
        frame = await super().next(timeout)
        if self.decode and frame.format in FORMATS:
            frame.image()
        return frame

    async def unsubscribe(self):
        """Stops the stream (the iterator ends, frames unread are dropped) and tells the
        server."""
        self._items.clear()
        self._end()
        await self.client._unsubscribe(self)

    async def __aenter__(self):
        return self

    async def __aexit__(self, *exc):
        await self.unsubscribe()


class Client:
    """A connection to skyd. Make one with `await connect(...)` (or `async with connect(...)`).

    hello (the server's hello), role ("viewer" or "controller"), limits (max_width, max_fps,
    ...) and server describe the current connection; reconnects counts reconnections."""

    def __init__(self, url=None, *, origin=None, open_timeout=10.0, reply_timeout=10.0,
                 client_name=None, simulation_events=False, reconnect=True,
                 reconnect_timeout=60.0, max_backoff=5.0, on_reconnect=None, ssl=None,
                 max_size=1 << 28):
        self.url = url or os.environ.get("SKYD_URL") or DEFAULT_URL
        self.origin = origin
        self.open_timeout = open_timeout
        self.reply_timeout = reply_timeout
        self.client_name = client_name
        self.simulation_events = simulation_events
        self.reconnect = reconnect
        self.reconnect_timeout = reconnect_timeout
        self.max_backoff = max_backoff
        self.on_reconnect = on_reconnect
        self._ssl = ssl
        self._max_size = max_size
        self.hello = {}
        self.role = None
        self.limits = {}
        self.server = None
        self.reconnects = 0
        self._ws = None
        self._token = None      # kept once auth succeeded, for reconnecting
        self._next_id = 0
        self._pending = {}      # id -> (future, request type, hook run by the reader)
        self._subscriptions = {}  # server number -> Subscription (this connection)
        self._active = []       # every Subscription not unsubscribed, across connections
        self._event_streams = []
        self._callbacks = []
        self._connected = asyncio.Event()  # a connection is being read
        self._ready = asyncio.Event()      # ... and its session restored: requests may go
        self._closing = False
        self._failure = None    # why the client gave up
        self._reconnect_task = None
        self._reader = None
        self._tasks = set()     # coroutines of callbacks, kept until done

    # -- connecting ------------------------------------------------------------------------

    async def _open(self):
        """One connection: hello read, the session restored (hello options, auth, views)."""
        kwargs = {"open_timeout": self.open_timeout, "ping_interval": None,
                  "close_timeout": 2, "max_size": self._max_size}
        if self.origin:
            kwargs["origin"] = self.origin
        if self._ssl is not None:
            kwargs["ssl"] = self._ssl
        try:
            ws = await websockets.connect(self.url, **kwargs)
        except (OSError, asyncio.TimeoutError, websockets.exceptions.WebSocketException) as e:
            raise SkydConnectionError(f"cannot connect to {self.url}: {e}") from e
        try:
            try:
                hello = json.loads(await asyncio.wait_for(ws.recv(), self.open_timeout))
            except (asyncio.TimeoutError, websockets.exceptions.ConnectionClosed, ValueError,
                    TypeError) as e:
                raise SkydConnectionError(f"{self.url}: no hello from the server ({e})") from e
            if hello.get("type") == "error":
                raise SkydError(hello, "connect")
            if hello.get("type") != "hello":
                raise SkydConnectionError(f"{self.url}: the first message is not hello")
            self._ws = ws
            self.hello = hello
            self.role = hello.get("role")
            self.limits = hello.get("limits", {})
            self.server = hello.get("server")
            self._subscriptions = {}
            self._reader = asyncio.get_running_loop().create_task(self._read(ws))
            self._connected.set()
            if self.client_name is not None or self.simulation_events:
                message = {"type": "hello", "protocol": 1}
                if self.client_name is not None:
                    message["client"] = self.client_name
                if self.simulation_events:
                    message["simulation_events"] = True
                await self._send_request(message)
            if self._token is not None:
                await self._auth(self._token)
            for sub in list(self._active):
                await self._subscribe(sub)
        except BaseException:
            self._connected.clear()
            if self._ws is ws:
                self._ws = None  # so that the reader, ending, leaves reconnecting to the caller
            await ws.close()
            raise
        self._ready.set()

    async def _reconnect(self):
        loop = asyncio.get_running_loop()
        deadline = (None if self.reconnect_timeout is None
                    else loop.time() + self.reconnect_timeout)
        delay = 0.1
        while not self._closing:
            try:
                await self._open()
            except (SkydConnectionError, asyncio.TimeoutError) as e:
                if deadline is not None and loop.time() + delay > deadline:
                    self._give_up(SkydConnectionError(
                        f"lost the connection to {self.url} and could not reconnect within "
                        f"{self.reconnect_timeout} s: {e}"))
                    return
                log.info("reconnect to %s failed (%s); again in %.1f s", self.url, e, delay)
                await asyncio.sleep(delay)
                delay = min(delay * 2, self.max_backoff)
                continue
            except Exception as e:  # noqa: BLE001 - the server refused the session back
                self._give_up(e)
                return
            self.reconnects += 1
            log.info("reconnected to %s", self.url)
            if self.on_reconnect is not None:
                self._call(self.on_reconnect, self)
            return

    def _give_up(self, error):
        self._failure = error
        self._closing = True
        for sub in self._active:
            sub._end(error)
        for stream in self._event_streams:
            stream._end(error)

    # -- reading -----------------------------------------------------------------------------

    async def _read(self, ws):
        announce = None  # the `frame` message whose binary comes next
        try:
            async for data in ws:
                if isinstance(data, bytes):
                    if announce is None:
                        log.warning("a binary message without a frame message before it")
                        continue
                    self._on_frame(announce, data)
                    announce = None
                    continue
                try:
                    message = json.loads(data)
                except ValueError:
                    log.warning("text that is not JSON from the server: %.80r", data)
                    continue
                if not isinstance(message, dict):
                    continue
                kind = message.get("type")
                if kind == "frame":
                    announce = message
                elif kind == "event":
                    self._on_event(message)
                elif "id" in message:
                    self._on_reply(message)
        except websockets.exceptions.ConnectionClosed:
            pass
        except Exception:  # noqa: BLE001 - a bug here must not leave requests hanging
            log.exception("reading from %s failed", self.url)
            await ws.close()
        self._lost(ws)

    def _lost(self, ws):
        if ws is not self._ws:
            return
        self._connected.clear()
        self._ready.clear()
        code, reason = ws.close_code, ws.close_reason
        error = SkydConnectionError(f"connection to {self.url} closed ({code} {reason})".strip())
        for future, _kind, _hook in self._pending.values():
            if not future.done():
                future.set_exception(error)
        self._pending.clear()
        self._subscriptions = {}
        if self._closing:
            for sub in self._active:
                sub._end(self._failure)
            for stream in self._event_streams:
                stream._end(self._failure)
        elif not self.reconnect:
            self._give_up(error)
        elif self._reconnect_task is None or self._reconnect_task.done():
            log.info("%s; reconnecting", error)
            self._reconnect_task = asyncio.get_running_loop().create_task(self._reconnect())

    def _on_reply(self, message):
        entry = self._pending.pop(message.get("id"), None)
        if entry is None:
            return  # its request timed out
        future, kind, hook = entry
        if future.done():
            return
        if message.get("type") == "error":
            future.set_exception(SkydError(message, kind))
            return
        if hook is not None:
            hook(message)
        future.set_result(message)

    def _on_frame(self, announce, binary):
        try:
            frame = parse_frame(binary)
        except ValueError as e:
            log.warning("dropped a frame: %s", e)
            return
        if frame.frame_number != announce.get("frame_number"):
            log.warning("frame %s announced as %s", frame.frame_number,
                        announce.get("frame_number"))
        if "subscription" in announce:
            sub = self._subscriptions.get(announce["subscription"])
            if sub is not None:
                frame.subscription = sub
                sub._push(frame)
        elif "id" in announce:
            self._on_reply(dict(announce, _frame=frame))

    def _on_event(self, event):
        for stream in self._event_streams:
            stream._push(event)
        for callback in self._callbacks:
            self._call(callback, event)

    def _call(self, callback, *args):
        try:
            result = callback(*args)
            if asyncio.iscoroutine(result):
                task = asyncio.get_running_loop().create_task(result)
                self._tasks.add(task)
                task.add_done_callback(self._tasks.discard)
        except Exception:  # noqa: BLE001 - the caller's callback
            log.exception("callback %r failed", callback)

    # -- requests ------------------------------------------------------------------------------

    async def _send_request(self, message, timeout=None, hook=None):
        timeout = self.reply_timeout if timeout is None else timeout
        self._next_id += 1
        message = dict(message, id=self._next_id)
        future = asyncio.get_running_loop().create_future()
        self._pending[message["id"]] = (future, message.get("type"), hook)
        try:
            await self._ws.send(json.dumps(message))
            return await asyncio.wait_for(asyncio.shield(future), timeout)
        except websockets.exceptions.ConnectionClosed as e:
            raise SkydConnectionError(f"connection to {self.url} closed ({e})") from e
        finally:
            self._pending.pop(message["id"], None)

    async def request(self, message, timeout=None):
        """Sends a client message (any type; `id` is filled in) and returns its reply;
        SkydError for an `error` reply, asyncio.TimeoutError when none comes in time. While
        the client reconnects it waits (within the timeout) for the connection."""
        timeout = self.reply_timeout if timeout is None else timeout
        if self._failure is not None:
            raise self._failure
        if self._closing:
            raise SkydConnectionError("the client is closed")
        if not self._ready.is_set():
            await asyncio.wait_for(self._ready.wait(), timeout)
        return await self._send_request(message, timeout)

    async def _auth(self, token):
        reply = await self._send_request({"type": "auth", "token": token})
        self.role = reply.get("role", self.role)
        return reply

    async def auth(self, token=None, token_file=None):
        """Becomes controller (token found as read_token() finds it); kept for reconnecting.
        Returns the role."""
        token = read_token(token, token_file)
        if not self._ready.is_set():
            await asyncio.wait_for(self._ready.wait(), self.reply_timeout)
        await self._auth(token)
        self._token = token
        return self.role

    async def get_state(self):
        """The `state` reply: {"revision": N, "state": {...}, ...}."""
        return await self.request({"type": "get_state"})

    async def set(self, patch):
        """Applies a patch (controller); returns the new revision."""
        return (await self.request({"type": "set", "patch": patch}))["revision"]

    async def apply_observation(self, metar):
        """Applies a METAR or SPECI report to the weather (controller): the `observation`
        reply, {"revision": N, "report": {...}, "patch": {...}, "unmapped": [...]}. A report
        the server refuses raises SkydError (bad_value at /metar, naming the group)."""
        return await self.request({"type": "apply_observation", "metar": metar})

    async def follow_forecast(self):
        """Follows the daemon's forecast folder (controller): weather.source becomes "forecast"
        and the world moves to the newest forecast through timed transitions; returns the new
        revision. A daemon with no forecast read raises SkydError (bad_value at
        /patch/weather/source, saying why)."""
        return await self.set({"weather": {"source": "forecast"}})

    async def snapshot(self, view, timeout=None, decode=False):
        """One frame rendered with view."""
        reply = await self.request({"type": "snapshot", "view": view}, timeout)
        frame = reply["_frame"]
        if decode:
            frame.image()
        return frame

    async def subscribe(self, view, keep=8, decode=False):
        """A Subscription (async iterator of Frame) for view; at most `keep` frames wait
        unread (older ones are dropped). decode=True decodes each frame's PNG as it is read."""
        sub = Subscription(self, view, keep, decode)
        await self._subscribe(sub)
        self._active.append(sub)
        return sub

    async def _subscribe(self, sub):
        def hook(reply):  # in the reader, before any frame of it can arrive
            sub.number = reply.get("subscription")
            sub.view = reply.get("view")
            self._subscriptions[sub.number] = sub
        await self._send_request({"type": "subscribe", "view": sub.request_view}, hook=hook)

    async def _unsubscribe(self, sub):
        if sub in self._active:
            self._active.remove(sub)
        number = sub.number
        if self._subscriptions.get(number) is sub and self._connected.is_set():
            del self._subscriptions[number]
            try:
                await self._send_request({"type": "unsubscribe", "subscription": number})
            except (SkydConnectionError, SkydError):
                pass

    def events(self, keep=256):
        """An async iterator of the `event` messages that arrive from now on (state_changed,
        and simulation ones when simulation_events is on). close() it when done."""
        stream = _EventStream(self, keep)
        self._event_streams.append(stream)
        return stream

    def on_event(self, callback):
        """Calls callback(event) for every `event` (a coroutine function is scheduled)."""
        self._callbacks.append(callback)

    async def close(self):
        """Closes the connection; iterators end."""
        self._closing = True
        if self._reconnect_task is not None and not self._reconnect_task.done():
            self._reconnect_task.cancel()
        for sub in self._active:
            sub._end()
        for stream in self._event_streams:
            stream._end()
        if self._ws is not None:
            await self._ws.close()

    async def __aenter__(self):
        return self

    async def __aexit__(self, *exc):
        await self.close()


class _EventStream(_Stream):
    def __init__(self, client, keep):
        super().__init__(keep)
        self._client = client

    def close(self):
        self._end()
        if self in self._client._event_streams:
            self._client._event_streams.remove(self)


class connect:
    """`await connect(url, ...)` or `async with connect(url, ...) as client`: a Client,
    connected, its hello read (and, with client_name or simulation_events, answered). Takes
    Client's keywords: origin, open_timeout, reply_timeout, client_name, simulation_events,
    reconnect, reconnect_timeout, max_backoff, on_reconnect, ssl, max_size. The first
    connection is not retried: SkydConnectionError says why it failed."""

    def __init__(self, url=None, **kwargs):
        self._client = Client(url, **kwargs)

    async def _connect(self):
        await self._client._open()
        return self._client

    def __await__(self):
        return self._connect().__await__()

    async def __aenter__(self):
        return await self._connect()

    async def __aexit__(self, *exc):
        await self._client.close()
