#!/usr/bin/env bash
# The clouds' review sheet: every cloud type by day, at sunset looking toward the sun and from
# 14 km straight above, rendered by `skyd render` into docs/images/clouds/ and listed in
# docs/CLOUDS.md. Usage: scripts/review-sheet.sh [BUILD_DIR] (default build). About a minute
# on two lavapipe cores.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
out=docs/images/clouds
mkdir -p "$out"
skyd="$root/$build/skyd"
size=(--width 480 --height 270)

# name | weather preset | extra settings
types=(
  "stratus|overcast|"
  "stratocumulus|broken|--set clouds.high.coverage=0"
  "cumulus|fair_cumulus|"
  "cumulus-congestus|scattered|--set clouds.low.type=0.85 --set clouds.low.thickness_km=3.5"
  "cumulonimbus|storm|--set clouds.low.coverage=0.55"
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
  echo "Every cloud type by day, at sunset looking toward the sun, and from 14 km straight above."
  echo "Regenerate with \`scripts/review-sheet.sh\` (it rewrites this page and the images)."
  echo
  echo "| type | day | sunset, toward the sun | from above |"
  echo "| --- | --- | --- | --- |"
} > "$doc"
for t in "${types[@]}"; do
  IFS='|' read -r name preset extra <<< "$t"
  row="| $name |"
  for v in "${views[@]}"; do
    IFS='|' read -r view settings <<< "$v"
    file="$out/$name-$view.png"
    # shellcheck disable=SC2086
    "$skyd" render "${size[@]}" --weather "$preset" $extra $settings --out "$file" >/dev/null
    row="$row ![$name, $view](images/clouds/$name-$view.png) |"
  done
  echo "$row" >> "$doc"
  echo "review-sheet: $name"
done
{
  echo
  echo "Settings per row (besides the view): stratus is the \`overcast\` preset, stratocumulus"
  echo "\`broken\` without its cirrus, cumulus \`fair_cumulus\`, congestus \`scattered\` with"
  echo "clouds.low.type 0.85 in a 3.5 km layer, cumulonimbus \`storm\` at coverage 0.55, cirrus and"
  echo "cirrostratus the high layer alone (type 1 and 0)."
} >> "$doc"
