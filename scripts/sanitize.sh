#!/usr/bin/env bash
# The sanitizer run of CI (issue 14): builds handcentric with AddressSanitizer (with
# LeakSanitizer) and UndefinedBehaviorSanitizer into ${ASAN_BUILD_DIR:-build-asan} (-O1 with line
# tables, no benchmarks) and runs the ctest labels unit, property and proofs there. A report
# aborts the test that caused it, so any report fails this script and CI. Prints the build and
# test times last. docs/RELIABILITY.md has the measured figures.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${ASAN_BUILD_DIR:-$root/build-asan}"
jobs="$(nproc 2>/dev/null || echo 2)"

start=$(date +%s)
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
      -DHANDCENTRIC_SANITIZE=address,undefined -DHANDCENTRIC_BUILD_BENCH=OFF >/dev/null
cmake --build "$build_dir" -j "$jobs"
built=$(date +%s)

export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export LSAN_OPTIONS="suppressions=$root/tests/support/lsan.supp"
(cd "$build_dir" && ctest --output-on-failure -j "$jobs" -L 'unit|property|proofs')
tested=$(date +%s)
echo "sanitize: build $((built - start)) s, tests $((tested - built)) s (labels unit, property, proofs)"
