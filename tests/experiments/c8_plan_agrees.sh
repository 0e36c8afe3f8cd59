#!/usr/bin/env bash
# A C8 cell (c8_base, centre (0, -60)) trained from its --plan line gives the in-process model
# byte for byte: the plan passes the centre to `handcentric train` (--c8-centre-y=-60).
# Usage: c8_plan_agrees.sh <handcentric> <scratch dir>
set -euo pipefail
cli="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"
grid=(--demos 2 --methods c8_base --steps 20 --trials 2 --jobs 1 --quiet)
"$cli" table1 "${grid[@]}" --out "$dir/inproc" > /dev/null
"$cli" table1 "${grid[@]}" --out "$dir/plan" --plan > /dev/null
grep -q -- "--head c8ddpm --steps 20 .*--c8-centre-x=0 --c8-centre-y=-60 " "$dir/plan/jobs.txt" ||
  { echo "the plan does not pass the C8 centre: $(cat "$dir/plan/jobs.txt")" >&2; exit 1; }
bash "$dir/plan/jobs.txt"
"$cli" table1 --collect "$dir/plan" > /dev/null
cmp "$dir/inproc/models/"*.hcm "$dir/plan/models/"*.hcm
cmp "$dir/inproc/table1.json" "$dir/plan/table1.json"
echo "c8 plan agrees"
