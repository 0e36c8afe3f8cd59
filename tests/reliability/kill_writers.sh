#!/usr/bin/env bash
# Crash-safe outputs: kills `handcentric demos`, `train` and `table1` (tiny settings) with SIGKILL
# at seeded random moments, and checks after each kill that every output path holds nothing or
# the previous complete file (byte for byte), never a partial one; then that a re-run (demos,
# train) or a --resume (table1) completes with the same bytes as an uninterrupted run.
#
# Usage: kill_writers.sh <handcentric> <scratch dir> [--expect-partial]
#   KILLS (default 20) kills per command; SEED (default 20261201) seeds the moments.
#   --expect-partial: the mutant check, run with HANDCENTRIC_FAULT_WRITE_IN_PLACE_MS set (a
#   writer that writes in place): passes only if a partial file is caught.
set -euo pipefail
cli="$1"
dir="$2"
mode="${3:-}"
kills="${KILLS:-20}"
RANDOM="${SEED:-20261201}"
rm -rf "$dir"
mkdir -p "$dir"

fail() {
  if [ "$mode" = --expect-partial ]; then
    echo "caught, as the planted fault must be: $*"
    exit 0
  fi
  echo "kill_writers: $*" >&2
  exit 1
}

# Milliseconds since the epoch.
now_ms() { date +%s%3N; }

# A moment in [0, limit_ms) ms, as seconds for sleep(1).
random_moment() {
  local ms=$(((RANDOM * 32768 + RANDOM) % $1))
  printf '%d.%03d' $((ms / 1000)) $((ms % 1000))
}

# Runs "$@" in the background and SIGKILLs it after a random moment within limit_ms ($1).
run_and_kill() {
  local limit_ms="$1"
  shift
  local moment
  moment="$(random_moment "$limit_ms")"
  "$@" >/dev/null 2>&1 &
  local pid=$!
  sleep "$moment"
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}

# $1 must be absent, or equal to one of the complete files that follow.
check_whole() {
  local path="$1"
  shift
  [ -e "$path" ] || return 0
  local whole
  for whole in "$@"; do
    cmp -s "$path" "$whole" && return 0
  done
  fail "$path is neither absent nor a complete file ($(wc -c <"$path") bytes): a partial write"
}

# Times an uninterrupted run of "$@" (ms), at least 50.
timed() {
  local start
  start=$(now_ms)
  "$@" >/dev/null 2>"$dir/last.err" ||
    { cat "$dir/last.err" >&2; fail "an uninterrupted run failed: $*"; }
  local took=$(($(now_ms) - start))
  echo $((took < 50 ? 50 : took))
}

# kill_and_rerun <name> <output> <previous> <reference> <ms> <command...>: kills the command
# (which writes <output>) at random moments, <output> holding the previous file each time, then
# runs it whole and compares with the reference.
kill_and_rerun() {
  local name="$1" output="$2" previous="$3" reference="$4" ms="$5"
  shift 5
  for ((k = 0; k < kills; ++k)); do
    cp "$previous" "$output"
    run_and_kill "$ms" "$@"
    check_whole "$output" "$previous" "$reference"
  done
  "$@" >/dev/null
  cmp -s "$output" "$reference" || fail "a re-run of $name differs from an uninterrupted run"
  # The killed runs' "<output>.tmp.<pid>" files: the complete run's write removes them.
  local leftovers
  leftovers="$(find "$(dirname "$output")" -name "$(basename "$output").tmp.*")"
  [ -z "$leftovers" ] ||
    fail "the re-run of $name left the killed runs' temporary files: $leftovers"
  echo "$name: $kills kills within $ms ms, every file whole, no temporary file left"
}

# demos and train: the previous file is another seed's.
demos=(demos --dist train --n 4 --out)
"$cli" "${demos[@]}" "$dir/previous.jsonl" --seed 2 >/dev/null
demos_ms=$(timed "$cli" "${demos[@]}" "$dir/reference.jsonl" --seed 3)
kill_and_rerun demos "$dir/demos.jsonl" "$dir/previous.jsonl" "$dir/reference.jsonl" "$demos_ms" \
  "$cli" "${demos[@]}" "$dir/demos.jsonl" --seed 3

train=(train --demos "$dir/reference.jsonl" --steps 20 --width 16 --layers 1 --batch 8 --quiet
       --out)
"$cli" "${train[@]}" "$dir/previous.hcm" --seed 2 >/dev/null
train_ms=$(timed "$cli" "${train[@]}" "$dir/reference.hcm" --seed 1)
kill_and_rerun train "$dir/model.hcm" "$dir/previous.hcm" "$dir/reference.hcm" "$train_ms" \
  "$cli" "${train[@]}" "$dir/model.hcm" --seed 1

# --- table1: killed again and again, each time resumed; every file written must be whole ------
table=(table1 --demos 2,3 --methods hand_centric --steps 20 --trials 2 --jobs 1 --quiet)
table_ms=$(timed "$cli" "${table[@]}" --out "$dir/table-reference")
files_of() { (cd "$1" && find . -type f ! -name '*.tmp.*' | sort); }
check_tree() {
  local file
  while read -r file; do
    [ -e "$dir/table-reference/$file" ] ||
      fail "table1 wrote $file, which an uninterrupted run does not"
    check_whole "$dir/table/$file" "$dir/table-reference/$file"
  done < <(files_of "$dir/table")
}
for ((k = 0; k < kills; ++k)); do
  run_and_kill "$table_ms" "$cli" "${table[@]}" --resume --out "$dir/table"
  [ -d "$dir/table" ] && check_tree
done
"$cli" "${table[@]}" --resume --out "$dir/table" >/dev/null 2>"$dir/last.err" ||
  { cat "$dir/last.err" >&2; fail "table1 --resume after the kills failed"; }
diff <(files_of "$dir/table") <(files_of "$dir/table-reference") >&2 ||
  fail "the resumed table1 folder lists other files than an uninterrupted run's"
check_tree
leftovers="$(find "$dir/table" -name '*.tmp.*')"
[ -z "$leftovers" ] || fail "the resumed table1 left the killed runs' temporary files: $leftovers"
echo "table1: $kills kills within ${table_ms} ms, each resumed;" \
     "every file whole, the same bytes at the end"

[ "$mode" = --expect-partial ] &&
  { echo "kill_writers: the planted in-place writer was not caught" >&2; exit 1; }
echo "kill_writers: $((3 * kills)) kills, no partial file"
