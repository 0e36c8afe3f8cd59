#!/usr/bin/env python3
"""robosuite's float32 quaternion round trip on an OSC step: the step rotation turned into a
float32 quaternion (mat2quat) and back into a rotation vector (quat2axisangle), which returns
zero once w rounds to 1 in float32.

Source   huggingface/lerobot@7427f31801f944f5ec9ce53cda02862ce7d1638b:
         src/lerobot/policies/xvla/utils.py:mat2quat
         (robosuite's mat2quat as LeRobot ships it: `mat = np.asarray(rmat).astype(np.float32)`,
         K of float32 entries, `np.linalg.eigh(k)`, the sign made w >= 0) and
         huggingface/lerobot@7427f31801f944f5ec9ce53cda02862ce7d1638b:
         src/lerobot/policies/xvla/utils.py:quat2axisangle
         (`if quat[3] > 1.0: quat[3] = 1.0`, `den = np.sqrt(1.0 - quat[3] * quat[3])`,
         `if math.isclose(den, 0.0): return np.zeros(3)`); robosuite composes the two in
         ARISE-Initiative/robosuite@1063bbdd3b871039c4250899b8c4fc6f2eedeede:
         robosuite/controllers/parts/arm/osc.py:OperationalSpaceController.delta_to_abs_action
         (`abs_rot = T.quat2axisangle(T.mat2quat(abs_ori))`). The observation as robosuite gives
         it, ARISE-Initiative/robosuite@0d1977bc524cd052c6b839160b70734488b60d1c:
         robosuite/robots/single_arm.py:SingleArm.get_observations
Config   no shipped config on steps (robosuite's delta_to_abs_action and LeRobot's X-VLA LIBERO
         postprocessor, make_xvla_libero_pre_post_processors, apply it to absolute orientations)
Formula  q = float32 (x, y, z, w) of R_k R_{k-1}^T, w >= 0;  w' = min(w, 1);
         d = sqrt(1 - w'^2) in float32;  v = 0 if d = 0, else (x, y, z) 2 acos(w') / d;
         actions      a_k = [(p_k - p_{k-1}) / 0.05, v / 0.5]
         observation  robot0_eef_pos and robot0_eef_quat (x, y, z, w) of the hand now
Assumed  the quaternion rounded to float32 from its exact value (robosuite's float32 eigh lands
         within a few units of the last place of it); robosuite's own mat2quat was read in
         LeRobot's copy, not at a pinned robosuite commit (conventions/README.md).
Theory   actions translation-invariant only (world-frame steps), and not injective: w = cos(t/2)
         rounds to 1 in float32 for t below sqrt(8 * 2^-25) ~ 4.9e-4 rad, so every step rotation
         smaller than that encodes to zero. The observation is absolute.
Expect   actions: translation; observation: none
"""
import numpy as np
from _geometry import flat, quaternion_xyzw, serve, step_rotations, steps


def rotation_vector_float32(R):
    """The float32 round trip of the Formula line, for a stack of rotations: (..., 3)."""
    q = quaternion_xyzw(R).astype(np.float32)
    w = np.minimum(q[..., 3], np.float32(1.0))
    den = np.sqrt(np.float32(1.0) - w * w)
    scale = np.where(den == 0, 0.0, 2.0 * np.arccos(w.astype(np.float64)) /
                     np.where(den == 0, np.float32(1.0), den).astype(np.float64))
    return (q[..., :3] * scale[..., None]).astype(np.float32).astype(np.float64)


def encode_batch(history, chunk, hand_points, world_points):
    before, after = steps(history, chunk)
    linear = (after[..., :3, 3] - before[..., :3, 3]) / 0.05
    angular = rotation_vector_float32(step_rotations(history, chunk)) / 0.5
    state = flat(history[:, 0, :3, 3], quaternion_xyzw(history[:, 0, :3, :3]))
    return flat(linear, angular), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
