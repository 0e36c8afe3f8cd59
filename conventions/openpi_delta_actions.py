#!/usr/bin/env python3
"""openpi's DeltaActions (and LeRobot's to_relative_actions, which mirrors it) on an end-effector
state [position, axis-angle]: every masked action dimension minus the same state dimension.

Source   Physical-Intelligence/openpi (commit 099c772), src/openpi/transforms.py,
         class DeltaActions:
         `actions[..., :dims] -= np.expand_dims(np.where(mask, state[..., :dims], 0), axis=-2)`;
         huggingface/lerobot, src/lerobot/processor/relative_action_processor.py,
         to_relative_actions: `actions[..., :dims] -= state_offset` ("Mirrors OpenPI's
         DeltaActions").
Formula  s = [p_0, r(R_0)], a_k = [p_k, r(R_k)] - s, r the rotation vector (LIBERO's state in
         openpi's examples is the end-effector position and axis-angle); observation s.
Assumed  the mask covers all six pose dimensions (openpi's configurations mask joint angles, or
         (6, -1): six deltas and an absolute gripper); the transform itself is component-wise
         whatever the numbers mean.
Theory   actions translation-invariant only: the rotation part r(R_k) - r(R_0) is a difference of
         world-frame rotation vectors; the state is absolute (nothing invariant).
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import flat, rotvec, serve


def pose(T):
    return np.concatenate([T[..., :3, 3], rotvec(T[..., :3, :3])], axis=-1)


def encode_batch(history, chunk, hand_points, world_points):
    state = pose(history[:, :1])  # (B, 1, 6)
    actions = pose(chunk) - state
    return flat(actions), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
