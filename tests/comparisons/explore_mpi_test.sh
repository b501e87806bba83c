#!/usr/bin/env bash
# rbx explore (contact and impact kinds) and rbx report under MPI: the same explore.json
# (timing aside) and scenes, and the same results.json (run times aside) and metrics.csv, with
# threads only and with 1, 2 and 3 ranks. Usage: explore_mpi_test.sh RBX MPIEXEC
set -euo pipefail
rbx="$1"
mpiexec="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
extra=(--oversubscribe)
[ "$(id -u)" -eq 0 ] && extra+=(--allow-run-as-root)
strip_explore() { /usr/bin/python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); j.pop("timing"); print(json.dumps(j, indent=1, sort_keys=True))' "$1"; }
# results.json: every run time (keys runtime_s and timing: a run's median, quartiles, cold call
# and the counts its timing chose) removed; everything else must match.
strip_results() {
  /usr/bin/python3 -c '
import json, sys
def strip(x):
    if isinstance(x, dict): return {k: strip(v) for k, v in x.items() if k not in ("runtime_s", "timing")}
    if isinstance(x, list): return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))' "$1"
}

for kind in contact impact; do
  if [ "$kind" = contact ]; then
    args=(explore --count 60 --seed 3 --backends custom,fcl,bullet-sat --shrink-budget 40 --no-figure)
  else
    args=(explore --kind impact --count 6 --seed 3 --backends custom,ode,mujoco --shrink-budget 10 --no-figure)
  fi
  "$rbx" "${args[@]}" --out "$work/$kind-threads" > /dev/null
  ref="$(strip_explore "$work/$kind-threads/explore.json")"
  for n in 1 2 3; do
    "$mpiexec" "${extra[@]}" -n "$n" "$rbx" "${args[@]}" --out "$work/$kind-ranks$n" > "$work/log$n"
    grep -q "on $n rank(s)" "$work/log$n" || { echo "$kind ranks=$n: not run on $n ranks"; cat "$work/log$n"; exit 1; }
    if [ "$ref" != "$(strip_explore "$work/$kind-ranks$n/explore.json")" ]; then
      echo "$kind: explore.json differs between threads and $n ranks"
      diff <(echo "$ref") <(strip_explore "$work/$kind-ranks$n/explore.json") | head -20
      exit 1
    fi
    diff -r "$work/$kind-threads/scenes" "$work/$kind-ranks$n/scenes" > /dev/null ||
      { echo "$kind: scenes differ between threads and $n ranks"; exit 1; }
  done
  echo "explore --kind $kind: explore.json and scenes identical with threads and with 1, 2, 3 ranks"
done

# rbx report on four scenes (two impacts with a closed form, two contacts).
scenes=(scenes/analytic/headon_e1.toml scenes/analytic/offcentre_vertex.toml
        scenes/contact/axis_x.toml scenes/contact/edge_edge_crossed.toml)
"$rbx" report "${scenes[@]}" --threads 1 --out "$work/report-t1" > /dev/null
ref="$(strip_results "$work/report-t1/results.json")"
runs=(t2 r1 r2 r3)
"$rbx" report "${scenes[@]}" --threads 2 --out "$work/report-t2" > /dev/null
for n in 1 2 3; do
  "$mpiexec" "${extra[@]}" -n "$n" "$rbx" report "${scenes[@]}" --out "$work/report-r$n" > "$work/rlog$n"
  grep -q "; $n rank(s)" "$work/rlog$n" || { echo "report ranks=$n: not run on $n ranks"; cat "$work/rlog$n"; exit 1; }
done
for r in "${runs[@]}"; do
  if [ "$ref" != "$(strip_results "$work/report-$r/results.json")" ]; then
    echo "report: results.json differs between 1 thread and $r"
    diff <(echo "$ref") <(strip_results "$work/report-$r/results.json") | head -20
    exit 1
  fi
  cmp -s "$work/report-t1/metrics.csv" "$work/report-$r/metrics.csv" ||
    { echo "report: metrics.csv differs between 1 thread and $r"; exit 1; }
done
echo "report: results.json and metrics.csv identical with 1 and 2 threads and with 1, 2, 3 ranks"
