#!/usr/bin/env python3
"""robosuite's OSC_POSE delta commands with input_ref_frame "base": the position step and the
rotation step written in the frame of the robot's base, each normalized by the controller's
output range; the base is a pose of the scene, moved by g with the hand.

Source   ARISE-Initiative/robosuite@1063bbdd3b871039c4250899b8c4fc6f2eedeede:
         robosuite/controllers/parts/arm/osc.py:OperationalSpaceController.compute_goal_pos
         ("base", achieved: `goal_pos = self.world_to_origin_frame(self.ref_pos) + delta`,
         reached in the world as `self.origin_pos + np.dot(self.origin_ori, self.goal_pos)` in
         run_controller); ARISE-Initiative/robosuite@1063bbdd3b871039c4250899b8c4fc6f2eedeede:
         robosuite/controllers/parts/arm/osc.py:OperationalSpaceController.compute_goal_ori
         ("base": `goal_ori = np.dot(rotation_mat_error, curr_goal_ori)` with curr_goal_ori =
         `self.goal_origin_to_eef_pose()[:3, :3]`, reached as `np.dot(self.origin_ori,
         self.goal_ori)`); the delta scaled from [-1, 1] to output_max (0.05 m, 0.5 rad), the
         constructor's defaults, whose input_ref_frame default is "base". The observation,
         ARISE-Initiative/robosuite@0d1977bc524cd052c6b839160b70734488b60d1c:
         robosuite/robots/single_arm.py:SingleArm.get_observations
         (eef_pos and eef_quat in the world frame).
Config   robosuite 1.5 OSC_POSE with input_ref_frame base (the constructor's default)
Formula  B the base pose (extra pose "base"), R_B its rotation:
         actions      a_k = [R_B^T (p_k - p_{k-1}) / 0.05, r(R_B^T R_k R_{k-1}^T R_B) / 0.5]
         observation  robot0_eef_pos and robot0_eef_quat (x, y, z, w) of the hand now
Assumed  the quaternion with w >= 0 (robosuite does not normalize its sign); the base fixed over
         the chunk (a mobile base moves it: then each step has its own R_B).
Theory   actions invariant under all of SE(3) when the base moves with g: (R~ R_B)^T R~ = R_B^T,
         and r(R_B^T R_k R_{k-1}^T R_B) = R_B^T r(R_k R_{k-1}^T). The observation stays in the
         world frame: nothing invariant. (With input_ref_frame "world": robomimic_osc_delta.py,
         translation only.)
Expect   actions: all; observation: none
"""
import numpy as np
from _geometry import flat, quaternion_xyzw, rotvec, serve, step_rotations, steps


def encode_batch(history, chunk, hand_points, world_points, extra_poses, scalars):
    RB = extra_poses["base"][:, None, :3, :3]  # (B, 1, 3, 3)
    RB_t = np.swapaxes(RB, -1, -2)
    before, after = steps(history, chunk)
    linear = (RB_t @ (after[..., :3, 3] - before[..., :3, 3])[..., None])[..., 0] / 0.05
    angular = rotvec(RB_t @ step_rotations(history, chunk) @ RB) / 0.5
    state = flat(history[:, 0, :3, 3], quaternion_xyzw(history[:, 0, :3, :3]))
    return flat(linear, angular), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch, extra_poses=("base",))
