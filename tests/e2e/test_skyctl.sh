#!/usr/bin/env bash
# skyctl against the real daemon: every command's output, its effect on the world state, and
# the exit statuses scripts rely on (0 ok, 1 server error naming the field, 2 usage,
# 3 connection failure). Usage: test_skyctl.sh SKYD SKYCTL OUTDIR
# Under the sanitizer build the preloads arrive as SKYD_DAEMON_LD_PRELOAD and go to skyd and
# skyctl only, not to the shell tools.
set -u
skyd=$1
skyctl_bin=$2
out=$3
preload=${SKYD_DAEMON_LD_PRELOAD:-}
token=skyctl-test-token
mkdir -p "$out"
rm -f "$out"/*.png "$out"/*.txt "$out"/state.json
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

skyctl() { LD_PRELOAD="$preload" "$skyctl_bin" --timeout 30 "$@"; }

# expect NAME STATUS STDOUT_REGEX STDERR_SUBSTRING CMD...: exit status, stdout matching the
# extended regex (whole output, newlines and tabs as spaces; "" for no output), stderr
# containing the text ("" for none).
expect() {
  local name=$1 status=$2 regex=$3 needle=$4; shift 4
  local rc stdout
  "$@" >"$out/stdout.txt" 2>"$out/stderr.txt"; rc=$?
  stdout=$(tr '\n\t' '  ' <"$out/stdout.txt" | sed 's/ *$//')
  if [ $rc -ne "$status" ]; then
    fail "$name: exit $rc, expected $status; stdout '$stdout'; stderr '$(cat "$out/stderr.txt")'"
  elif [ -z "$regex" ] && [ -n "$stdout" ]; then
    fail "$name: printed on stdout: '$stdout'"
  elif [ -n "$regex" ] && ! printf '%s\n' "$stdout" | grep -Eqx -- "$regex"; then
    fail "$name: stdout '$stdout' !~ /$regex/"
  elif [ -n "$needle" ] && ! grep -qF -- "$needle" "$out/stderr.txt"; then
    fail "$name: stderr lacks '$needle': '$(cat "$out/stderr.txt")'"
  elif [ -z "$needle" ] && [ -s "$out/stderr.txt" ]; then
    fail "$name: unexpected stderr '$(cat "$out/stderr.txt")'"
  else
    pass
  fi
}

num='-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?'

# png_check FILE...: each file is a whole PNG (signature, chunk CRCs, IDAT inflating to the
# rows its header announces); prints WIDTHxHEIGHTxBITS for each, or fails.
png_check() {
  python3 - "$@" <<'PY'
import struct, sys, zlib
for path in sys.argv[1:]:
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        sys.exit(path + ': no PNG signature')
    pos, idat, ihdr = 8, b'', None
    while pos + 12 <= len(data):
        length, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack('>I', data[pos + 8 + length:pos + 12 + length])
        if zlib.crc32(kind + body) != crc:
            sys.exit(path + ': bad CRC in ' + kind.decode('latin-1'))
        if kind == b'IHDR':
            ihdr = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat += body
        pos += 12 + length
        if kind == b'IEND':
            break
    else:
        sys.exit(path + ': no IEND')
    width, height, depth, color, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color]
    if interlace or len(zlib.decompress(idat)) != height * (1 + width * channels * depth // 8):
        sys.exit(path + ': pixel data does not fit the header')
    print('%dx%dx%d' % (width, height, depth))
PY
}

# expect_json NAME STATUS CHECK CMD...: exit status; stdout only lines that are each one JSON
# object; CHECK, a Python expression over `lines` (the parsed objects), holds; stderr empty
# when STATUS is 0.
expect_json() {
  local name=$1 status=$2 check=$3 rc; shift 3
  "$@" >"$out/json.txt" 2>"$out/json-err.txt"; rc=$?
  if [ $rc -ne "$status" ]; then
    fail "$name: exit $rc, expected $status; stderr '$(cat "$out/json-err.txt")'"
  elif [ "$status" -eq 0 ] && [ -s "$out/json-err.txt" ]; then
    fail "$name: unexpected stderr '$(cat "$out/json-err.txt")'"
  elif ! python3 - "$out/json.txt" "$check" >"$out/json-check.txt" 2>&1 <<'PY'
import json, os, sys
lines = [json.loads(line) for line in open(sys.argv[1])]
if not all(isinstance(line, dict) for line in lines):
    sys.exit('a line is not an object')
if not eval(sys.argv[2]):
    sys.exit('fails: ' + sys.argv[2])
PY
  then
    fail "$name: $(tail -n 1 "$out/json-check.txt"); stdout '$(cat "$out/json.txt")'"
  else
    pass
  fi
}

# --- without a daemon: usage and connection failures
expect "help" 0 '.*exit status:.*3  cannot connect.*examples:.*skyctl watch --count 10.*' "" \
  skyctl --help
expect "no command" 2 '' "no command" skyctl
expect "unknown command" 2 '' "unknown command frob" skyctl frob
expect "unknown option" 2 '' "unknown option --frob" skyctl --frob 1 stats
expect "set without assignments" 2 '' "needs at least one PATH=VALUE" skyctl set
expect "set without =" 2 '' '"sun" is not PATH=VALUE' skyctl set sun
expect "set twice" 2 '' "given twice" skyctl set a.b=1 a.b=2
expect "snapshot without --out" 2 '' "needs --out" skyctl snapshot
expect "preset without name" 2 '' "give either NAME or --list" skyctl preset
expect "bad --timeout" 2 '' "--timeout needs" skyctl --timeout -1 stats
expect "connection refused" 3 '' "cannot connect to ws://127.0.0.1:1/" \
  skyctl --url ws://127.0.0.1:1/ stats
expect "help names --token-file" 0 '.*--token-file FILE .*neither --token +nor \$SKYD_TOKEN.*' "" \
  skyctl --help
expect "--token-file missing" 2 '' "--token-file $out/none.txt: No such file" \
  skyctl --token-file "$out/none.txt" stats
printf ' \r\nsecond line\n' >"$out/empty-token.txt"
expect "--token-file without a token" 2 '' "no token on its first line" \
  skyctl --token-file "$out/empty-token.txt" stats

# --- the daemon, on a free port
cat >"$out/skyd.json" <<EOF
{"listen": {"address": "127.0.0.1", "port": 0}, "web_root": "$out",
 "state_file": "$out/state.json", "controller_token": "$token",
 "render": {"device": "", "validation": false}}
EOF
# start_daemon NAME: runs skyd serve with $out/NAME.json in the background; sets daemon and
# port, or fails the whole test.
start_daemon() {
  local name=$1
  LD_PRELOAD="$preload" "$skyd" serve --config "$out/$name.json" >"$out/$name.stdout.txt" \
    2>"$out/$name.log" &
  daemon=$!
  port=
  for _ in $(seq 1 600); do
    port=$(sed -nE 's|^skyd: listening on https?://127\.0\.0\.1:([0-9]+)/$|\1|p' \
      "$out/$name.stdout.txt")
    [ -n "$port" ] && break
    kill -0 $daemon 2>/dev/null || break
    sleep 0.1
  done
  if [ -z "$port" ]; then
    echo "FAIL: skyd ($name) did not start: $(tail -c 600 "$out/$name.log")"
    kill $daemon 2>/dev/null
    exit 1
  fi
}
trap 'kill $daemon 2>/dev/null' EXIT
start_daemon skyd
export SKYD_URL="ws://127.0.0.1:$port/"
c() { skyctl "$@"; }
t() { skyctl --token "$token" "$@"; }

expect "get one field" 0 '45' "" c get sun.elevation_deg
# The daemon's clock starts at 12:00:00 and runs at real time (time_scale 1) until the set below
# pauses it: allow the minutes a slow (sanitizer) start may take.
running='2026-06-21T12:0[0-4]:[0-9]{2}(\.[0-9]{1,9})?Z'
expect "get by pointer: the clock runs from 12:00" 0 "$running" "" c get /clock/utc
first_utc=$(cat "$out/stdout.txt")
expect "get an RGB channel" 0 '0\.3' "" c get atmosphere.ground_albedo.1
expect "get a group" 0 "\\{ +\"utc\": +\"$running\", +\"time_scale\": +1, .*\\}" "" \
  c get clock
sleep 1.1
expect "the clock advanced" 0 "$running" "" c get clock.utc
[[ "$(cat "$out/stdout.txt")" > "$first_utc" ]] && pass ||
  fail "clock.utc did not advance: $first_utc then $(cat "$out/stdout.txt")"
expect "get all" 0 '\{ +"clock": .*"render": .*\}' "" c get
expect "get revision" 0 '0' "" c get revision
expect "get unknown field" 2 '' "no field sun.bogus" c get sun.bogus

expect "viewer set is forbidden" 1 '' "set: set needs the controller role [forbidden]" \
  c set sun.elevation_deg=10
expect "wrong token" 1 '' "auth: wrong token [auth_failed]" \
  skyctl --token wrong set sun.elevation_deg=10
# The clock is paused in the same set, so the rest of the test sees exact times.
expect "set" 0 'revision 1' "" \
  t set sun.elevation_deg=10 clock.utc=2026-06-21T18:00:00Z clock.time_scale=0 \
  atmosphere.ground_albedo=[0.1,0.2,0.3]
expect "set took effect: number" 0 '10' "" c get sun.elevation_deg
expect "set took effect: time text" 0 '2026-06-21T18:00:00Z' "" c get clock.utc
expect "set took effect: RGB" 0 '\[0\.1, 0\.2, 0\.3\]' "" c get atmosphere.ground_albedo
expect "set out of range names the field" 1 '' \
  "set: /patch/location/latitude_deg: must be in [-90, 90], got 123 [out_of_range]" \
  t set sun.elevation_deg=30 location.latitude_deg=123
expect "rejected set changed nothing (all or nothing)" 0 '10' "" c get sun.elevation_deg
expect "rejected set left the revision" 0 '1' "" c get revision
expect "set unknown field" 1 '' "set: /patch/sun/bogus: unknown field" t set sun.bogus=1
expect "set wrong type" 1 '' "/patch/clock/utc: expected an ISO 8601 UTC time" t set clock.utc=5
expect "sun set in ephemeris mode names the field" 1 '' "set: /patch/sun/elevation_deg:" \
  t set clock.sky_bodies=ephemeris sun.elevation_deg=20
expect "refused ephemeris switch changed nothing" 0 'manual' "" c get clock.sky_bodies

expect "preset list" 0 '.*' "" c preset --list
grep -qx earth "$out/stdout.txt" && grep -qx mars "$out/stdout.txt" && pass ||
  fail "preset list lacks earth or mars: $(cat "$out/stdout.txt")"
expect "preset as viewer" 1 '' "[forbidden]" c preset mars
expect "preset mars" 0 'revision 2' "" t preset mars
expect "mars radius" 0 '3389\.5' "" c get atmosphere.bottom_radius_km
expect "preset unknown" 1 '' "[not_found]" t preset nosuch
expect "preset bad name" 1 '' "/name" t preset NoSuch
expect "preset earth" 0 'revision 3' "" t preset earth

expect "probe transmittance" 0 "\{ +\"quantity\": +\"transmittance\", +\"transmittance\": +\[$num, $num, $num\] +\}" "" \
  c probe transmittance altitude_km=0 mu=1
read -r tr tg tb < <(tr -d '\n\t ' <"$out/stdout.txt" | sed -nE 's/.*\[([^,]+),([^,]+),([^]]+)\].*/\1 \2 \3/p')
if awk -v r="$tr" -v g="$tg" -v b="$tb" 'BEGIN { exit !(r < 1 && b > 0 && r > g && g > b) }'; then
  pass
else
  fail "zenith transmittance should fall from red to blue in (0, 1): $tr $tg $tb"
fi
expect "probe missing parameter" 1 '' "probe: /sun_zenith_deg: required for illuminance [missing_field]" \
  c probe illuminance
expect "probe unknown quantity" 1 '' "/quantity" c probe colour
expect "stats" 0 "\{ +\"fps\": +$num, +\"clients\": +1, +\"passes\": .*\"lut_rebuild_progress\": +$num, +\"simulation_time_s\": +1782064800, +\"multiple_scattering\": +\{ +\"weight\": +$num, +\"progress\": +$num, +\"order\": +$num +\}, +\"subscriptions\": +\[ *\] +\}" "" \
  c stats

expect "snapshot toward the sun" 0 "$out/south.png: 160x90 PNG, [0-9]+ bytes, state revision 3, frame [0-9]+" "" \
  c snapshot --out "$out/south.png" --width 160 --height 90 --set camera.yaw_deg=180 \
  --set exposure.mode=manual --set exposure.ev100=14
expect "snapshot away from the sun" 0 "$out/north.png: 160x90 PNG, [0-9]+ bytes, state revision 3, frame [0-9]+" "" \
  c snapshot --out "$out/north.png" --width 160 --height 90 --set camera.yaw_deg=0 \
  --set exposure.mode=manual --set exposure.ev100=14
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{ print $1*16777216+$2*65536+$3*256+$4 "x" $5*16777216+$6*65536+$7*256+$8 }'; }
if [ "$(head -c 8 "$out/south.png" | od -An -tx1 | tr -d ' ')" = 89504e470d0a1a0a ] &&
   [ "$(png_size "$out/south.png")" = 160x90 ]; then pass; else fail "snapshot is not a 160x90 PNG"; fi
if ! cmp -s "$out/south.png" "$out/north.png"; then pass; else fail "the view's yaw did not change the image"; fi
expect "environment map snapshot" 0 "$out/env16.png: 64x32 PNG16, [0-9]+ bytes, state revision 3, frame [0-9]+" "" \
  c snapshot --out "$out/env16.png" --width 64 --height 32 --set projection=equirectangular \
  --set format=png16
if [ "$(od -An -tu1 -j24 -N2 "$out/env16.png" | tr -s ' ')" = " 16 2" ]; then pass
else fail "environment map snapshot is not 16-bit RGB"; fi
expect "jpeg snapshot by extension" 0 "$out/south.jpg: 160x90 JPEG, [0-9]+ bytes, state revision 3, frame [0-9]+" "" \
  c snapshot --out "$out/south.jpg" --width 160 --height 90 --set quality=70
if [ "$(head -c 2 "$out/south.jpg" | od -An -tx1 | tr -d ' ')" = ffd8 ] &&
   [ "$(tail -c 2 "$out/south.jpg" | od -An -tx1 | tr -d ' ')" = ffd9 ]; then pass
else fail "snapshot --out x.jpg is not a JPEG"; fi
expect "jpeg snapshot quality with png" 1 '' "snapshot: /view/quality: quality is for format jpeg only [inconsistent]" \
  c snapshot --out "$out/q.png" --set quality=70
expect "snapshot too wide names the field" 1 '' "snapshot: /view/width: must be in [1, 3840], got 99999 [out_of_range]" \
  c snapshot --out "$out/wide.png" --width 99999
[ ! -e "$out/wide.png" ] && pass || fail "a refused snapshot wrote a file"

expect "watch frames" 0 "subscribed [0-9]+( frame [0-9]+ revision 3 time 1782064800\.000 s 160x90 [0-9]+ bytes){3}" "" \
  c watch --count 3 --width 160 --height 90 --fps 5
mkdir -p "$out/jpeg-frames"
expect "watch jpeg frames into a directory" 0 "subscribed [0-9]+( frame [0-9]+ revision 3 time 1782064800\.000 s 80x45 [0-9]+ bytes $out/jpeg-frames/frame_[0-9]+_rev_0+3\.jpg){2}" "" \
  c watch --count 2 --width 80 --height 45 --fps 5 --set format=jpeg --out "$out/jpeg-frames"

# Weather presets: a transition over simulated time. The clock is paused, so the transition's
# progress follows only the clock.utc sets below (smoothstep: 0.5 at half time).
expect "weather preset list" 0 '.*' "" c preset --list --kind weather
for name in clear fair_cumulus scattered broken overcast storm altocumulus warm_front; do
  grep -qx "$name" "$out/stdout.txt" && pass || fail "weather presets lack $name: $(cat "$out/stdout.txt")"
done
expect "weather transition out of range" 1 '' "preset: /transition_s: must be in [0, 604800]" \
  t preset --kind weather --transition-s 700000 storm
expect "transition_s for an atmosphere preset" 1 '' "/transition_s" \
  t preset --kind atmosphere --transition-s 60 earth
expect "storm over 600 s" 0 'revision 4' "" t preset --kind weather --transition-s 600 storm
expect "the transition starts" 0 "\\{ +\"start\": +\"2026-06-21T18:00:00Z\", +\"duration_s\": +600, +\"progress\": +0, .*\"to\": +\\{ +\"clouds\": +\\{ +\"low\": +\\{ +\"coverage\": +0\\.85, .*\\}" "" \
  c get weather.transition
expect "coverage starts where it was" 0 '0' "" c get clouds.low.coverage
expect "half the transition" 0 'revision 5' "" t set clock.utc=2026-06-21T18:05:00Z
expect "progress at half time" 0 '0\.5' "" c get weather.transition.progress
expect "coverage half way" 0 '0\.425' "" c get clouds.low.coverage
expect "transition time passes" 0 'revision 6' "" t set clock.utc=2026-06-21T18:10:00Z
expect "progress at the end" 0 '1' "" c get weather.transition.progress
expect "storm coverage reached" 0 '0\.85' "" c get clouds.low.coverage
expect "storm rain reached" 0 '0\.9' "" c get clouds.precipitation
expect "transition state is read-only" 1 '' "/patch/weather/transition/progress" \
  t set weather.transition.progress=0.5

# A client weather map from a PNG file (any PNG up to 512x512 is a map: here a snapshot).
expect "weather-map as viewer" 1 '' "[forbidden]" c weather-map "$out/south.png"
printf 'not a png' >"$out/not-a-map.png"
expect "weather-map of a text file names /data" 1 '' "weather-map: /data: not a PNG file" \
  t weather-map "$out/not-a-map.png"
expect "weather-map of a missing file" 2 '' "cannot open" t weather-map "$out/none.png"
expect "weather-map" 0 'revision 7' "" t weather-map "$out/south.png"
expect "the map is selected" 0 'client' "" c get weather.map_source
[ -s "$out/state.weather-map.png" ] && pass || fail "the weather map was not saved beside the state"

# A METAR applied to the weather: the revision, each étage's group in its layer (nothing
# unmapped), the state's source; a refused report names its group; a viewer is refused.
expect "metar as viewer" 1 '' "[forbidden]" c metar "METAR LFLY 211200Z 18008KT 9999 FEW040 22/10 Q1018"
expect "metar with a bad group" 1 '' 'group 6 "BKN0X0"' \
  t metar "METAR EGLL 281150Z 24010KT 9999 BKN0X0 12/09 Q1005"
expect "metar" 0 '^revision 8$' "" \
  t metar "METAR LFLY 211200Z 18008KT 9999 SCT030 BKN100 22/10 Q1018"
expect "metar sets weather.source" 0 'metar' "" c get weather.source
expect "metar's low layer" 0 '0.4375' "" c get clouds.low.coverage
expect "metar's middle layer" 0 '0.75' "" c get clouds.mid.coverage
expect "metar needs a report" 2 '' "takes one REPORT" t metar

# watch prints the event of a change made by another client.
c watch --no-frames --count 1 >"$out/watch-events.txt" 2>&1 &
watcher=$!
elevation=11
for _ in $(seq 1 40); do
  kill -0 $watcher 2>/dev/null || break
  t set sun.elevation_deg=$elevation >/dev/null
  elevation=$((elevation + 1))
  sleep 0.5
done
wait $watcher; rc=$?
if [ $rc -eq 0 ] && grep -Eqx "event state_changed revision [0-9]+ /sun/elevation_deg" "$out/watch-events.txt"; then
  pass
else
  fail "watch --no-frames: exit $rc, output '$(cat "$out/watch-events.txt")'"
fi

# watch ends with status 0 on SIGINT.
LD_PRELOAD="$preload" "$skyctl_bin" watch --width 160 --height 90 --fps 2 >"$out/watch-int.txt" 2>&1 &
watcher=$!
for _ in $(seq 1 300); do grep -q '^frame' "$out/watch-int.txt" && break; sleep 0.1; done
kill -INT $watcher
wait $watcher; rc=$?
if [ $rc -eq 0 ] && grep -q '^frame' "$out/watch-int.txt"; then pass; else
  fail "watch interrupted: exit $rc, output '$(head -c 400 "$out/watch-int.txt")'"
fi

# Where the token comes from: --token, else $SKYD_TOKEN, else --token-file's first line.
printf '  %s \r\nsecond line\n' "$token" >"$out/token.txt"
printf 'wrong\n' >"$out/wrong-token.txt"
env_token() { local value=$1; shift; SKYD_TOKEN=$value skyctl "$@"; }
expect "token from SKYD_TOKEN" 0 'revision [0-9]+' "" env_token "$token" set sun.elevation_deg=21
expect "token from --token-file, trimmed" 0 'revision [0-9]+' "" \
  skyctl --token-file "$out/token.txt" set sun.elevation_deg=22
expect "--token-file with an empty SKYD_TOKEN" 0 'revision [0-9]+' "" \
  env_token "" --token-file "$out/token.txt" set sun.elevation_deg=23
expect "--token before SKYD_TOKEN" 0 'revision [0-9]+' "" \
  env_token wrong --token "$token" set sun.elevation_deg=24
expect "SKYD_TOKEN before --token-file" 1 '' "auth: wrong token [auth_failed]" \
  env_token wrong --token-file "$out/token.txt" set sun.elevation_deg=25
expect "--token before --token-file" 1 '' "auth: wrong token [auth_failed]" \
  skyctl --token wrong --token-file "$out/token.txt" set sun.elevation_deg=25
expect "a wrong token in --token-file" 1 '' "auth: wrong token [auth_failed]" \
  skyctl --token-file "$out/wrong-token.txt" set sun.elevation_deg=25
expect "the refused sets changed nothing" 0 '24' "" c get sun.elevation_deg

# watch --out saves every frame as a PNG named by its frame number and state revision; a set
# during the watch shows in the later names. --count counts frames, not the event lines.
rm -rf "$out/frames"
c watch --out "$out/frames/live" --count 8 --width 64 --height 36 --fps 5 \
  >"$out/watch-out.txt" 2>"$out/watch-out-err.txt" &
watcher=$!
for _ in $(seq 1 300); do
  [ "$(grep -c '^frame' "$out/watch-out.txt")" -ge 2 ] && break
  kill -0 $watcher 2>/dev/null || break
  sleep 0.1
done
t set sun.elevation_deg=30 >/dev/null
wait $watcher; rc=$?
saved=$(find "$out/frames/live" -name '*.png' | wc -l)
if [ $rc -eq 0 ] && [ "$saved" -eq 8 ] && [ "$(grep -c '^frame' "$out/watch-out.txt")" -eq 8 ] &&
   [ ! -s "$out/watch-out-err.txt" ]; then pass
else
  fail "watch --out: exit $rc, $saved files, output '$(cat "$out/watch-out.txt" "$out/watch-out-err.txt")'"
fi
# Each frame line ends with its file's path; numbers grow, and so does the revision.
if grep '^frame' "$out/watch-out.txt" | awk -v dir="$out/frames/live" '
    { name = sprintf("%s/frame_%06d_rev_%06d.png", dir, $2, $4)
      if ($NF != name || (NR > 1 && ($2 <= frame || $4 < revision))) exit 1
      if (NR == 1) first = $4
      frame = $2; revision = $4 }
    END { exit !(NR == 8 && revision > first) }'; then pass
else fail "watch --out: names or numbers wrong: $(cat "$out/watch-out.txt")"; fi
grep -q '^event state_changed revision [0-9]* /sun/elevation_deg$' "$out/watch-out.txt" && pass ||
  fail "watch --out did not print the set's event: $(cat "$out/watch-out.txt")"
sizes=$(png_check "$out"/frames/live/*.png | sort -u | tr '\n' ' ')
[ "$sizes" = "64x36x8 " ] && pass || fail "watch --out files are not all 64x36 8-bit PNGs: $sizes"
expect "watch --out png16" 0 "subscribed [0-9]+ frame [0-9]+ revision [0-9]+ time $num s 32x16 [0-9]+ bytes $out/frames/16/frame_[0-9]{6}_rev_[0-9]{6}\\.png" "" \
  c watch --out "$out/frames/16" --count 1 --width 32 --height 16 --set format=png16
[ "$(png_check "$out"/frames/16/*.png)" = 32x16x16 ] && pass ||
  fail "watch --out png16 did not save a 16-bit PNG"
expect "watch --out under a file" 2 '' "cannot create $out/token.txt" \
  c watch --out "$out/token.txt/frames" --count 1
expect "watch --out with --no-frames" 2 '' "does not go with --no-frames" \
  c watch --out "$out/frames" --no-frames --count 1

# --json: one JSON object per line on stdout and nothing else; errors stay text on stderr
# with the same exit statuses.
cj() { skyctl --json "$@"; }
expect "help names --json" 0 '.*--json +print one JSON object per line.*Errors stay text on stderr.*' "" \
  skyctl --help
expect_json "json get" 0 \
  "len(lines) == 1 and lines[0]['path'] == 'sun.elevation_deg' and lines[0]['value'] == 30 and type(lines[0]['revision']) is int" \
  cj get sun.elevation_deg
revision=$(python3 -c 'import json, sys; print(json.load(sys.stdin)["revision"])' <"$out/json.txt")
expect_json "json get revision" 0 "lines == [{'path': 'revision', 'value': $revision, 'revision': $revision}]" \
  cj get revision
expect_json "json get group" 0 "len(lines) == 1 and lines[0]['value']['time_scale'] == 0" \
  cj get clock
expect_json "json get all" 0 "len(lines) == 1 and set(lines[0]) == {'state', 'revision'} and 'clock' in lines[0]['state']" \
  cj get
expect_json "json set" 0 "lines == [{'type': 'ack', 'revision': $((revision + 1))}]" \
  cj --token "$token" set sun.elevation_deg=31
expect_json "json preset list" 0 "len(lines) == 1 and lines[0]['kind'] == 'weather' and 'storm' in lines[0]['names']" \
  cj preset --list --kind weather
expect_json "json preset" 0 "len(lines) == 1 and lines[0]['type'] == 'ack'" cj --token "$token" preset earth
expect_json "json probe" 0 "len(lines) == 1 and lines[0]['type'] == 'probe_result' and len(lines[0]['transmittance']) == 3" \
  cj probe transmittance altitude_km=0 mu=1
expect_json "json stats" 0 "len(lines) == 1 and lines[0]['type'] == 'stats' and lines[0]['clients'] == 1" cj stats
expect_json "json snapshot" 0 \
  "len(lines) == 1 and lines[0]['type'] == 'frame' and lines[0]['path'] == '$out/json.png' and (lines[0]['width'], lines[0]['height'], lines[0]['format']) == (32, 16, 'png') and lines[0]['bytes'] == os.path.getsize('$out/json.png')" \
  cj snapshot --out "$out/json.png" --width 32 --height 16
# watch: the subscription, a line per frame with its file, and the event of a set meanwhile.
rm -rf "$out/frames/json"
cj watch --out "$out/frames/json" --count 4 --width 32 --height 16 --fps 5 >"$out/json-watch.txt" &
watcher=$!
for _ in $(seq 1 300); do
  grep -q '"type":"frame"' "$out/json-watch.txt" && break
  kill -0 $watcher 2>/dev/null || break
  sleep 0.1
done
t set sun.elevation_deg=32 >/dev/null
wait $watcher; rc=$?
[ $rc -eq 0 ] && pass || fail "json watch: exit $rc"
expect_json "json watch lines" 0 "[l['type'] for l in lines if l['type'] != 'event'] == ['subscribed'] + ['frame'] * 4 and \
all(set(l) == {'type', 'frame_number', 'revision', 'simulation_time_s', 'width', 'height', 'format', 'bytes', 'path'} and os.path.getsize(l['path']) == l['bytes'] for l in lines if l['type'] == 'frame') and \
[l['changed'] for l in lines if l['type'] == 'event'] == [['/sun/elevation_deg']]" \
  cat "$out/json-watch.txt"
expect_json "json: an error is text on stderr only" 2 "lines == []" cj get sun.bogus
grep -qx "skyctl get: the world state has no field sun.bogus" "$out/json-err.txt" && pass ||
  fail "json error on stderr: $(cat "$out/json-err.txt")"
expect_json "json: a server error" 1 "lines == []" cj set sun.elevation_deg=10
expect_json "json: no connection" 3 "lines == []" cj --url ws://127.0.0.1:1/ get
expect_json "json: unknown watch argument" 2 "lines == []" cj watch --bogus

# The daemon goes away: connection failures are status 3.
kill -TERM $daemon
wait $daemon; rc=$?
[ $rc -eq 0 ] && pass || fail "skyd exit status $rc after SIGTERM"
expect "daemon gone" 3 '' "cannot connect" c get

# --- wss://: a daemon serving TLS with a self-signed certificate made here
expect "help names --ca-file and --insecure" 0 '.*--ca-file FILE wss: trust.*--insecure +wss: accept any.*' "" \
  skyctl --help
tls_cert() { # tls_cert NAME: $out/NAME-cert.pem and $out/NAME-key.pem for 127.0.0.1
  openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=127.0.0.1 \
    -addext subjectAltName=IP:127.0.0.1 -keyout "$out/$1-key.pem" -out "$out/$1-cert.pem" \
    >"$out/openssl.txt" 2>&1 || { echo "FAIL: openssl: $(cat "$out/openssl.txt")"; exit 1; }
}
tls_cert tls
tls_cert other
cat >"$out/skyd-tls.json" <<EOF
{"listen": {"address": "127.0.0.1", "port": 0, "tls_certificate": "$out/tls-cert.pem",
            "tls_private_key": "$out/tls-key.pem"},
 "web_root": "$out", "state_file": "$out/state-tls.json", "controller_token": "$token",
 "render": {"device": "", "validation": false}}
EOF
rm -f "$out"/state-tls.json*
start_daemon skyd-tls
grep -qx "skyd: listening on https://127.0.0.1:$port/" "$out/skyd-tls.stdout.txt" && pass ||
  fail "the TLS daemon does not say https: $(cat "$out/skyd-tls.stdout.txt")"
wss="wss://127.0.0.1:$port/"
s() { skyctl --url "$wss" --ca-file "$out/tls-cert.pem" "$@"; }
not_accepted="the server's certificate was not accepted: self-signed certificate"
expect "wss with --ca-file: get" 0 '0' "" s get revision
expect "wss with --ca-file: set" 0 'revision 1' "" s --token "$token" set sun.elevation_deg=12
expect "wss with --ca-file: the set took" 0 '12' "" s get sun.elevation_deg
expect "wss with --ca-file: snapshot" 0 "$out/tls.png: 64x36 PNG, [0-9]+ bytes, state revision 1, frame [0-9]+" "" \
  s snapshot --out "$out/tls.png" --width 64 --height 36
expect "wss watch --out" 0 "subscribed [0-9]+ (frame [0-9]+ revision 1 time $num s 48x24 [0-9]+ bytes $out/frames/tls/frame_[0-9]{6}_rev_000001\\.png ?){2}" "" \
  s watch --out "$out/frames/tls" --count 2 --width 48 --height 24 --fps 5
[ "$(png_check "$out"/frames/tls/*.png | tr '\n' ' ')" = "48x24x8 48x24x8 " ] && pass ||
  fail "wss watch --out did not save two 48x24 PNGs"
expect_json "wss json get" 0 "lines == [{'path': 'sun.elevation_deg', 'value': 12, 'revision': 1}]" \
  s --json get sun.elevation_deg
expect "wss untrusted" 3 '' "$not_accepted" skyctl --url "$wss" get revision
expect "wss untrusted names the options" 3 '' "--ca-file FILE trusts a PEM certificate" \
  skyctl --url "$wss" get revision
expect "wss trusting another certificate" 3 '' "$not_accepted" \
  skyctl --url "$wss" --ca-file "$out/other-cert.pem" get revision
expect "wss to a host the certificate does not name" 3 '' \
  "the server's certificate was not accepted: hostname mismatch" \
  skyctl --url "wss://localhost:$port/" --ca-file "$out/tls-cert.pem" get revision
expect "wss --insecure works, with a warning" 0 '12' "warning: --insecure: the server's certificate is not checked" \
  skyctl --url "$wss" --insecure get sun.elevation_deg
expect "wss --insecure, another host name" 0 '1' "warning: --insecure" \
  skyctl --url "wss://localhost:$port/" --insecure get revision
expect "--ca-file missing" 2 '' "--ca-file $out/none.pem: No such file" \
  skyctl --url "$wss" --ca-file "$out/none.pem" get revision
expect "--ca-file without a certificate" 2 '' "no PEM certificate in it" \
  skyctl --url "$wss" --ca-file "$out/token.txt" get revision
expect "ws:// to the TLS port" 3 '' "cannot connect to ws://127.0.0.1:$port/" \
  skyctl --url "ws://127.0.0.1:$port/" get revision
expect "wss to a closed port" 3 '' "cannot connect to wss://127.0.0.1:1/" \
  skyctl --url wss://127.0.0.1:1/ --ca-file "$out/tls-cert.pem" get revision
expect "bad URL scheme" 3 '' "expected ws://host:port/path or wss://host:port/path" \
  skyctl --url https://127.0.0.1:1/ get revision
kill -TERM $daemon
wait $daemon; rc=$?
[ $rc -eq 0 ] && pass || fail "TLS skyd exit status $rc after SIGTERM"

echo "skyctl: $passed passed, $failed failed"
[ $failed -eq 0 ]
