#!/usr/bin/env python3
"""openpi's pi0 LIBERO pipeline as trained: LIBERO's step actions with DeltaActions applied on
top, each step minus the state [position, axis-angle].

Source   Physical-Intelligence/openpi@15a9616a00943ada6c20a0f158e3adb39df2ccac:
         src/openpi/training/config.py:LeRobotLiberoDataConfig.create
         ("LIBERO already represents actions as deltas, but we have some old Pi0 checkpoints that
         are trained with this extra delta transform": `if self.extra_delta_transform:` pushes
         `DeltaActions(make_bool_mask(6, -1))`),
         Physical-Intelligence/openpi@15a9616a00943ada6c20a0f158e3adb39df2ccac:
         src/openpi/transforms.py:DeltaActions
         and AbsoluteActions (state subtracted, added back at evaluation);
         Physical-Intelligence/openpi@15a9616a00943ada6c20a0f158e3adb39df2ccac:
         examples/libero/main.py:eval_libero
         (state = [robot0_eef_pos, _quat2axisangle(robot0_eef_quat), robot0_gripper_qpos]);
         the actions are LIBERO's OSC_POSE commands,
         Lifelong-Robot-Learning/LIBERO@8f1084e3132a39270c3a13ebe37270a43ece2a01:
         libero/libero/envs/env_wrapper.py:ControlEnv.__init__
         (`controller="OSC_POSE"`, robosuite 1.4.0's default configuration: world frame,
         output_max 0.05 m and 0.5 rad; the step as in robomimic_osc_delta.py).
Config   openpi src/openpi/training/config.py: pi0_libero, pi0_libero_low_mem_finetune,
         pi0_fast_libero, pi0_fast_libero_low_mem_finetune (extra_delta_transform=True)
Formula  s = [p_0, r(R_0)];  a_k = [(p_k - p_{k-1}) / 0.05, r(R_k R_{k-1}^T) / 0.5] - s;
         observation s
Assumed  the dataset's state as main.py builds it at evaluation; the axis-angle with w >= 0
         (robosuite's quaternion is not sign-normalized, and _quat2axisangle of -q gives the same
         rotation with an angle above pi: absolute either way); eef_pos is the grip site's and
         eef_quat the hand body's, a fixed offset taken as the identity (g does not see it); the
         normalizer (per-dimension statistics, affine) and the gripper dimensions (held fixed by
         g) left out.
Theory   nothing invariant: the step part is translation-invariant, but the subtracted state is
         absolute, so even a translation moves every action (by -t in its position part).
Expect   actions: none; observation: none
"""
import numpy as np
from _geometry import flat, osc_world_step, pose_rotvec, serve


def encode_batch(history, chunk, hand_points, world_points):
    state = pose_rotvec(history[:, :1])  # (B, 1, 6)
    linear, angular = osc_world_step(history, chunk)
    actions = np.concatenate([linear, angular], axis=-1) - state  # (B, K, 6)
    return flat(actions), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
