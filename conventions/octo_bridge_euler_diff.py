#!/usr/bin/env python3
"""Octo's (and OpenVLA's) relabelled Bridge actions: the difference of consecutive proprio
states [position, Euler angles], component by component.

Source   octo-models/octo (commit 0f05001), octo/data/utils/data_utils.py, relabel_actions:
         `movement_actions = traj["observation"]["state"][1:, :6] -
         traj["observation"]["state"][:-1, :6]`; the same line in OpenVLA's
         prismatic/vla/datasets/rlds/utils/data_utils.py, relabel_bridge_actions.
Formula  state s(T) = [p, euler_xyz(R)];  a_k = s(T_k) - s(T_{k-1});  observation s(T_0)
Assumed  Bridge's state holds extrinsic xyz Euler angles (roll, pitch, yaw) as its last three
         pose numbers; the codebases subtract whatever the six numbers are.
Theory   translation-invariant only: Euler angles are world-frame coordinates of R, and their
         difference is not a function of R_{k-1}^T R_k (it also jumps by 2 pi where an angle
         wraps). The state is absolute.
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import euler_xyz, flat, serve, steps


def state(T):
    return np.concatenate([T[..., :3, 3], euler_xyz(T[..., :3, :3])], axis=-1)


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    return flat(state(after) - state(before)), flat(state(history[:, 0]), hand_points,
                                                     world_points)


if __name__ == "__main__":
    serve(encode_batch)
