"""Rotation conventions the plug-ins of this folder share (NumPy only, stacks of any shape).

The audit hands every plug-in world_T_hand matrices; each public codebase stores a pose its own
way (Euler angles, rotation vectors, 6D, quaternions) and differences it its own way. These are
the conversions, written once here so that each plug-in is its formula and nothing else.

euler_xyz      extrinsic x-y-z Euler angles (SciPy's "xyz", TF Graphics' from_euler):
               R = Rz(c) Ry(b) Rx(a), returns (a, b, c); b in [-pi/2, pi/2].
euler_matrix   the inverse: (a, b, c) -> Rz(c) Ry(b) Rx(a).
rotvec         rotation vector (axis * angle, angle in [0, pi]); the helper's rotation_vector.
rotvec_matrix  exp([r]x) for a stack of rotation vectors (Rodrigues).
rot6d_rows     the first two ROWS of R, flattened (PyTorch3D's matrix_to_rotation_6d, copied by
               UMI's mat_to_rot6d, robomimic, LeRobot and OpenVLA's rotmat_to_rot6d).
rot6d_columns  the first two COLUMNS of R (Zhou et al., "On the Continuity of Rotation
               Representations in Neural Networks", CVPR 2019, the definition of the paper).
quaternion_xyzw  unit quaternion (x, y, z, w) with w >= 0.
step_rotations, osc_world_step, pose_rotvec  the step rotations R_k R_{k-1}^T, robosuite's
               OSC_POSE world-frame delta command, and [p, r(R)] (a position and a rotation
               vector), which several rows share.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, os.pardir, "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402, F401  (the plug-ins import hp from here)


def euler_xyz(R):
    a = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    b = np.arctan2(-R[..., 2, 0], np.hypot(R[..., 2, 1], R[..., 2, 2]))
    c = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    return np.stack([a, b, c], axis=-1)


def euler_matrix(angles):
    a, b, c = angles[..., 0], angles[..., 1], angles[..., 2]
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    R = np.empty(angles.shape[:-1] + (3, 3))
    R[..., 0, 0] = cc * cb
    R[..., 0, 1] = cc * sb * sa - sc * ca
    R[..., 0, 2] = cc * sb * ca + sc * sa
    R[..., 1, 0] = sc * cb
    R[..., 1, 1] = sc * sb * sa + cc * ca
    R[..., 1, 2] = sc * sb * ca - cc * sa
    R[..., 2, 0] = -sb
    R[..., 2, 1] = cb * sa
    R[..., 2, 2] = cb * ca
    return R


def rotvec(R):
    return hp.rotation_vector(R)


def rotvec_matrix(r):
    angle = np.linalg.norm(r, axis=-1)[..., None, None]
    K = np.zeros(r.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2] = -r[..., 2], r[..., 1]
    K[..., 1, 0], K[..., 1, 2] = r[..., 2], -r[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -r[..., 1], r[..., 0]
    small = angle < 1e-4  # Taylor below: the next terms are under 1e-18
    safe = np.where(small, 1.0, angle)
    a = np.where(small, 1 - angle ** 2 / 6, np.sin(safe) / safe)
    b = np.where(small, 0.5 - angle ** 2 / 24, 2 * (np.sin(safe / 2) / safe) ** 2)
    return np.eye(3) + a * K + b * (K @ K)


def rot6d_rows(R):
    return R[..., :2, :].reshape(R.shape[:-2] + (6,))


def rot6d_columns(R):
    return np.swapaxes(R[..., :, :2], -1, -2).reshape(R.shape[:-2] + (6,))


def quaternion_xyzw(R):
    w = 0.5 * np.sqrt(np.maximum(0.0, 1 + R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]))
    x = 0.5 * np.sqrt(np.maximum(0.0, 1 + R[..., 0, 0] - R[..., 1, 1] - R[..., 2, 2]))
    y = 0.5 * np.sqrt(np.maximum(0.0, 1 - R[..., 0, 0] + R[..., 1, 1] - R[..., 2, 2]))
    z = 0.5 * np.sqrt(np.maximum(0.0, 1 - R[..., 0, 0] - R[..., 1, 1] + R[..., 2, 2]))
    x = np.copysign(x, R[..., 2, 1] - R[..., 1, 2])
    y = np.copysign(y, R[..., 0, 2] - R[..., 2, 0])
    z = np.copysign(z, R[..., 1, 0] - R[..., 0, 1])
    return np.stack([x, y, z, w], axis=-1)


def in_frame(T0, T):
    """T0^-1 T for batches: T0 (B,4,4), T (B,n,4,4) -> (B,n,4,4) (the helper's, exact digits)."""
    return hp.batch_relative_pose(T0, T)


def steps(history, chunk):
    """The consecutive pairs (T_{k-1}, T_k), k = 1..K, with T_0 = history[:, 0], the hand now:
    two (B,K,4,4) stacks."""
    poses = np.concatenate([history[:, :1], chunk], axis=1)
    return poses[:, :-1], poses[:, 1:]


def step_rotations(history, chunk):
    """R_k R_{k-1}^T, k = 1..K: each step's rotation in the world frame, (B,K,3,3)."""
    before, after = steps(history, chunk)
    return after[..., :3, :3] @ np.swapaxes(before[..., :3, :3], -1, -2)


def osc_world_step(history, chunk):
    """robosuite's OSC_POSE delta command, world frame, default output ranges: the position step
    / 0.05 and the rotation vector of R_k R_{k-1}^T / 0.5, two (B,K,3) stacks."""
    before, after = steps(history, chunk)
    return ((after[..., :3, 3] - before[..., :3, 3]) / 0.05,
            rotvec(step_rotations(history, chunk)) / 0.5)


def pose_rotvec(T):
    """[p, r(R)] of a stack of poses, (..., 6): a position and a rotation vector."""
    return np.concatenate([T[..., :3, 3], rotvec(T[..., :3, :3])], axis=-1)


def flat(*arrays):
    """Each (B, ...) array flattened to (B, -1) and joined: one action or observation row per
    scene."""
    B = arrays[0].shape[0]
    return np.concatenate([np.reshape(a, (B, -1)) for a in arrays], axis=1)


def serve(encode_batch, extra_poses=()):
    """Every plug-in of this folder answers batched requests, base64-encoded; extra_poses names
    the world-frame poses (a robot's base, an episode's start) that move with g, which
    encode_batch then gets as the keywords extra_poses={name: (B,4,4)} and scalars={}."""
    hp.serve(encode_batch, batched=True, batch_size=256, extra_poses=tuple(extra_poses))
