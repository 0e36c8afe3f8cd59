#!/usr/bin/env python3
"""World-frame "delta" actions: each pose relative to the one before, in the world frame.

actions     : for k = 1..K, [p_k - p_{k-1}, r(R_k R_{k-1}^T)], with T_0 (the hand now) before T_1
observation : hand-centric, as examples/python_representation/repr.py

This is the `pose_rep == 'delta'` branch of convert_pose_mat_rep in the Universal Manipulation
Interface (github.com/real-stanford/universal_manipulation_interface,
diffusion_policy/common/pose_repr_util.py, commit c34ba9c): np.diff of the positions with the
base pose first, and curr_rot @ inv(prev_rot).

What the audit should find: actions translation-invariant only. A global rotation R~ turns
p_k - p_{k-1} into R~ (p_k - p_{k-1}) and R_k R_{k-1}^T into its conjugate R~ R_k R_{k-1}^T R~^T,
so actions fail rotation, se2, se3 and c8; the observation stays invariant everywhere.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    poses = [history[0], *chunk]  # T_0, T_1, ..., T_K
    actions = [np.concatenate([b[:3, 3] - a[:3, 3], hp.rotation_vector(b[:3, :3] @ a[:3, :3].T)])
               for a, b in zip(poses, poses[1:])]
    T0 = history[0]
    observation = [hp.pose_vector(hp.relative_pose(T0, T)) for T in history]
    observation += [hand_points, hp.relative_points(T0, world_points)]
    return actions, observation


if __name__ == "__main__":
    hp.serve(encode)
