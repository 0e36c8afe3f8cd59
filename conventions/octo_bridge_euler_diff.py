#!/usr/bin/env python3
"""Octo's (and OpenVLA's) relabelled Bridge actions: the difference of consecutive proprio
states [position, Euler angles of the rotation relative to the robot's default rotation],
component by component.

Source   octo-models/octo@241fb3514b7c40957a86d869fecb7c7fc353f540:
         octo/data/utils/data_utils.py:relabel_actions
         `movement_actions = traj["observation"]["state"][1:, :6] -
         traj["observation"]["state"][:-1, :6]`, called by
         octo-models/octo@241fb3514b7c40957a86d869fecb7c7fc353f540:
         octo/data/oxe/oxe_standardization_transforms.py:bridge_dataset_transform
         (which also makes the state the proprio); the same line in
         openvla/openvla@c8f03f48af692657d3060c19588038c7220e9af9:
         prismatic/vla/datasets/rlds/utils/data_utils.py:relabel_bridge_actions
         The state Bridge records,
         rail-berkeley/bridge_data_robot@a902e5b96c518deddc4d756c26f32d033cef5718:
         widowx_envs/widowx_envs/base/robot_base_env.py:RobotBaseEnv.get_full_state
         `tr.transform2state(eep, ..., self._controller.default_rot)`;
         rail-berkeley/bridge_data_robot@a902e5b96c518deddc4d756c26f32d033cef5718:
         widowx_envs/widowx_envs/utils/transformation_utils.py:transform2state
         `euler = rotationMatrixToEulerAngles(rot.dot(default_rotation.transpose()), ...)`,
         (x, y, z) of R = Rz(z) Ry(y) Rx(x);
         rail-berkeley/bridge_data_robot@a902e5b96c518deddc4d756c26f32d033cef5718:
         widowx_envs/widowx_controller/src/widowx_controller/widowx_controller.py:
         WidowX_Controller.__init__
         `self.default_rot = np.dot(tr.eulerAnglesToRotationMatrix([0, 0, normal_base_angle]),
         DEFAULT_ROTATION)`, DEFAULT_ROTATION = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]].
Config   Octo's OXE registry bridge_dataset; OpenVLA's bridge_oxe, bridge_orig, bridge_dataset
Formula  D = DEFAULT_ROTATION (normal_base_angle 0);  s(T) = [p, euler_xyz(R D^T)];
         a_k = s(T_k) - s(T_{k-1});  observation s(T_0)
Assumed  workspace_rotation_angle_z = 0, RobotBaseEnv's default (normal_base_angle); the world
         frame is the robot's base frame, in which Bridge records its poses. D is a constant of
         the robot: it does not move with g.
Theory   translation-invariant only: Euler angles of R D^T are world-frame coordinates of R, and
         their difference is not a function of R_{k-1}^T R_k (it also jumps by 2 pi where an
         angle wraps). The state is absolute.
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import euler_xyz, flat, serve, steps

DEFAULT_ROTATION = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


def state(T):
    return np.concatenate([T[..., :3, 3], euler_xyz(T[..., :3, :3] @ DEFAULT_ROTATION.T)], axis=-1)


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    return flat(state(after) - state(before)), flat(state(history[:, 0]), hand_points,
                                                     world_points)


if __name__ == "__main__":
    serve(encode_batch)
