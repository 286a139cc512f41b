#!/usr/bin/env bash
# The default job: starts the daemon with config/skyd.json from the project root (where the
# config's relative paths point) and prints its URL; Ctrl-C stops it and saves the state.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
exec "$root/$build/skyd" serve --config "$root/config/skyd.json"
