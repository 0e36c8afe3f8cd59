#!/usr/bin/env python3
"""UMI, pose_rep 'abs': world-frame poses, as they are.

Source   real-stanford/universal_manipulation_interface (commit c34ba9c),
         diffusion_policy/common/pose_repr_util.py, convert_pose_mat_rep(pose_mat, base_pose_mat,
         pose_rep='abs'): `return pose_mat`; the policy then sees pose10d =
         [position, first two rows of R] (diffusion_policy/common/pose_util.py, mat_to_pose10d and
         mat_to_rot6d: `mat[..., :2, :]`).
Formula  actions      a_k = [p_k, rows(R_k)]                 k = 1..K
         observation  o_h = [p_-h, rows(R_-h)]               h = 0..H (the same pose_rep)
Theory   nothing is invariant: every number is a world coordinate.
Expect   actions: none; observation: none
"""
from _geometry import flat, rot6d_rows, serve


def encode_batch(history, chunk, hand_points, world_points):
    actions = flat(chunk[..., :3, 3], rot6d_rows(chunk[..., :3, :3]))
    observation = flat(history[..., :3, 3], rot6d_rows(history[..., :3, :3]), hand_points,
                       world_points)
    return actions, observation


if __name__ == "__main__":
    serve(encode_batch)
