"""Representations and policies with planted faults, on NumPy, for the module's tests.

Each fault is one line away from the correct code, as such bugs are in practice:
  world_noise  the policy adds its noise to the translations in the WORLD frame after decoding:
               the same noise moves differently under a rotation, so not equivariant pointwise
               under rotations; N(0, I) is rotation invariant, so equivariant in distribution.
  forgets_T0   decodes without T_0 (T_k = hand0_T_handk): equivariant under nothing.
  wrong_order  reads the history as oldest first, so it takes history[-1] (the OLDEST pose) for
               T_0. Every pose moves with g, so this stays equivariant (no symmetry audit can
               see it); the representation's decoder, which is given the real T_0, then misses
               the chunk, which the audit's round trip decode(encode(s)) = chunk finds.
"""
import numpy as np

import handcentric

K = 4


def inverse(T):
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out


def pose_vector(T):
    """[p, r(R)] (6,) of one pose."""
    return np.concatenate([T[:3, 3], handcentric.so3_log(T[:3, :3])])


def pose_matrix(v):
    T = np.eye(4)
    T[:3, :3] = handcentric.so3_exp(v[3:])
    T[:3, 3] = v[:3]
    return T


def make_policy(fault=None):
    """An outer hand-centric policy around a small fixed random network (Theorem 1's setting)."""
    rng = np.random.default_rng(7)
    W1 = rng.normal(size=(32, 6 + 3 + 8)) * 0.3
    W2 = rng.normal(size=(6 * K, 32)) * 0.1

    def policy(history, hand_points, world_points, noise):
        T0 = history[-1] if fault == "wrong_order" else history[0]
        feature = pose_vector(inverse(T0) @ history[1]) if len(history) > 1 else np.zeros(6)
        point = hand_points[0] if len(hand_points) else np.zeros(3)
        x = np.concatenate([feature, point, noise[:8]])
        actions = (W2 @ np.tanh(W1 @ x)).reshape(K, 6)
        hand0_T_handk = np.stack([pose_matrix(a) for a in actions])
        if fault == "forgets_T0":
            return hand0_T_handk
        chunk = T0 @ hand0_T_handk
        if fault == "world_noise":
            chunk[:, :3, 3] += 0.05 * noise[8:8 + 3 * K].reshape(K, 3)
        if fault == "world_spot" and np.linalg.norm(T0[:3, 3] - [1.0, 0.0, 0.0]) < 0.5:
            chunk[:, 0, 3] += 0.05  # pushed along world x where the hand is near one world point
        return chunk

    policy.__qualname__ = "policy_" + (fault or "hand_centric")
    return policy


def hand_centric_actions(history, chunk, hand_points, world_points):
    T0inv = inverse(history[0])
    return np.concatenate([pose_vector(T0inv @ T) for T in chunk])


def hand_centric_observation(history, hand_points, world_points):
    T0inv = inverse(history[0])
    world = (world_points - history[0][:3, 3]) @ history[0][:3, :3]  # T_0^-1 q
    return np.concatenate([pose_vector(T0inv @ T) for T in history]
                          + [hand_points.ravel(), world.ravel()])


def hand_centric_decode(actions, history, hand_points, world_points):
    return np.stack([history[0] @ pose_matrix(a) for a in actions.reshape(-1, 6)])


def wrong_order_actions(history, chunk, hand_points, world_points):
    T0inv = inverse(history[-1])  # the fault: the oldest pose taken for the hand now
    return np.concatenate([pose_vector(T0inv @ T) for T in chunk])


def absolute_actions(history, chunk, hand_points, world_points):
    return np.concatenate([pose_vector(T) for T in chunk])


def noise_recording_policy(seen, fault=None):
    """make_policy(fault) that adds noise[0] of every row it is asked with to the set `seen`."""
    base = make_policy(fault)

    def recording(history, hand_points, world_points, noise):
        seen.add(float(noise[0]))
        return base(history, hand_points, world_points, noise)
    return recording
