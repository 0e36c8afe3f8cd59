#!/usr/bin/env bash
# The mutants of the conventions table: a plug-in audited as it is, then with a planted fault in
# its formula. The two tables must differ in the plug-in's row, and the mutant must be reported
# against its Expect line (exit 1, naming the cell), while the original passes.
#   mutant_formula.sh HANDCENTRIC SOURCE_DIR PYTHON WORK_DIR [FAULT]
# FAULT (default rel):
#   rel   umi_relative.py with UMI's 'rel' formula (world-frame differences) instead of
#         T_0^-1 T_k: its actions turn NOT invariant under rotation;
#   base  robosuite_osc_base.py with the identity as the base instead of the extra pose that
#         moves with g: its actions turn NOT invariant under rotation.
set -u
cli=$1 source=$2 python=$3 work=$4 fault=${5:-rel}
case "$fault" in
  rel)
    plugin=umi_relative
    mutate() {
      sed 's#    actions = in_frame(T0, chunk)#    actions = chunk.copy(); '\
'actions[..., :3, 3] -= T0[:, None, :3, 3]; '\
'actions[..., :3, :3] = chunk[..., :3, :3] @ np.swapaxes(T0[:, None, :3, :3], -1, -2)#' |
        sed 's#^from _geometry import#import numpy as np\nfrom _geometry import#'
    } ;;
  base)
    plugin=robosuite_osc_base
    mutate() {
      sed 's#    RB = extra_poses\["base"\]\[:, None, :3, :3\]  \# (B, 1, 3, 3)#'\
'    RB = np.broadcast_to(np.eye(3), (history.shape[0], 1, 3, 3))#'
    } ;;
  *) echo "unknown fault '$fault' (rel or base)"; exit 2 ;;
esac
rm -rf "$work" && mkdir -p "$work/original" "$work/mutant"
cp "$source/conventions/_geometry.py" "$source/conventions/$plugin.py" "$work/original/"
cp "$source/conventions/_geometry.py" "$work/mutant/"
# _geometry.py finds the helper beside the source tree; point it there from the copies.
for d in original mutant; do
  sed -i "s#os.path.join(HERE, os.pardir, \"python\")#\"$source/python\"#" "$work/$d/_geometry.py"
done
mutate < "$source/conventions/$plugin.py" > "$work/mutant/$plugin.py"
cmp -s "$work/original/$plugin.py" "$work/mutant/$plugin.py" &&
  { echo "the mutation did not apply: $plugin.py changed"; exit 1; }
run() {
  "$cli" conventions --plugins "$work/$1" --python "$python" --cases 100 \
    --out "$work/$1.md" 2> "$work/$1.err"
}
run original; original=$?
run mutant; mutant=$?
echo "original exit $original, mutant exit $mutant"
cat "$work/mutant.err"
[ "$original" -eq 0 ] || { echo "the original plug-in does not pass"; exit 1; }
[ "$mutant" -eq 1 ] || { echo "the mutant is not reported"; exit 1; }
grep -q "$plugin: actions (pointwise, eye-in-hand) under rotation: the audit says NOT" \
  "$work/mutant.err" || { echo "the mutant's rotation cell is not named"; exit 1; }
# The convention's row of the eye-in-hand table (its first row in the file).
row() { grep -F "[${plugin//_/\\_}](#conventions-$plugin) |" "$1" | head -1; }
echo "original: $(row "$work/original.md")"
echo "mutant:   $(row "$work/mutant.md")"
[ -n "$(row "$work/original.md")" ] || { echo "no $plugin row in the table"; exit 1; }
[ "$(row "$work/original.md")" != "$(row "$work/mutant.md")" ] ||
  { echo "the mutant's row is the original's"; exit 1; }
echo "mutant caught"
