#!/usr/bin/env bash
# An installed skyd needs nothing of its source or build tree: `cmake --install BUILD --prefix
# P` into a temporary folder, then, with the source and build trees hidden, the installed skyd
# renders every installed atmosphere and weather preset and `skyd serve`, started without
# --config, reads the installed configuration, serves the installed web client (checked with
# curl against the installed files) and lists the installed presets to the installed skyctl.
#
# Hidden means: in a private mount namespace (unshare; as root, or as a user where user
# namespaces are allowed) an empty tmpfs lies over the source tree and the build tree, so their
# files are gone for every process of the check; and $SKYD_NO_SOURCE_TREE=1 turns off skyd's
# source-tree fallback (server/cli/install_paths.h) even where no namespace can be made. A
# first pass with the installed presets moved away must fail and name the installed folder:
# it shows that the checks reach the installation and nothing else.
#
# Usage: test_install.sh BUILD_DIR SOURCE_DIR BUILT_PREFIX BINDIR CONFDIR DATADIR OUT_DIR
# (what the build was configured with: CMAKE_INSTALL_PREFIX, CMAKE_INSTALL_FULL_BINDIR and
# skyd's configuration and data folders, CMakeLists.txt's SKYD_INSTALL_CONFDIR and _DATADIR.)
# $SKYD_DAEMON_LD_PRELOAD goes to the installed skyd only (the sanitizer build's preloads).
set -u
build=$(cd "$1" && pwd)
source_dir=$(cd "$2" && pwd)
built_prefix=${3%/}
out=$7
mkdir -p "$out"
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

scratch=$(mktemp -d /tmp/skyd-install-test.XXXXXX)
trap 'rm -rf "$scratch"' EXIT
prefix=$scratch/prefix
# The sanitizer build's LeakSanitizer reads its suppressions from the source tree, which the
# checks hide: a copy goes with them.
if [[ "${LSAN_OPTIONS:-}" =~ suppressions=([^:]+) ]]; then
  supp=${BASH_REMATCH[1]}
  cp "$supp" "$scratch/lsan.supp" || exit 1
  export LSAN_OPTIONS=${LSAN_OPTIONS/"$supp"/"$scratch/lsan.supp"}
fi
if ! cmake --install "$build" --prefix "$prefix" >"$out/install.log" 2>&1; then
  echo "FAIL: cmake --install: $(tail -5 "$out/install.log")"
  exit 1
fi

# What was installed, and where (GNUInstallDirs relative to the prefix; /etc and /var when
# the build's prefix is /usr, where they do not move with --prefix).
under_prefix() { # FULL_DIR_FOR_BUILT_PREFIX -> the same directory under $prefix
  case "$1" in
    "$built_prefix"/*) echo "$prefix${1#"$built_prefix"}" ;;
    *) echo "$1" ;;
  esac
}
bindir=$(under_prefix "$4")
confdir=$(under_prefix "$5")
datadir=$(under_prefix "$6")
for f in "$bindir/skyd" "$bindir/skyctl" "$confdir/skyd.json" "$datadir/web/index.html"; do
  if [ -s "$f" ]; then pass; else fail "not installed: $f"; fi
done
for kind in atmosphere weather; do
  want=$(cd "$source_dir/config/$kind" && ls -- *.json | sort | tr '\n' ' ')
  got=$(cd "$datadir/$kind" 2>/dev/null && ls -- *.json | sort | tr '\n' ' ')
  if [ "$got" = "$want" ] && [ "$got" != "" ]; then pass; else fail "$kind presets: installed '$got', shipped '$want'"; fi
done
if grep -qF -e "$source_dir" -e "$build" -e '"clients/web"' "$confdir/skyd.json"; then
  fail "the installed configuration names a development path: $(cat "$confdir/skyd.json")"
else pass; fi
atmospheres=$(cd "$datadir/atmosphere" && ls -- *.json | sed 's/\.json$//' | tr '\n' ' ')
weathers=$(cd "$datadir/weather" && ls -- *.json | sed 's/\.json$//' | tr '\n' ' ')

# The checks that run with the trees hidden: a script of their own in the scratch folder, since
# this one lies in the source tree. Arguments: MODE (check | moved-presets) PREFIX ...
cat >"$scratch/hidden.sh" <<'EOF'
#!/usr/bin/env bash
set -u
mode=$1 bindir=$2 datadir=$3 confdir=$4 scratch=$5 atmospheres=$6 weathers=$7
shift 7
for tree in "$@"; do # given only where a mount namespace was made
  mount -t tmpfs -o size=1m skyd-hidden "$tree" || exit 1
  if [ -n "$(ls -A "$tree")" ]; then echo "FAIL: $tree is still visible"; exit 1; fi
done
export SKYD_NO_SOURCE_TREE=1
cd "$scratch" || exit 1
skyd() { LD_PRELOAD="${SKYD_DAEMON_LD_PRELOAD:-}" "$bindir/skyd" "$@"; }
status=0
if [ "$mode" = moved-presets ]; then
  # The installed presets moved away: the preset cannot be found, and the message names the
  # installation's folder (nothing else was looked at).
  skyd render --width 16 --height 9 --preset earth --out "$scratch/none.png" 2>"$scratch/moved.err"
  rc=$?
  if [ $rc -ne 2 ] || ! grep -qF "$datadir/atmosphere/earth.json" "$scratch/moved.err"; then
    echo "FAIL: without the installed presets: exit $rc: $(cat "$scratch/moved.err")"; exit 1
  fi
  echo "moved-presets: refused as it should be: $(tail -1 "$scratch/moved.err")"
  exit 0
fi
# Every preset renders. A process starts slowly (seconds for pipelines and cloud noise on a
# CPU), so each renders two frames: weather A, then at the end of a transition to weather B
# (--weather A --weather-to B), in one of the atmospheres; every preset is used at least once.
set -- $atmospheres; atmosphere_list=("$@")
set -- $weathers; weather_list=("$@")
runs=$(( (${#weather_list[@]} + 1) / 2 ))
[ ${#atmosphere_list[@]} -gt "$runs" ] && runs=${#atmosphere_list[@]}
for ((i = 0; i < runs; i++)); do
  a=${atmosphere_list[i % ${#atmosphere_list[@]}]}
  w=${weather_list[(2 * i) % ${#weather_list[@]}]}
  to=${weather_list[(2 * i + 1) % ${#weather_list[@]}]}
  pattern="$scratch/$a-$w-$to-%d.png"
  if ! skyd render --width 48 --height 27 --preset "$a" --weather "$w" --weather-to "$to" \
       --frames 2 --step-s 600 --out "$pattern" >"$scratch/render.out" 2>"$scratch/render.err"; then
    echo "FAIL: render --preset $a --weather $w --weather-to $to: $(cat "$scratch/render.err")"; status=1
    continue
  fi
  for frame in 0 1; do
    png=${pattern/\%d/$frame}
    if ! grep -qxF "$png" "$scratch/render.out" || ! head -c 8 "$png" | od -An -tx1 | grep -q "89 50 4e 47"; then
      echo "FAIL: render --preset $a --weather $w --weather-to $to: no $png ($(cat "$scratch/render.out"))"; status=1
    fi
  done
  echo "rendered --preset $a --weather $w --weather-to $to"
done
# The daemon without --config: the installed configuration, web client and presets.
LD_PRELOAD="${SKYD_DAEMON_LD_PRELOAD:-}" "$bindir/skyd" serve --port 0 --state-file "$scratch/state.json" \
  >"$scratch/serve.out" 2>"$scratch/serve.err" &
daemon=$!
url=""
for _ in $(seq 1 600); do
  url=$(sed -n 's/^skyd: listening on \(http:[^ ]*\)$/\1/p' "$scratch/serve.out")
  [ -n "$url" ] && break
  kill -0 $daemon 2>/dev/null || break
  sleep 0.1
done
if [ -z "$url" ]; then
  echo "FAIL: skyd serve did not listen: $(cat "$scratch/serve.err")"; kill $daemon 2>/dev/null; exit 1
fi
grep -qF "configuration $confdir/skyd.json" "$scratch/serve.err" ||
  { echo "FAIL: serve did not read $confdir/skyd.json: $(cat "$scratch/serve.err")"; status=1; }
for page in "" "style.css" "js/app.js"; do
  file="$datadir/web/${page:-index.html}"
  if ! curl -sf -o "$scratch/page" "$url$page" || ! cmp -s "$scratch/page" "$file"; then
    echo "FAIL: GET /$page is not $file"; status=1
  else
    echo "served /$page = $file"
  fi
done
ws=${url/http:/ws:}
for kind in atmosphere weather; do
  want=$([ $kind = atmosphere ] && echo "$atmospheres" || echo "$weathers")
  got=$("$bindir/skyctl" --url "$ws" --timeout 60 preset --list --kind $kind 2>"$scratch/skyctl.err" | tr -s ' \n' ' ')
  if [ "$(echo $got | tr ' ' '\n' | sort | tr '\n' ' ')" != "$(echo $want | tr ' ' '\n' | sort | tr '\n' ' ')" ]; then
    echo "FAIL: skyctl preset --list --kind $kind: '$got' ($(cat "$scratch/skyctl.err")), installed '$want'"; status=1
  else
    echo "serve lists the $kind presets: $got"
  fi
done
kill -TERM $daemon
wait $daemon
rc=$?
[ $rc -eq 0 ] || { echo "FAIL: skyd serve exited $rc at SIGTERM: $(tail -5 "$scratch/serve.err")"; status=1; }
exit $status
EOF
chmod +x "$scratch/hidden.sh"

# A private mount namespace where one can be made: as root, or in a user namespace.
trees=("$source_dir")
case "$build/" in "$source_dir"/*) ;; *) trees+=("$build") ;; esac
run_hidden() {
  if [ "$namespace" != "" ]; then
    $namespace "$scratch/hidden.sh" "$@" "${trees[@]}"
  else
    "$scratch/hidden.sh" "$@"
  fi
}
namespace=""
if unshare --mount --propagation private true 2>/dev/null; then
  namespace="unshare --mount --propagation private"
elif unshare --user --map-root-user --mount true 2>/dev/null; then
  namespace="unshare --user --map-root-user --mount"
fi
if [ "$namespace" != "" ]; then
  echo "the source and build trees are hidden by tmpfs mounts ($namespace)"
else
  echo "no mount namespace to be had: the source tree is hidden by SKYD_NO_SOURCE_TREE=1 alone"
fi

args=("$bindir" "$datadir" "$confdir" "$scratch" "$atmospheres" "$weathers")
mv "$datadir/atmosphere" "$datadir/atmosphere.away"
if run_hidden moved-presets "${args[@]}"; then pass; else fail "the check without installed presets"; fi
mv "$datadir/atmosphere.away" "$datadir/atmosphere"
if run_hidden check "${args[@]}"; then pass; else fail "the installed skyd"; fi
cp -r "$scratch"/*.png "$out/" 2>/dev/null

echo "install: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
