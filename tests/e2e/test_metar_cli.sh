#!/usr/bin/env bash
# `skyd metar`: the decoded report as JSON on stdout and a summary on stderr; a refused report
# names the offending group on stderr, prints nothing on stdout and exits 2.
# Usage: test_metar_cli.sh SKYD OUTDIR
set -u
skyd=$1
out=$2
mkdir -p "$out"
passed=0
failed=0

pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# expect_json NAME PYTHON_ASSERTIONS SKYD_ARGS...: exit 0, stdout JSON (as `j`) passing the
# assertions, a summary line on stderr.
expect_json() {
  local name=$1 assertions=$2; shift 2
  local rc
  "$skyd" metar "$@" >"$out/stdout.json" 2>"$out/stderr.txt"; rc=$?
  if [ $rc -ne 0 ]; then fail "$name: exit $rc: $(cat "$out/stderr.txt")"; return; fi
  if ! LD_PRELOAD= /usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
$assertions
" "$out/stdout.json" 2>"$out/python.txt"; then
    fail "$name: $(tail -3 "$out/python.txt")"; return
  fi
  if [ "$(wc -l <"$out/stderr.txt")" -ne 1 ]; then fail "$name: stderr is not one line"; return; fi
  pass
}

# expect_refusal NAME STATUS STDERR_SUBSTRING SKYD_ARGS...
expect_refusal() {
  local name=$1 status=$2 needle=$3; shift 3
  local rc
  "$skyd" metar "$@" >"$out/stdout.txt" 2>"$out/stderr.txt"; rc=$?
  if [ $rc -ne "$status" ]; then fail "$name: exit $rc, expected $status"; return; fi
  if ! grep -qF -- "$needle" "$out/stderr.txt"; then
    fail "$name: stderr lacks '$needle': $(cat "$out/stderr.txt")"; return
  fi
  if [ -s "$out/stdout.txt" ]; then fail "$name: printed on stdout: $(cat "$out/stdout.txt")"; return; fi
  pass
}

expect_json "EGLL" '
assert j["type"] == "METAR" and j["station"] == "EGLL", j
assert j["observed"] == {"day": 28, "hour": 12, "minute": 50}, j["observed"]
assert j["wind"]["direction_deg"] == 240 and abs(j["wind"]["speed_m_s"] - 15 * 1852 / 3600) < 1e-9
assert abs(j["wind"]["gust_m_s"] - 28 * 1852 / 3600) < 1e-9
v = j["visibility"]
assert v["metres"] == 10000 and v["bound"] == "at_least" and v["ndv"] is False, v
assert abs(v["extinction_per_m"] - 3.912e-4) < 1e-15 and abs(v["extinction_per_km"] - 0.3912) < 1e-12, v
c = j["clouds"]
assert [l["amount"] for l in c] == ["FEW", "BKN"] and [l["coverage"] for l in c] == [0.1875, 0.75]
assert abs(c[0]["base_m"] - 365.76) < 1e-9 and abs(c[1]["base_m"] - 762) < 1e-9, c
assert c[1]["cumulonimbus"] and not c[0]["cumulonimbus"]
assert j["weather"]["rain"] == "light" and j["weather"]["showers"] == "light"
assert abs(j["relative_humidity"] - 0.765) < 0.005, j["relative_humidity"]
' "METAR EGLL 281250Z 24015G28KT 9999 -SHRA FEW012 BKN025CB 12/08 Q1002 NOSIG="
if grep -q "EGLL day 28 12:50Z" "$out/stderr.txt" && grep -q "BKN 762 m CB" "$out/stderr.txt"; then pass
else fail "EGLL summary: $(cat "$out/stderr.txt")"; fi

# The groups may come as separate arguments; a US report with remarks.
expect_json "KJFK, unquoted" '
assert j["visibility"]["metres"] == 10 * 1609.344 and j["sky"] == "layers"
assert j["temperature_c"] == -2 and j["dew_point_c"] == -4 and j["weather"]["mist"]
assert j["wind"]["sector_deg"] is None and j["vertical_visibility_m"] is None
' METAR KJFK 281251Z 31012KT 10SM BR OVC008 M02/M04 A2992 RMK AO2 SLP132 '$'
expect_json "CAVOK" '
assert j["cavok"] and j["sky"] == "CAVOK" and j["clouds"] == [] and j["visibility"]["bound"] == "at_least"
' "METAR LIRF 281250Z 18010KT CAVOK 25/15 Q1015 NOSIG"

expect_refusal "malformed cloud" 2 'group 6 "BKN0X0" (offset 32): cloud height must be three digits' \
  "METAR EGLL 281250Z 24015KT 9999 BKN0X0 12/08 Q1002"
expect_refusal "truncated" 2 'group 3 "281250Z" (offset 11): the report ends here without the wind' \
  "METAR EGLL 281250Z"
expect_refusal "garbage" 2 'group 6 "XYZ" (offset 32): not a METAR group' \
  "METAR EGLL 281250Z 24015KT 9999 XYZ 12/08"
expect_refusal "overlong" 2 "longer than 1024 characters" "METAR EGLL $(printf 'X%.0s' $(seq 1 1100))"
expect_refusal "no report" 2 "usage: skyd metar"
if "$skyd" metar --help | grep -q "Exit status 2 when the report is"; then pass; else fail "--help"; fi
if "$skyd" --help | grep -q "metar"; then pass; else fail "skyd --help does not list metar"; fi

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
