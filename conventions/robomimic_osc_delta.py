#!/usr/bin/env python3
"""robomimic's delta actions for robosuite's OSC_POSE controller: a world-frame position step and
an axis-angle rotation applied on the left, each normalized by the controller's output range.

Source   ARISE-Initiative/robosuite (v1.4), robosuite/utils/control_utils.py,
         set_goal_orientation: `quat_error = trans.axisangle2quat(delta)`,
         `rotation_mat_error = trans.quat2mat(quat_error)`,
         `goal_orientation = np.dot(rotation_mat_error, current_orientation)`, and
         set_goal_position:
         `goal_position = current_position + delta`; robomimic trains on these actions (its
         datasets store them in [-1, 1], scaled to output_max 0.05 m and 0.5 rad by the
         controller's default configuration).
Formula  actions      a_k = [(p_k - p_{k-1}) / 0.05, r(R_k R_{k-1}^T) / 0.5]  (r: rotation vector)
         observation  robomimic's low-dim proprio: robot0_eef_pos and robot0_eef_quat of the hand
                      now (quaternion x, y, z, w with w >= 0)
Assumed  the controller's default output_max (0.05, 0.5) and world (base) frame input; the read
         code's commit is not pinned (read from the index, robosuite v1.4 layout).
Theory   actions translation-invariant only; the observation is absolute.
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import flat, quaternion_xyzw, rotvec, serve, steps


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    linear = (after[..., :3, 3] - before[..., :3, 3]) / 0.05
    angular = rotvec(after[..., :3, :3] @ np.swapaxes(before[..., :3, :3], -1, -2)) / 0.5
    state = flat(history[:, 0, :3, 3], quaternion_xyzw(history[:, 0, :3, :3]))
    return flat(linear, angular), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
