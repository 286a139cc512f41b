"""The test client keeps a frame message and its binary together when the caller's time
runs out between the two (a soak saw "binary message without a preceding frame message"
after a pump whose deadline fell there). A real python3-websockets server on loopback sends
a frame message, waits, then sends its binary; the client's short pump must not split them."""

import asyncio
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import serve_harness as H  # noqa: E402
import websockets  # noqa: E402

BINARY_DELAY_S = 0.4


async def serve_one(ws, path=None):
    await ws.send(json.dumps({"type": "hello"}))
    for n in range(3):
        await ws.send(json.dumps({"type": "frame", "subscription": 1, "frame": n}))
        await asyncio.sleep(BINARY_DELAY_S)
        await ws.send(bytes([n]) * 1000)
    await ws.send(json.dumps({"type": "ack", "id": 7}))
    await asyncio.sleep(1.0)


async def main():
    async with websockets.serve(serve_one, "127.0.0.1", 0) as server:
        port = server.sockets[0].getsockname()[1]
        c = await H.Client.connect(f"ws://127.0.0.1:{port}", "pairing")
        # Each pump ends while a binary is still on its way.
        await c.pump(0.1)
        await c.pump(0.1)
        reply = await c.reply(5.0)
        H.check("pairing: the reply after the frames arrives", reply.get("id") == 7,
                H.short(reply))
        got = [(m.get("frame"), b) for m, b, _ in c.frames]
        H.check("pairing: every frame message kept its own binary",
                got == [(n, bytes([n]) * 1000) for n in range(3)],
                f"frames {[(f, None if b is None else len(b)) for f, b in got]}")
        await c.close()
    print(f"harness pairing: {H.passed} passed, {H.failed} failed")
    return 1 if H.failed else 0


if __name__ == "__main__":
    sys.exit(asyncio.run(main()))
