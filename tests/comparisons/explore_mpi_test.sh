#!/usr/bin/env bash
# rbx explore under MPI: the same explore.json (timing aside) and the same scenes with threads
# only and with 1, 2 and 3 ranks. Usage: explore_mpi_test.sh RBX MPIEXEC
set -euo pipefail
rbx="$1"
mpiexec="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
args=(explore --count 60 --seed 3 --backends custom,fcl,bullet-sat --shrink-budget 40 --no-figure)
extra=(--oversubscribe)
[ "$(id -u)" -eq 0 ] && extra+=(--allow-run-as-root)
"$rbx" "${args[@]}" --out "$work/threads" > /dev/null
for n in 1 2 3; do
  "$mpiexec" "${extra[@]}" -n "$n" "$rbx" "${args[@]}" --out "$work/ranks$n" > "$work/log$n"
  grep -q "on $n rank(s)" "$work/log$n" || { echo "ranks=$n: not run on $n ranks"; cat "$work/log$n"; exit 1; }
done
strip() { /usr/bin/python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); j.pop("timing"); print(json.dumps(j, indent=1, sort_keys=True))' "$1"; }
ref="$(strip "$work/threads/explore.json")"
for n in 1 2 3; do
  if [ "$ref" != "$(strip "$work/ranks$n/explore.json")" ]; then
    echo "explore.json differs between threads and $n ranks"
    diff <(echo "$ref") <(strip "$work/ranks$n/explore.json") | head -20
    exit 1
  fi
  diff -r "$work/threads/scenes" "$work/ranks$n/scenes" > /dev/null ||
    { echo "scenes differ between threads and $n ranks"; exit 1; }
done
echo "explore.json and scenes identical with threads and with 1, 2, 3 ranks"
