#!/usr/bin/env python3
"""The hand-centric representation as a plug-in for `handcentric audit --exec` (NumPy).

actions     : for k = 1..K, T_0^-1 T_k as [R_0^T (p_k - p_0), r(R_0^T R_k)]         (eqs. 1-2)
observation : for h = 0..H, T_0^-1 T_-h as [translation, rotation vector]           (eq. 3),
              then the eye-in-hand points as they are,
              then the world points in the hand frame, T_0^-1 q = R_0^T (q - p_0).
r(R) is the rotation vector, angle in [0, pi] (handcentric_plugin.rotation_vector: accurate near
0 and near pi). The audit should find actions, observation and flow invariant under all five
groups, as for the built-in hand_centric ("Guaranteed SE(3)-Equivariant Control via Hand-Centric
Behavior Cloning", Theorem 1); world points expressed in the hand frame keep the observation
invariant even in a third-person view (the built-in copies them raw and is not).

Run:  handcentric audit --exec 'python3 examples/python_representation/repr.py'
      handcentric audit --exec 'python3 examples/python_representation/repr.py --batched'
With --batched it answers up to 256 scenes per request, of any shapes (encode_batch() on stacked
arrays; the audit's verdicts and JSON are the same, in a fraction of the time), their arrays as
base64 of their float64 bytes when the audit takes that encoding (--batched --text: as JSON
numbers).
Copy this file and change encode() (or encode_batch()) to audit your own representation.
"""
import os
import shutil
import sys


def _find_helper():
    """Put the folder holding the helper package handcentric_plugin/ first on sys.path.

    In order: $HANDCENTRIC_PYTHON (a folder, to override); the source tree (this file is
    examples/python_representation/repr.py, the helper python/handcentric_plugin/); an install
    (<prefix>/share/handcentric/python, with <prefix> found from the `handcentric` program on
    PATH, or /usr/local, /usr). Symbolic links to this file are resolved first, so a link to it
    from elsewhere still finds its source tree. Failing all of them, a plain import (PYTHONPATH).
    """
    here = os.path.dirname(os.path.realpath(__file__))
    candidates = [os.environ.get("HANDCENTRIC_PYTHON", ""),
                  os.path.join(here, os.pardir, os.pardir, "python")]
    program = shutil.which("handcentric")
    prefixes = [os.path.dirname(os.path.dirname(os.path.realpath(program)))] if program else []
    candidates += [os.path.join(p, "share", "handcentric", "python")
                   for p in prefixes + ["/usr/local", "/usr"]]
    for folder in candidates:
        if folder and os.path.isfile(os.path.join(folder, "handcentric_plugin", "__init__.py")):
            sys.path.insert(0, os.path.abspath(folder))
            return
    # Not found: leave sys.path alone; the import below then tries PYTHONPATH.


_find_helper()
try:
    import numpy as np  # the helpers below need it: fail here, with a clear line
    import handcentric_plugin as hp
except ImportError as error:  # one clear line: the audit quotes our stderr
    sys.exit("repr.py: %s (with %s). It needs NumPy (Debian: python3-numpy) and "
             "the package handcentric_plugin (the source tree's python/ folder, an install's "
             "share/handcentric/python, or $HANDCENTRIC_PYTHON)." % (error, sys.executable))


def hand_centric(T0, poses):
    """T_0^-1 T for each pose of a stack (n, 4, 4), as [translation, rotation vector]: (n, 6)."""
    return hp.pose_vector(hp.relative_pose(T0, poses))


def encode(history, chunk, hand_points, world_points):
    T0 = history[0]  # history is newest first: index 0 is the hand now
    actions = hand_centric(T0, chunk)  # eqs. (1)-(2)
    observation = [hand_centric(T0, history), hand_points,
                   hp.relative_points(T0, world_points)]  # eq. (3)
    return actions, observation


def encode_batch(history, chunk, hand_points, world_points):
    """encode() on B scenes of one shape at once: history (B,H+1,4,4), chunk (B,K,4,4), points
    (B,n,3), (B,m,3) -> actions (B,6K), observation (B,o), row b equal to encode() on scene b."""
    B, K, T0 = len(history), chunk.shape[1], history[:, 0]
    # Chunk and history poses relative to T_0, as one stack: one pass of the rotation vector
    # (most of a call's time is NumPy's per-call overhead, not the arithmetic).
    relative = np.concatenate([hp.batch_relative_pose(T0, chunk),
                               hp.batch_relative_pose(T0, history)], axis=1)
    vectors = hp.pose_vector(relative)  # (B, K + H + 1, 6)
    actions = vectors[:, :K].reshape(B, -1)
    observation = np.concatenate(
        [vectors[:, K:].reshape(B, -1), hand_points.reshape(B, -1),
         hp.batch_relative_points(T0, world_points).reshape(B, -1)], axis=1)
    return actions, observation


if __name__ == "__main__":
    if sys.argv[1:] in (["--batched"], ["--batched", "--text"]):
        # The helper offers the base64 encoding of batched lines (the same numbers in fewer
        # bytes and less parsing); --text keeps them JSON numbers, to compare the two.
        hp.serve(encode_batch, batched=True,
                 encoding=None if "--text" in sys.argv else "base64")
    elif sys.argv[1:]:
        sys.exit("repr.py: unknown arguments %s; the options are --batched and --batched --text"
                 % sys.argv[1:])
    else:
        hp.serve(encode)
