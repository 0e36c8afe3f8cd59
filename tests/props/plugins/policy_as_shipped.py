#!/usr/bin/env python3
"""A whole policy as shipped code speaks, for `handcentric audit --policy-exec`: its poses as
position + quaternion (x, y, z, w) vectors, a gripper width per step beside its chunk, and, with
--hands, two hands (UMI-style: the right hand seen in the left hand's frame). Hand-centric
inside (the paper's steps 1-3) around a small fixed random network, its noise its only
randomness.

argv picks planted faults (the audit must find each):
  (none)          equivariant in every group; every output
  gripper_height  the gripper width reads the hand's WORLD height: NO under translation (and
                  se3) for the gripper only, the hand chunk still equivariant
  bad_quat        answers quaternions of norm 1.5: a layout the numbers contradict (an error)
  gripper_length  one gripper width fewer where the hand's world x is positive (an error)
  undeclared      answers its 7-number poses without declaring action_format (an error)
  --hands         two hands; with right_world_x the right hand's chunk reads its WORLD x: NO
                  under translation for the right hand, the left still equivariant
  --stateful      keeps state between calls (reset= declared): a queue that replans every 2
                  steps (equivariant in closed loop); with world_memory it adds 0.1 times the
                  previous call's WORLD hand position to every position: every single call
                  (after reset) is equivariant, the closed loop is NO under translation
  --batched       served batched (the same numbers, row by row)
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

ARGS = sys.argv[1:]
FLAGS = {"--hands", "--stateful", "--batched"}
FAULT = ([a for a in ARGS if a not in FLAGS] or [""])[0]
K = 4
LAYOUT = "pos_quat_xyzw"
RNG = np.random.default_rng(11)
W1 = RNG.normal(size=(24, 6 + 3 + 8)) * 0.3
W2 = RNG.normal(size=(7 * K, 24)) * 0.1
state = {"queue": [], "previous": None}


def reset():
    state["queue"], state["previous"] = [], None


def plan(T0, feature, hand_points, noise):
    """hand0_T_handk from invariant inputs, the chunk T0 hand0_T_handk and K gripper widths."""
    points = hand_points[:1].ravel() if len(hand_points) else np.zeros(3)
    x = np.concatenate([feature, np.pad(points, (0, 3 - len(points))), noise[:8]])
    out = (W2 @ np.tanh(W1 @ x)).reshape(K, 7)
    chunk = T0 @ np.stack([hp.pose_matrix(a[:6]) for a in out])
    return chunk, np.tanh(out[:, 6])


def one_hand(history, hand_points, noise):
    T = hp.formats.decode(history, LAYOUT)  # (H+1, 4, 4)
    T0 = T[0]
    feature = hp.pose_vector(hp.relative_pose(T0, T[1])) if len(T) > 1 else np.zeros(6)
    chunk, gripper = plan(T0, feature, hand_points, noise)
    if FAULT == "gripper_height":
        gripper = gripper + T0[2, 3]
    if FAULT == "gripper_length" and T0[0, 3] > 0:
        gripper = gripper[:-1]
    if "--stateful" in ARGS:
        if FAULT == "world_memory" and state["previous"] is not None:
            chunk[:, :3, 3] += 0.1 * state["previous"]
        state["previous"] = T0[:3, 3].copy()
        # The queue: a plan kept in the world frame and served again at the next step.
        if state["queue"]:
            chunk, gripper = state["queue"].pop()
        else:
            state["queue"].append((chunk.copy(), gripper.copy()))
    vectors = hp.formats.encode(chunk, LAYOUT)
    if FAULT == "bad_quat":
        vectors[:, 3:] *= 1.5
    return vectors, gripper


def two_hands(history, hand_points, noise):
    L = hp.formats.decode(history["left"], LAYOUT)
    R = hp.formats.decode(history["right"], LAYOUT)
    left_in_right = hp.pose_vector(hp.relative_pose(L[0], R[0]))  # UMI's robot1_eef_pos_wrt0
    left, gripper = plan(L[0], left_in_right, hand_points, noise)
    feature = -left_in_right
    if FAULT == "right_world_x":
        feature = feature + np.array([R[0][0, 3], 0, 0, 0, 0, 0])
    right, _ = plan(R[0], feature, hand_points, noise[::-1])
    return {"left": hp.formats.encode(left, LAYOUT), "right": hp.formats.encode(right, LAYOUT),
            "gripper": gripper}


def policy(history, hand_points, world_points, noise):
    if "--hands" in ARGS:
        return two_hands(history, hand_points, noise)
    vectors, gripper = one_hand(history, hand_points, noise)
    if FAULT == "undeclared":
        return vectors
    return {"hand": vectors, "gripper": gripper}


def policy_batch(history, hand_points, world_points, noise):
    rows = [policy({k: v[i] for k, v in history.items()} if isinstance(history, dict)
                   else history[i], hand_points[i], world_points[i], noise[i])
            for i in range(len(noise))]
    if isinstance(rows[0], dict):
        return {k: np.stack([r[k] for r in rows]) for k in rows[0]}
    return np.stack(rows)


if __name__ == "__main__":
    keywords = {"state_format": LAYOUT, "outputs": {"gripper": "invariant"}}
    if "--hands" in ARGS:
        keywords["hands"] = ("left", "right")
    else:
        keywords["outputs"] = {"hand": "pose", "gripper": "invariant"}
    if FAULT != "undeclared":
        keywords["action_format"] = LAYOUT
    else:
        keywords.pop("outputs")
    if "--stateful" in ARGS:
        keywords["reset"] = reset
    if "--batched" in ARGS:
        hp.serve_policy(policy_batch, batched=True, batch_size=64, **keywords)
    else:
        hp.serve_policy(policy, **keywords)
