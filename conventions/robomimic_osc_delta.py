#!/usr/bin/env python3
"""robomimic's delta actions for robosuite's OSC_POSE controller, input_ref_frame "world": a
world-frame position step and an axis-angle rotation applied on the left, each normalized by the
controller's output range.

Source   ARISE-Initiative/robosuite@1063bbdd3b871039c4250899b8c4fc6f2eedeede:
         robosuite/controllers/parts/arm/osc.py:OperationalSpaceController.compute_goal_pos
         ("world": `goal_pos = self.ref_pos + delta`) and
         ARISE-Initiative/robosuite@1063bbdd3b871039c4250899b8c4fc6f2eedeede:
         robosuite/controllers/parts/arm/osc.py:OperationalSpaceController.compute_goal_ori
         ("world": `goal_ori = np.dot(rotation_mat_error, curr_goal_ori)`,
         rotation_mat_error = quat2mat(axisangle2quat(delta))), the delta scaled from [-1, 1] to
         output_max (0.05, 0.05, 0.05, 0.5, 0.5, 0.5, the constructor's defaults); the
         observation,
         ARISE-Initiative/robosuite@0d1977bc524cd052c6b839160b70734488b60d1c:
         robosuite/robots/single_arm.py:SingleArm.get_observations
         (`eef_quat` = `T.convert_quat(self.sim.data.get_body_xquat(self.robot_model.eef_name),
         to="xyzw")`: MuJoCo's body quaternion, whose sign is not normalized). Without
         abs_action, Diffusion Policy passes these actions on as they are,
         real-stanford/diffusion_policy@5ba07ac6661db573af695b419a7947ecb704690f:
         diffusion_policy/dataset/robomimic_replay_image_dataset.py:_convert_actions
Config   robomimic's delta-action datasets (robosuite 1.4: world frame), as Diffusion Policy's
         task configs with abs_action False train on them; robosuite 1.5 with input_ref_frame world
Formula  actions      a_k = [(p_k - p_{k-1}) / 0.05, r(R_k R_{k-1}^T) / 0.5]  (r: rotation vector)
         observation  robomimic's low-dim proprio: robot0_eef_pos and robot0_eef_quat of the hand
                      now (x, y, z, w)
Assumed  the quaternion with w >= 0: robosuite passes MuJoCo's body quaternion on unnormalized,
         so its sign follows the kinematic chain, not R alone; either sign is absolute, so the
         verdict is the same. robosuite 1.4.0 itself was not read at its tag
         (conventions/README.md).
Theory   actions translation-invariant only; the observation is absolute.
Expect   actions: translation; observation: none
"""
from _geometry import flat, osc_world_step, quaternion_xyzw, serve


def encode_batch(history, chunk, hand_points, world_points):
    linear, angular = osc_world_step(history, chunk)
    state = flat(history[:, 0, :3, 3], quaternion_xyzw(history[:, 0, :3, :3]))
    return flat(linear, angular), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
