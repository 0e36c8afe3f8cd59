#!/usr/bin/env bash
# The mutants of `audit --model --locate` (tests/experiments/test_model_locate.cpp and the
# sim_cli_locate_* tests): each plants one fault in the source, rebuilds, and must make the
# tests named beside it fail; the source is restored after each (also on interrupt). Rebuilding
# takes minutes, so ctest does not run it; run it after changing the locating code:
#   bash tests/experiments/mutant_locate.sh SOURCE_DIR BUILD_DIR [MUTANT...]
# MUTANT (default: all):
#   skip_layer   Mlp::infer hands no hidden layer to the watches (a hook that skips a layer)
#   skip_conv    ConvEncoder hands no layer to the watches
#   outer_first  the watches called outermost first: a recorder sees a layer before the planted
#                fault inside it changes it, so the break shows one layer late
#   chunk_kind   the decoded chunk marked "features" (the wrong kind) instead of "poses"
#   self_compare each output compared with itself: nothing can break
#   no_refusal   --locate without --model not refused
#   page_mark    the report's table never marks the planted fault's first break
set -u
src=${1:?usage: mutant_locate.sh SOURCE_DIR BUILD_DIR [MUTANT...]}
build=${2:?usage: mutant_locate.sh SOURCE_DIR BUILD_DIR [MUTANT...]}
shift 2
mutants=("$@")
[ ${#mutants[@]} -gt 0 ] ||
  mutants=(skip_layer skip_conv outer_first chunk_kind self_compare no_refusal page_mark)
unit='locate_'
cli='sim_cli_locate_'
plant() {  # prints three lines: the file, the sed expression, the ctest regex
  case "$1" in
    skip_layer) printf '%s\n' 'policy/src/mlp.cpp' \
      's|^    watch_layer("mlp.layer", l, scratch\[current\]);|    // skipped|' "$unit" ;;
    skip_conv) printf '%s\n' 'policy/src/conv_encoder.cpp' \
      's|^    watch_layer("encoder.conv",.*|    // skipped|' "${unit}watches_an_image" ;;
    outer_first) printf '%s\n' 'policy/src/layer_watch.cpp' \
      's|now.rbegin(); it != now.rend();|now.begin(); it != now.end();|' \
      "${unit}finds_a_world" ;;
    chunk_kind) printf '%s\n' 'experiments/src/model_locate.cpp' \
      's|key == kChunkKey ? LayerKind::poses : LayerKind::features|LayerKind::features|' \
      "${unit}watches_every|${cli}a_hand_centric_3d" ;;
    self_compare) printf '%s\n' 'experiments/src/model_locate.cpp' \
      's|error = feature_difference(a, b);|error = feature_difference(a, a);|' \
      "${unit}finds|${cli}with_the_table|${cli}an_absolute" ;;
    no_refusal) printf '%s\n' 'apps/cmd_audit.cpp' \
      's|^  if (options.locate) check_locate_options|  if (false) check_locate_options|' \
      "${cli}without_a_model" ;;
    page_mark) printf '%s\n' 'experiments/src/locate_page.cpp' \
      's|located_layer_cell(y, &y == first_b)|located_layer_cell(y, false)|' "report_section" ;;
    *) echo "unknown mutant '$1'" >&2; exit 2 ;;
  esac
}
status=0
for m in "${mutants[@]}"; do
  mapfile -t planted < <(plant "$m")
  [ ${#planted[@]} -eq 3 ] || exit 2
  file=${planted[0]} expr=${planted[1]} regex=${planted[2]}
  cp "$src/$file" "$src/$file.orig"
  # Restored with a new time stamp: make must rebuild what the mutant built.
  trap 'mv "$src/$file.orig" "$src/$file"; touch "$src/$file"' EXIT INT TERM
  sed -i "$expr" "$src/$file"
  if cmp -s "$src/$file" "$src/$file.orig"; then
    echo "mutant $m: the sed changed nothing in $file (the source moved on)"; status=1
  elif ! make -C "$build" -j2 handcentric test_experiments >/dev/null 2>&1; then
    echo "mutant $m: does not build"; status=1
  elif (cd "$build" && ctest -R "$regex" >/dev/null 2>&1); then
    echo "mutant $m: NOT caught (ctest -R '$regex' passes)"; status=1
  else
    echo "mutant $m: caught (ctest -R '$regex' fails)"
  fi
  mv "$src/$file.orig" "$src/$file"
  touch "$src/$file"
  trap - EXIT INT TERM
done
make -C "$build" -j2 handcentric test_experiments >/dev/null 2>&1 ||
  { echo "rebuild failed"; exit 1; }
[ $status -eq 0 ] && echo "all mutants caught"
exit $status
