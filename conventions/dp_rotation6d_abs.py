#!/usr/bin/env python3
"""Diffusion Policy's absolute actions: robomimic's absolute end-effector targets with the
rotation turned by RotationTransformer from axis-angle to rotation_6d (the first two rows).

Source   real-stanford/diffusion_policy@5ba07ac6661db573af695b419a7947ecb704690f:
         diffusion_policy/dataset/robomimic_replay_image_dataset.py:_convert_actions
         (`if abs_action:` `rot = rotation_transformer.forward(rot)` on the actions [3:6], the
         same in robomimic_replay_lowdim_dataset.py), the transformer built as
         `RotationTransformer(from_rep='axis_angle', to_rep=rotation_rep)`, rotation_6d;
         real-stanford/diffusion_policy@5ba07ac6661db573af695b419a7947ecb704690f:
         diffusion_policy/model/common/rotation_transformer.py:RotationTransformer
         (axis_angle_to_matrix, then matrix_to_rotation_6d, both PyTorch3D's),
         facebookresearch/pytorch3d@9381c4016376345bb795b97c45a6c2de66db354a:
         pytorch3d/transforms/rotation_conversions.py:matrix_to_rotation_6d
         (`matrix[..., :2, :]`: rows); decoded at evaluation by
         real-stanford/diffusion_policy@5ba07ac6661db573af695b419a7947ecb704690f:
         diffusion_policy/env_runner/robomimic_image_runner.py:
         RobomimicImageRunner.undo_transform_action
         (`self.rotation_transformer.inverse(rot)`). The observation as robosuite gives it,
         ARISE-Initiative/robosuite@0d1977bc524cd052c6b839160b70734488b60d1c:
         robosuite/robots/single_arm.py:SingleArm.get_observations
Config   Diffusion Policy diffusion_policy/config/task/*_abs.yaml (abs_action True: lift, can,
         square, tool_hang, transport; lowdim and image)
Formula  actions      a_k = [p_k, rows(R_k)]   (robomimic's absolute target [p_k, r(R_k)], world)
         observation  robot0_eef_pos, robot0_eef_quat (x, y, z, w) of the hand now
Assumed  the quaternion with w >= 0 (robosuite does not normalize its sign; absolute either way);
         the normalizer (per dimension, affine) and the gripper left out.
Theory   nothing invariant: world-frame targets and an absolute observation.
Expect   actions: none; observation: none
"""
from _geometry import flat, quaternion_xyzw, rot6d_rows, serve


def encode_batch(history, chunk, hand_points, world_points):
    state = flat(history[:, 0, :3, 3], quaternion_xyzw(history[:, 0, :3, :3]))
    return (flat(chunk[..., :3, 3], rot6d_rows(chunk[..., :3, :3])),
            flat(state, hand_points, world_points))


if __name__ == "__main__":
    serve(encode_batch)
