#!/usr/bin/env python3
"""Every protocol v2 feature at once: an extra pose, a scalar, decode and flow.

Declares extra_poses ["start"] (the episode's start pose, world frame: it moves with g) and
scalars ["gripper"] (a width: g leaves it alone), so the first request gets the hello.

actions     : hand-centric, for k = 1..K: T_0^-1 T_k as [t, r]         (as repr.py)
observation : T_0^-1 T_-h as [t, r] for h = 0..H, then T_0^-1 T_start as [t, r], then [gripper]
decode      : T_k = T_0 exp(a_k), with exp([t, r]) = [[exp(r), t], [0, 1]]
flow        : rectified flow, x_t = t a + (1 - t) eps; flow_input = [x_t, t, observation],
              flow_target = a - eps

What the audit should find: actions, observation, flow input and target invariant under all
five groups, pointwise; decode(encode(s)) = chunk and decode equivariant, so the outer policy is
SE(3)-equivariant (Theorem 1 of "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior
Cloning").
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points, extra_poses, scalars):
    T0 = history[0]
    actions = np.concatenate([hp.pose_vector(hp.relative_pose(T0, T)) for T in chunk])
    observation = np.concatenate([hp.pose_vector(hp.relative_pose(T0, T)) for T in history] +
                                 [hp.pose_vector(hp.relative_pose(T0, extra_poses["start"])),
                                  [scalars["gripper"]]])
    return actions, observation


def decode(actions, history, hand_points, world_points, extra_poses, scalars):
    return [history[0] @ hp.pose_matrix(a) for a in actions.reshape(-1, 6)]


def flow(history, chunk, hand_points, world_points, eps, t, extra_poses, scalars):
    a, observation = encode(history, chunk, hand_points, world_points, extra_poses, scalars)
    return np.concatenate([t * a + (1 - t) * eps, [t], observation]), a - eps


if __name__ == "__main__":
    hp.serve(encode, decode=decode, flow=flow, extra_poses=["start"], scalars=["gripper"])
