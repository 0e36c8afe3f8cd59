#!/usr/bin/env python3
"""LeRobot's fixed-reference relative end-effector chunks: each target in the frame of the
current end-effector pose, rotation as the first two rows of the relative rotation.

Source   huggingface/lerobot@1aaab1d714dda078077a3c3fb14d6394b260f2f7:
         src/lerobot/processor/relative_ee_processor.py:absolute_ee_to_relative
         `relative_rotation = reference_rotation_t @ target_rotation`,
         `relative_translation = reference_rotation_t @ (target[..., :3] - reference[..., :3])`;
         huggingface/lerobot@1aaab1d714dda078077a3c3fb14d6394b260f2f7:
         src/lerobot/processor/relative_ee_processor.py:matrix_to_rotation_6d
         `matrix[..., :2, :]` (rows);
         huggingface/lerobot@1aaab1d714dda078077a3c3fb14d6394b260f2f7:
         src/lerobot/processor/relative_ee_processor.py:to_relative_ee_state
         the [previous, current] poses relative to the current one.
Config   not on main: only on pull request 4251 of huggingface/lerobot (head 1aaab1d), the flag
         use_relative_ee of its act, pi05 and smolvla policy configurations (default False)
Formula  actions      a_k = [R_0^T (p_k - p_0), rows(R_0^T R_k)]
         observation  [previous, current] relative to current (previous = current when the
                      history has one pose, as RelativeEEStateStep does on its first call);
                      world points in the hand frame (LeRobot has none; added for the view)
Theory   invariant under all of SE(3) in both views (T_0^-1 T).
Expect   actions: all; observation: all
"""
import numpy as np
from _geometry import flat, hp, in_frame, rot6d_rows, serve


def encode_batch(history, chunk, hand_points, world_points):
    T0 = history[:, 0]
    actions = in_frame(T0, chunk)
    previous = history[:, 1:2] if history.shape[1] > 1 else history[:, :1]
    state = in_frame(T0, np.concatenate([previous, history[:, :1]], axis=1))
    observation = flat(state[..., :3, 3], rot6d_rows(state[..., :3, :3]), hand_points,
                       hp.batch_relative_points(T0, world_points))
    return flat(actions[..., :3, 3], rot6d_rows(actions[..., :3, :3])), observation


if __name__ == "__main__":
    serve(encode_batch)
