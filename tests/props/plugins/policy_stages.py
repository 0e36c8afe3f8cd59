#!/usr/bin/env python3
"""A policy plug-in that declares the stages of its pipeline, for `handcentric audit
--policy-exec CMD --locate`: each call returns (its chunk, {stage: output}) and serve_policy's
stages= names them in the hello. Hand-centric inside (the paper's steps 1-3) around a small
fixed random network, its noise its only randomness:

  to_hand      features  every history pose in T_0's frame, and the first hand points
  normalize    features  (x - MEAN) / STD with fixed constants
  network      features  W2 tanh(W1 [x, noise]): K hand-frame pose vectors
  decode       poses     T_0 exp(a_k): the chunk in the world
  unnormalize  poses     the chunk as executed (the same poses)

argv picks a planted fault (locate must name its stage):
  (none)             no stage breaks its kind
  world_normalizer   the normalizer fit in world coordinates, placed before the hand frame: a
                     "poses" stage that scales the world positions per axis (p - MU) / S, then
                     to_hand on them: first break at 'normalize'
  world_unnormalizer the un-normalizer adds the world mean MU back after the decoder: equivariant
                     under translation, not under rotation: first break at 'unnormalize' (se3)
  --batched          served batched (the same numbers, row by row)
  --outputs          answers named outputs, {"gripper": K widths (invariant), "hand": the chunk}
                     (the gripper declared first: the chunk locate decides is the hand's)
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

ARGS = sys.argv[1:]
FAULT = ([a for a in ARGS if not a.startswith("--")] or [""])[0]
K = 3
RNG = np.random.default_rng(5)
W1 = RNG.normal(size=(16, 6 + 6 + 8)) * 0.3
W2 = RNG.normal(size=(6 * K, 16)) * 0.1
MEAN, STD = RNG.normal(size=12) * 0.1, 1.0 + RNG.random(12)
MU, S = np.array([0.4, -0.2, 0.3]), np.array([1.0, 2.0, 0.5])  # a world-frame fit


def to_hand(T, hand_points):
    """Invariant features: T_-1 in T_0's frame and the first two hand points (padded)."""
    previous = hp.pose_vector(hp.relative_pose(T[0], T[1])) if len(T) > 1 else np.zeros(6)
    points = np.zeros(6)
    few = np.asarray(hand_points)[:2].ravel()
    points[:len(few)] = few
    return np.concatenate([previous, points])


def policy(history, hand_points, world_points, noise):
    T = np.asarray(history)
    stages = {}
    if FAULT == "world_normalizer":
        T = T.copy()
        T[:, :3, 3] = (T[:, :3, 3] - MU) / S
        stages["normalize"] = T
        x = to_hand(T, hand_points)
        stages["to_hand"] = x
    else:
        x = to_hand(T, hand_points)
        stages["to_hand"] = x
        x = (x - MEAN) / STD
        stages["normalize"] = x
    a = W2 @ np.tanh(W1 @ np.concatenate([x, noise[:8]]))
    stages["network"] = a
    chunk = T[0] @ np.stack([hp.pose_matrix(v) for v in a.reshape(K, 6)])
    stages["decode"] = chunk
    if FAULT == "world_unnormalizer":
        chunk = chunk.copy()
        chunk[:, :3, 3] += MU
    stages["unnormalize"] = chunk
    if "--outputs" in ARGS:
        return {"gripper": np.tanh(a[:K]), "hand": chunk}, stages
    return chunk, stages


def policy_batch(history, hand_points, world_points, noise):
    rows = [policy(history[i], hand_points[i], world_points[i], noise[i])
            for i in range(len(noise))]
    def stacked(values):
        if isinstance(values[0], dict):
            return {name: np.stack([v[name] for v in values]) for name in values[0]}
        return np.stack(values)
    return stacked([r[0] for r in rows]), stacked([r[1] for r in rows])


def declared():
    first = [("normalize", "poses"), ("to_hand", "features")] \
        if FAULT == "world_normalizer" else [("to_hand", "features"), ("normalize", "features")]
    return first + [("network", "features"), ("decode", "poses"), ("unnormalize", "poses")]


if __name__ == "__main__":
    keywords = {"stages": declared()}
    if "--outputs" in ARGS:
        keywords["outputs"] = {"gripper": "invariant", "hand": "pose"}
    if "--batched" in ARGS:
        hp.serve_policy(policy_batch, batched=True, batch_size=16, **keywords)
    else:
        hp.serve_policy(policy, **keywords)
