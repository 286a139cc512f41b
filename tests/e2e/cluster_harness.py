"""Support for tests/e2e/test_cluster.py: the real redis-server and haproxy the test starts on
free loopback ports and stops (by the process it started, never by name), a minimal RESP
client to read Redis's keys, and skyd nodes configured for one shared world."""

import os
import signal
import socket
import subprocess
import time

from serve_harness import Daemon, info, make_config, stop_process

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIG_DIR = os.path.normpath(os.path.join(HERE, "..", "..", "config"))
REDIS_CONF = os.path.join(CONFIG_DIR, "redis.conf")
HAPROXY_CFG = os.path.join(CONFIG_DIR, "haproxy.cfg")


def free_port():
    """A loopback port nobody listens on now (the kernel's pick)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def resp(port, *args, timeout=2.0):
    """One Redis command over a fresh connection; returns the decoded reply (bytes, int,
    list, None) or raises OSError / RuntimeError for an error reply."""
    out = b"*%d\r\n" % len(args)
    for a in args:
        a = a if isinstance(a, bytes) else str(a).encode()
        out += b"$%d\r\n%s\r\n" % (len(a), a)
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(out)
        f = s.makefile("rb")
        return _read_reply(f)


def resp_pipeline(port, commands, timeout=10.0):
    """Many Redis commands on one connection, sent at once; returns their replies."""
    parts = []
    for args in commands:
        parts.append(b"*%d\r\n" % len(args))
        for a in args:
            a = a if isinstance(a, bytes) else str(a).encode()
            parts.append(b"$%d\r\n%s\r\n" % (len(a), a))
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(b"".join(parts))
        f = s.makefile("rb")
        return [_read_reply(f) for _ in commands]


def _read_reply(f):
    line = f.readline()
    if not line:
        raise OSError("connection closed")
    kind, rest = line[:1], line[1:-2]
    if kind == b"+":
        return rest
    if kind == b"-":
        raise RuntimeError(rest.decode())
    if kind == b":":
        return int(rest)
    if kind == b"$":
        n = int(rest)
        if n < 0:
            return None
        data = f.read(n + 2)
        return data[:-2]
    if kind == b"*":
        n = int(rest)
        return None if n < 0 else [_read_reply(f) for _ in range(n)]
    raise OSError(f"unexpected reply {line!r}")


class Redis:
    """redis-server with config/redis.conf (append-only file, appendfsync always)."""

    def __init__(self, scratch, port):
        self.port = port
        self.dir = os.path.join(scratch, "redis")
        os.makedirs(self.dir, exist_ok=True)
        self.log_path = os.path.join(scratch, "redis.log")
        self.proc = None

    def start(self, timeout=10.0):
        log = open(self.log_path, "ab")
        self.proc = subprocess.Popen(["redis-server", REDIS_CONF, "--port", str(self.port),
                                      "--dir", self.dir],
                                     stdin=subprocess.DEVNULL, stdout=log, stderr=log)
        log.close()
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if resp(self.port, "PING") == b"PONG":
                    return
            except (OSError, RuntimeError):
                pass
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise RuntimeError(f"redis-server on port {self.port} did not start; see {self.log_path}")

    def stop(self, sig=signal.SIGTERM):
        stop_process(self.proc, sig, timeout=10)
        self.proc = None


class Haproxy:
    """haproxy with config/haproxy.cfg in front of three node ports."""

    def __init__(self, scratch, port, node_ports):
        self.port = port
        self.env = dict(os.environ, SKYD_LB_PORT=str(port))
        for i, p in enumerate(node_ports, 1):
            self.env[f"SKYD_NODE{i}_PORT"] = str(p)
        self.log_path = os.path.join(scratch, "haproxy.log")
        self.proc = None

    def start(self, timeout=10.0):
        log = open(self.log_path, "ab")
        self.proc = subprocess.Popen(["haproxy", "-db", "-f", HAPROXY_CFG],
                                     stdin=subprocess.DEVNULL, stdout=log, stderr=log,
                                     env=self.env)
        log.close()
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                return
            except OSError:
                if self.proc.poll() is not None:
                    break
                time.sleep(0.05)
        raise RuntimeError(f"haproxy on port {self.port} did not start; see {self.log_path}")

    def url(self):
        return f"ws://127.0.0.1:{self.port}/"

    def stop(self):
        stop_process(self.proc, timeout=10)
        self.proc = None


def node_config(scratch, name, redis_port, world, port=0, initial_state=None):
    config = make_config(scratch, os.path.join(scratch, f"{name}-state.json"))
    config["listen"]["port"] = port
    config["cluster"] = {"redis": f"redis://127.0.0.1:{redis_port}", "world": world}
    if initial_state is not None:
        config["initial_state"] = initial_state
    return config


def start_node(skyd, scratch, name, redis_port, world, port=0, initial_state=None):
    d = Daemon(skyd, scratch, name, node_config(scratch, name, redis_port, world, port,
                                                initial_state))
    t0 = time.monotonic()
    d.start()
    info(f"{name} listening on port {d.port} after {time.monotonic() - t0:.1f} s")
    return d


def run_bad_config(skyd, scratch, name, cluster, timeout=60):
    """`skyd serve` with a bad cluster section: (exit status, stderr)."""
    config = make_config(scratch, os.path.join(scratch, f"{name}-state.json"))
    config["cluster"] = cluster
    d = Daemon(skyd, scratch, name, config)
    with open(d.config_path, "w") as f:
        import json
        json.dump(config, f)
    p = subprocess.run([skyd, "serve", "--config", d.config_path], cwd=scratch,
                       stdin=subprocess.DEVNULL, capture_output=True, timeout=timeout)
    return p.returncode, p.stderr.decode("utf-8", "replace")
