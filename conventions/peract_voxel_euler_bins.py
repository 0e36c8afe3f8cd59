#!/usr/bin/env python3
"""PerAct's discretized actions: the gripper's position as the index of its voxel in a 100^3 grid
over the scene bounds, its rotation as extrinsic xyz Euler angles in 5 degree bins, both in the
world frame.

Source   peract/peract@02fb87681c5a47be9dbf20141bedb836ee2d3ef9:
         helpers/utils.py:point_to_voxel_index
         `voxel_indicy = np.minimum(np.floor((point - bb_mins) / (res + 1e-12)).astype(
         np.int32), dims_m_one)`, res = (bb_maxs - bb_mins) / (voxel_size + 1e-12);
         peract/peract@02fb87681c5a47be9dbf20141bedb836ee2d3ef9:
         helpers/utils.py:quaternion_to_discrete_euler
         `euler = Rotation.from_quat(quaternion).as_euler('xyz', degrees=True) + 180`,
         `disc = np.around((euler / resolution)).astype(int)`,
         `disc[disc == int(360 / resolution)] = 0`. Scene bounds [-0.3, -0.5, 0.6, 0.7, 0.5,
         1.6] (conf/config.yaml), voxel_sizes [100] and rotation_resolution 5
         (conf/method/PERACT_BC.yaml).
Config   PerAct conf/method/PERACT_BC.yaml (method=PERACT_BC; conf/config.yaml defaults to C2FARM)
Formula  a_k = [voxel(p_k), bins(R_k)] for each pose of the chunk (PerAct predicts one next key
         pose; applied here to each); observation: the same of the hand now.
Assumed  positions outside the bounds keep
         PerAct's behaviour (clamped above, not below: negative indices).
Theory   nothing invariant (world-frame indices), and not injective: chunks that differ by less
         than a voxel (1 cm) or a bin (5 degrees) give the same action.
Expect   actions: none; observation: none
"""
import numpy as np
from _geometry import euler_xyz, flat, serve

BOUNDS = np.array([-0.3, -0.5, 0.6, 0.7, 0.5, 1.6])
VOXELS = 100
DEGREES = 5


def voxel(p):
    res = (BOUNDS[3:] - BOUNDS[:3]) / (VOXELS + 1e-12)
    return np.minimum(np.floor((p - BOUNDS[:3]) / (res + 1e-12)), VOXELS - 1)


def bins(R):
    euler = np.degrees(euler_xyz(R)) + 180
    disc = np.around(euler / DEGREES)
    return np.where(disc == 360 // DEGREES, 0, disc)


def encode_batch(history, chunk, hand_points, world_points):
    actions = flat(voxel(chunk[..., :3, 3]), bins(chunk[..., :3, :3]))
    now = history[:, 0]
    return actions, flat(voxel(now[:, :3, 3]), bins(now[:, :3, :3]), hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
