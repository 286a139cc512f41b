"""Drives one `set` through a daemon built with the tracer: a subscriber streams 32x18 PNGs at
4 fps; tracing starts, the set goes, the first frame carrying its revision arrives, tracing
stops. Usage: scenario.py SKYD SCRATCH"""
import asyncio, os, signal, sys, time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "e2e"))
from serve_harness import HEADER, Client, Daemon, make_config

async def main(skyd, scratch):
    os.makedirs(os.path.join(scratch, "web"), exist_ok=True)
    cfg = make_config(scratch, os.path.join(scratch, "state.json"))
    d = Daemon(skyd, scratch, "walk", cfg, env={"WALK_OUT": os.path.join(scratch, "trace.bin")})
    d.start()
    try:
        c = await Client.connect(d.url(), "walk")
        await c.auth()
        r = await c.request({"type": "subscribe", "id": "s", "view": {"width": 32, "height": 18, "fps": 4}})
        sub = r["subscription"]
        for _ in range(4):
            await c.wait_frame(lambda m: m.get("subscription") == sub, 30)
        await c.pump(0.05)
        d.proc.send_signal(signal.SIGUSR1)
        await asyncio.sleep(0.05)
        r = await c.request({"type": "set", "id": "x", "patch": {"sun": {"elevation_deg": 12.5}}})
        rev = r["revision"]
        while True:
            m, b = await c.wait_frame(lambda m: m.get("subscription") == sub, 30)
            if HEADER.unpack_from(b)[4] >= rev:
                break
        d.proc.send_signal(signal.SIGUSR2)
        print("acked", rev, "frame", m.get("frame_number"), HEADER.unpack_from(b)[3:5])
        await c.close()
    finally:
        d.terminate()
        d.proc.wait(30)

asyncio.run(main(sys.argv[1], sys.argv[2]))
