#!/usr/bin/env bash
# ./rbx in a copied tree whose build folder's CMake cache names another source tree (what `cp -a`
# of a built repository gives) must say so and reconfigure for the copy, not build the original.
# The copy holds no sources, so configuring it fails: the test then also sees the quiet build's
# failure path (the log on stderr, exit 2).
set -uo pipefail
script="$1"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
cp "$script" "$dir/rbx"
mkdir -p "$dir/build"
printf 'CMAKE_HOME_DIRECTORY:INTERNAL=/nonexistent/original\n' > "$dir/build/CMakeCache.txt"
err=$(cd "$dir" && ./rbx scenes 2>&1 >/dev/null)
code=$?
fail=0
grep -q "rbx: build/ was configured for /nonexistent/original; reconfiguring for $dir" <<<"$err" ||
  { echo "FAIL: no reconfigure line: $err"; fail=1; }
[ ! -f "$dir/build/CMakeCache.txt" ] || ! grep -q /nonexistent "$dir/build/CMakeCache.txt" ||
  { echo "FAIL: the original's cache was kept"; fail=1; }
[ "$code" -eq 2 ] || { echo "FAIL: exit $code for a failed configure (expected 2)"; fail=1; }
grep -q "rbx: build failed (log: $dir/build/rbx-build.log)" <<<"$err" ||
  { echo "FAIL: no build-failed line: $err"; fail=1; }
[ $fail -eq 0 ] && echo "ok: copied tree reconfigured, failure reported with its log"
exit $fail
