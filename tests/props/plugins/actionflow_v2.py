#!/usr/bin/env python3
"""ActionFlow's field, through the protocol v2 flow request.

actions     : the absolute translations p_k, k = 1..K (3K numbers, world frame)
observation : world proprioception, [p, r(R)] per history pose (h = 0..H)
flow        : x_t = t p_k + (1 - t) eps_k; flow_input = [x_t, t, observation];
              flow_target_k = R_k^T (p_k - eps_k)      (eq. 29, App. A.4 of "Guaranteed
              SE(3)-Equivariant Control via Hand-Centric Behavior Cloning")

What the audit should find: no component invariant pointwise under any group. flow_target is
rotation-invariant IN DISTRIBUTION: for a rotation R~ about the origin,
(R~ R_k)^T (R~ p_k - eps) = R_k^T (p_k - R~^T eps), and R~^T eps ~ N(0, I) again. It is not
translation-invariant (p_k + p~ - eps has a shifted mean), and flow_input, actions and
observation are not invariant in distribution either.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    return chunk[:, :3, 3].ravel(), [hp.pose_vector(T) for T in history]


def flow(history, chunk, hand_points, world_points, eps, t):
    p, observation = encode(history, chunk, hand_points, world_points)
    eps = eps.reshape(-1, 3)
    target = [T[:3, :3].T @ (T[:3, 3] - e) for T, e in zip(chunk, eps)]
    return [t * p + (1 - t) * eps.ravel(), [t], observation], target


if __name__ == "__main__":
    hp.serve(encode, flow=flow)
