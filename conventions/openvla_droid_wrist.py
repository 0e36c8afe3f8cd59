#!/usr/bin/env python3
"""OpenVLA's DROID actions in the wrist frame: DROID's cartesian_velocity rotated into the frame
of the hand at that step, its rotation turned back into a matrix and written as 6D rows.

Source   openvla/openvla@c8f03f48af692657d3060c19588038c7220e9af9:
         prismatic/vla/datasets/rlds/oxe/utils/droid_utils.py:velocity_act_to_wrist_frame
         `vel_t = (R_frame_inv @ velocity[:, :3][..., None])[..., 0]`,
         `dR = euler_to_rmat(velocity[:, 3:6])`, `dR = R_frame_inv @ (dR @ R_frame)`,
         `dR_r6 = rotmat_to_rot6d(dR)` (first two rows), R_frame =
         euler_to_rmat(wrist_in_robot_frame[:, 3:6]); its only caller is
         openvla/openvla@c8f03f48af692657d3060c19588038c7220e9af9:
         prismatic/vla/datasets/rlds/oxe/utils/droid_utils.py:droid_wristact_transform
         (velocity = action_dict cartesian_velocity, wrist_in_robot_frame = cartesian_position;
         droid_cartesian_velocity.py in this folder).
Config   no shipped config (its caller droid_wristact_transform is in no entry of
         OXE_STANDARDIZATION_TRANSFORMS)
Formula  v_k = [(p_k - p_{k-1}) / 0.075, euler_xyz(R_k R_{k-1}^T) / 0.15]
         a_k = [R_{k-1}^T v_k[:3], rows(R_{k-1}^T euler_matrix(v_k[3:]) R_{k-1})]
         observation: DROID's proprio, [p_0, euler_xyz(R_0)]
Theory   If v_k[3:] were the Euler angles of R_k R_{k-1}^T, the rotation would be
         R_{k-1}^T R_k R_{k-1}^T R_{k-1} = R_{k-1}^T R_k, and the action SE(3)-invariant (a body-
         frame step). But the angles were divided by 0.15 before euler_to_rmat reads them, and
         scaling Euler angles does not commute with conjugation, so the conjugation by R_{k-1}
         no longer cancels a global rotation: translation-invariant only.
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import euler_matrix, euler_xyz, flat, rot6d_rows, serve, steps


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    R_frame = before[..., :3, :3]
    R_frame_inv = np.swapaxes(R_frame, -1, -2)
    linear = (after[..., :3, 3] - before[..., :3, 3]) / 0.075
    angular = euler_xyz(after[..., :3, :3] @ R_frame_inv) / 0.15
    vel_t = (R_frame_inv @ linear[..., None])[..., 0]
    dR = R_frame_inv @ (euler_matrix(angular) @ R_frame)
    state = flat(history[:, 0, :3, 3], euler_xyz(history[:, 0, :3, :3]))
    return flat(vel_t, rot6d_rows(dR)), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
