#!/usr/bin/env bash
# The mutant of the conventions table: umi_relative.py audited as it is, then with its actions
# computed by UMI's 'rel' formula (world-frame differences) instead of T_0^-1 T_k. The two tables
# must differ in umi_relative's row, and the mutant must be reported against its Expect line
# (exit 1, naming the cell), while the original passes.
#   mutant_formula.sh HANDCENTRIC SOURCE_DIR PYTHON WORK_DIR
set -u
cli=$1 source=$2 python=$3 work=$4
rm -rf "$work" && mkdir -p "$work/original" "$work/mutant"
cp "$source/conventions/_geometry.py" "$source/conventions/umi_relative.py" "$work/original/"
cp "$source/conventions/_geometry.py" "$work/mutant/"
# _geometry.py finds the helper beside the source tree; point it there from the copies.
for d in original mutant; do
  sed -i "s#os.path.join(HERE, os.pardir, \"python\")#\"$source/python\"#" "$work/$d/_geometry.py"
done
sed 's#    actions = in_frame(T0, chunk)#    actions = chunk.copy(); '\
'actions[..., :3, 3] -= T0[:, None, :3, 3]; '\
'actions[..., :3, :3] = chunk[..., :3, :3] @ np.swapaxes(T0[:, None, :3, :3], -1, -2)#' \
  "$source/conventions/umi_relative.py" |
  sed 's#^from _geometry import#import numpy as np\nfrom _geometry import#' \
  > "$work/mutant/umi_relative.py"
cmp -s "$work/original/umi_relative.py" "$work/mutant/umi_relative.py" &&
  { echo "the mutation did not apply: umi_relative.py changed"; exit 1; }
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
grep -q "umi_relative: actions (pointwise, eye-in-hand) under rotation: the audit says NOT" \
  "$work/mutant.err" || { echo "the mutant's rotation cell is not named"; exit 1; }
# The convention's row of the eye-in-hand table (its first row in the file).
row() { grep -F '[umi\_relative](#conventions-umi_relative) |' "$1" | head -1; }
echo "original: $(row "$work/original.md")"
echo "mutant:   $(row "$work/mutant.md")"
[ -n "$(row "$work/original.md")" ] || { echo "no umi_relative row in the table"; exit 1; }
[ "$(row "$work/original.md")" != "$(row "$work/mutant.md")" ] ||
  { echo "the mutant's row is the original's"; exit 1; }
echo "mutant caught"
