#!/usr/bin/env bash
# Installs the Debian packages skyd needs to build, run and test, when any is missing.
# Called by `make` (deps target); safe to run repeatedly: it does nothing when all are present.
# SKYD_DEPS_EXTRA adds packages a single target needs (make deb: debhelper, dh-python,
# dpkg-dev and lintian, listed in the Makefile's DEB_DEPS).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libvulkan-dev vulkan-tools mesa-vulkan-drivers vulkan-validationlayers
  glslang-tools
  libwebsockets-dev libcjson-dev libpng-dev libturbojpeg0-dev libsystemd-dev systemd
  python3 python3-websockets openssl curl man-db
  redis-server libhiredis-dev haproxy
  clang libclang-rt-dev clang-format
  libeccodes-dev libeccodes-tools
  chromium chromium-driver
)
if [ "${SKYD_DEPS_EXTRA:-}" != "" ]; then
  # shellcheck disable=SC2206
  packages+=(${SKYD_DEPS_EXTRA})
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
