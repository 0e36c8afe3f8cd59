#!/usr/bin/env bash
# Quick start, command 2: installs what is missing, builds (Release, every core), runs every
# ctest suite, then installs the package into a staging prefix and builds and tests
# examples/downstream against it with find_package(handcentric); last, the sanitizer run
# (scripts/sanitize.sh: a second tree with ASan + UBSan, labels unit, property, proofs).
# SANITIZE=0 skips the sanitizer run (CI never does).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"

bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh"

echo "== ctest"
(cd "$build_dir" && ctest --output-on-failure -j "$jobs")

echo "== downstream project against the installed package"
stage="$build_dir/stage"
rm -rf "$stage" "$build_dir/downstream"
cmake --install "$build_dir" --prefix "$stage" >/dev/null
cmake -S "$root/examples/downstream" -B "$build_dir/downstream" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$stage" >/dev/null
cmake --build "$build_dir/downstream" -j "$jobs"
(cd "$build_dir/downstream" && ctest --output-on-failure -j "$jobs")

if [ "${SANITIZE:-1}" != 0 ]; then
  echo "== sanitizers: AddressSanitizer + LeakSanitizer + UndefinedBehaviorSanitizer"
  bash "$root/scripts/sanitize.sh"
fi
