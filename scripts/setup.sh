#!/usr/bin/env bash
# Installs rlpbrt's build dependencies from Debian 12 packages (idempotent) and builds it.
# Usage: scripts/setup.sh [build-dir]   (default: build)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}

pkgs=(build-essential cmake ninja-build pkg-config
      libembree-dev libopenimageio-dev libopenexr-dev libimath-dev libopenvdb-dev libglm-dev libtbb-dev
      libboost-iostreams-dev openimageio-tools libopencv-core-dev
      openmpi-bin libopenmpi-dev  # distributed renders: docs/DISTRIBUTED.md
      libcli11-dev libfmt-dev nlohmann-json3-dev libnanoflann-dev libgtest-dev libgmock-dev libbenchmark-dev
      clang llvm libclang-rt-14-dev)  # clang + libFuzzer runtime: scripts/fuzz.sh
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo=sudo
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --parallel "$(nproc)"
