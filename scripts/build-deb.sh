#!/usr/bin/env bash
# Builds the Debian packages skyd and skyd-clients (debian/) with dpkg-buildpackage -us -uc -b
# from a copy of this tree in OUT/skyd-VERSION (so that the tree gets none of the packaging's
# build files and the packages land in OUT, not beside the checkout), then checks them with
# lintian, whose errors and warnings fail the build. `make deb` calls it.
#   scripts/build-deb.sh [OUT]       (default build-deb)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
out=${1:-build-deb}

# One version: CMake's project() and debian/changelog's.
cmake_version=$(sed -nE 's/^project\(skyd VERSION ([0-9.]+) .*/\1/p' CMakeLists.txt)
deb_version=$(dpkg-parsechangelog -S Version)
if [ "${deb_version%%-*}" != "$cmake_version" ]; then
  echo "build-deb: debian/changelog says $deb_version, CMakeLists.txt $cmake_version: add a changelog entry (dch -v $cmake_version)" >&2
  exit 1
fi

mkdir -p "$out"
out=$(cd "$out" && pwd)
src="$out/skyd-$cmake_version"
rm -rf "$src" "$out"/*.deb "$out"/*.changes "$out"/*.buildinfo
mkdir -p "$src"
# The files of the tree: a checkout's tracked and new files (not what .gitignore leaves out,
# such as build folders), else everything but build folders.
if git -C "$root" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  git -C "$root" ls-files -z --cached --others --exclude-standard |
    while IFS= read -r -d '' f; do [ -e "$f" ] && printf '%s\0' "$f"; done |
    tar --null -T - -cf - | tar -xf - -C "$src"
else
  tar --exclude='./build*' --exclude='./out' --exclude='./var' -cf - . | tar -xf - -C "$src"
fi

echo "build-deb: dpkg-buildpackage in $src"
(cd "$src" && nice -n 10 dpkg-buildpackage -us -uc -b -j"${JOBS:-$(nproc)}")

changes=$(ls "$out"/skyd_"$deb_version"_*.changes)
echo "build-deb: lintian $changes"
lintian --fail-on error,warning --info "$changes"
ls -l "$out"/*.deb
