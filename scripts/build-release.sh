#!/usr/bin/env bash
# Builds every target (skyd, skyctl, tests, benchmarks) the way Debian builds packages: the
# compiler and linker flags of dpkg-buildflags (with every hardening feature on: -O2,
# -D_FORTIFY_SOURCE=2, -fstack-protector-strong, -Wformat -Werror=format-security, relro,
# bind now) under a CMake build type, and warnings as errors, so that a build type or a
# hardening flag that the daily RelWithDebInfo build does not use cannot break silently.
# `make release` and .ci/run call it.
#   scripts/build-release.sh [BUILD_DIR]            (default build-release)
#   SKYD_BUILD_TYPE=Debug|RelWithDebInfo|MinSizeRel (default Release)
#   CC=clang                                        (default: CMake's choice, gcc on Debian)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-release}
type=${SKYD_BUILD_TYPE:-Release}
case "$type" in
  Release | RelWithDebInfo | Debug | MinSizeRel) ;;
  *) echo "build-release: SKYD_BUILD_TYPE must be Release, RelWithDebInfo, Debug or MinSizeRel, got '$type'" >&2
     exit 2 ;;
esac

export DEB_BUILD_MAINT_OPTIONS=hardening=+all
# CMake reads CFLAGS and LDFLAGS but not CPPFLAGS (where _FORTIFY_SOURCE is), as debhelper
# knows too: the preprocessor's flags go with the compiler's.
CFLAGS="$(dpkg-buildflags --get CFLAGS) $(dpkg-buildflags --get CPPFLAGS)"
LDFLAGS="$(dpkg-buildflags --get LDFLAGS)"
export CFLAGS LDFLAGS

# A build directory keeps the flags it was first configured with; start again when they or
# the compiler differ.
stamp="$build/.skyd-build-flags"
want="type=$type cc=${CC:-default} cflags=$CFLAGS ldflags=$LDFLAGS"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" != "$want" ]; then
  rm -rf "$build"
fi
mkdir -p "$build"
echo "build-release: $type, ${CC:-default compiler}, CFLAGS=$CFLAGS LDFLAGS=$LDFLAGS"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE="$type" -DSKYD_WERROR=ON >/dev/null
echo "$want" >"$stamp"
cmake --build "$build" -j"${JOBS:-$(nproc)}"
