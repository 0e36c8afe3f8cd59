#!/usr/bin/env python3
"""openpi's DeltaActions (and LeRobot's to_relative_actions, which mirrors it) on absolute
end-effector actions [position, axis-angle]: every masked action dimension minus the same state
dimension.

Source   Physical-Intelligence/openpi@15a9616a00943ada6c20a0f158e3adb39df2ccac:
         src/openpi/transforms.py:DeltaActions
         `actions[..., :dims] -= np.expand_dims(np.where(mask, state[..., :dims], 0), axis=-2)`
         (inverted at evaluation by AbsoluteActions, `+=`);
         huggingface/lerobot@7427f31801f944f5ec9ce53cda02862ce7d1638b:
         src/lerobot/processor/relative_action_processor.py:to_relative_actions
         `actions[..., :dims] -= state_offset` ("Mirrors OpenPI's DeltaActions").
Config   no shipped config on pose actions (openpi's pose-space configs are LIBERO's, whose actions
         are already steps: openpi_libero_pi0.py); LeRobot's use_relative_actions (default False)
Formula  s = [p_0, r(R_0)], a_k = [p_k, r(R_k)] - s, r the rotation vector; observation s.
Assumed  absolute pose actions and a mask over the six pose dimensions. openpi's configurations
         mask joint angles (aloha, droid) or apply it to LIBERO's step actions; LeRobot's
         use_relative_actions (the pi0, pi05, pi0_fast, groot and vla_jepa policy
         configurations) masks whatever the dataset's actions are. The transform is
         component-wise whatever the numbers mean.
Theory   actions translation-invariant only: the rotation part r(R_k) - r(R_0) is a difference of
         world-frame rotation vectors; the state is absolute (nothing invariant).
Expect   actions: translation; observation: none
"""
from _geometry import flat, pose_rotvec, serve


def encode_batch(history, chunk, hand_points, world_points):
    state = pose_rotvec(history[:, :1])  # (B, 1, 6)
    actions = pose_rotvec(chunk) - state
    return flat(actions), flat(state, hand_points, world_points)


if __name__ == "__main__":
    serve(encode_batch)
