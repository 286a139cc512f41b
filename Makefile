# skyd: `make run` renders/serves the default job, `make test` runs every test suite.
# Both install missing Debian packages first (scripts/install-deps.sh).

BUILD      ?= build
MAKEFLAGS  += --no-print-directory
ASAN_BUILD ?= build-asan
RELEASE_BUILD ?= build-release
DEB_BUILD ?= build-deb
# What `make deb` needs besides the build's own packages (install-deps.sh, SKYD_DEPS_EXTRA).
DEB_DEPS = debhelper dh-python dpkg-dev lintian
JOBS       ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=RelWithDebInfo

FUZZ_SECONDS ?= 1800

.PHONY: all deps configure build release deb run cluster test test-long test-asan fuzz bench soak format format-check clean

all: build

deps:
	@./scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j$(JOBS)

# Everything built as Debian builds packages (dpkg-buildflags, hardening on) in a Release
# build, warnings as errors (scripts/build-release.sh; SKYD_BUILD_TYPE and CC pick others).
release: deps
	@./scripts/build-release.sh $(RELEASE_BUILD)

# The Debian packages skyd and skyd-clients (debian/), built from a copy of the tree with
# dpkg-buildpackage -us -uc -b and checked by lintian, in $(DEB_BUILD)/ (scripts/build-deb.sh).
deb: deps
	@SKYD_DEPS_EXTRA="$(DEB_DEPS)" ./scripts/install-deps.sh
	@./scripts/build-deb.sh $(DEB_BUILD)

run: build
	@./scripts/run-default.sh $(BUILD)

# Redis, three nodes sharing one world and haproxy in front, on loopback ports, in the
# foreground (docs/SCALING.md); prints the one URL to open. SKYD_CLUSTER_PORT picks its port.
cluster: build
	@./scripts/cluster.sh $(BUILD)

# Every suite: unit, reference, render (lavapipe with validation), command line; then a short
# fuzzing run (about 60 s) of the protocol parser, weather maps, the METAR decoder and the
# configuration loader; last, that the C sources are in the .clang-format style (a few seconds).
test: build
	@cd $(BUILD) && ctest --output-on-failure --timeout 900 --label-exclude long
	@./scripts/fuzz.sh 60
	@./scripts/format.sh --check

# The tests labelled long (the sky against the Monte Carlo reference, the cloud shapes, the
# clouds against the path tracer, the cloud fields from 14 km against the published
# statistics, the middle layer against the path tracer, an installation, device faults on the
# daemon, no pipeline compiled at dispatch, skyd forecast and render --metar/--forecast, a slow
# forecast read and the forecast's weather map), kept out of `make test`'s 20 minutes; CI runs
# them after it, and make test-asan runs those not labelled shader_bound or reference_bound.
test-long: build
	@cd $(BUILD) && ctest --output-on-failure --timeout 1800 --label-regex long

# A long fuzzing run (FUZZ_SECONDS, shared by the targets); the corpus grows in build-fuzz/.
fuzz: deps
	@./scripts/fuzz.sh $(FUZZ_SECONDS)

# The same suites built with AddressSanitizer and UndefinedBehaviorSanitizer, leak checks on.
# The Vulkan loader unloads the driver at vkDestroyInstance, after which LeakSanitizer can
# neither scan nor name it; preloading it (after the ASan runtime, which must come first)
# keeps it resident, and tests/common/lsan.supp then suppresses what it allocates, by module name.
# The driver allocates and frees blocks of a few hundred KiB per dispatch; behind ASan's
# default 256 MiB quarantine each one is freshly mapped, which made a sanitized frame four
# times slower, almost all of it in the kernel. A 16 MiB quarantine still holds the last
# frames' frees, so a use after free in our code is still caught.
# Tests labelled shader_bound (the path tracer, the cloud shapes, fields and middle layer, the
# pipeline-compile counts of skyd render and of a daemon) spend their time in lavapipe running
# shaders, which the sanitizers do not see; their C paths (a render's setup, its passes,
# readback) run in the other render tests.
# They are left out here, as is accuracy (reference_bound: a Monte Carlo reference in tests/,
# whose library ctest reference runs here), which keeps CI, which runs them unsanitized,
# inside its time.
ASAN_RUNTIME = $(shell $(CC) -print-file-name=libasan.so)
VK_DRIVER = $(wildcard /usr/lib/*/libvulkan_lvp.so)
test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DSKYD_SANITIZE=ON >/dev/null
	@cmake --build $(ASAN_BUILD) -j$(JOBS)
	@cd $(ASAN_BUILD) && LD_PRELOAD="$(ASAN_RUNTIME) $(VK_DRIVER)" \
	  ASAN_OPTIONS=detect_leaks=1:quarantine_size_mb=16 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/common/lsan.supp \
	  UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure --timeout 1800 --label-exclude 'shader_bound|reference_bound'

bench: build
	@$(BUILD)/bench/skyd_bench $(BENCH_ARGS)

# The daemon with validation on, clients attached and random valid changes for 30 simulated
# minutes after a 10-minute warm-up (about 6 real minutes): fails when its memory grows 5 % or
# more, on any validation message or on any refused change. Not part of `make test`.
# SOAK_ARGS="--help" lists options.
soak: build
	@/usr/bin/python3 bench/soak.py --skyd $(BUILD)/skyd $(SOAK_ARGS)

# The C sources in the style of .clang-format (clang-format 14 or later); format-check changes
# nothing and fails when a file is not formatted.
format: deps
	@./scripts/format.sh

format-check: deps
	@./scripts/format.sh --check

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(RELEASE_BUILD) $(DEB_BUILD) build-fuzz out
