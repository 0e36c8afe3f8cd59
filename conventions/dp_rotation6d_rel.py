#!/usr/bin/env python3
"""The 'rel' actions of the robomimic tasks in UMI's copy of Diffusion Policy: robomimic's
absolute targets and the observed poses relative to the hand now, world-frame differences, the
rotations turned to rotation_6d by RotationTransformer, the current rotation read from
robosuite's quaternion in the wrong component order.

Source   real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/dataset/robomimic_replay_dataset.py:RobomimicReplayDataset.__getitem__
         `current_rot_mat = copy.copy(self.rot_quat2mat.forward(obs_dict['robot0_eef_quat'][-1]))`
         with `self.rot_quat2mat = RotationTransformer(from_rep='quaternion', to_rep='matrix')`;
         observations and actions through compute_relative_pose with base_pos=current_pos and
         base_rot_mat=current_rot_mat when the pose_repr is 'rel';
         real-stanford/universal_manipulation_interface@d095ba9590df789df5189eea5ee7e431689038a6:
         diffusion_policy/common/pose_repr_util.py:compute_relative_pose
         `output_pos = pos if base_pos is None else pos - base_pos`,
         `rot_transformer_to_target.forward(rot_transformer_to_mat.forward(rot) @
         np.linalg.inv(base_rot_mat))`;
         facebookresearch/pytorch3d@9381c4016376345bb795b97c45a6c2de66db354a:
         pytorch3d/transforms/rotation_conversions.py:quaternion_to_matrix
         ("quaternions with real part first"), and matrix_to_rotation_6d (rows). robosuite's
         quaternion is (x, y, z, w):
         ARISE-Initiative/robosuite@0d1977bc524cd052c6b839160b70734488b60d1c:
         robosuite/robots/single_arm.py:SingleArm.get_observations
         (`T.convert_quat(..., to="xyzw")`).
Config   UMI diffusion_policy/config/task/tool_hang_abs.yaml, task/lift.yaml and
         legacy/task/{lift,square,tool_hang}_abs.yaml (obs and action pose_repr rel)
Formula  M(R) = the rotation of the quaternion (x, y, z, w) of R read as (w, x, y, z), i.e. of
         (w', x', y', z') = (x, y, z, w); M_0 = M(R_0)
         actions      a_k = [p_k - p_0, rows(R_k M_0^T)]   (R_k from robomimic's axis-angle)
         observation  for each history pose: [p_-h - p_0, rows(M(R_-h) M_0^T)]
Assumed  robomimic's datasets keep robosuite's (x, y, z, w) order (the dataset reorders nothing);
         M does not depend on the quaternion's sign. task/lift.yaml also feeds the world height
         robot0_eef_pos_abs and the raw robot0_eef_quat_abs (not modelled: its observation is
         then not translation-invariant).
Theory   translation-invariant only: the differences are world-frame, and M_0 is not R_0 (nor a
         function that commutes with a global rotation).
Expect   actions: translation; observation: translation
"""
import numpy as np
from _geometry import flat, quaternion_xyzw, rot6d_rows, serve


def misread_matrix(R):
    """The rotation PyTorch3D's quaternion_to_matrix gives for robosuite's (x, y, z, w) of R,
    read as (w, x, y, z): the standard formula on (r, i, j, k) = (x, y, z, w)."""
    r, i, j, k = np.moveaxis(quaternion_xyzw(R), -1, 0)
    M = np.empty(R.shape)
    M[..., 0, 0] = 1 - 2 * (j * j + k * k)
    M[..., 0, 1] = 2 * (i * j - k * r)
    M[..., 0, 2] = 2 * (i * k + j * r)
    M[..., 1, 0] = 2 * (i * j + k * r)
    M[..., 1, 1] = 1 - 2 * (i * i + k * k)
    M[..., 1, 2] = 2 * (j * k - i * r)
    M[..., 2, 0] = 2 * (i * k - j * r)
    M[..., 2, 1] = 2 * (j * k + i * r)
    M[..., 2, 2] = 1 - 2 * (i * i + j * j)
    return M


def encode_batch(history, chunk, hand_points, world_points):
    p0 = history[:, None, 0, :3, 3]
    M0_t = np.swapaxes(misread_matrix(history[:, :1, :3, :3]), -1, -2)  # (B, 1, 3, 3)
    actions = flat(chunk[..., :3, 3] - p0, rot6d_rows(chunk[..., :3, :3] @ M0_t))
    observation = flat(history[..., :3, 3] - p0,
                       rot6d_rows(misread_matrix(history[..., :3, :3]) @ M0_t),
                       hand_points, world_points)
    return actions, observation


if __name__ == "__main__":
    serve(encode_batch)
