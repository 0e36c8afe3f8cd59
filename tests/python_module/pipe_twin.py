#!/usr/bin/env python3
"""The hand-centric representation of policies.py served over the --exec pipe, so that a test can
compare `handcentric audit --exec` with the in-process handcentric.audit on the same code.
Needs PYTHONPATH with the package and the helper (build/python holds both)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
import handcentric_plugin as hp  # noqa: E402
import policies  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    return (policies.hand_centric_actions(history, chunk, hand_points, world_points),
            policies.hand_centric_observation(history, hand_points, world_points))


if __name__ == "__main__":
    hp.serve(encode)
