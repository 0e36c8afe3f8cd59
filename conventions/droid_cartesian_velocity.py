#!/usr/bin/env python3
"""DROID's cartesian_velocity: the world-frame pose difference to the next target, its rotation
as extrinsic xyz Euler angles of R_k R_{k-1}^T, divided by the controller's largest step.

Source   droid-dataset/droid@1548722f199772a43217c0d4c811c639be66e380:
         droid/franka/robot.py:FrankaRobot.create_action_dict
         `cartesian_delta = pose_diff(action[:-1], robot_state["cartesian_position"])`,
         `cartesian_velocity = self._ik_solver.cartesian_delta_to_velocity(cartesian_delta)`;
         droid-dataset/droid@1548722f199772a43217c0d4c811c639be66e380:
         droid/misc/transformations.py:pose_diff
         `lin_diff = np.array(target[:3]) - np.array(source[:3])`, and angle_diff:
         `(R.from_euler("xyz", target) * R.from_euler("xyz", source).inv()).as_euler("xyz")`;
         droid-dataset/droid@1548722f199772a43217c0d4c811c639be66e380:
         droid/robot_ik/robot_ik_solver.py:RobotIKSolver.cartesian_delta_to_velocity
         `/ self.max_lin_delta` (0.075) and `/ self.max_rot_delta` (0.15). OpenVLA trains on these
         numbers as they are,
         openvla/openvla@c8f03f48af692657d3060c19588038c7220e9af9:
         prismatic/vla/datasets/rlds/oxe/utils/droid_utils.py:droid_baseact_transform
         (`dt`, `dR` = action_dict cartesian_velocity[:, :3], [:, 3:6]; proprio =
         cartesian_position and gripper_position).
Config   DROID's recorded action_dict (every trajectory); OpenVLA's OXE registry droid
         (droid_baseact_transform) and droid_wipe (droid_finetuning_transform)
Formula  actions      a_k = [(p_k - p_{k-1}) / 0.075, euler_xyz(R_k R_{k-1}^T) / 0.15]
         observation  cartesian_position of the hand now, [p_0, euler_xyz(R_0)] (DROID's proprio)
Assumed  one target per step of the chunk, each differenced with the pose before it (DROID
         records one action per step, against the state of that step).
Theory   actions translation-invariant only; the observation is absolute.
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import euler_xyz, flat, serve, steps


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    linear = (after[..., :3, 3] - before[..., :3, 3]) / 0.075
    angular = euler_xyz(after[..., :3, :3] @ np.swapaxes(before[..., :3, :3], -1, -2)) / 0.15
    state = flat(history[:, 0, :3, 3], euler_xyz(history[:, 0, :3, :3]))
    return flat(linear, angular), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
