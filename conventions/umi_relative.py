#!/usr/bin/env python3
"""UMI, pose_rep 'relative': each pose in the frame of the hand now (hand-centric).

Source   real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/common/pose_repr_util.py:convert_pose_mat_rep
         (pose_rep 'relative'): `out = np.linalg.inv(base_pose_mat) @ pose_mat`; then pose10d
         (rows of R),
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         umi/common/pose_util.py:mat_to_pose10d
Config   UMI diffusion_policy/config/task/umi.yaml, task/umi_bimanual.yaml (both reprs relative;
         the pipeline as they train it: umi_trained.py)
Formula  actions      a_k = [R_0^T (p_k - p_0), rows(R_0^T R_k)]   (T_0^-1 T_k)
         observation  the same of each history pose; eye-in-hand points as they are; world points
                      in the hand frame, R_0^T (q - p_0)
Theory   invariant under every global rigid transform (SE(3), hence all five groups), in both
         views: (g T_0)^-1 (g T_k) = T_0^-1 T_k. This is the paper's hand-centric representation.
Expect   actions: all; observation: all
"""
from _geometry import flat, hp, in_frame, rot6d_rows, serve


def encode_batch(history, chunk, hand_points, world_points):
    T0 = history[:, 0]
    actions = in_frame(T0, chunk)
    past = in_frame(T0, history)
    observation = flat(past[..., :3, 3], rot6d_rows(past[..., :3, :3]), hand_points,
                       hp.batch_relative_points(T0, world_points))
    return flat(actions[..., :3, 3], rot6d_rows(actions[..., :3, :3])), observation


if __name__ == "__main__":
    serve(encode_batch)
