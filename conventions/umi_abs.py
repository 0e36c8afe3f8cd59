#!/usr/bin/env python3
"""UMI, pose_rep 'abs': world-frame poses, as they are.

Source   real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/common/pose_repr_util.py:convert_pose_mat_rep
         (pose_rep 'abs', the training branch: `return pose_mat`); the policy then sees pose10d,
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         umi/common/pose_util.py:mat_to_pose10d
         (position and mat_to_rot6d, `mat[..., :2, :]`: the first two rows of R);
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/dataset/umi_dataset.py:UmiDataset.__getitem__
         converts the observed poses and the actions, both with `pose_rep=self.obs_pose_repr`.
Config   UMI diffusion_policy/config/legacy/task/umi.yaml (obs_pose_repr and action_pose_repr
         abs)
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
