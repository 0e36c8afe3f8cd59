#!/usr/bin/env bash
# The mutants of `handcentric conventions --detect`: the detector copied as it is and with a
# planted fault, both run by the command on one recording; the original's output must say what
# the fault hides, and the mutant's must not.
#   mutant_detect.sh HANDCENTRIC SOURCE_DIR PYTHON WORK_DIR FAULT
# FAULT:
#   flag      _component_wise_flag returns "": Euler angles differenced component-wise are no
#             longer flagged (tests/conventions/detect/euler_component_wise.jsonl);
#   declared  _flag_declared does nothing: a mis-declared Euler order is no longer named
#             (euler_zyx.jsonl, declared pos_euler_xyz);
#   finite    _finite checks nothing: a NaN action is no longer the one-line error naming it
#             (nan_action.jsonl).
set -u
cli=$1 source=$2 python=$3 work=$4 fault=$5
recordings="$source/tests/conventions/detect"
declared=()
case "$fault" in
  flag) function=_component_wise_flag arguments="layout" value='""'
        file=euler_component_wise.jsonl expect="rotation differenced component-wise" ;;
  declared) function=_flag_declared arguments="merged, declared" value=None
            file=euler_zyx.jsonl expect="mis-declared: the data were declared pos_euler_xyz"
            declared=(--declared pos_euler_xyz) ;;
  finite) function=_finite arguments="name, values" value=None
          file=nan_action.jsonl expect="error: action\[1, 3\] is nan" ;;
  *) echo "unknown fault '$fault' (flag, declared or finite)"; exit 2 ;;
esac
rm -rf "$work"
for d in original mutant; do
  mkdir -p "$work/$d/conventions" "$work/$d/python/handcentric"
  cp "$source"/conventions/*.py "$work/$d/conventions/"
  ln -s "$source/python/handcentric_plugin" "$work/$d/python/handcentric_plugin"
done
cp "$source/python/handcentric/detect.py" "$work/original/python/handcentric/"
# The fault: the function returns at once (its first statement).
sed "/^def $function($arguments):\$/a\\    return $value" "$source/python/handcentric/detect.py" \
  > "$work/mutant/python/handcentric/detect.py"
cmp -s "$work/original/python/handcentric/detect.py" "$work/mutant/python/handcentric/detect.py" &&
  { echo "the mutation did not apply: $function is not in detect.py"; exit 1; }
run() {
  "$cli" conventions --detect "$recordings/$file" --plugins "$work/$1/conventions" \
    --python "$python" "${declared[@]}" 2>&1
}
original=$(run original)
grep -q -- "$expect" <<< "$original" ||
  { echo "the original detector does not say '$expect':"; echo "$original"; exit 1; }
mutant=$(run mutant)
grep -q -- "$expect" <<< "$mutant" &&
  { echo "the mutant ($fault) still says '$expect': the test would not catch it"; exit 1; }
echo "mutant caught: without $function, the command no longer says '$expect'"
