#!/usr/bin/env bash
# rbx: one entry point. First use installs missing Debian packages, configures CMake (Release,
# build/), builds incrementally, then runs the compiled `rbx` with the same arguments.
# `./rbx test [--sanitize]` builds and runs the whole test suite with ctest.
# `./rbx fuzz [SECONDS]` builds the libFuzzer targets (tests/fuzz) with clang, ASan and UBSan in
# build-fuzz/ and runs each for SECONDS (default 60) from its seed corpus.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"

packages=(cmake g++ pkg-config libeigen3-dev libbullet-dev libfcl-dev libccd-dev libgtest-dev
          libbenchmark-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libmujoco-dev
          libode-dev libqhull-dev libtinyobjloader-dev python3-matplotlib)
# Fuzzing needs clang and libFuzzer, which Debian ships in libclang-rt-14-dev (only recommended
# by clang-14, so not always there).
if [ "${1:-}" = "fuzz" ]; then
  packages+=(clang libclang-rt-14-dev)
fi

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

jobs=$(nproc 2>/dev/null || echo 2)

# Fuzzing: its own build folder and compiler; a crash leaves its input in
# build-fuzz/crashes/<target>/ (copy it to tests/fuzz/regressions/<target>/ once fixed) and
# makes the action exit 1. New inputs found go to build-fuzz/corpus/<target>/, never into the
# committed seed corpus.
if [ "${1:-}" = "fuzz" ]; then
  seconds="${2:-60}"
  if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -eq 0 ] || [ $# -gt 2 ]; then
    echo "rbx: usage: ./rbx fuzz [SECONDS]  (seconds per target, a positive integer; default 60)" >&2
    exit 2
  fi
  if [ ! -f build-fuzz/CMakeCache.txt ]; then
    CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DRBX_SANITIZE=ON -DRBX_FUZZ=ON >&2
  fi
  targets=(scene_parser obj_loader convex_detect)
  cmake --build build-fuzz -j "$jobs" --target "${targets[@]/#/fuzz_}" >&2
  failed=()
  for t in "${targets[@]}"; do
    mkdir -p "build-fuzz/corpus/$t" "build-fuzz/crashes/$t"
    dict=()
    [ -f "tests/fuzz/$t.dict" ] && dict=(-dict="tests/fuzz/$t.dict")
    echo "rbx fuzz: $t for ${seconds} s" >&2
    # -timeout: one input running 30 s is a hang; -rss_limit_mb: 2 GiB is far above any input.
    if ! "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 \
        -print_final_stats=1 "${dict[@]}" -artifact_prefix="build-fuzz/crashes/$t/" \
        "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t"; then
      failed+=("$t")
    fi
  done
  if [ ${#failed[@]} -gt 0 ]; then
    echo "rbx fuzz: FAILED: ${failed[*]} (inputs in build-fuzz/crashes/)" >&2
    exit 1
  fi
  echo "rbx fuzz: ${#targets[@]} targets, ${seconds} s each, no crash" >&2
  exit 0
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
cmake --build "$build_dir" -j "$jobs" >&2

if [ "${1:-}" = "test" ]; then
  cd "$build_dir"
  exec ctest --output-on-failure -j "$jobs"
fi
exec "$build_dir/comparisons/rbx" "$@"
