#!/usr/bin/env python3
"""repr.py's hand-centric maps computed in float32, as many training codebases do.

Inputs are cast to np.float32 first; every product and the rotation vector then run in float32
(handcentric_plugin's geometry keeps the dtype), and the helper sends the float32 results as
doubles.

What the audit should find: NOT invariant at its default tolerance of 1e-9 (1 + L). Float32
keeps ~7 digits: with translations of metres, T_0^-1 T_k of a scene and of the moved scene differ
by ~1e-6, far above 1e-9 yet far below a real symmetry breaking. This is rounding, not a broken
symmetry: a relative tolerance near 1e-4 (CheckOptions::relative_tolerance) would pass it.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    history, chunk = history.astype(np.float32), chunk.astype(np.float32)
    hand_points, world_points = hand_points.astype(np.float32), world_points.astype(np.float32)
    T0 = history[0]
    actions = [hp.pose_vector(hp.relative_pose(T0, T)) for T in chunk]
    observation = [hp.pose_vector(hp.relative_pose(T0, T)) for T in history]
    observation += [hand_points, hp.relative_points(T0, world_points)]
    return np.concatenate(actions), np.concatenate([np.ravel(x) for x in observation])


if __name__ == "__main__":
    hp.serve(encode)
