#!/usr/bin/env bash
# Our image encoder + MLP training step (bench_conv) against PyTorch (Debian's python3-torch,
# CPU, its convolutions on oneDNN) on the same network, in one run on this machine. Prints both
# throughputs per batch size and last one line per batch, `ratio at batch B: X (machine), Y
# (ours on 1 thread), Z (CPU time, 1 thread each)`: X = our training samples/s on 2 threads (a
# step's slices on two lanes, SliceTeam) / PyTorch's best samples/s (1 or 2 threads, either
# memory format), Y = the same with ours on 1 thread, Z = the same per second of CPU time, each on
# one thread (on a shared machine the wall times include waits for a core, which differ between
# the two runs).
#
#   bench/vs_pytorch_conv.sh [BUILD_DIR] [NETWORK]   (defaults: build, bench)
#
# NETWORK: `bench`, the network above (bench_conv's BM_conv_train_step), or `default`, the image
# policies' default encoder (BM_default_encoder_train_step: 6 x 48 x 64 -> 8, 16, 16, 16).
#
# As bench/vs_pytorch.sh: /usr/bin/python3 (Debian's torch imports only there), both sides
# pinned with taskset when it exists, each on core 0 (1 thread) and cores 0 and 1 (2 threads),
# PyTorch in both memory formats (its best is taken). PyTorch's Linear layers run on
# the BLAS it loads (printed): scripts/install-deps.sh installs OpenBLAS (libopenblas0), which
# the alternatives system then prefers; a run on the reference BLAS, whose slow Linear layers
# would flatter us, is flagged in the output.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
network="${2:-bench}"
case "$network" in
  bench) filter=BM_conv_train_step ;;
  default) filter=BM_default_encoder_train_step ;;
  *)
    echo "vs_pytorch_conv.sh: unknown network '$network': use bench or default" >&2
    exit 2
    ;;
esac
bench="$build/bench/bench_conv"
python=/usr/bin/python3

if [[ ! -x "$bench" ]]; then
  echo "vs_pytorch_conv.sh: $bench not found: build first (cmake --build $build --target" \
    "bench_conv)" >&2
  exit 1
fi
if ! "$python" -c "import torch" 2>/dev/null; then
  echo "vs_pytorch_conv.sh: PyTorch is missing: bench/vs_pytorch.sh installs it" >&2
  exit 1
fi
echo "handcentric's kernels: ${HANDCENTRIC_KERNELS:-best for this CPU}; network: $network"
pin() { if command -v taskset >/dev/null; then taskset -c "$1" "${@:2}"; else "${@:2}"; fi; }

# Ours on one thread (core 0), then on two (cores 0 and 1: a step's slices on two lanes,
# SliceTeam), as PyTorch runs on one and two.
ours_json="$(pin 0 "$bench" --benchmark_filter="^$filter/[0-9]+/1/" \
  --benchmark_repetitions=3 --benchmark_format=json 2>/dev/null)"
ours2_json="$(pin 0,1 "$bench" --benchmark_filter="^$filter/[0-9]+/2/" \
  --benchmark_repetitions=3 --benchmark_format=json 2>/dev/null)"
torch_lines="$(pin 0 "$python" "$here/vs_pytorch_conv.py" --threads 1 --network "$network"
               pin 0,1 "$python" "$here/vs_pytorch_conv.py" --threads 2 --network "$network")"
echo "$torch_lines" | sed 's/^/pytorch: /'
"$python" -c '
import json, sys
ours, ours_cpu, ours2 = {}, {}, {}
for b in json.loads(sys.argv[1])["benchmarks"]:
    if b.get("run_type") != "iteration":
        continue
    batch = int(b["name"].split("/")[1])
    ours[batch] = max(ours.get(batch, 0.0), b["items_per_second"])
    cpu_seconds = b["cpu_time"] * {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
    ours_cpu[batch] = max(ours_cpu.get(batch, 0.0), batch / cpu_seconds)
for b in json.loads(sys.argv[3])["benchmarks"]:
    if b.get("run_type") == "iteration":
        batch = int(b["name"].split("/")[1])
        ours2[batch] = max(ours2.get(batch, 0.0), b["items_per_second"])
torch, best_of, torch_cpu = {}, {}, {}
for line in sys.argv[2].splitlines():
    run = json.loads(line)
    batch = run["batch"]
    if run["train_samples_per_s"] > torch.get(batch, 0.0):
        torch[batch] = run["train_samples_per_s"]
        best_of[batch] = "%d thread(s), %s" % (run["threads"], run["format"])
    if run["threads"] == 1:
        torch_cpu[batch] = max(torch_cpu.get(batch, 0.0), run["train_samples_per_cpu_s"])
    blas = run["blas"]
print("pytorch BLAS: %s%s" % (blas, " (the reference BLAS: its Linear layers are slow)"
                              if "/blas/" in blas else ""))
for batch in sorted(ours):
    print("handcentric: batch %d train %.0f samples/s on 1 thread (%.0f per CPU second), %.0f on "
          "2; pytorch best %.0f samples/s (%s; 1 thread: %.0f per CPU second)" %
          (batch, ours[batch], ours_cpu[batch], ours2.get(batch, 0.0), torch[batch],
           best_of[batch], torch_cpu[batch]))
# Both sides on the whole machine (ours on 2 threads, PyTorch at its best of 1 or 2), and per
# core: ours on 1 thread against PyTorch at its best, and per CPU second on 1 thread each (the
# one to read on a shared machine).
for batch in sorted(ours):
    print("ratio at batch %d: %.3f (machine: ours on 2 threads, wall), %.3f (ours on 1 thread, "
          "wall), %.3f (CPU time, 1 thread each)" %
          (batch, ours2.get(batch, 0.0) / torch[batch], ours[batch] / torch[batch],
           ours_cpu[batch] / torch_cpu[batch]))' \
  "$ours_json" "$torch_lines" "$ours2_json"
