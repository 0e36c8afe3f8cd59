#!/usr/bin/env bash
# Our image encoder + MLP training step (bench_conv) against PyTorch (Debian's python3-torch,
# CPU, its convolutions on oneDNN) on the same network, in one run on this machine. Prints both
# throughputs per batch size and last one line per batch, `ratio at batch B: X` = our training
# samples/s / PyTorch's best samples/s (1 or 2 threads).
#
#   bench/vs_pytorch_conv.sh [BUILD_DIR]        (default: build)
#
# As bench/vs_pytorch.sh: /usr/bin/python3 (Debian's torch imports only there), both sides
# pinned with taskset when it exists, ours on core 0, PyTorch on core 0 (1 thread) and cores 0
# and 1 (2 threads). python3-torch and OpenBLAS are installed by bench/vs_pytorch.sh if missing.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
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
echo "handcentric's kernels: ${HANDCENTRIC_KERNELS:-best for this CPU}"
pin() { if command -v taskset >/dev/null; then taskset -c "$1" "${@:2}"; else "${@:2}"; fi; }

ours_json="$(pin 0 "$bench" --benchmark_filter='BM_conv_train_step' \
  --benchmark_repetitions=3 --benchmark_format=json 2>/dev/null)"
torch_lines="$(pin 0 "$python" "$here/vs_pytorch_conv.py" --threads 1;
               pin 0,1 "$python" "$here/vs_pytorch_conv.py" --threads 2)"
echo "$torch_lines" | sed 's/^/pytorch: /'
"$python" -c '
import json, sys
ours = {}
for b in json.loads(sys.argv[1])["benchmarks"]:
    if b.get("run_type") != "iteration":
        continue
    batch = int(b["name"].split("/")[1])
    ours[batch] = max(ours.get(batch, 0.0), b["items_per_second"])
torch = {}
for line in sys.argv[2].splitlines():
    run = json.loads(line)
    batch = run["batch"]
    torch[batch] = max(torch.get(batch, 0.0), run["train_samples_per_s"])
for batch in sorted(ours):
    print("handcentric: batch %d train %.0f samples/s; pytorch best %.0f samples/s" %
          (batch, ours[batch], torch[batch]))
for batch in sorted(ours):
    print("ratio at batch %d: %.3f" % (batch, ours[batch] / torch[batch]))' \
  "$ours_json" "$torch_lines"
