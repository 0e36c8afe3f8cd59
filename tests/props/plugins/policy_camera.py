#!/usr/bin/env python3
"""A whole policy that sees a camera, for `handcentric audit --policy-exec`: a small fixed random
network on the image the audit renders (the hello's "cameras") and the hand-centric
proprioception, decoded in the hand frame (T_k = T_0 [I, p_k], eq. 1), served batched.

argv[1] is the camera the policy looks through:
  eye_in_hand   (default) the image does not change with g, so the policy is equivariant
  third_person  the planted fault: a camera fixed in the world, whose image moves with g
argv[2] "floor" adds the floor and the lamp (then eye_in_hand keeps se2 and c8 only).
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

CAMERA = sys.argv[1] if len(sys.argv) > 1 else "eye_in_hand"
FLOOR = "floor" in sys.argv[2:]
SIZE = (16, 12)
K = 2
RNG = np.random.default_rng(3)
W = RNG.normal(size=(3 * K, 4 * SIZE[0] * SIZE[1])) * 0.02


def policy(history, hand_points, world_points, noise, images):
    image = images[CAMERA]                                   # (B, 4, 12, 16) float32
    assert image.shape[1:] == (4, SIZE[1], SIZE[0]) and image.dtype == np.float32
    steps = np.tanh(image.reshape(len(image), -1).astype(np.float64) @ W.T)
    steps = steps.reshape(-1, K, 3) + 0.01 * noise[:, :1, None]
    local = np.tile(np.eye(4), (len(steps), K, 1, 1))
    local[:, :, :3, 3] = steps
    return history[:, :1] @ local                            # T_0 [I, p_k]


hp.serve_policy(policy, noise=1, batched=True, batch_size=64,
                cameras={"views": [CAMERA], "image_size": list(SIZE), "floor": FLOOR})
