#!/usr/bin/env bash
# Installs the Debian bookworm packages handcentric needs, only when some are missing.
# Runs as root (CI) or through sudo. Every dependency is a Debian package: nothing is
# downloaded at build time and nothing is vendored.
set -euo pipefail

packages=(
  ca-certificates cmake g++ make pkg-config python3
  libeigen3-dev catch2 librapidcheck-dev libbox2d-dev libfcl-dev libopencv-dev libginac-dev
  libcli11-dev nlohmann-json3-dev libbenchmark-dev libhwy-dev zlib1g-dev libzip-dev
  # props/src/checks/special_functions.cpp: Boost.Math's distributions (header-only, private)
  libboost-math-dev
  python3-numpy python3-pytest time
  # tests/python_package: `pip install --no-build-isolation .` into a venv of Debian's Python
  python3-venv python3-pip python3-setuptools python3-wheel
  parallel
  python3-dev pybind11-dev python3-torch
  # libtorch's first Recommends, which --no-install-recommends would drop: torch then runs its
  # linear layers on OpenBLAS, as an `apt install python3-torch` user's does, not on the
  # reference BLAS (docs/BENCHMARKS.md, "Python: batched audits")
  libopenblas0
  # scripts/fuzz.sh: clang, libFuzzer, and the sanitizer and fuzzer runtimes clang links (only
  # recommended by clang, so not installed under --no-install-recommends without this name)
  clang libfuzzer-14-dev libclang-rt-14-dev
  # tests/support/check_style.py: the tracked files and their formatting
  git clang-format
  # experiments/chart.hpp: the report's figures as PNG and SVG, in DejaVu Sans
  libcairo2-dev fonts-dejavu-core
  # scripts/check_report_html.sh: the report page opened in headless Chromium (a ctest)
  chromium
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "install-deps: missing packages (${missing[*]}) and not root;" \
         "install them or run as root" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
# --no-install-recommends keeps OpenCV to its -dev packages (we link core and imgproc).
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
