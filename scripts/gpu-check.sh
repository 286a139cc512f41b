#!/usr/bin/env bash
# A device check anyone can run: skyd's render suites and benches on the Vulkan device this
# machine has (a GPU when there is one, else lavapipe), with the figures written into
# docs/PERFORMANCE.md's "Device check" section (between its gpu-check markers):
#   - the device and driver, the commit, whether the validation layer was on;
#   - each render suite, passed or failed, and its time;
#   - per-pass GPU times of sky + aerial perspective and of sky + clouds + aerial perspective at
#     1280x720, 1920x1080 and 3840x2160 (640x360 and 1280x720 with --quick);
#   - the atmosphere LUT rebuild, the converged multiple scattering's fade-in, and streaming
#     frame rates (JPEG and PNG, 1 and 4 clients).
# The render tests run as programs, not through ctest: ctest turns validation on, and a machine
# with only a GPU driver has no validation layer. Without the layer they run with
# SKYD_VALIDATION=0 and the section says so. The benches always run without it.
#
# usage: scripts/gpu-check.sh [--build DIR] [--logs DIR] [--quick] [--no-tests] [--no-benches]
#                             [--no-write] [--device NAME]
#   --build DIR    the build folder (default build)
#   --logs DIR     where each program's output goes (default BUILD/gpu-check)
#   --quick        smaller sizes and fewer frames (for a CPU device)
#   --no-tests     benches only; --no-benches: tests only
#   --no-write     print the section, leave docs/PERFORMANCE.md alone
#   --device NAME  the device the benches ask for (SKYD_DEVICE: gpu, cpu, an index or a name)
# Exit status: 0 when every suite passed and every bench ran, 1 otherwise, 2 on bad usage.
set -uo pipefail
cd "$(dirname "$0")/.."

build=build logs="" quick=0 run_tests=1 run_benches=1 write=1
device="${SKYD_DEVICE:-}"
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="${2:?--build needs a folder}"; shift 2 ;;
    --logs) logs="${2:?--logs needs a folder}"; shift 2 ;;
    --device) device="${2:?--device needs a name}"; shift 2 ;;
    --quick) quick=1; shift ;;
    --no-tests) run_tests=0; shift ;;
    --no-benches) run_benches=0; shift ;;
    --no-write) write=0; shift ;;
    -h|--help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "gpu-check: unknown option $1" >&2; exit 2 ;;
  esac
done
logs="${logs:-$build/gpu-check}"
for f in "$build/skyd" "$build/bench/skyd_bench" "$build/bench/skyd_bench_serve"; do
  if [ ! -x "$f" ]; then
    echo "gpu-check: $f is missing: build first (make build)" >&2
    exit 2
  fi
done
mkdir -p "$logs"
export SKYD_DEVICE="$device"
status=0

# The device, as skyd's renderer chooses it (its first log line names it).
probe_png="$logs/probe.png"
"$build/skyd" render --width 16 --height 16 --weather clear --out "$probe_png" >"$logs/device.txt" 2>&1
device_line=$(grep -m1 'vulkan device:' "$logs/device.txt" | sed 's/^.*vulkan device: //')
if [ -z "$device_line" ]; then
  echo "gpu-check: no Vulkan device answered (see $logs/device.txt)" >&2
  exit 1
fi
driver="unknown"
if command -v vulkaninfo >/dev/null 2>&1; then
  vulkaninfo --summary >"$logs/vulkaninfo.txt" 2>&1 || true
  name="${device_line%% (*}"
  driver=$(awk -v n="$name" '/deviceName/ && index($0, n) { found = 1 }
                             found && /driverInfo/ { sub(/.*= /, ""); print; exit }' \
                             "$logs/vulkaninfo.txt")
  driver="${driver:-unknown}"
fi
# The validation layer, if this machine has it.
validation=0
for dir in ${VK_LAYER_PATH:-} ${VK_ADD_LAYER_PATH:-} /usr/share/vulkan/explicit_layer.d \
           /etc/vulkan/explicit_layer.d /usr/local/share/vulkan/explicit_layer.d; do
  if ls "$dir"/*khronos_validation*.json >/dev/null 2>&1; then validation=1; fi
done
export SKYD_VALIDATION=$validation
echo "gpu-check: device $device_line; driver $driver; validation $([ $validation = 1 ] && echo on || echo off)"

# One program under a timeout with line-buffered output (a program killed at its timeout keeps
# what it printed). Appends "name|result|seconds" to $logs/results.txt.
: >"$logs/results.txt"
run() {
  local name=$1 limit=$2
  shift 2
  local t0 t1 rc
  t0=$(date +%s.%N)
  timeout "$limit" stdbuf -oL -eL "$@" >"$logs/$name.txt" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  local result=passed
  [ $rc -eq 124 ] && result="timed out"
  [ $rc -ne 0 ] && [ $rc -ne 124 ] && result="failed ($rc)"
  [ $rc -ne 0 ] && status=1
  awk -v n="$name" -v r="$result" -v a="$t0" -v b="$t1" 'BEGIN { printf "%s|%s|%.1f\n", n, r, b - a }' \
    >>"$logs/results.txt"
  echo "gpu-check: $name $result"
}

out="$build/test-output/gpu-check"
mkdir -p "$out"
if [ $run_tests = 1 ]; then
  t="$build/tests"
  run render 1800 "$t/test_render" "$out"
  run clouds 1800 "$t/test_clouds" "$out"
  run cloud_shapes 1800 "$t/test_cloud_shapes" "$out" config
  run cloud_stream 1800 "$t/test_cloud_stream" "$out"
  run cloud_vs_reference 1800 "$t/test_cloud_vs_reference" "$out" config
  run night 1800 "$t/test_night" "$out"
  run envmap 1800 "$t/test_envmap" "$out"
  run lut_amortization 1800 "$t/test_lut_amortization"
  run render_multiple_scattering 1800 "$t/test_ms_refine"
  run cloud_quality 1800 "$t/test_cloud_quality"
  run units 1800 "$t/test_units"
fi

if [ $run_benches = 1 ]; then
  export SKYD_VALIDATION=0 # the layer's checks would be timed with the passes
  if [ $quick = 1 ]; then
    sizes=(--size 640x360 --size 1280x720) frames=20 stream_sizes=(640x360) seconds=5
  else
    sizes=(--size 1280x720 --size 1920x1080 --size 3840x2160) frames=200
    stream_sizes=(1920x1080 3840x2160) seconds=10
  fi
  bench="$build/bench/skyd_bench"
  run bench_sky 1800 "$bench" --rebuilds 15 --frames $frames "${sizes[@]}"
  run bench_clouds 1800 "$bench" --rebuilds 1 --frames $frames --clouds "${sizes[@]}"
  # Frames as a stream's (live views, maps under the daemon's budget), with
  # clouds.quality.resolution auto under a 2 ms frame budget: the level reached, the cost, p99
  run bench_clouds_auto 1800 "$bench" --rebuilds 1 --frames $frames --clouds "${sizes[@]}" \
    --stream --set clouds.quality.resolution=auto --frame-budget 2
  run bench_converge 1800 "$bench" --rebuilds 1 --frames 300 --size 1280x720 --converge --fps 60
  for size in "${stream_sizes[@]}"; do
    for format in jpeg png; do
      run "stream_${format}_$size" 600 "$build/bench/skyd_bench_serve" --skyd "$build/skyd" \
        --clients 1,4 --size "$size" --fps 60 --format "$format" --warmup 3 --seconds $seconds
    done
  done
fi

# The section, from the logs.
section="$logs/section.md"
/usr/bin/python3 scripts/gpu_check_report.py --logs "$logs" --device "$device_line" \
  --driver "$driver" --validation $validation --commit "$(git rev-parse --short HEAD 2>/dev/null || echo unknown)" \
  --command "scripts/gpu-check.sh $([ $quick = 1 ] && echo --quick)" >"$section" || status=1
cat "$section"
if [ $write = 1 ] && [ -s "$section" ]; then
  /usr/bin/python3 scripts/gpu_check_report.py --insert "$section" docs/PERFORMANCE.md || status=1
  echo "gpu-check: docs/PERFORMANCE.md's device check section rewritten"
fi
exit $status
