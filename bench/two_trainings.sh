#!/usr/bin/env bash
# Do two independent trainings on the two cores each keep >= 90% of the speed of one alone?
# It runs the training benchmark alone on core 0, then one copy on each of cores 0 and 1 at the
# same time. Prints the three rates and, last, `kept: X Y` = each concurrent rate / the solo rate.
#
#   bench/two_trainings.sh [BUILD_DIR]        (default: build; needs 2 cores and taskset)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
bench="$build/bench/bench_policy"
if [[ ! -x "$bench" ]]; then
  echo "two_trainings.sh: $bench not found: build first" \
       "(cmake --build $build --target bench_policy)" >&2
  exit 1
fi
if [[ "$(nproc)" -lt 2 ]]; then
  echo "two_trainings.sh: needs 2 cores, this machine has $(nproc)" >&2
  exit 1
fi
rate() {  # median items_per_second of 3 repetitions, from the JSON on stdin
  python3 -c '
import json, sys
runs = [b for b in json.load(sys.stdin)["benchmarks"] if b.get("aggregate_name") == "median"]
print(runs[0]["items_per_second"])'
}
run() { taskset -c "$1" "$bench" --benchmark_filter=BM_flow_train_step --benchmark_repetitions=3 \
          --benchmark_report_aggregates_only=true --benchmark_format=json 2>/dev/null; }
solo="$(run 0 | rate)"
out0="$(mktemp)" out1="$(mktemp)"
trap 'rm -f "$out0" "$out1"' EXIT
run 0 >"$out0" & pid0=$!
run 1 >"$out1" & pid1=$!
wait "$pid0" "$pid1"
both0="$(rate <"$out0")" both1="$(rate <"$out1")"
echo "solo (core 0): $solo samples/s"
echo "together: core 0 $both0, core 1 $both1 samples/s"
python3 -c 'import sys; s = float(sys.argv[1]); '\
'print("kept: %.3f %.3f" % (float(sys.argv[2]) / s, float(sys.argv[3]) / s))' \
  "$solo" "$both0" "$both1"
