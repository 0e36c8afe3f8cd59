#!/usr/bin/env bash
# Quick start, command 2: installs what is missing, builds (Release, every core), runs every
# ctest suite, then installs the package into a staging prefix and builds and tests
# examples/downstream against it with find_package(handcentric); last, the sanitizer run
# (scripts/sanitize.sh: a second tree built by clang with ASan + UBSan, labels unit and proofs
# and the numerics properties, then each libFuzzer target for 10 s). SANITIZE=0 leaves the
# sanitizer run out (a quick local check); CI runs it. The sanitizer tree builds at nice 19
# from the start, beside the Release build, tests and downstream projects: they leave part of
# the two cores idle (serial links, waits on Chromium, Python and subprocesses: ~12% of the
# tests' time), which the build takes; its output is printed once it is done. Each phase
# prints its start time; docs/BENCHMARKS.md ("CI") has the measured phases.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"

t0=$(date +%s)
phase() { echo "== $1 (at $(( $(date +%s) - t0 )) s)"; }
bash "$root/scripts/install-deps.sh"
sanitize="${SANITIZE:-1}"
if [ "$sanitize" != 0 ]; then
  # Its own process group (job control, set -m), so that a failure below stops the whole build
  # with it. Not its own session (setsid): the kernel's autogroups give each session an equal
  # share of the CPU whatever its nice value (the build then took half of the cores, and the
  # Release tests ran 833 s instead of 420).
  mkdir -p "$build_dir"
  asan_log="$build_dir/sanitize-build.log"
  set -m
  nice -n 19 bash "$root/scripts/sanitize.sh" build >"$asan_log" 2>&1 &
  asan_build=$!
  set +m
  trap 'kill -- "-$asan_build" 2>/dev/null || true' EXIT
fi

phase "build"
bash "$root/scripts/build.sh"

phase "ctest"
(cd "$build_dir" && ctest --output-on-failure -j "$jobs")

echo "== downstream project against the installed package"
stage="$build_dir/stage"
rm -rf "$stage" "$build_dir/downstream"
cmake --install "$build_dir" --prefix "$stage" >/dev/null
# OpenCV and Box2D made unfindable: the components it asks for (core, props) must not need them.
cmake -S "$root/examples/downstream" -B "$build_dir/downstream" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$stage" -DCMAKE_DISABLE_FIND_PACKAGE_OpenCV=TRUE \
      -DCMAKE_DISABLE_FIND_PACKAGE_box2d=TRUE >/dev/null
cmake --build "$build_dir/downstream" -j "$jobs"
(cd "$build_dir/downstream" && ctest --output-on-failure -j "$jobs")

echo "== a second downstream project that asks for core, policy and props only"
rm -rf "$build_dir/policy_downstream"
cmake -S "$root/examples/policy_downstream" -B "$build_dir/policy_downstream" \
      -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$stage" -DCMAKE_DISABLE_FIND_PACKAGE_OpenCV=TRUE \
      -DCMAKE_DISABLE_FIND_PACKAGE_box2d=TRUE >/dev/null
cmake --build "$build_dir/policy_downstream" -j "$jobs"
(cd "$build_dir/policy_downstream" && ctest --output-on-failure)

if [ "$sanitize" != 0 ]; then
  phase "sanitizers"
  echo "== sanitizers: AddressSanitizer + LeakSanitizer + UndefinedBehaviorSanitizer"
  status=0
  wait "$asan_build" || status=$?
  trap - EXIT
  tail -n 5 "$asan_log"
  if [ "$status" != 0 ]; then
    echo "test.sh: the sanitizer build failed (exit $status); its whole log:" >&2
    cat "$asan_log" >&2
    exit 1
  fi
  phase "sanitizer tests"
  bash "$root/scripts/sanitize.sh" test
fi
phase "done"
