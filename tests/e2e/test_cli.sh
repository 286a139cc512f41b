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
expect_error "schema with an argument" 2 'usage: skyd schema' "$skyd" schema extra
expect_ok "schema config" "\\{" "$skyd" schema config
if "$skyd" schema config >"$out/schema-config.json" 2>"$out/stderr.txt" &&
   LD_PRELOAD= /usr/bin/python3 -c '
import json, sys
p = json.load(open(sys.argv[1]))["properties"]
assert p["read_only"]["type"] == "boolean" and p["read_only"]["default"] is False, p["read_only"]
assert "token" in p["controller_token"]["description"], p["controller_token"]
' "$out/schema-config.json"; then pass; else fail "schema config lacks read_only: $(cat "$out/stderr.txt")"; fi

# skyd schema: one JSON Schema document (2020-12) with the world state's fields.
if "$skyd" schema >"$out/schema.json" 2>"$out/stderr.txt" &&
   LD_PRELOAD= /usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["$schema"] == "https://json-schema.org/draft/2020-12/schema"
sun = s["properties"]["sun"]["properties"]["elevation_deg"]
assert sun["type"] == "number" and sun["minimum"] == -90 and sun["x-unit"] == "deg", sun
assert s["properties"]["exposure"]["properties"]["tonemap"]["enum"] == ["aces", "reinhard", "clamp"]
' "$out/schema.json"; then pass; else fail "skyd schema: $(cat "$out/stderr.txt")"; fi
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
  "$skyd" probe transmittance --altitude 0 --mu 1 --config "$(dirname "$0")/../../config/skyd.json"

# Sun and moon positions (the ephemeris alone, no renderer): the JSON's exact shape, a case of
# PyEphem's reference table (tests/unit/ephemeris_reference.h) within the ephemeris's tolerances, and
# usage errors that name the option.
expect_ok "probe sun" "\{\"azimuth_deg\":$num,\"elevation_deg\":$num\}" \
  "$skyd" probe sun --time 2026-06-21T12:00:00Z --lat 48.1 --lon 11.6
expect_ok "probe moon" "\{\"azimuth_deg\":$num,\"elevation_deg\":$num,\"phase\":$num\}" \
  "$skyd" probe moon --time "2026-06-21 14:00+02:00" --lat -33.9 --lon 18.4 --altitude 100 --refraction

# reference_case COLUMN: time, lat, lon, altitude, sun az/el/refracted el, moon az/el, fraction
# of the table's first row whose column COLUMN (an elevation) is above 5 degrees.
reference_case() {
  awk -v col="$1" '/^    \{ "/ {
      gsub(/[{"]/, ""); head = $0; getline; gsub(/[} ]/, ""); split(head $0, f, /, */)
      if (f[col] > 5) { print f[2], f[4], f[5], f[6], f[9], f[10], f[11], f[12], f[13], f[15]; exit }
    }' "$(dirname "$0")/../unit/ephemeris_reference.h"
}
# within NAME JSON AZ EL TOLERANCE: the JSON's direction is within TOLERANCE deg of (AZ, EL).
within() {
  local az el
  az=$(printf '%s' "$2" | sed -nE 's/.*"azimuth_deg":(-?[0-9.]+).*/\1/p')
  el=$(printf '%s' "$2" | sed -nE 's/.*"elevation_deg":(-?[0-9.]+).*/\1/p')
  if [ -z "$az" ] || [ -z "$el" ]; then fail "$1: no position in '$2'"; return; fi
  if awk -v a1="$az" -v e1="$el" -v a2="$3" -v e2="$4" -v tol="$5" 'BEGIN {
      r = atan2(0, -1) / 180; s = sin((e2 - e1) * r / 2); t = sin((a2 - a1) * r / 2)
      h = s * s + cos(e1 * r) * cos(e2 * r) * t * t
      exit !(2 * atan2(sqrt(h), sqrt(1 - h)) / r <= tol) }'; then
    pass
  else
    fail "$1: ($az, $el) is not within $5 deg of ($3, $4)"
  fi
}
read -r time lat lon alt sun_az sun_el sun_el_r _ _ _ <<<"$(reference_case 10)"
sun=$("$skyd" probe sun --time "$time" --lat "$lat" --lon "$lon" --altitude "$alt")
within "probe sun at $time" "$sun" "$sun_az" "$sun_el" 0.01
sun_r=$("$skyd" probe sun --time "$time" --lat "$lat" --lon "$lon" --altitude "$alt" --refraction)
within "probe sun --refraction at $time" "$sun_r" "$sun_az" "$sun_el_r" 0.02
lift=$(printf '%s %s' "$sun" "$sun_r" | sed -E 's/.*"elevation_deg":([^,}]*).*"elevation_deg":([^,}]*).*/\1 \2/')
if awk -v a="${lift% *}" -v b="${lift#* }" 'BEGIN { exit !(b - a > 0 && b - a < 0.2) }'; then pass
else fail "--refraction lifted the sun from ${lift% *} to ${lift#* }"; fi
read -r time lat lon alt _ _ _ moon_az moon_el fraction <<<"$(reference_case 13)"
moon=$("$skyd" probe moon --time "$time" --lat "$lat" --lon "$lon" --altitude "$alt")
within "probe moon at $time" "$moon" "$moon_az" "$moon_el" 0.3
phase=$(printf '%s' "$moon" | sed -nE 's/.*"phase":([0-9.]+)\}$/\1/p')
if awk -v a="$phase" -v b="$fraction" 'BEGIN { exit !(a != "" && (a - b) ^ 2 <= 0.02 ^ 2) }'; then pass
else fail "probe moon at $time: phase '$phase', reference $fraction"; fi

expect_error "sun without --time" 2 '--time is required' "$skyd" probe sun --lat 10 --lon 20
expect_error "moon without --lon" 2 '--lon is required' "$skyd" probe moon --time 2026-06-21T12:00Z --lat 10
expect_error "sun bad latitude" 2 '--lat: 95 is out of range' \
  "$skyd" probe sun --time 2026-06-21T12:00Z --lat 95 --lon 0
expect_error "moon bad time" 2 '--time: "2026-06-21T12:00": missing time zone' \
  "$skyd" probe moon --time 2026-06-21T12:00 --lat 10 --lon 0
expect_error "sun unknown option" 2 'unknown option "--preset"' \
  "$skyd" probe sun --time 2026-06-21T12:00Z --lat 10 --lon 0 --preset earth

# World simulation offline: --time/--lat/--lon put the sun where the ephemeris says (noon is
# brighter than midnight at a fixed exposure), and a time-lapse advances the clock and a
# weather transition between frames.
mean_png() {
  /usr/bin/python3 - "$1" <<'PY'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
pos, idat = 8, b""
while pos < len(data):
    length, kind = struct.unpack(">I4s", data[pos:pos + 8])
    if kind == b"IDAT":
        idat += data[pos + 8:pos + 8 + length]
    pos += 12 + length
raw = zlib.decompress(idat)
print(sum(raw) / len(raw))
PY
}
fixed=(--set exposure.mode=manual --set exposure.ev100=12 --width 48 --height 32)
expect_ok "render --time noon" "$out/noon.png" \
  "$skyd" render "${fixed[@]}" --time 2026-06-21T11:30:00Z --lat 45 --lon 6 --out "$out/noon.png" --validation
expect_ok "render --time midnight" "$out/midnight.png" \
  "$skyd" render "${fixed[@]}" --time 2026-06-21T23:30:00Z --lat 45 --lon 6 --out "$out/midnight.png"
day=$(mean_png "$out/noon.png"); night=$(mean_png "$out/midnight.png")
if awk -v d="$day" -v n="$night" 'BEGIN { exit !(d > 5 && d > 20 * n) }'; then pass
else fail "noon mean $day should be far above midnight mean $night"; fi
expect_ok "time-lapse" "$out/lapse-00\.png
$out/lapse-01\.png
$out/lapse-02\.png" \
  "$skyd" render --width 32 --height 16 --time 2026-06-21T03:00:00Z --lat 45 --lon 6 \
  --weather clear --frames 3 --step-s 10800 --weather-to storm --out "$out/lapse-%02d.png"
if grep -q "sun at -7" "$out/stderr.txt" && grep -q "sun at 2[0-9]\." "$out/stderr.txt"; then pass
else fail "time-lapse: the sun did not rise over the frames: $(cat "$out/stderr.txt")"; fi
expect_error "lapse without %d" 2 'needs one %d' \
  "$skyd" render --width 8 --height 8 --frames 2 --out "$out/x.png"
expect_error "transition without target" 2 '--transition-s needs --weather-to' \
  "$skyd" render --width 8 --height 8 --transition-s 60 --out "$out/x.png"
expect_error "render bad time" 2 '/clock/utc' \
  "$skyd" render --width 8 --height 8 --time 2026-13-01T00:00Z --lat 1 --lon 1 --out "$out/x.png"
expect_error "unknown weather" 2 'no weather preset named "hail"' \
  "$skyd" render --width 8 --height 8 --weather hail --out "$out/x.png"

# A client weather map (any PNG up to 512x512; here the render above) turns a clear sky cloudy.
expect_ok "render with a weather map" "$out/mapped\.png" \
  "$skyd" render --width 64 --height 36 --weather clear --weather-map "$out/cli.png" \
  --set sun.elevation_deg=30 --set camera.pitch_deg=20 --out "$out/mapped.png" --validation
expect_ok "render without it" "$out/unmapped\.png" \
  "$skyd" render --width 64 --height 36 --weather clear \
  --set sun.elevation_deg=30 --set camera.pitch_deg=20 --out "$out/unmapped.png"
if ! cmp -s "$out/mapped.png" "$out/unmapped.png"; then pass; else fail "the weather map changed nothing"; fi
expect_error "weather map missing" 2 'cannot open' \
  "$skyd" render --width 8 --height 8 --weather-map "$out/none.png" --out "$out/x.png"
printf 'not a png' >"$out/not-a-map.png"
expect_error "weather map not a PNG" 2 'not a PNG file' \
  "$skyd" render --width 8 --height 8 --weather-map "$out/not-a-map.png" --out "$out/x.png"

# An opaque but valid atmosphere (Mie absorption 10 /km) gives finite numbers, not NaN.
expect_ok "probe an opaque atmosphere" "\{\"luminance\":\[$num,$num,$num\]\}" \
  "$skyd" probe luminance --altitude 2 --view-zenith 60 --view-azimuth 90 --sun-zenith 30 \
  --set atmosphere.mie.absorption_per_km=10 --set atmosphere.mie.scale_height_km=11.1 --validation

# Environment maps: an equirectangular 2:1 panorama, 8-bit or 16-bit linear with its scale.
expect_ok "render an environment map" "$out/env\.png" \
  "$skyd" render --width 64 --height 32 --projection equirectangular --out "$out/env.png" --validation
expect_ok "render a 16-bit environment map" "$out/env16\.png" \
  "$skyd" render --width 64 --height 32 --projection equirectangular --format png16 \
  --out "$out/env16.png" --validation
# IHDR: bit depth 16 (byte 24), colour type 2 (byte 25); then the tEXt keyword.
if [ "$(od -An -tu1 -j24 -N2 "$out/env16.png" | tr -s ' ')" = " 16 2" ]; then pass
else fail "png16: IHDR depth/colour $(od -An -tu1 -j24 -N2 "$out/env16.png")"; fi
if grep -qa "Luminance full scale cd/m2" "$out/env16.png"; then pass; else fail "png16: no full-scale tEXt"; fi
expect_error "panorama not 2:1" 2 'width must be twice --height (32), got 48' \
  "$skyd" render --width 48 --height 32 --projection equirectangular --out "$out/x.png"
expect_error "unknown projection" 2 'expected perspective or equirectangular, got "fisheye"' \
  "$skyd" render --width 64 --height 32 --projection fisheye --out "$out/x.png"
expect_error "unknown format" 2 'expected png, png16 or jpeg, got "exr"' \
  "$skyd" render --width 64 --height 32 --format exr --out "$out/x.png"

# JPEG: by --format or by the file's extension; --quality only with JPEG.
# jpeg_info FILE: "SOI EOI WIDTHxHEIGHT" from the markers and the baseline SOF0 segment.
jpeg_info() {
  local soi eoi sof
  soi=$(od -An -tx1 -N2 "$1" | tr -d ' ')
  eoi=$(tail -c 2 "$1" | od -An -tx1 | tr -d ' ')
  sof=$(LC_ALL=C grep -obUaP '\xff\xc0' "$1" | head -1 | cut -d: -f1)
  [ -n "$sof" ] || { echo "$soi $eoi none"; return; }
  od -An -tu1 -j$((sof + 5)) -N4 "$1" | awk -v s="$soi $eoi" '{ print s, $3*256+$4 "x" $1*256+$2 }'
}
expect_ok "render a JPEG" "$out/sky\.jpeg" \
  "$skyd" render --width 96 --height 54 --format jpeg --quality 60 --out "$out/sky.jpeg" --validation
info=$(jpeg_info "$out/sky.jpeg")
[ "$info" = "ffd8 ffd9 96x54" ] && pass || fail "render --format jpeg: $info"
expect_ok "render a JPEG by its extension" "$out/ext\.jpg" \
  "$skyd" render --width 64 --height 36 --out "$out/ext.jpg"
info=$(jpeg_info "$out/ext.jpg")
[ "$info" = "ffd8 ffd9 64x36" ] && pass || fail "render --out x.jpg: $info"
expect_error "quality with png" 2 '--quality is for JPEG' \
  "$skyd" render --width 64 --height 32 --quality 50 --out "$out/x.png"
expect_error "quality out of range" 2 '--quality' \
  "$skyd" render --width 64 --height 32 --format jpeg --quality 101 --out "$out/x.jpg"
[ ! -e "$out/x.jpg" ] && pass || fail "a refused render wrote a file"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
