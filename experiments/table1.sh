#!/usr/bin/env bash
# The paper's Table 1 (Sec. 4.2) on this library: closed-loop success of four policies trained
# on the first N of 100 expert demos, N = 5 10 20 40 60 80 100, 100 rollouts each on scenes of
# the training distribution, and on out-of-distribution scenes for N = 100.
#
#   bash experiments/table1.sh            # STEPS=60000 per model, all cores
#   STEPS=150000 JOBS=2 bash experiments/table1.sh
#
# Environment: STEPS (Adam steps per model, default 60000), LR (2e-3), JOBS (trainings at once,
# default: the number of cores), DEMO_SEED (1), TRAIN_SEED (1), EVAL_SEED (100; a seed that no
# setting was tuned on), COUNTS (the numbers of demos, default "5 10 20 40 60 80 100"; the
# largest is also evaluated out of distribution), TRIALS (rollouts per cell, 100), OUT (default
# build/table1), HANDCENTRIC (the CLI, default build/apps/handcentric). Writes $OUT/table1.md (the table, with the wall time) and one JSON
# line per model in $OUT/results.jsonl.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cli="${HANDCENTRIC:-$root/build/apps/handcentric}"
out="${OUT:-$root/build/table1}"
steps="${STEPS:-60000}"
lr="${LR:-2e-3}"
jobs="${JOBS:-$(nproc 2>/dev/null || echo 1)}"
demo_seed="${DEMO_SEED:-1}"
train_seed="${TRAIN_SEED:-1}"
eval_seed="${EVAL_SEED:-100}"
trials="${TRIALS:-100}"
read -r -a counts <<< "${COUNTS:-5 10 20 40 60 80 100}"
# row label | representation | head
policies=("Hand-Centric-Flow|hand_centric|flow"
          "Relative-Action-Flow|relative|flow"
          "Absolute-Action-Flow|absolute|flow"
          "C8-symmetrized flow (analogue of Equivariant-DiffPo [7])|absolute|c8flow")

if [ "${#counts[@]}" -eq 0 ]; then
  echo "table1.sh: COUNTS is empty; give numbers of demos, e.g. COUNTS=\"5 100\"" >&2
  exit 2
fi
for value in "$steps" "$jobs" "$trials" "${counts[@]}"; do
  if ! [[ "$value" =~ ^[1-9][0-9]*$ ]]; then
    echo "table1.sh: STEPS, JOBS, TRIALS and COUNTS must be positive integers, got '$value'" >&2
    exit 2
  fi
done
for value in "$demo_seed" "$train_seed" "$eval_seed"; do
  if ! [[ "$value" =~ ^[0-9]+$ ]]; then
    echo "table1.sh: seeds must be non-negative integers, got '$value'" >&2
    exit 2
  fi
done
if [ ! -x "$cli" ]; then
  echo "table1.sh: no CLI at $cli; build first (bash scripts/build.sh) or set HANDCENTRIC" >&2
  exit 2
fi

largest=$(printf '%s\n' "${counts[@]}" | sort -n | tail -1)
if [ "$largest" -gt 100 ]; then
  echo "table1.sh: COUNTS goes up to 100 demos (the file has 100), got $largest" >&2
  exit 2
fi

mkdir -p "$out/models"
demos="$out/demos-seed$demo_seed.jsonl"
[ -f "$demos" ] || "$cli" demos --n 100 --dist train --seed "$demo_seed" --out "$demos"

# One model: train, then evaluate; prints one JSON line, or fails (and xargs with it) naming the cell.
run_one() {
  local label="$1" repr="$2" head="$3" n="$4"
  local model="$out/models/$repr-$head-n$n-steps$steps.hcm" start end train ood="null"
  local cell="$repr/$head on $n demos"
  start=$(date +%s)
  "$cli" train --demos "$demos" --max-demos "$n" --repr "$repr" --head "$head" --steps "$steps" --lr "$lr" \
    --seed "$train_seed" --out "$model" --quiet >/dev/null || { echo "table1.sh: training $cell failed" >&2; return 1; }
  end=$(date +%s)
  train=$("$cli" eval --model "$model" --dist train --trials "$trials" --seed "$eval_seed" --json) ||
    { echo "table1.sh: evaluating $cell failed" >&2; return 1; }
  if [ "$n" = "$largest" ]; then
    ood=$("$cli" eval --model "$model" --dist ood --trials "$trials" --seed "$eval_seed" --json) ||
      { echo "table1.sh: evaluating $cell out of distribution failed" >&2; return 1; }
  fi
  printf '{"policy": "%s", "repr": "%s", "head": "%s", "demos": %s, "steps": %s, "train_seconds": %s, "train": %s, "ood": %s}\n' \
    "$label" "$repr" "$head" "$n" "$steps" "$((end - start))" "$train" "$ood"
}
export -f run_one
export cli out steps lr train_seed eval_seed trials demos largest

wall_start=$(date +%s)
results="$out/results.jsonl"
: > "$results.tmp"
cells() {
  for policy in "${policies[@]}"; do
    IFS='|' read -r label repr head <<< "$policy"
    for n in "${counts[@]}"; do printf '%s\0%s\0%s\0%s\0' "$label" "$repr" "$head" "$n"; done
  done
}
if ! cells | xargs -0 -n 4 -P "$jobs" bash -c 'run_one "$@"' _ >> "$results.tmp"; then
  echo "table1.sh: a cell failed (see above); no table written, the finished cells are in $results.tmp" >&2
  exit 1
fi
wall=$(( $(date +%s) - wall_start ))
mv "$results.tmp" "$results"

python3 - "$results" "$out/table1.md" "$wall" "$steps" "$lr" "$jobs" "$eval_seed" "$demo_seed" "$train_seed" \
  "$trials" "${counts[@]}" <<'PY'
import json, os, sys
results, table, wall, steps, lr, jobs, eval_seed, demo_seed, train_seed, trials = sys.argv[1:11]
counts = sorted(set(int(n) for n in sys.argv[11:]))
rows = {}
for line in open(results):
    r = json.loads(line)
    rows.setdefault(r["policy"], {})[r["demos"]] = r
order = ["Hand-Centric-Flow", "Relative-Action-Flow", "Absolute-Action-Flow",
         "C8-symmetrized flow (analogue of Equivariant-DiffPo [7])"]
lines = ["| number of demos | " + " | ".join(map(str, counts)) + " | %d, O.O.D. |" % counts[-1],
         "|---" * (len(counts) + 2) + "|"]
train_seconds = 0
for policy in order:
    cells = []
    for n in counts:
        r = rows[policy][n]
        train_seconds += r["train_seconds"]
        cells.append("%.2f" % r["train"]["success"])
    ood = rows[policy][counts[-1]]["ood"]["success"]
    cells.append("%.2f" % ood)
    lines.append("| " + policy + " | " + " | ".join(cells) + " |")
text = "\n".join(lines) + "\n\n" + (
    "Success of %s closed-loop rollouts each (eval seed %s); demos: `demos --n 100 --dist train --seed %s`, "
    "models: `train --max-demos N --steps %s --lr %s --seed %s`. %d trainings, %d s of training in all, "
    "%d s of wall time with %s at once.\n" % (trials, eval_seed, demo_seed, steps, lr, train_seed,
                                              len(counts) * len(order), train_seconds, int(wall), jobs))
tmp = table + ".tmp"
with open(tmp, "w") as f:
    f.write(text)
os.replace(tmp, table)
print(text, end="")
PY
