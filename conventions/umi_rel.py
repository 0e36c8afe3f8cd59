#!/usr/bin/env python3
"""UMI, pose_rep 'rel' (the "legacy buggy implementation" the code keeps "for compatibility").

Source   real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/common/pose_repr_util.py:convert_pose_mat_rep
         (pose_rep 'rel'): `pos = pose_mat[...,:3,3] - base_pose_mat[:3,3]`,
         `rot = pose_mat[...,:3,:3] @ np.linalg.inv(base_pose_mat[:3,:3])`; then pose10d (rows),
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         umi/common/pose_util.py:mat_to_pose10d
Config   no shipped config
Assumed  the configurations of UmiDataset set abs (legacy/task/umi.yaml) or relative
         (task/umi.yaml, task/umi_bimanual.yaml); the robomimic tasks' 'rel' goes through another
         function, compute_relative_pose (dp_rotation6d_rel.py).
Formula  actions      a_k = [p_k - p_0, rows(R_k R_0^T)]       k = 1..K, T_0 the hand now
         observation  the same of each history pose T_-h
Theory   translation-invariant only: a global rotation R~ turns p_k - p_0 into R~ (p_k - p_0)
         and R_k R_0^T into R~ R_k R_0^T R~^T (a world-frame difference, not T_0^-1 T_k).
Expect   actions: translation; observation: translation
"""
import numpy as np
from _geometry import flat, rot6d_rows, serve


def rel(T0, T):
    p = T[..., :3, 3] - T0[:, None, :3, 3]
    R = T[..., :3, :3] @ np.swapaxes(T0[:, None, :3, :3], -1, -2)
    return flat(p, rot6d_rows(R))


def encode_batch(history, chunk, hand_points, world_points):
    T0 = history[:, 0]
    return rel(T0, chunk), flat(rel(T0, history), hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
