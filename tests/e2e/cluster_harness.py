"""Support for tests/e2e/test_cluster.py: the real redis-server and haproxy the test starts on
free loopback ports and stops (by the process it started, never by name), a minimal RESP
client to read Redis's keys (as the operators' default user unless told otherwise), and skyd
nodes configured for one shared world, authenticating as the user "skyd" of config/redis.conf
with its password in the URL or in a password file."""

import os
import signal
import socket
import subprocess
import time
import urllib.parse

from serve_harness import Daemon, info, make_config, stop_process

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
CONFIG_DIR = os.path.join(REPO, "config")
REDIS_CONF_SCRIPT = os.path.join(REPO, "scripts", "redis-conf.sh")
HAPROXY_CFG = os.path.join(CONFIG_DIR, "haproxy.cfg")

# The nodes' password holds what a URL must encode ('@', ':', '/', '%', a space): the URL form
# is percent-encoded, the file form is the line as it is.
SKYD_PASSWORD = "n0de p@ss:w/rd%7"
ADMIN_PASSWORD = "operator-" + os.urandom(12).hex()
ADMIN = ("default", ADMIN_PASSWORD)


def free_port():
    """A loopback port nobody listens on now (the kernel's pick)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _command(args):
    out = [b"*%d\r\n" % len(args)]
    for a in args:
        a = a if isinstance(a, bytes) else str(a).encode()
        out.append(b"$%d\r\n%s\r\n" % (len(a), a))
    return b"".join(out)


def resp(port, *args, timeout=2.0, auth=ADMIN):
    """One Redis command over a fresh connection, after AUTH as `auth` (user, password; None:
    no AUTH); returns the decoded reply (bytes, int, list, None) or raises OSError /
    RuntimeError for an error reply (AUTH's included)."""
    return resp_pipeline(port, [args], timeout=timeout, auth=auth)[0]


def resp_pipeline(port, commands, timeout=10.0, auth=ADMIN):
    """Many Redis commands on one connection, sent at once after AUTH; returns their replies
    (the first error reply raises)."""
    parts = [_command(["AUTH", *auth])] if auth else []
    parts += [_command(args) for args in commands]
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(b"".join(parts))
        f = s.makefile("rb")
        if auth:
            _read_reply(f)
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


def write_secret(path, text, mode=0o600):
    """A password file: `text` and a newline, with `mode`."""
    with open(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), "w") as f:
        f.write(text + "\n")
    os.chmod(path, mode)
    return path


class Redis:
    """redis-server with config/redis.conf (append-only file, appendfsync always; users who
    must authenticate), its users' passwords filled in by scripts/redis-conf.sh from password
    files and read from stdin."""

    def __init__(self, scratch, port):
        self.port = port
        self.dir = os.path.join(scratch, "redis")
        os.makedirs(self.dir, exist_ok=True)
        self.log_path = os.path.join(scratch, "redis.log")
        self.skyd_password_file = write_secret(os.path.join(scratch, "redis-skyd-password"),
                                               SKYD_PASSWORD)
        self.admin_password_file = write_secret(os.path.join(scratch, "redis-default-password"),
                                                ADMIN_PASSWORD)
        self.proc = None

    def start(self, timeout=10.0):
        conf = subprocess.run([REDIS_CONF_SCRIPT, self.skyd_password_file,
                               self.admin_password_file], check=True, capture_output=True).stdout
        log = open(self.log_path, "ab")
        self.proc = subprocess.Popen(["redis-server", "-", "--port", str(self.port),
                                      "--dir", self.dir],
                                     stdin=subprocess.PIPE, stdout=log, stderr=log)
        log.close()
        self.proc.stdin.write(conf)
        self.proc.stdin.close()
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


def cluster_section(redis_port, world, password_in="url", password=SKYD_PASSWORD,
                    password_file=None):
    """The nodes' "cluster" section: the password percent-encoded in the URL, or in a file."""
    if password_in == "url":
        quoted = urllib.parse.quote(password, safe="")
        return {"redis": f"redis://skyd:{quoted}@127.0.0.1:{redis_port}", "world": world}
    return {"redis": f"redis://skyd@127.0.0.1:{redis_port}", "world": world,
            "redis_password_file": password_file}


def node_config(scratch, name, redis_port, world, port=0, initial_state=None, password_in="url"):
    config = make_config(scratch, os.path.join(scratch, f"{name}-state.json"))
    config["listen"]["port"] = port
    password_file = None
    if password_in == "file":
        password_file = write_secret(os.path.join(scratch, f"{name}-redis-password"),
                                     SKYD_PASSWORD)
    config["cluster"] = cluster_section(redis_port, world, password_in,
                                        password_file=password_file)
    if initial_state is not None:
        config["initial_state"] = initial_state
    return config


def start_node(skyd, scratch, name, redis_port, world, port=0, initial_state=None,
               password_in="url"):
    d = Daemon(skyd, scratch, name, node_config(scratch, name, redis_port, world, port,
                                                initial_state, password_in))
    t0 = time.monotonic()
    d.start()
    info(f"{name} listening on port {d.port} after {time.monotonic() - t0:.1f} s")
    return d


def run_bad_config(skyd, scratch, name, cluster, timeout=60):
    """`skyd serve` with a bad cluster section: (exit status, stderr, stdout)."""
    config = make_config(scratch, os.path.join(scratch, f"{name}-state.json"))
    config["cluster"] = cluster
    d = Daemon(skyd, scratch, name, config)
    with open(d.config_path, "w") as f:
        import json
        json.dump(config, f)
    p = subprocess.run([skyd, "serve", "--config", d.config_path], cwd=scratch,
                       stdin=subprocess.DEVNULL, capture_output=True, timeout=timeout)
    return (p.returncode, p.stderr.decode("utf-8", "replace"),
            p.stdout.decode("utf-8", "replace"))
