#!/usr/bin/env bash
# `handcentric table1` three ways on one tiny grid, which must agree byte for byte:
#   1. in process (2 jobs);  2. --plan, the jobs run by GNU parallel, --collect;
#   3. after deleting a model and a result of run 1, --resume redoes only that cell.
# Usage: table1_plan_collect.sh <handcentric> <scratch dir>
set -euo pipefail
cli="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"
grid=(--demos 2,3 --methods hand_centric,absolute --steps 20 --trials 3 --jobs 2)

"$cli" table1 "${grid[@]}" --out "$dir/inproc" > "$dir/inproc.out" 2> "$dir/inproc.err"
grep -q "^\[4/4\]" "$dir/inproc.err" || { echo "no progress line [4/4] on stderr" >&2; exit 1; }

"$cli" table1 "${grid[@]}" --out "$dir/plan" --plan
jobs=$(wc -l < "$dir/plan/jobs.txt")
[ "$jobs" -eq 4 ] || { echo "jobs.txt has $jobs lines, expected 4" >&2; exit 1; }
command -v parallel > /dev/null ||
  { echo "GNU parallel is missing: bash scripts/install-deps.sh" >&2; exit 1; }
parallel --will-cite -j 2 --halt now,fail=1 < "$dir/plan/jobs.txt"
"$cli" table1 --collect "$dir/plan" > "$dir/plan.out"
cmp "$dir/inproc/table1.json" "$dir/plan/table1.json" ||
  { echo "the plan's table differs from the in-process one" >&2; exit 1; }
"$cli" table1 "${grid[@]}" --out "$dir/plan" --plan --resume
[ ! -s "$dir/plan/jobs.txt" ] || { echo "a finished plan still lists jobs" >&2; exit 1; }

# Resume: one model and one result gone; exactly one cell is redone, the others are found.
first_model=$(ls "$dir/inproc/models" | head -1)
rm "$dir/inproc/models/$first_model" "$dir/inproc/results/${first_model%.hcm}.ood-"*.json
cp "$dir/inproc/table1.json" "$dir/before.json"
"$cli" table1 "${grid[@]}" --out "$dir/inproc" --resume > /dev/null 2> "$dir/resume.err"
done_count=$(grep -c ": done " "$dir/resume.err" || true)
found_count=$(grep -c ": found " "$dir/resume.err" || true)
[ "$done_count" -eq 1 ] && [ "$found_count" -eq 3 ] ||
  { echo "resume redid $done_count cells and found $found_count, expected 1 and 3" >&2; exit 1; }
cmp "$dir/before.json" "$dir/inproc/table1.json" ||
  { echo "the resumed table differs" >&2; exit 1; }
echo "table1: in process, plan + parallel + collect, and resume agree"
