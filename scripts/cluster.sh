#!/usr/bin/env bash
# `make cluster`: Redis, three skyd nodes sharing one world and haproxy in front of them, all
# on loopback ports, in the foreground; prints the one URL to open. Ctrl-C stops everything
# it started (by process id). Data and logs in var/cluster/ (Redis's append-only file keeps
# the world between runs).
#   scripts/cluster.sh [BUILD]      environment: SKYD_CLUSTER_PORT (haproxy, default 8090),
#                                   SKYD_CLUSTER_WORLD (default "demo")
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
skyd="$build/skyd"
[ -x "$skyd" ] || { echo "cluster: $skyd is missing: run make build" >&2; exit 1; }
for tool in redis-server haproxy python3; do
  command -v "$tool" >/dev/null || { echo "cluster: $tool is missing: run make deps" >&2; exit 1; }
done

dir=var/cluster
mkdir -p "$dir/redis"
world=${SKYD_CLUSTER_WORLD:-demo}
lb_port=${SKYD_CLUSTER_PORT:-8090}
free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
redis_port=$(free_port)
node_ports=("$(free_port)" "$(free_port)" "$(free_port)")
token_file="$dir/controller-token"
[ -s "$token_file" ] || (umask 077; head -c 18 /dev/urandom | base64 | tr '+/' '-_' > "$token_file")
token=$(cat "$token_file")
# Redis's passwords (config/redis.conf's users): the nodes' and the operators' (redis-cli -a).
for user in skyd default; do
  [ -s "$dir/redis-$user-password" ] ||
    (umask 077; head -c 24 /dev/urandom | base64 | tr '+/' '-_' > "$dir/redis-$user-password")
done

pids=()
stop() {
  trap - INT TERM EXIT
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  echo "cluster: stopped"
}
trap stop INT TERM EXIT

# The configuration, passwords filled in, through stdin: on no command line, in no other file.
scripts/redis-conf.sh "$dir/redis-skyd-password" "$dir/redis-default-password" |
  redis-server - --port "$redis_port" --dir "$dir/redis" >"$dir/redis.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
  python3 - "$redis_port" <<'PY' 2>/dev/null && break
import socket, sys
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=1)
s.sendall(b"PING\r\n")
sys.exit(0 if s.recv(16).startswith((b"+PONG", b"-NOAUTH")) else 1)
PY
  sleep 0.1
done

for i in 1 2 3; do
  port=${node_ports[$((i - 1))]}
  cat >"$dir/node$i.json" <<JSON
{
  "listen": { "address": "127.0.0.1", "port": $port },
  "web_root": "clients/web",
  "state_file": "$dir/node$i-state.json",
  "controller_token": "$token",
  "allowed_origins": ["http://127.0.0.1:$lb_port", "http://localhost:$lb_port"],
  "cluster": { "redis": "redis://skyd@127.0.0.1:$redis_port", "world": "$world",
               "redis_password_file": "$dir/redis-skyd-password" },
  "initial_state": { "clock": { "utc": "now", "time_scale": 1, "sky_bodies": "ephemeris" } }
}
JSON
  "$skyd" serve --config "$dir/node$i.json" >"$dir/node$i.out" 2>"$dir/node$i.log" &
  pids+=($!)
done
for i in 1 2 3; do
  for _ in $(seq 600); do
    grep -q "listening on" "$dir/node$i.out" 2>/dev/null && break
    kill -0 "${pids[$i]}" 2>/dev/null || { echo "cluster: node$i failed:" >&2; tail -5 "$dir/node$i.log" >&2; exit 1; }
    sleep 0.1
  done
done

SKYD_LB_PORT=$lb_port SKYD_NODE1_PORT=${node_ports[0]} SKYD_NODE2_PORT=${node_ports[1]} \
  SKYD_NODE3_PORT=${node_ports[2]} haproxy -db -f config/haproxy.cfg >"$dir/haproxy.log" 2>&1 &
pids+=($!)
sleep 0.5
kill -0 "${pids[4]}" 2>/dev/null || { echo "cluster: haproxy failed:" >&2; tail -5 "$dir/haproxy.log" >&2; exit 1; }

echo "cluster: redis on 127.0.0.1:$redis_port (redis-cli -p $redis_port -a \"\$(cat $dir/redis-default-password)\"), nodes on ${node_ports[*]}, world \"$world\"; logs in $dir/"
echo "cluster: open http://127.0.0.1:$lb_port/#token=$token"
echo "cluster: Ctrl-C stops it"
wait -n "${pids[@]}" || true
echo "cluster: a process exited; stopping the rest" >&2
