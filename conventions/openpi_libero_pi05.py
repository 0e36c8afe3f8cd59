#!/usr/bin/env python3
"""openpi's pi05 LIBERO pipeline as trained: LIBERO's step actions as the dataset holds them,
beside the state [position, axis-angle].

Source   Physical-Intelligence/openpi@15a9616a00943ada6c20a0f158e3adb39df2ccac:
         src/openpi/training/config.py:LeRobotLiberoDataConfig.create
         with extra_delta_transform False pushes no DeltaActions: the model regresses the
         dataset's actions, LIBERO's OSC_POSE commands
         (Lifelong-Robot-Learning/LIBERO@8f1084e3132a39270c3a13ebe37270a43ece2a01:
         libero/libero/envs/env_wrapper.py:ControlEnv.__init__, robosuite 1.4.0's defaults), and
         is given the state its LIBERO client builds,
         Physical-Intelligence/openpi@15a9616a00943ada6c20a0f158e3adb39df2ccac:
         examples/libero/main.py:eval_libero
Config   openpi src/openpi/training/config.py: pi05_libero (extra_delta_transform=False)
Formula  a_k = [(p_k - p_{k-1}) / 0.05, r(R_k R_{k-1}^T) / 0.5];  observation s = [p_0, r(R_0)]
Assumed  as in openpi_libero_pi0.py (the state's axis-angle with w >= 0, the grip site and the
         hand body taken as one frame, the normalizer and the gripper left out).
Theory   actions translation-invariant only (world-frame steps); the state is absolute.
Expect   actions: translation; observation: none
"""
from _geometry import flat, osc_world_step, pose_rotvec, serve


def encode_batch(history, chunk, hand_points, world_points):
    linear, angular = osc_world_step(history, chunk)
    state = pose_rotvec(history[:, 0])
    return flat(linear, angular), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
