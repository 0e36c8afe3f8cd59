#!/usr/bin/env python3
"""UMI, pose_rep 'delta': each pose relative to the one before, in the world frame.

Source   real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/common/pose_repr_util.py:convert_pose_mat_rep
         (pose_rep 'delta'): `out_pos = np.diff(all_pos, axis=0)` with the base position first,
         and `out_rot = np.matmul(curr_rot, prev_rot)`, prev_rot = inv(R_{k-1}); then pose10d
         (rows),
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         umi/common/pose_util.py:mat_to_pose10d
Config   no shipped config
Assumed  no configuration sets action_pose_repr delta (task/umi.yaml names it in a comment), and
         UmiDataset.__getitem__ (diffusion_policy/dataset/umi_dataset.py) converts the actions
         with obs_pose_repr, so no training sees 'delta' actions: the row is the function's branch.
Formula  actions      a_k = [p_k - p_{k-1}, rows(R_k R_{k-1}^T)]   k = 1..K, T_0 the hand now
         observation  'relative' (the branch does not fix the observation; this row pairs it with
                      the 'relative' observation of UMI's configurations)
Theory   actions translation-invariant only (R~ (p_k - p_{k-1}), R~ R_k R_{k-1}^T R~^T); the
         observation invariant under all of SE(3).
Expect   actions: translation; observation: all
"""
import numpy as np
from _geometry import flat, hp, in_frame, rot6d_rows, serve, steps


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    p = after[..., :3, 3] - before[..., :3, 3]
    R = after[..., :3, :3] @ np.swapaxes(before[..., :3, :3], -1, -2)
    T0 = history[:, 0]
    past = in_frame(T0, history)
    observation = flat(past[..., :3, 3], rot6d_rows(past[..., :3, :3]), hand_points,
                       hp.batch_relative_points(T0, world_points))
    return flat(p, rot6d_rows(R)), observation


if __name__ == "__main__":
    serve(encode_batch)
