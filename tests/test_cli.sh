#!/usr/bin/env bash
# Command-line contract of `skyd render` and `skyd probe`: exact output formats, errors that
# name the problem, and exit statuses (0 ok, 2 usage). Usage: test_cli.sh SKYD OUTDIR
set -u
skyd=$1
out=$2
mkdir -p "$out"
passed=0
failed=0

pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# expect_ok NAME REGEX CMD...: exit 0 and stdout matching the anchored regex.
expect_ok() {
  local name=$1 regex=$2; shift 2
  local stdout rc
  stdout=$("$@" 2>"$out/stderr.txt"); rc=$?
  if [ $rc -ne 0 ]; then fail "$name: exit $rc: $(cat "$out/stderr.txt")"; return; fi
  if ! printf '%s' "$stdout" | grep -Eqx "$regex"; then fail "$name: stdout '$stdout' !~ $regex"; return; fi
  # With --validation a validation message makes the exit status 3; check the text too.
  if grep -q "vulkan validation" "$out/stderr.txt"; then fail "$name: validation messages"; return; fi
  pass
}

# expect_error NAME STATUS STDERR_SUBSTRING CMD...: given exit status and message.
expect_error() {
  local name=$1 status=$2 needle=$3; shift 3
  local rc
  "$@" >"$out/stdout.txt" 2>"$out/stderr.txt"; rc=$?
  if [ $rc -ne "$status" ]; then fail "$name: exit $rc, expected $status"; return; fi
  if ! grep -qF -- "$needle" "$out/stderr.txt"; then
    fail "$name: stderr lacks '$needle': $(cat "$out/stderr.txt")"; return
  fi
  if [ -s "$out/stdout.txt" ]; then fail "$name: printed on stdout: $(cat "$out/stdout.txt")"; return; fi
  pass
}

num='-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?'
expect_ok "probe transmittance" "\{\"transmittance\":\[$num,$num,$num\]\}" \
  "$skyd" probe transmittance --altitude 0 --mu 1 --validation
expect_ok "probe transmittance mars" "\{\"transmittance\":\[$num,$num,$num\]\}" \
  "$skyd" probe transmittance --altitude 2 --mu 0.3 --preset mars
expect_ok "probe luminance" "\{\"luminance\":\[$num,$num,$num\]\}" \
  "$skyd" probe luminance --altitude 0.5 --view-zenith 60 --view-azimuth 90 --sun-zenith 30 --validation
expect_ok "probe illuminance" "\{\"sun_lux\":$num,\"sky_lux\":$num\}" \
  "$skyd" probe illuminance --sun-zenith 30 --validation
expect_ok "probe with --set" "\{\"transmittance\":\[$num,$num,$num\]\}" \
  "$skyd" probe transmittance --altitude 0 --mu 1 --set atmosphere.mie.scattering_per_km=0.02
expect_ok "render" "$out/cli.png" \
  "$skyd" render --width 64 --height 36 --out "$out/cli.png" --validation --set sun.elevation_deg=10
if [ -s "$out/cli.png" ] && head -c 8 "$out/cli.png" | od -An -tx1 | grep -q "89 50 4e 47"; then pass; else fail "render: not a PNG"; fi

# Zenith transmittance decreases when Mie scattering grows (the --set reached the LUT).
t1=$("$skyd" probe transmittance --altitude 0 --mu 1 | sed -E 's/.*\[([^,]*),.*/\1/')
t2=$("$skyd" probe transmittance --altitude 0 --mu 1 --set atmosphere.mie.scattering_per_km=0.02 | sed -E 's/.*\[([^,]*),.*/\1/')
if awk -v a="$t1" -v b="$t2" 'BEGIN { exit !(b < a) }'; then pass; else fail "--set had no effect: $t1 vs $t2"; fi

expect_error "unknown command" 2 'unknown command "bogus"' "$skyd" bogus
expect_error "unknown probe" 2 'unknown quantity "colour"' "$skyd" probe colour
expect_error "unknown option" 2 'unknown option "--bogus"' "$skyd" probe transmittance --altitude 0 --mu 1 --bogus
expect_error "missing value" 2 '--mu needs a value' "$skyd" probe transmittance --altitude 0 --mu
expect_error "bad number" 2 '--mu: "abc" is not a finite number' "$skyd" probe transmittance --altitude 0 --mu abc
expect_error "out of range" 2 '--mu: 2 is out of range [-1, 1]' "$skyd" probe transmittance --altitude 0 --mu 2
expect_error "nan" 2 '--altitude: "nan" is not a finite number' "$skyd" probe transmittance --altitude nan --mu 1
expect_error "missing option" 2 '--sun-zenith is required' "$skyd" probe illuminance
expect_error "unknown path" 2 '/atmosphere/bogus' "$skyd" probe transmittance --altitude 0 --mu 1 --set atmosphere.bogus=1
expect_error "bad set value" 2 '/atmosphere/mie/g' "$skyd" probe transmittance --altitude 0 --mu 1 --set atmosphere.mie.g=1.5
expect_error "set without =" 2 'expects PATH=VALUE' "$skyd" probe transmittance --altitude 0 --mu 1 --set atmosphere.mie.g
expect_error "inconsistent radii" 2 'top_radius' "$skyd" probe transmittance --altitude 0 --mu 1 --set atmosphere.top_radius_km=6000
expect_error "unknown preset" 2 'earth' "$skyd" probe transmittance --altitude 0 --mu 1 --preset venus
expect_error "bad preset name" 2 'preset' "$skyd" probe transmittance --altitude 0 --mu 1 --preset ../etc
expect_error "render needs size" 2 '--width, --height and --out are required' "$skyd" render --out "$out/x.png"
expect_error "render bad width" 2 '--width: 0 is out of range' "$skyd" render --width 0 --height 10 --out "$out/x.png"
expect_error "render bad dir" 1 'cannot create' "$skyd" render --width 8 --height 8 --out /nonexistent/dir/x.png

# --config: the file's render.device is used (a device that does not exist fails, naming it),
# a flag overrides it, and a bad file is rejected field by field.
printf '{"render":{"device":"no-such-device","validation":true}}' > "$out/config-device.json"
expect_error "config device" 1 'matches "no-such-device"' \
  "$skyd" probe transmittance --altitude 0 --mu 1 --config "$out/config-device.json"
expect_ok "config device overridden" "\{\"transmittance\":\[$num,$num,$num\]\}" \
  "$skyd" probe transmittance --altitude 0 --mu 1 --device cpu --config "$out/config-device.json"
printf '{"render":{"device":7},"bogus":true}' > "$out/config-bad.json"
expect_error "config bad field" 2 '/render/device' \
  "$skyd" probe transmittance --altitude 0 --mu 1 --config "$out/config-bad.json"
expect_error "config unknown field" 2 '/bogus' \
  "$skyd" probe transmittance --altitude 0 --mu 1 --config "$out/config-bad.json"
expect_ok "shipped config" "\{\"transmittance\":\[$num,$num,$num\]\}" \
  "$skyd" probe transmittance --altitude 0 --mu 1 --config "$(dirname "$0")/../config/skyd.json"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
