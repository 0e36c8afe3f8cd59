#!/usr/bin/env bash
# Configures and builds handcentric (Release, every core) into ${BUILD_DIR:-build}, as a unity
# build: the libraries and the command compile a few batches of files instead of one compiler
# run per file, which takes a fresh build from ~8.5 to ~6 minutes on two cores
# (docs/BENCHMARKS.md, "Build"). The test programs are unity-built too, so file-local helpers
# need distinct names across a program's files (cmake/HandcentricTarget.cmake).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-$root/build}"
jobs="$(nproc 2>/dev/null || echo 2)"

cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON "$@" >/dev/null
cmake --build "$build_dir" -j "$jobs"
