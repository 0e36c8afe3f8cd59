#!/usr/bin/env python3
"""UMI as its configurations train it: the observed poses in the frame of the hand now, their
rotation relative to the episode's start, and the actions converted with the observation's
representation.

Source   real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/dataset/umi_dataset.py:UmiDataset.__getitem__
         `obs_pose_mat = convert_pose_mat_rep(pose_mat, base_pose_mat=pose_mat[-1],
         pose_rep=self.obs_pose_repr, ...)` and `action_pose_mat = convert_pose_mat_rep(
         action_mat, base_pose_mat=pose_mat[-1], pose_rep=self.obs_pose_repr, ...)` (the actions
         too with obs_pose_repr); `robot0_eef_rot_axis_angle_wrt_start` = the rotation part of
         mat_to_pose10d(convert_pose_mat_rep(pose_mat, base_pose_mat=start_pose_mat,
         pose_rep='relative')); the conversion itself,
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/common/pose_repr_util.py:convert_pose_mat_rep
         ('relative': `np.linalg.inv(base_pose_mat) @ pose_mat`), and the decoding at evaluation,
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         umi/real_world/real_inference_util.py:get_real_umi_action
         (backward 'relative': `base_pose_mat @ pose_mat`).
Config   UMI diffusion_policy/config/task/umi.yaml (obs_pose_repr relative)
Formula  actions      a_k = [R_0^T (p_k - p_0), rows(R_0^T R_k)]             k = 1..K
         observation  for each history pose T_-h: [R_0^T (p_-h - p_0), rows(R_0^T R_-h),
                      rows(R_s^T R_-h)], T_s the episode's start pose (an extra pose that moves
                      with g); eye-in-hand points; world points in the hand frame
Assumed  task/umi.yaml's low-dim observation keys robot0_eef_pos, robot0_eef_rot_axis_angle and
         robot0_eef_rot_axis_angle_wrt_start; the start pose without the training-time noise
         UmiDataset adds to it (a HACK comment in the code); the gripper width (held fixed by g)
         left out; task/umi.yaml's low-dim horizon is 2, the audit draws 1 to 5 history poses.
Theory   invariant under all of SE(3) in both views: (g T_0)^-1 (g T) = T_0^-1 T, and
         (R~ R_s)^T (R~ R_-h) = R_s^T R_-h because the start pose moves with g.
Expect   actions: all; observation: all
"""
from _geometry import flat, hp, in_frame, rot6d_rows, serve


def encode_batch(history, chunk, hand_points, world_points, extra_poses, scalars):
    T0 = history[:, 0]
    actions = in_frame(T0, chunk)
    past = in_frame(T0, history)
    since_start = in_frame(extra_poses["start"], history)
    observation = flat(past[..., :3, 3], rot6d_rows(past[..., :3, :3]),
                       rot6d_rows(since_start[..., :3, :3]), hand_points,
                       hp.batch_relative_points(T0, world_points))
    return flat(actions[..., :3, 3], rot6d_rows(actions[..., :3, :3])), observation


if __name__ == "__main__":
    serve(encode_batch, extra_poses=("start",))
