#!/usr/bin/env bash
# A Table 1 grid run from its --plan lines gives the in-process models byte for byte and the same
# table: the plan passes every setting of the cell to `handcentric train` and `eval` (the C8
# centre, --c8-centre-y=-60 for c8_base; the task's --workspace and --clearance), and the jobs
# file is checked to name it. The plan trains every cell, the in-process run once per training
# (c8_averaged takes c8_centre's weights): equal models say the sharing changes no bit.
# Usage: plan_agrees.sh <handcentric> <scratch dir> <regex the jobs file must match> <grid...>
set -euo pipefail
cli="$1"
dir="$2"
pattern="$3"
shift 3
grid=("$@" --trials 2 --jobs 1 --quiet)
rm -rf "$dir"
mkdir -p "$dir"
"$cli" table1 "${grid[@]}" --out "$dir/inproc" > /dev/null
"$cli" table1 "${grid[@]}" --out "$dir/plan" --plan > /dev/null
grep -q -- "$pattern" "$dir/plan/jobs.txt" ||
  { echo "the plan does not say '$pattern': $(cat "$dir/plan/jobs.txt")" >&2; exit 1; }
bash "$dir/plan/jobs.txt"
"$cli" table1 --collect "$dir/plan" > /dev/null
models=0
for model in "$dir/inproc/models/"*.hcm; do
  cmp "$model" "$dir/plan/models/$(basename "$model")"
  models=$((models + 1))
done
[ "$models" -eq "$(ls "$dir/plan/models/" | wc -l)" ] ||
  { echo "the plan made $(ls "$dir/plan/models/" | wc -l) models, in process $models" >&2; exit 1; }
cmp "$dir/inproc/table1.json" "$dir/plan/table1.json"
cmp "$dir/inproc/table1.md" "$dir/plan/table1.md"
echo "plan agrees"
