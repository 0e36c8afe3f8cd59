#!/usr/bin/env python3
"""A hand-centric action representation written in Python, for `handcentric audit --exec`.

Reads one JSON request per line on stdin, answers one JSON line on stdout (docs/AUDIT.md):
  request : {"id": n, "history": [H+1 4x4 row-major matrices, [0] = T_0], "chunk": [K matrices],
             "hand_points": [[x, y, z], ...], "world_points": [[x, y, z], ...]}
  response: {"id": n, "actions": [...], "observation": [...]}

actions     : for k = 1..K, R_0^T (p_k - p_0) and r(R_0^T R_k)        (eqs. 1-2 of the paper)
observation : for h = 0..H, T_0^{-1} T_{-h} as (translation, rotation vector)   (eq. 3),
              then the eye-in-hand points as they are.
Standard library only. Run: handcentric audit --exec 'python3 examples/python_representation/repr.py'
"""
import json
import math
import sys


def rotation(m):
    """The 3x3 rotation block of a row-major 4x4 matrix (16 numbers)."""
    return [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]]


def translation(m):
    return [m[3], m[7], m[11]]


def transpose_times(a, b):
    """A^T B for 3x3 matrices."""
    return [[sum(a[k][i] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose_apply(a, v):
    """A^T v."""
    return [sum(a[k][i] * v[k] for k in range(3)) for i in range(3)]


def rotation_vector(r):
    """r(R) = angle * axis, angle in [0, pi]; accurate near 0 and near pi."""
    cos_angle = max(-1.0, min(1.0, 0.5 * (r[0][0] + r[1][1] + r[2][2] - 1.0)))
    w = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    sin_angle = 0.5 * math.sqrt(sum(x * x for x in w))
    angle = math.atan2(sin_angle, cos_angle)
    if angle < 1e-6:  # first order: r = vee(R - R^T) / 2
        return [0.5 * x for x in w]
    if angle < math.pi - 1e-6:
        return [angle / (2.0 * sin_angle) * x for x in w]
    # Near pi: the axis from the largest diagonal of (R + I) / 2 = axis axis^T (approximately).
    i = max(range(3), key=lambda j: r[j][j])
    column = [0.5 * (r[j][i] + r[i][j]) + (1.0 if j == i else 0.0) for j in range(3)]
    column[i] = 1.0 + r[i][i]
    norm = math.sqrt(sum(x * x for x in column))
    axis = [x / norm for x in column]
    if sum(a * b for a, b in zip(axis, w)) < 0.0:
        axis = [-x for x in axis]
    return [angle * x for x in axis]


def hand_centric(world_T_hand0, world_T_handk):
    """hand0_T_handk = T_0^{-1} T_k as (R_0^T (p_k - p_0), r(R_0^T R_k))   (eq. 2)."""
    r0 = rotation(world_T_hand0)
    dp = [a - b for a, b in zip(translation(world_T_handk), translation(world_T_hand0))]
    return transpose_apply(r0, dp) + rotation_vector(transpose_times(r0, rotation(world_T_handk)))


def answer(request):
    world_T_hand0 = request["history"][0]
    actions = [x for T in request["chunk"] for x in hand_centric(world_T_hand0, T)]
    observation = [x for T in request["history"] for x in hand_centric(world_T_hand0, T)]
    observation += [x for point in request["hand_points"] for x in point]
    return {"id": request["id"], "actions": actions, "observation": observation}


def main():
    for line in sys.stdin:
        if line.strip():
            sys.stdout.write(json.dumps(answer(json.loads(line))) + "\n")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
