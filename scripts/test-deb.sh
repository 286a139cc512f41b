#!/usr/bin/env bash
# Installs the packages `make deb` built (skyd, skyd-clients) with dpkg -i and checks the
# installation as a user would meet it: the system user skyd and its state directory, the
# configuration as a conffile, the unit installed, enabled and verified by systemd-analyze; the
# installed skyd renders a frame as the user skyd; the daemon, started as the unit starts it,
# makes its controller token at the first start, serves the installed web client and takes a
# change from the installed skyctl with that token; Debian's python3 imports the module; the
# manual pages are found. Then it purges the packages again (unless they were installed
# before) and checks that the state went with them. .ci/run calls it after `make deb`.
# Needs root (or sudo); no systemd has to run.
#   scripts/test-deb.sh [DEB_DIR]    (default build-deb)
set -uo pipefail
cd "$(dirname "$0")/.."
debs=${1:-build-deb}
as_root=()
[ "$(id -u)" -eq 0 ] || as_root=(sudo)
passed=0
failed=0
pass() { passed=$((passed + 1)); echo "ok: $*"; }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
expect() { # NAME COMMAND...: the command succeeds
  local name=$1; shift
  if "$@"; then pass "$name"; else fail "$name"; fi
}

version=$(dpkg-parsechangelog -S Version)
arch=$(dpkg --print-architecture)
packages=("$debs/skyd_${version}_$arch.deb" "$debs/skyd-clients_${version}_$arch.deb")
for p in "${packages[@]}"; do
  [ -f "$p" ] || { echo "test-deb: $p is missing: run make deb first" >&2; exit 1; }
done
installed_before=$(dpkg-query -W -f='${Status}\n' skyd skyd-clients 2>/dev/null | grep -c "install ok installed")

scratch=$(mktemp -d /tmp/skyd-deb-test.XXXXXX)
daemon=""
cleanup() {
  [ -n "$daemon" ] && "${as_root[@]}" kill "$daemon" 2>/dev/null
  rm -rf "$scratch"
}
trap cleanup EXIT
chmod 0755 "$scratch"

echo "test-deb: dpkg -i ${packages[*]}"
if ! "${as_root[@]}" dpkg -i "${packages[@]}"; then
  echo "test-deb: dpkg -i failed" >&2
  exit 1
fi

# The system user, its state directory, the conffile, the unit.
expect "the system user skyd, home /var/lib/skyd" \
  sh -c 'getent passwd skyd | grep -q "^skyd:x:[0-9]*:[0-9]*:[^:]*:/var/lib/skyd:/usr/sbin/nologin$"'
expect "/var/lib/skyd belongs to skyd, mode 700" \
  "${as_root[@]}" sh -c '[ "$(stat -c "%U:%G %a" /var/lib/skyd)" = "skyd:skyd 700" ]'
expect "/etc/skyd/skyd.json is a conffile" \
  sh -c 'dpkg-query -W -f="\${Conffiles}\n" skyd | grep -q "^ /etc/skyd/skyd.json "'
expect "skyd.service is enabled" \
  test -L /etc/systemd/system/multi-user.target.wants/skyd.service
unit=$(dpkg -L skyd | grep '/systemd/system/skyd.service$' | head -1)
expect "systemd-analyze verify $unit" sh -c "systemd-analyze verify --man=no '$unit' 2>&1 | tee '$scratch/verify.txt' | (! grep -q .)"

# A frame, rendered by the installed skyd as the service's user, with installed presets.
"${as_root[@]}" chown skyd:skyd "$scratch"
frame="$scratch/frame.png"
if "${as_root[@]}" setpriv --reuid=skyd --regid=skyd --init-groups env HOME=/var/lib/skyd /usr/bin/skyd render --width 64 \
     --height 36 --preset mars --weather fair_cumulus --set sun.elevation_deg=20 \
     --out "$frame" >"$scratch/render.out" 2>"$scratch/render.err" &&
   [ "$(cat "$scratch/render.out")" = "$frame" ] &&
   /usr/bin/python3 - "$frame" <<'EOF'
import struct, sys
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
assert struct.unpack(">II", data[16:24]) == (64, 36), struct.unpack(">II", data[16:24])
EOF
then
  pass "the installed skyd renders a 64x36 frame as skyd ($(tail -1 "$scratch/render.err"))"
else
  fail "skyd render as skyd: $(cat "$scratch/render.err")"
fi

# The first start, as the unit starts it: the token is made, the web client served, skyctl
# changes the world with the token.
"${as_root[@]}" rm -f /var/lib/skyd/state.json /var/lib/skyd/state.json.token
"${as_root[@]}" setpriv --reuid=skyd --regid=skyd --init-groups env HOME=/var/lib/skyd /usr/bin/skyd serve \
  --config /etc/skyd/skyd.json --state-file /var/lib/skyd/state.json --port 0 \
  >"$scratch/serve.out" 2>"$scratch/serve.err" &
daemon=$!
url=""
for _ in $(seq 1 600); do
  url=$(sed -n 's/^skyd: listening on \(http:[^ ]*\)$/\1/p' "$scratch/serve.out")
  [ -n "$url" ] && break
  kill -0 "$daemon" 2>/dev/null || break
  sleep 0.1
done
if [ -z "$url" ]; then
  fail "skyd serve as skyd did not listen: $(cat "$scratch/serve.err")"
else
  pass "skyd serve as skyd listens on $url"
  expect "skyd serve read the cloud noise skyd render kept in ~skyd/.cache/skyd" \
    grep -q '^skyd: cloud noise read from the cache in /var/lib/skyd/.cache/skyd$' "$scratch/serve.err"
  sleep 0.5 # the control line follows the listening line
  shown=$(sed -n 's/^skyd: control at .*#token=\([0-9a-f]*\)$/\1/p' "$scratch/serve.out")
  kept=$("${as_root[@]}" cat /var/lib/skyd/state.json.token 2>/dev/null)
  expect "the first start made the controller token, kept in /var/lib/skyd/state.json.token" \
    "${as_root[@]}" sh -c "[ -n '$shown' ] && [ '$shown' = '$kept' ] &&
           [ \"\$(stat -c '%U %a' /var/lib/skyd/state.json.token)\" = 'skyd 600' ]"
  expect "GET / serves /usr/share/skyd/web/index.html" \
    sh -c "curl -sf '$url' -o '$scratch/index.html' && cmp -s '$scratch/index.html' /usr/share/skyd/web/index.html"
  ws=${url/http:/ws:}
  expect "skyctl --token-file changes the world" \
    sh -c "${as_root[*]} skyctl --url '$ws' --timeout 60 --token-file /var/lib/skyd/state.json.token set clock.time_scale=0 >'$scratch/set.out' 2>&1"
  expect "skyctl reads the change back" \
    sh -c "[ \"\$(skyctl --url '$ws' --timeout 60 get clock.time_scale 2>&1)\" = 0 ]"
  "${as_root[@]}" kill -TERM "$daemon"
  wait "$daemon"
  rc=$?
  daemon=""
  expect "skyd serve exits 0 at SIGTERM and saved the state" \
    "${as_root[@]}" sh -c "[ $rc -eq 0 ] && test -s /var/lib/skyd/state.json"
fi

expect "Debian's python3 imports skyd_client and skyd_png" \
  sh -c 'cd / && /usr/bin/python3 -I -c "import skyd_client, skyd_png; print(skyd_client.__file__)"'
if grep -rqs '^path-exclude.*/usr/share/man' /etc/dpkg/dpkg.cfg.d/; then
  # A minimal image's dpkg leaves manual pages out: the packages must still hold them.
  expect "the packages hold skyd(1), skyctl(1), skyd.json(5) (this dpkg excludes man pages)" \
    sh -c "dpkg-deb -c '${packages[0]}' | grep -q 'man1/skyd.1.gz' &&
           dpkg-deb -c '${packages[0]}' | grep -q 'man5/skyd.json.5.gz' &&
           dpkg-deb -c '${packages[1]}' | grep -q 'man1/skyctl.1.gz'"
else
  expect "man finds skyd(1), skyctl(1), skyd.json(5)" \
    sh -c 'man -w skyd >/dev/null && man -w skyctl >/dev/null && man -w 5 skyd.json >/dev/null'
fi

if [ "$installed_before" -eq 0 ]; then
  echo "test-deb: dpkg --purge skyd-clients skyd"
  "${as_root[@]}" dpkg --purge skyd-clients skyd >/dev/null
  expect "purged: no /var/lib/skyd, no /var/cache/skyd, no /etc/skyd, no enabled unit" \
    "${as_root[@]}" sh -c '! [ -e /var/lib/skyd ] && ! [ -e /var/cache/skyd ] && ! [ -e /etc/skyd ] && ! [ -e /etc/systemd/system/multi-user.target.wants/skyd.service ]'
else
  echo "test-deb: skyd was installed before: left installed (this version)"
fi

echo "test-deb: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
