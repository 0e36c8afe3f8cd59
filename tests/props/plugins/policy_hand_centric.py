#!/usr/bin/env python3
"""A whole policy for `handcentric audit --policy-exec`: the outer hand-centric policy of the
paper (Sec. 3, steps 1-3) around a small fixed random network, with its noise as its only
randomness.

  observation -> hand-centric (eq. 3) -> network(observation, noise) -> hand0_T_handk
              -> T_k = T_0 hand0_T_handk (inverse of eq. 1)

argv[1] picks a planted fault (the audit must find each):
  (none)        equivariant in every group, pointwise and in distribution (Theorem 1)
  world_noise   adds 0.05 * noise to each translation in the WORLD frame after decoding: the
                same noise moves differently under a rotation, so not equivariant pointwise
                under rotations; N(0, I) is rotation invariant, so equivariant in distribution
                under rotation and c8 (and, pointwise and in distribution, under translations)
  forgets_T0    decodes without T_0 (T_k = hand0_T_handk): equivariant under nothing
  world_velocity feeds the network the world-frame step p_0 - p_-1 (history order matters):
                translation-equivariant only
  own_noise     adds 1 cm of noise per step drawn from NumPy's global generator inside, in the
                hand frame (equivariant for the same draws): without --rng the audit's preflight
                sees answers that differ at every call and gives no verdict; with --rng (served
                with rng="numpy") it is equivariant
  own_noise_world  the same noise added in the world frame: with --rng, not equivariant under
                rotations
  world_clip    clips each position to [-0.5, 0.5] m per WORLD axis, as a policy clipping its
                output to a workspace box does: equivariant only while the hand stays inside
                the box, so under no group, pointwise or in distribution; seen only on cases
                whose scenes reach past 0.5 m (a check that drew small scenes called it "yes")
--batched (after the fault, if any): the same policy served batched, row by row (each row as
the unbatched call computes it, so the audit's JSON must not change); --batched row_bias adds
1e-7 times the row's index in its batch to every translation (an answer that depends on its
batch: the planted fault of the batched-equals-unbatched test); --batched text keeps the
batched lines' numbers JSON text (the helper offers base64 otherwise).
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

ARGS = sys.argv[1:]
BATCHED = "--batched" in ARGS
ROW_BIAS = "row_bias" in ARGS
TEXT = "text" in ARGS
SEEDED = "--rng" in ARGS
FAULT = ([a for a in ARGS if a not in ("--batched", "row_bias", "text", "--rng")] or [""])[0]
K = 4
RNG = np.random.default_rng(7)
W1 = RNG.normal(size=(32, 6 + 3 + 8)) * 0.3
W2 = RNG.normal(size=(6 * K, 32)) * 0.1


def policy(history, hand_points, world_points, noise):
    T0 = history[0]  # index 0: the hand now
    if FAULT == "world_velocity" and len(history) > 1:
        feature = np.concatenate([history[0][:3, 3] - history[1][:3, 3], np.zeros(3)])
    elif len(history) > 1:
        feature = hp.pose_vector(hp.relative_pose(T0, history[1]))
    else:
        feature = np.zeros(6)
    points = hand_points[:1].ravel() if len(hand_points) else np.zeros(3)
    x = np.concatenate([feature, np.pad(points, (0, 3 - len(points))), noise[:8]])
    actions = (W2 @ np.tanh(W1 @ x)).reshape(K, 6)
    hand0_T_handk = np.stack([hp.pose_matrix(a) for a in actions])
    if FAULT == "forgets_T0":
        return hand0_T_handk
    chunk = T0 @ hand0_T_handk
    if FAULT == "world_noise":
        chunk[:, :3, 3] += 0.05 * noise[8:8 + 3 * K].reshape(K, 3)
    if FAULT == "world_clip":
        chunk[:, :3, 3] = np.clip(chunk[:, :3, 3], -0.5, 0.5)
    if FAULT.startswith("own_noise"):
        step = 0.01 * np.random.normal(size=(K, 3))
        chunk[:, :3, 3] += step if FAULT == "own_noise_world" else step @ T0[:3, :3].T
    return chunk


def policy_batch(history, hand_points, world_points, noise):
    chunks = np.stack([policy(*row) for row in zip(history, hand_points, world_points, noise)])
    if ROW_BIAS:
        chunks[:, :, :3, 3] += 1e-7 * np.arange(len(chunks))[:, None, None]
    return chunks


if __name__ == "__main__":
    rng = "numpy" if SEEDED else None
    if BATCHED:
        hp.serve_policy(policy_batch, batched=True, batch_size=64,
                        encoding=None if TEXT else "base64", rng=rng)
    else:
        hp.serve_policy(policy, rng=rng)
