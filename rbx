#!/usr/bin/env bash
# rbx: one entry point. First use installs missing Debian packages, configures CMake (Release,
# build/), builds incrementally, then runs the compiled `rbx` with the same arguments.
# `./rbx test [--sanitize]` builds and runs the whole test suite with ctest.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"

packages=(cmake g++ pkg-config libeigen3-dev libbullet-dev libfcl-dev libccd-dev libgtest-dev
          libbenchmark-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libmujoco-dev
          libode-dev libqhull-dev libtinyobjloader-dev python3-matplotlib)

# Install whatever Debian package is missing (root), or say exactly what to run (not root).
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    echo "rbx: installing ${missing[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2
    apt-get install -y -qq "${missing[@]}" >&2
  else
    echo "rbx: missing packages; run: sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 2
  fi
fi

# Configure once per build flavour, then build incrementally.
build_dir=build
cmake_flags=(-DCMAKE_BUILD_TYPE=Release)
if [ "${1:-}" = "test" ] && [ "${2:-}" = "--sanitize" ]; then
  build_dir=build-sanitize
  cmake_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DRBX_SANITIZE=ON)
fi
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  cmake -S . -B "$build_dir" "${cmake_flags[@]}" >&2
fi
jobs=$(nproc 2>/dev/null || echo 2)
cmake --build "$build_dir" -j "$jobs" >&2

if [ "${1:-}" = "test" ]; then
  cd "$build_dir"
  exec ctest --output-on-failure -j "$jobs"
fi
exec "$build_dir/comparisons/rbx" "$@"
