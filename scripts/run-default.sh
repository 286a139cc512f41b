#!/usr/bin/env bash
# The default job: renders the default sky (config defaults, Earth) to out/default-sky.png
# and prints its path.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$root/out"
"$root/$build/skyd" render --width 1280 --height 720 --out "$root/out/default-sky.png" >/dev/null
echo "$root/out/default-sky.png"
