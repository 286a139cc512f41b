#!/bin/sh
# config/redis.conf with passwords for its users, on stdout, for `redis-server -` to read from
# stdin (so that no password or hash is on a command line or in another file):
#   scripts/redis-conf.sh SKYD_PASSWORD_FILE [DEFAULT_PASSWORD_FILE] | redis-server - --port N
# Each file's first line is the password (a trailing CR is dropped, as skyd drops it); the
# user "skyd" (and the operators' "default" user when its file is given) gets it as a SHA-256
# hash. SKYD_PASSWORD_FILE is the file the nodes' cluster.redis_password_file names
# (docs/SCALING.md).
set -eu
conf="$(dirname "$0")/../config/redis.conf"
hash_of() {
  [ -r "$1" ] || { echo "redis-conf: cannot read $1" >&2; exit 1; }
  line=$(head -n 1 "$1" | tr -d '\r')
  [ -n "$line" ] || { echo "redis-conf: $1 holds no password on its first line" >&2; exit 1; }
  printf '%s' "$line" | sha256sum | cut -d ' ' -f 1
}
[ $# -ge 1 ] && [ $# -le 2 ] || { echo "usage: $0 SKYD_PASSWORD_FILE [DEFAULT_PASSWORD_FILE]" >&2; exit 2; }
skyd_hash=$(hash_of "$1")
default_hash=""
[ $# -lt 2 ] || default_hash=$(hash_of "$2")
grep -q '^user skyd ' "$conf" || { echo "redis-conf: $conf has no user skyd line" >&2; exit 1; }
awk -v skyd="$skyd_hash" -v default="$default_hash" '
  /^user skyd / { print $0 " #" skyd; next }
  /^user default / && default != "" { print $0 " #" default; next }
  { print }' "$conf"
