#!/usr/bin/env bash
# Installs this build into a temporary prefix (cmake --install), then configures, builds and runs
# examples/cmake_consumer/ against it, as a separate project would: find_package(rbx) and
# target_link_libraries(app rbx::eval).
# Usage: cmake_consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1"
source="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
cmake -S "$source/examples/cmake_consumer" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log"
cmake --build "$work/build" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
"$work/build/app" "$source/scenes/contact/axis_z.toml"
