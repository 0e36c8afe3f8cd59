#!/usr/bin/env python3
"""EquiBot's state with gravity, read in the hand's frame: the end-effector position and two axis
directions of its history, and the gravity direction, which a global transform of the scene
does not move.

Source   yjy0625/equibot@dc70059191beb29903d78fc4d0193392be5134fc:
         equibot/policies/agents/equibot_policy.py:EquiBotPolicy._convert_state_to_vec
         "state format for 7d actions: eef_pos, eef_rot_x, eef_rot_z, gravity_dir,
         gripper_pose", `vec_state_dir = torch.cat([dir1, dir2, gravity_dir], dim=2)`;
         yjy0625/equibot@dc70059191beb29903d78fc4d0193392be5134fc:
         equibot/policies/agents/equibot_policy.py:EquiBotPolicy._convert_action_to_vec
         "rotation actions are always treated as relative axis-angle rotation", the position
         and axis-angle steps handed to the network as 3-vectors.
Config   EquiBot equibot/policies/configs/base.yaml (dof 7, ac_mode rel) with agent equibot
         (*_mobile_equibot.yaml)
Formula  (this project's reading) EquiBot's SIM(3)-equivariant network sees these vectors; what
         it can be invariant to is what they are invariant to in the hand's frame at T_0:
         actions      a_k = [R_0^T (p_k - p_{k-1}), R_0^T r(R_k R_{k-1}^T)]
         observation  [R_0^T (p_-h - p_0), R_0^T x_-h, R_0^T z_-h] for each history pose,
                      R_0^T gravity with gravity = (0, 0, -1) fixed in the world,
                      eye-in-hand points, world points in the hand frame
Assumed  the hand-frame reading (EquiBot itself centres and scales by the point cloud and keeps
         rotations equivariant in the network, not in the representation).
Theory   actions invariant under all of SE(3) (r(R~ M R~^T) = R~ r(M)); the observation, through
         gravity, only under the groups that keep the vertical: translation, se2 and c8, not
         rotation or se3.
Expect   actions: all; observation: translation, se2, c8
"""
import numpy as np
from _geometry import flat, hp, in_frame, rotvec, serve, steps

GRAVITY = np.array([0.0, 0.0, -1.0])


def encode_batch(history, chunk, hand_points, world_points):
    T0 = history[:, 0]
    R0_T = np.swapaxes(T0[:, :3, :3], -1, -2)
    before, after = steps(history, chunk)
    step = (R0_T[:, None] @ (after[..., :3, 3] - before[..., :3, 3])[..., None])[..., 0]
    turn = rotvec(after[..., :3, :3] @ np.swapaxes(before[..., :3, :3], -1, -2))
    turn = (R0_T[:, None] @ turn[..., None])[..., 0]
    past = in_frame(T0, history)
    gravity = R0_T @ GRAVITY
    observation = flat(past[..., :3, 3], past[..., :3, 0], past[..., :3, 2], gravity, hand_points,
                       hp.batch_relative_points(T0, world_points))
    return flat(step, turn), observation


if __name__ == "__main__":
    serve(encode_batch)
