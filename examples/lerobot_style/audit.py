"""Audit examples/lerobot_style/policy.py as it is: one call, no edit to the policy.

    PYTHONPATH=build/python /usr/bin/python3 examples/lerobot_style/audit.py
    ... audit.py --fault world_state      (NO under translation, in every single call)
    ... audit.py --fault world_velocity   (NO under rotation, in the closed loop only)

Prints one line per check and exits 0 (the verdicts are the output, not the exit status).
"""
import argparse
import os
import sys

import handcentric

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from policy import FAULTS, STATE, WRIST, HandCentricPolicy  # noqa: E402


def audit(policy, groups=("translation", "rotation", "se3"), cases=40, episodes=4,
          episode_length=12, seed=1):
    """The documented call: the policy's layouts, its gripper, its reset, its own noise, its
    queue in closed loop and its wrist camera, declared to the audit."""
    return handcentric.audit_policy(
        handcentric.lerobot_policy(policy, state=STATE, scalars=("gripper",),
                                   images={"eye_in_hand": WRIST},
                                   action={"hand": 7, "gripper": 1}),
        groups=groups, views=("eye_in_hand",), cases=cases, seed=seed, noise=1,
        state_format="pos_quat_wxyz", action_format="pos_quat_wxyz",
        scalars=["gripper"], outputs={"hand": "pose", "gripper": "invariant"},
        reset=policy.reset, rng="torch", episodes=episodes, episode_length=episode_length,
        cameras=("eye_in_hand",), image_size=(32, 24), history=0, hand_points=3,
        precision="float32", quiet=True)


def table(report):
    lines = ["%-8s %-12s %-12s %-12s %s" % ("output", "group", "view", "mode", "verdict")]
    for check in report["checks"]:
        verdict = {True: "yes", False: "NO"}.get(check["equivariant"], "-")
        lines.append("%-8s %-12s %-12s %-12s %s" % (check.get("output", ""), check["group"],
                                                     check["view"], check["mode"], verdict))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fault", choices=[f for f in FAULTS if f], default=None,
                        help="plant a symmetry breaking in the policy (policy.py, fault=)")
    args = parser.parse_args()
    report = audit(HandCentricPolicy(fault=args.fault))
    print(table(report))


if __name__ == "__main__":
    main()
