#!/usr/bin/env python3
"""The hand-centric chunk with its rotation as the first two COLUMNS of R_0^T R_k (the 6D
representation as Zhou et al. define it), beside UMI's and LeRobot's first two ROWS.

Source   Zhou, Barnes, Lu, Yang, Li, "On the Continuity of Rotation Representations in Neural
         Networks", CVPR 2019, Sec. 4: the 6D representation is the first two columns of the
         matrix. The codebases read here take rows instead:
         facebookresearch/pytorch3d@9381c4016376345bb795b97c45a6c2de66db354a:
         pytorch3d/transforms/rotation_conversions.py:matrix_to_rotation_6d
         (`matrix[..., :2, :]`, whose docstring cites Zhou et al.), copied by
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         umi/common/pose_util.py:mat_to_rot6d
         and by LeRobot's matrix_to_rotation_6d and OpenVLA's rotmat_to_rot6d. LeRobot's X-VLA
         takes columns, of absolute rotations:
         huggingface/lerobot@7427f31801f944f5ec9ce53cda02862ce7d1638b:
         src/lerobot/policies/xvla/processor_xvla.py:LiberoProcessorStep._mat_to_rotate6d
         (`col1 = rot_mats[:, :3, 0]`); no codebase read takes columns of a hand-centric rotation.
Config   no shipped config (the paper's definition, on the hand-centric chunk)
Formula  actions      a_k = [R_0^T (p_k - p_0), columns(R_0^T R_k)]
         observation  the same of each history pose; world points in the hand frame
Theory   rows or columns, both encode the invariant matrix T_0^-1 T_k: invariant under all of
         SE(3). The choice changes what the network regresses, not the symmetry (compare with
         umi_relative.py, rows).
Expect   actions: all; observation: all
"""
from _geometry import flat, hp, in_frame, rot6d_columns, serve


def encode_batch(history, chunk, hand_points, world_points):
    T0 = history[:, 0]
    actions = in_frame(T0, chunk)
    past = in_frame(T0, history)
    observation = flat(past[..., :3, 3], rot6d_columns(past[..., :3, :3]), hand_points,
                       hp.batch_relative_points(T0, world_points))
    return flat(actions[..., :3, 3], rot6d_columns(actions[..., :3, :3])), observation


if __name__ == "__main__":
    serve(encode_batch)
