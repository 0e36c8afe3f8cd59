#!/usr/bin/env python3
"""A whole policy for `handcentric audit --policy-exec ... --observations FILE`: it steps toward
a goal pose seen from the hand, scaled by a gripper width and the mean of a wrist image, all
three recorded in the user's observations (extra_poses "goal", scalars "gripper", held "wrist").

argv[1] picks where it reads the goal (the audit must tell the two apart):
  (none)     from extra_poses: the goal moves with g as the hand does, so equivariant
  held_goal  from held["goal"], the same world-frame matrix filed as held (unchanged by g): the
             planted fault, equivariant under nothing
--batched: served batched (held arrays then arrive stacked, (B, ...)).
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

HELD_GOAL = "held_goal" in sys.argv[1:]
BATCHED = "--batched" in sys.argv[1:]


def act(T0, goal, gripper, wrist, noise):
    hand_goal = hp.relative_pose(T0, goal)
    gain = 0.1 * gripper * float(np.mean(wrist))
    step = np.eye(4)
    turn = 0.1 * hp.rotation_vector(hand_goal[:3, :3]) + [0.0, 0.0, 0.01 * noise[0]]
    step[:3, :3] = hp.rotation_matrix(turn)
    step[:3, 3] = gain * hand_goal[:3, 3]
    return np.stack([T0 @ step, T0 @ step @ step])


def policy(history, hand_points, world_points, noise, extra_poses, scalars, held):
    goal = held["goal"] if HELD_GOAL else extra_poses["goal"]
    if not BATCHED:
        return act(history[0], goal, scalars["gripper"], held["wrist"], noise)
    return np.stack([act(history[b, 0], goal[b], scalars["gripper"][b], held["wrist"][b],
                         noise[b]) for b in range(len(history))])


if __name__ == "__main__":
    hp.serve_policy(policy, extra_poses=("goal",), scalars=("gripper",), noise=2, batched=BATCHED)
