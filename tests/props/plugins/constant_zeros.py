#!/usr/bin/env python3
"""A degenerate map: 6K zeros for the actions, whatever the scene; no observation.

What the audit should find: "invariant" under every group (a constant cannot change), with no
decode: invariance alone does not make a representation useful. The chunk cannot be recovered
from zeros, so nothing here can drive an equivariant policy (Theorem 1 of "Guaranteed
SE(3)-Equivariant Control via Hand-Centric Behavior Cloning" needs decode(encode(s)) = chunk).
Its length, 6K, is that of a real pose-per-action map, so length checks do not tell it apart.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    return [0.0] * (6 * len(chunk))


if __name__ == "__main__":
    hp.serve(encode)
