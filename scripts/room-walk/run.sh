#!/usr/bin/env bash
# Counts the rooms a `set` walks through, from the WebSocket to the next frame on the wire:
# builds skyd with -finstrument-functions and tracer.c (render/'s internals stay out: render/
# is one room, sky_renderer.c), traces one set on a streaming daemon (scenario.py) and counts
# (analyze.py). Usage: scripts/room-walk/run.sh [BUILD_DIR] (default build-walk).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build-walk}
mkdir -p "$build"
cc -O2 -c "$here/tracer.c" -o "$build/walk_tracer.o"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_C_FLAGS=-finstrument-functions -finstrument-functions-exclude-file-list=render/vk,render/sky/,render/clouds,render/night,/usr/ -Wno-format-truncation" \
    "-DCMAKE_EXE_LINKER_FLAGS=$build/walk_tracer.o" >/dev/null
cmake --build "$build" -j2 --target skyd >/dev/null
scratch=$(mktemp -d)
/usr/bin/python3 "$here/scenario.py" "$build/skyd" "$scratch"
/usr/bin/python3 "$here/analyze.py" "$build/skyd" "$scratch/trace.bin" --walk
rm -rf "$scratch"
