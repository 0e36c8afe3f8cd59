#!/usr/bin/env bash
# The fuzzing run of CI: builds the libFuzzer targets of tests/fuzz with clang, AddressSanitizer
# and UndefinedBehaviorSanitizer into ${FUZZ_BUILD_DIR:-build-fuzz}, then runs each target for
# SECONDS (default 60) on a copy of its seed corpus (tests/fuzz/corpus/<target>/ is never
# grown), two targets at a time. Any crash, sanitizer report, input taking over 5 s or using
# over 512 MB fails the script; the input that did it is kept in <build>/fuzz-artifacts/.
# Prints the executions and corpus size of each target, and the build and run times.
#
#   bash scripts/fuzz.sh        # 60 s per target
#   bash scripts/fuzz.sh 10     # a quick look
set -euo pipefail
seconds="${1:-60}"
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] ||
  { echo "fuzz.sh: SECONDS must be a positive integer, got '$seconds'" >&2; exit 2; }
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
cxx="${FUZZ_CXX:-clang++}"
command -v "$cxx" >/dev/null || {
  echo "fuzz.sh: $cxx not found: bash scripts/install-deps.sh (clang, libfuzzer-14-dev)" >&2
  exit 2
}
targets=(fuzz_demo_file fuzz_model_file fuzz_plugin_reply fuzz_geometry fuzz_observations)

start=$(date +%s)
# A tree configured for fuzzing already (scripts/sanitize.sh's, with the tests) is used as it is.
if ! grep -q '^HANDCENTRIC_FUZZ:BOOL=ON' "$build_dir/CMakeCache.txt" 2>/dev/null; then
  CXX="$cxx" cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DHANDCENTRIC_FUZZ=ON \
        -DHANDCENTRIC_SANITIZE=address,undefined -DHANDCENTRIC_BUILD_TESTS=OFF \
        -DHANDCENTRIC_BUILD_BENCH=OFF >/dev/null
fi
cmake --build "$build_dir" -j 2 --target "${targets[@]}"
built=$(date +%s)

export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export LSAN_OPTIONS="suppressions=$root/tests/support/lsan.supp:print_suppressions=0"
work="$(mktemp -d "${TMPDIR:-/tmp}/handcentric-fuzz.XXXXXX")"
trap 'rm -rf "$work"' EXIT
artifacts="$build_dir/fuzz-artifacts"
mkdir -p "$artifacts"

run_target() {
  local target="$1"
  mkdir -p "$work/$target"
  cp "$root/tests/fuzz/corpus/$target/"* "$work/$target/"
  local status=0
  "$build_dir/tests/fuzz/$target" "$work/$target" -max_total_time="$seconds" -rss_limit_mb=512 \
      -timeout=5 -print_final_stats=1 -artifact_prefix="$artifacts/$target-" \
      >"$work/$target.log" 2>&1 || status=$?
  echo "$status" >"$work/$target.status"
}

# Two at a time: the machine has 2 cores.
for target in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge 2 ]; do wait -n || true; done
  run_target "$target" &
done
wait
finished=$(date +%s)

failed=0
printf '%-20s %12s %8s %s\n' target executions corpus result
for target in "${targets[@]}"; do
  status="$(cat "$work/$target.status")"
  executions="$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$target.log" | tail -1)"
  corpus="$(find "$work/$target" -type f | wc -l)"
  if [ "$status" -eq 0 ]; then result=ok; else result="FAILED (exit $status)"; failed=1; fi
  printf '%-20s %12s %8s %s\n' "$target" "${executions:-?}" "$corpus" "$result"
done
for target in "${targets[@]}"; do
  if [ "$(cat "$work/$target.status")" -ne 0 ]; then
    echo "---- $target: the end of its log (inputs in $artifacts/) ----" >&2
    tail -60 "$work/$target.log" >&2
  fi
done
echo "fuzz.sh: build $((built - start)) s, runs $((finished - built)) s" \
     "(${seconds} s per target, 2 at a time)"
exit "$failed"
