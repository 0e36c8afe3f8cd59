#!/usr/bin/env python3
"""hand_centric discretized as voxel and tokenized-action policies do: the translation of
T_0^-1 T_k in 1 cm voxels, its rotation as ZYX Euler angles in 5 degree bins (the indices are
the actions); the observation as examples/python_representation/repr.py.

What the audit should find: NOT injective below about 1 cm (and 5 degrees = 0.087 rad): chunks
that differ by less fall into one voxel and one bin, so no policy trained on these actions can
tell them apart. The bins are taken in the hand frame, yet the actions are not pointwise
invariant: where a coordinate sits on a bin edge, the rounding of T_0^-1 T_k in a moved scene
can push it into the next bin (the shrunk witnesses land on such edges, with round numbers).
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

VOXEL = 0.01  # m
ANGLE_BIN = np.radians(5.0)


def encode(history, chunk, hand_points, world_points):
    T0 = history[0]
    relative = hp.relative_pose(T0, chunk)  # (K, 4, 4)
    R = relative[:, :3, :3]
    yaw = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    pitch = np.arctan2(-R[:, 2, 0], np.hypot(R[:, 2, 1], R[:, 2, 2]))
    roll = np.arctan2(R[:, 2, 1], R[:, 2, 2])
    voxels = np.floor(relative[:, :3, 3] / VOXEL)
    bins = np.floor(np.stack([yaw, pitch, roll], axis=1) / ANGLE_BIN)
    actions = np.concatenate([voxels, bins], axis=1)
    observation = [hp.pose_vector(hp.relative_pose(T0, T)) for T in history]
    observation += [hand_points, hp.relative_points(T0, world_points)]
    return actions.ravel(), np.concatenate([np.ravel(x) for x in observation])


if __name__ == "__main__":
    hp.serve(encode)
