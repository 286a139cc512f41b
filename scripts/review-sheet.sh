#!/usr/bin/env bash
# The clouds' review sheet: every cloud type by day, at sunset looking toward the sun and from
# 14 km straight above, each beside the path-traced reference of the same view (`skyd render
# --reference`), rendered into docs/images/clouds/ and listed in docs/CLOUDS.md; then the
# README's cloud image and time-lapse (docs/images/clouds.png, timelapse.png). Usage:
# scripts/review-sheet.sh [BUILD_DIR] (default build); REVIEW_SPP sets the reference's samples
# per pixel (default 16). The references take nearly all of its time: on two lavapipe cores
# about an hour at 16, most of it in the decks seen from below (light diffuses through tens
# of optical depths, and the few paths that bring it make bright specks); 64 takes four times
# as long. REVIEW_ONLY="altocumulus altostratus" renders those rows alone (the page is
# rewritten whole, the other rows keep their images); the README's images are rendered only
# when REVIEW_ONLY is empty or names `readme` (they take a minute: no reference).
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
out=docs/images/clouds
mkdir -p "$out"
skyd="$root/$build/skyd"
size=(--width 320 --height 180)
spp=${REVIEW_SPP:-16}
only=${REVIEW_ONLY:-}

# name | weather preset | extra settings
types=(
  "stratus|overcast|"
  "stratocumulus|broken|--set clouds.high.coverage=0"
  "cumulus|fair_cumulus|"
  "cumulus-congestus|scattered|--set clouds.low.type=0.85 --set clouds.low.thickness_km=3.5"
  "cumulonimbus|storm|--set clouds.low.coverage=0.55"
  "altocumulus|altocumulus|--set clouds.low.coverage=0 --set clouds.high.coverage=0"
  "altostratus|warm_front|--set clouds.low.coverage=0 --set clouds.high.coverage=0"
  "cirrus|clear|--set clouds.high.coverage=0.6 --set clouds.high.type=1 --set clouds.high.density=0.3"
  "cirrostratus|clear|--set clouds.high.coverage=0.9 --set clouds.high.type=0 --set clouds.high.density=0.3"
)
views=(
  "day|--set sun.elevation_deg=40 --set sun.azimuth_deg=150 --set camera.yaw_deg=20 --set camera.pitch_deg=10 --set camera.fov_deg=70"
  "sunset|--set sun.elevation_deg=4 --set sun.azimuth_deg=270 --set camera.yaw_deg=270 --set camera.pitch_deg=8 --set camera.fov_deg=70"
  "above|--set sun.elevation_deg=40 --set sun.azimuth_deg=150 --set camera.altitude_km=14 --set camera.pitch_deg=-90 --set camera.fov_deg=90"
)

doc=docs/CLOUDS.md
{
  echo "# Cloud review sheet"
  echo
  echo "Every cloud type by day, at sunset looking toward the sun, and from 14 km straight above,"
  echo "each beside its path-traced reference: \`skyd render --reference --spp $spp\` traces the same"
  echo "density with delta tracking and every order of scattering, sun and sky light, and no"
  echo "approximation (its grain is its own Monte Carlo noise). Both are exposed alike."
  echo "Regenerate with \`scripts/review-sheet.sh\` (it rewrites this page and the images)."
  echo
  echo "| type | day | day, reference | sunset, toward the sun | sunset, reference | from above | from above, reference |"
  echo "| --- | --- | --- | --- | --- | --- | --- |"
} > "$doc"
for t in "${types[@]}"; do
  IFS='|' read -r name preset extra <<< "$t"
  row="| $name |"
  for v in "${views[@]}"; do
    IFS='|' read -r view settings <<< "$v"
    file="$out/$name-$view.png"
    if [ -n "$only" ] && [[ " $only " != *" $name "* ]]; then
      row="$row ![$name, $view](images/clouds/$name-$view.png) | ![$name, $view, reference](images/clouds/$name-$view-reference.png) |"
      continue
    fi
    # One exposure for the pair: the renderer's metered one, read back from its stats.
    # shellcheck disable=SC2086
    ev=$("$skyd" render "${size[@]}" --weather "$preset" $extra $settings --out "$file" --stats |
         /usr/bin/python3 -c 'import json, math, sys; print("%.3f" % json.load(sys.stdin)["metered_ev100"])')
    # shellcheck disable=SC2086
    "$skyd" render "${size[@]}" --weather "$preset" $extra $settings --set exposure.mode=manual \
      --set exposure.ev100="$ev" --reference --spp "$spp" --out "$out/$name-$view-reference.png" >/dev/null
    row="$row ![$name, $view](images/clouds/$name-$view.png) | ![$name, $view, reference](images/clouds/$name-$view-reference.png) |"
  done
  echo "$row" >> "$doc"
  echo "review-sheet: $name"
done
{
  echo
  echo "Settings per row (besides the view): stratus is the \`overcast\` preset, stratocumulus"
  echo "\`broken\` without its cirrus, cumulus \`fair_cumulus\`, congestus \`scattered\` with"
  echo "clouds.low.type 0.85 in a 3.5 km layer, cumulonimbus \`storm\` at coverage 0.55,"
  echo "altocumulus and altostratus the middle layer alone (\`altocumulus\` and \`warm_front\`"
  echo "without their low and high layers), cirrus and cirrostratus the high layer alone (type 1"
  echo "and 0)."
} >> "$doc"

[ -z "$only" ] || [[ " $only " == *" readme "* ]] || exit 0
# The README's images: fair-weather cumulus under a thin high layer, and a day's time-lapse
# (the command the README shows; twelve of its hourly frames, four to a row).
"$skyd" render --width 640 --height 360 --weather fair_cumulus --set camera.pitch_deg=10 \
  --out docs/images/clouds.png >/dev/null
lapse=$(mktemp -d)
trap 'rm -rf "$lapse"' EXIT
"$skyd" render --width 320 --height 180 --time 2026-08-27T04:00:00Z --lat 45 --lon 6 \
  --set camera.yaw_deg=115 --set camera.pitch_deg=12 --weather overcast --weather-to clear \
  --transition-s 50400 --frames 20 --step-s 3600 --out "$lapse/f-%02d.png" >/dev/null
frames=()
for i in 00 01 02 04 08 12 14 15 16 17 18 19; do frames+=("$lapse/f-$i.png"); done
/usr/bin/python3 scripts/contact-sheet.py 4 docs/images/timelapse.png "${frames[@]}"
echo "review-sheet: README images"
