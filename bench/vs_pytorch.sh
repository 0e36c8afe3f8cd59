#!/usr/bin/env bash
# Our flow trainer (bench_policy) against PyTorch (Debian's python3-torch, CPU) on the same
# network, in one run on this machine. Prints both throughputs and sampling latencies, and
# last a line `ratio: X` = our training samples/s / PyTorch's best samples/s (1 or 2 threads;
# on this machine 1 thread is its best).
#
#   bench/vs_pytorch.sh [BUILD_DIR]        (default: build)
#
# Debian's torch imports only under Debian's own /usr/bin/python3, not under another python3
# earlier on PATH, so the script calls /usr/bin/python3 explicitly; it installs python3-torch
# and OpenBLAS with apt-get when they are missing (root, or sudo).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
bench="$build/bench/bench_policy"
python=/usr/bin/python3

if [[ ! -x "$bench" ]]; then
  echo "vs_pytorch.sh: $bench not found: build first (cmake --build $build --target bench_policy)" \
    >&2
  exit 1
fi
# Debian's torch does its CPU matrix products through whatever libblas.so.3 the alternatives
# system points to; with only the reference BLAS (libblas3) it trains ~6x slower (4.2k
# samples/s measured here), which would flatter us. So PyTorch gets OpenBLAS.
missing=()
"$python" -c "import torch" 2>/dev/null || missing+=(python3-torch)
dpkg -s libopenblas0-pthread >/dev/null 2>&1 || dpkg -s libopenblas0-openmp >/dev/null 2>&1 ||
  dpkg -s libopenblas0-serial >/dev/null 2>&1 || missing+=(libopenblas0-pthread)
if ((${#missing[@]})); then
  echo "vs_pytorch.sh: installing ${missing[*]} (Debian packages) ..." >&2
  sudo_cmd=""
  if [[ "$(id -u)" -ne 0 ]]; then sudo_cmd="sudo"; fi
  $sudo_cmd apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y "${missing[@]}"
fi
echo "pytorch's BLAS: $(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3 2>/dev/null ||
                        echo unknown)"
echo "handcentric's kernels: ${HANDCENTRIC_KERNELS:-best for this CPU}"

# Both sides pinned: one thread on core 0 (two threads on cores 0 and 1), when taskset exists.
pin() { if command -v taskset >/dev/null; then taskset -c "$1" "${@:2}"; else "${@:2}"; fi; }

ours_json="$(pin 0 "$bench" \
  --benchmark_filter='BM_flow_train_step_batch256|BM_flow_sample_10_euler_steps_batch1' \
  --benchmark_repetitions=3 --benchmark_format=json 2>/dev/null)"
read -r ours_rate ours_sample_us < <("$python" -c '
import json, sys
runs = [b for b in json.load(sys.stdin)["benchmarks"] if b.get("run_type") == "iteration"]
rate = max(b["items_per_second"] for b in runs if "train_step" in b["name"])
sample = min(b["real_time"] for b in runs if "sample" in b["name"])  # microseconds
print(rate, sample)' <<<"$ours_json")

torch_best=0
for threads in 1 2; do
  cores=0
  if [[ "$threads" -eq 2 ]]; then cores=0,1; fi
  line="$(pin "$cores" "$python" "$here/vs_pytorch.py" --threads "$threads")"
  echo "pytorch: $line"
  rate="$("$python" -c 'import json,sys; print(json.loads(sys.argv[1])["train_samples_per_s"])' \
    "$line")"
  if "$python" -c 'import sys; sys.exit(0 if float(sys.argv[1]) > float(sys.argv[2]) else 1)' \
       "$rate" "$torch_best"; then
    torch_best="$rate"
  fi
  if [[ "$threads" -eq 1 ]]; then
    torch_sample_us="$("$python" -c 'import json,sys; print(json.loads(sys.argv[1])["sample_us"])' \
      "$line")"
  fi
done
echo "handcentric: train ${ours_rate} samples/s," \
     "10-step Euler sampling at batch 1 ${ours_sample_us} us"
echo "pytorch: best train ${torch_best} samples/s (1 or 2 threads)," \
     "sampling ${torch_sample_us} us (1 thread)"
"$python" -c 'import sys; print("ratio: %.3f" % (float(sys.argv[1]) / float(sys.argv[2])))' \
  "$ours_rate" "$torch_best"
