#!/usr/bin/env bash
# rbx: one entry point. First use installs missing Debian packages, configures CMake (Release,
# build/), builds incrementally, then runs the compiled `rbx` with the same arguments.
# `./rbx test [--quick | --sanitize] [CTEST ARGS...]` builds and runs the test suite with ctest:
# every tier (unit, scene, e2e: tests/CMakeLists.txt); --quick, the unit tier only (the one to run
# while editing); --sanitize, the unit and scene tiers under ASan and UBSan in build-sanitize/.
# Further arguments go to ctest (for example -R NAME).
# `./rbx python [ARGS...]` builds the Python module and runs python3 with `import rbx` working.
# `./rbx format [--check]` applies (or checks) clang-format on every tracked C++ source.
# `./rbx fuzz [SECONDS]` builds the libFuzzer targets (tests/fuzz) with clang, ASan and UBSan in
# build-fuzz/ and runs each for SECONDS (default 60) from its starting corpus, one per core at a time.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# Paths on the command line are the caller's: remember where the caller stands, build from the
# repository, and run the compiled rbx from the caller's directory.
caller="$(pwd)"
cd "$here"

packages=(cmake g++ pkg-config libeigen3-dev libbullet-dev libfcl-dev libccd-dev libgtest-dev
          libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libmujoco-dev
          libode-dev libqhull-dev libtinyobjloader-dev python3-matplotlib zlib1g-dev
          libjs-three chromium python3-pil libopenmpi-dev openmpi-bin python3-dev pybind11-dev
          python3-numpy python3-pytest libdart-dev libmd4c-dev libmd4c-html0-dev lld)
# python3-dev, pybind11-dev, python3-numpy, python3-pytest: the Python module (`./rbx python`,
# python/) and its tests.
# libmd4c-dev, libmd4c-html0-dev: md4c, which renders the report's Markdown as its HTML pages.
# lld: LLVM's linker, which links the test executables faster than GNU ld (CMakeLists.txt).
# libjs-three: three.js for the replay pages (`rbx view`, report views/); chromium and python3-pil:
# the browser test of those pages (headless screenshots read with PIL).
# `./rbx format [--check]` needs clang-format (Debian's `clang-format`, version 14 here).
if [ "${1:-}" = "format" ]; then
  packages+=(clang-format)
fi
# Fuzzing and the sanitizer build need clang and its sanitizer runtimes (libFuzzer, ASan, UBSan),
# which Debian ships in libclang-rt-14-dev (only recommended by clang-14, so not always there).
if [ "${1:-}" = "fuzz" ] || { [ "${1:-}" = "test" ] && [ "${2:-}" = "--sanitize" ]; }; then
  packages+=(clang libclang-rt-14-dev)
fi

# Fast path, when everything is up to date: the packages were all found since dpkg last changed
# anything (a stamp newer than dpkg's status file), the build folder belongs to this tree, and
# no source or CMake file is newer than the binary. Then the binary runs at once (no package
# queries, no build check); anything else takes the full path below.
stamp=build/.rbx-packages-found
case "${1:-}" in
  test | format | fuzz | python) ;;
  *)
    if [ -x build/comparisons/rbx ] && [ -f "$stamp" ] && [ "$stamp" -nt /var/lib/dpkg/status ] &&
       [ "$(cat "$stamp")" = "${packages[*]}" ] &&
       grep -qxF "CMAKE_HOME_DIRECTORY:INTERNAL=$here" build/CMakeCache.txt 2>/dev/null &&
       [ -z "$(find CMakeLists.txt engine reference comparisons -newer build/comparisons/rbx \
               -print -quit)" ]; then
      cd "$caller"
      exec "$here/build/comparisons/rbx" "$@"
    fi
    ;;
esac

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

# Every package is there now: remember it (the default list only) for the fast path above.
if [ "${1:-}" != format ] && [ "${1:-}" != fuzz ]; then
  mkdir -p build
  echo "${packages[*]}" >"$stamp"
fi

jobs=$(nproc 2>/dev/null || echo 2)

# Formatting: every tracked C++ source through clang-format (.clang-format at the root).
# `--check` changes nothing and exits 1 naming the files that are not formatted.
if [ "${1:-}" = "format" ]; then
  mapfile -t sources < <(git ls-files '*.cpp' '*.h')
  if [ "${2:-}" = "--check" ]; then
    bad=()
    for f in "${sources[@]}"; do
      clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
    done
    if [ ${#bad[@]} -gt 0 ]; then
      echo "rbx format: not formatted (run ./rbx format): ${bad[*]}" >&2
      exit 1
    fi
    echo "rbx format: ${#sources[@]} files formatted"
    exit 0
  elif [ $# -gt 1 ]; then
    echo "rbx: usage: ./rbx format [--check]" >&2
    exit 2
  fi
  clang-format -i "${sources[@]}"
  echo "rbx format: ${#sources[@]} files formatted"
  exit 0
fi

# Fuzzing: its own build folder and compiler; a crash leaves its input in
# build-fuzz/crashes/<target>/ (copy it to tests/fuzz/regressions/<target>/ once fixed) and
# makes the action exit 1. New inputs found go to build-fuzz/corpus/<target>/, never into the
# committed starting corpus.
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
  # One target per core at a time, each for its full SECONDS; each one's output is kept in its
  # own log and printed whole, in target order, once it has finished.
  fuzz_one() {
    local t=$1
    mkdir -p "build-fuzz/corpus/$t" "build-fuzz/crashes/$t"
    local dict=()
    [ -f "tests/fuzz/$t.dict" ] && dict=(-dict="tests/fuzz/$t.dict")
    # -timeout: one input running 30 s is a hang; -rss_limit_mb: 2 GiB is far above any input.
    "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 \
      -print_final_stats=1 "${dict[@]}" -artifact_prefix="build-fuzz/crashes/$t/" \
      "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" >"build-fuzz/$t.log" 2>&1
  }
  failed=()
  pids=()
  for i in "${!targets[@]}"; do
    t=${targets[$i]}
    # Wait for the oldest running target once every core has one.
    if [ ${#pids[@]} -ge "$jobs" ]; then
      j=$((i - jobs))
      wait "${pids[$j]}" || failed+=("${targets[$j]}")
      echo "rbx fuzz: ${targets[$j]} for ${seconds} s" >&2
      cat "build-fuzz/${targets[$j]}.log" >&2
    fi
    fuzz_one "$t" &
    pids+=($!)
  done
  for ((j = ${#targets[@]} - jobs < 0 ? 0 : ${#targets[@]} - jobs; j < ${#targets[@]}; j++)); do
    wait "${pids[$j]}" || failed+=("${targets[$j]}")
    echo "rbx fuzz: ${targets[$j]} for ${seconds} s" >&2
    cat "build-fuzz/${targets[$j]}.log" >&2
  done
  if [ ${#failed[@]} -gt 0 ]; then
    echo "rbx fuzz: FAILED: ${failed[*]} (inputs in build-fuzz/crashes/)" >&2
    exit 1
  fi
  echo "rbx fuzz: ${#targets[@]} targets, ${seconds} s each, no crash" >&2
  exit 0
fi

# Configure once per build flavour, then build incrementally. The build is quiet: one line on
# stderr while something is compiled, the whole log when the build fails, nothing when up to date.
build_dir=build
cmake_flags=(-DCMAKE_BUILD_TYPE=Release)
targets=(--target rbx)  # the scene commands need the rbx executable only; `test` builds everything
if [ "${1:-}" = "python" ]; then
  targets=(--target _rbx)
fi
ctest_args=()
if [ "${1:-}" = "test" ]; then
  targets=()
  shift
  case "${1:-}" in
    --sanitize)
      build_dir=build-sanitize
      # clang, as for the fuzzers: with ASan and UBSan it compiles this code two to three times
      # faster than GCC (docs/testing.md), and its sanitizers are the reference ones.
      cmake_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DRBX_SANITIZE=ON "-DRBX_TEST_TIERS=unit;scene"
                   -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++)
      ctest_args=(-L '^(unit|scene)$')
      shift
      ;;
    --quick)
      ctest_args=(-L '^unit$')
      shift
      ;;
  esac
  ctest_args+=("$@")
  set -- test
fi
mkdir -p "$build_dir"
log="$build_dir/rbx-build.log"

# A build folder configured for another source tree (a copied repository: `cp -a` keeps the
# CMake cache, whose home directory still names the original) would build the original's sources.
if [ -f "$build_dir/CMakeCache.txt" ]; then
  home=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build_dir/CMakeCache.txt")
  if [ "$home" != "$here" ]; then
    echo "rbx: $build_dir/ was configured for $home; reconfiguring for $here" >&2
    rm -rf "${build_dir:?}/CMakeCache.txt" "${build_dir:?}/CMakeFiles"
  fi
  # A sanitizer build folder from before it moved to clang is configured afresh (CMake cannot
  # change the compiler of a configured folder).
  if [ "$build_dir" = build-sanitize ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang++' "$build_dir/CMakeCache.txt"; then
    echo "rbx: $build_dir/ was configured with another compiler; reconfiguring with clang" >&2
    rm -rf "${build_dir:?}"
    mkdir -p "$build_dir"
  fi
fi

# Runs one build step with its output in the log; announces itself once if it does any work.
announced=0
quiet() {
  "$@" >"$log" 2>&1 &
  local pid=$!
  while kill -0 "$pid" 2>/dev/null; do
    if [ $announced -eq 0 ] && grep -qE 'Building|Linking|Configuring|Generating' "$log" 2>/dev/null; then
      echo "rbx: building (log: $here/$log)" >&2
      announced=1
    fi
    sleep 0.2
  done
  if ! wait "$pid"; then
    cat "$log" >&2
    echo "rbx: build failed (log: $here/$log)" >&2
    exit 2
  fi
}
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  quiet cmake -S . -B "$build_dir" "${cmake_flags[@]}"
fi
quiet cmake --build "$build_dir" -j "$jobs" "${targets[@]}"

if [ "${1:-}" = "test" ]; then
  cd "$build_dir"
  exec ctest --output-on-failure -j "$jobs" "${ctest_args[@]}"
fi
cd "$caller"
# `./rbx python [ARGS...]`: Debian's python3 (its numpy and matplotlib) with the module rbx
# importable from this tree; nothing is installed.
if [ "${1:-}" = "python" ]; then
  shift
  export PYTHONPATH="$here/python:$here/$build_dir/python${PYTHONPATH:+:$PYTHONPATH}"
  exec /usr/bin/python3 "$@"
fi
exec "$here/$build_dir/comparisons/rbx" "$@"
