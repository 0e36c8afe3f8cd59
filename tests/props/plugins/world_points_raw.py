#!/usr/bin/env python3
"""Hand-centric actions with a fixed camera's point cloud copied raw into the observation.

actions     : hand-centric, as examples/python_representation/repr.py
observation : hand-centric proprioception and eye-in-hand points as repr.py, then the world
              points q AS THEY ARE (world frame), not T_0^-1 q

What the audit should find: actions invariant under every group. The observation is invariant
on eye-in-hand scenes (no world points: the audit's default), but in a third-person view (scenes
with world points) it is NOT invariant under any group with a translation or a rotation: g moves
q to R~ q + p~ and nothing undoes it. The paper's Theorem 1 ("Guaranteed SE(3)-Equivariant
Control via Hand-Centric Behavior Cloning") needs the observation in the hand frame.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    T0 = history[0]
    actions = [hp.pose_vector(hp.relative_pose(T0, T)) for T in chunk]
    observation = [hp.pose_vector(hp.relative_pose(T0, T)) for T in history]
    observation += [hand_points, world_points]  # the planted fault: world frame, raw
    return actions, observation


if __name__ == "__main__":
    hp.serve(encode)
