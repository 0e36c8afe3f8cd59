"""Closed-loop audits of stateful policies (episodes=, episode_length=, reset=): an action queue
that replans every few steps and temporal ensembling of world-frame poses hold under se3;
ensembling raw world-frame Euler angles is NO under rotation."""
import numpy as np
import pytest

import handcentric
from handcentric_plugin import formats
from policies import make_policy

K = 4  # make_policy's chunk length


class QueuePolicy:
    """LeRobot's action queue: a fresh hand-centric chunk when the queue is empty, then one
    queued pose per call (returned as a chunk of one)."""

    def __init__(self):
        self.inner = make_policy()
        self.reset()

    def reset(self):
        self.queue = []

    def __call__(self, history, hand_points, world_points, noise):
        if not self.queue:
            self.queue = list(self.inner(history, hand_points, world_points, noise))
        return self.queue.pop(0)[None]


class EnsemblingPolicy:
    """ACT's temporal ensembling: every step a new chunk; the pose executed now is the average of
    what every earlier chunk planned for now (positions averaged; rotations averaged as
    matrices and projected to SO(3); or, the fault, world-frame Euler angles averaged)."""

    def __init__(self, euler=False):
        self.inner, self.euler = make_policy(), euler
        self.reset()

    def reset(self):
        self.plans = []  # [chunk, age]

    def __call__(self, history, hand_points, world_points, noise):
        self.plans = [[c, a + 1] for c, a in self.plans if a + 1 < K]
        self.plans.append([self.inner(history, hand_points, world_points, noise), 0])
        now = np.stack([c[a] for c, a in self.plans])
        out = np.eye(4)
        out[:3, 3] = now[:, :3, 3].mean(axis=0)
        if self.euler:
            angles = formats.encode(now, "pos_euler_xyz")[:, 3:].mean(axis=0)
            out[:3, :3] = formats.decode(np.r_[0, 0, 0, angles], "pos_euler_xyz")[:3, :3]
        else:
            u, _, vt = np.linalg.svd(now[:, :3, :3].mean(axis=0))
            out[:3, :3] = u @ np.diag([1, 1, np.linalg.det(u @ vt)]) @ vt
        return out[None]


def closed_loop(report):
    return {(c["group"], c["view"]): c for c in report["checks"] if c["mode"] == "closed_loop"}


def test_an_action_queue_that_replans_every_4_steps_holds_in_the_closed_loop():
    policy = QueuePolicy()
    report = handcentric.audit_policy(policy, groups=["se3"], cases=30, episodes=8,
                                      episode_length=10, reset=policy.reset, quiet=True)
    loops = closed_loop(report)
    assert set(loops) == {("se3", "eye_in_hand"), ("se3", "third_person")}
    assert all(c["equivariant"] and c["cases"] >= 7 for c in loops.values())
    assert report["summary"]["eye_in_hand"]["closed_loop"]["se3"] is True


def test_temporal_ensembling_of_world_poses_holds_and_of_euler_angles_does_not():
    ensembling = EnsemblingPolicy()
    report = handcentric.audit_policy(ensembling, groups=["se3"], views=["eye_in_hand"], cases=30,
                                      episodes=8, episode_length=8, reset=ensembling.reset,
                                      quiet=True)
    assert closed_loop(report)[("se3", "eye_in_hand")]["equivariant"]
    euler = EnsemblingPolicy(euler=True)
    report = handcentric.audit_policy(euler, groups=["translation", "rotation"],
                                      views=["eye_in_hand"], cases=30, episodes=8,
                                      episode_length=8, reset=euler.reset, quiet=True)
    loops = closed_loop(report)
    assert loops[("translation", "eye_in_hand")]["equivariant"]
    failed = loops[("rotation", "eye_in_hand")]
    assert not failed["equivariant"] and "closed loop, episode" in failed["witness"]["detail"]
    # Each single call starts afresh (reset= before every call): one chunk, no ensembling, so the
    # single-call checks hold; only the closed loop sees the breaking.
    single = [c for c in report["checks"] if c["mode"] == "pointwise"]
    assert all(c["equivariant"] for c in single)


def test_a_stateful_policy_without_reset_is_refused_not_judged():
    with pytest.raises(handcentric.StatefulPolicyError):
        handcentric.audit_policy(QueuePolicy(), groups=["se3"], cases=10, episodes=4, quiet=True)


def test_episode_arguments_are_checked():
    policy = QueuePolicy()
    with pytest.raises(ValueError, match="episodes"):
        handcentric.audit_policy(policy, episodes=0, reset=policy.reset, quiet=True)
    with pytest.raises(ValueError, match="episode_length=5 without episodes="):
        handcentric.audit_policy(policy, episode_length=5, reset=policy.reset, quiet=True)
    with pytest.raises(ValueError, match="episode_length"):
        handcentric.audit_policy(policy, episodes=2, episode_length=0, reset=policy.reset,
                                 quiet=True)


class GripperFromWorldMotion:
    """The hand steps 5 cm along its own z (hand-centric); the gripper width is the x component
    of the hand's world displacement since the last call (0 after reset): a state kept in world
    coordinates that only an invariant output reads."""

    def reset(self):
        self.previous = None

    def __call__(self, history, hand_points, world_points, noise):
        world_T_hand = history[0]
        moved = np.zeros(3) if self.previous is None else world_T_hand[:3, 3] - self.previous
        self.previous = world_T_hand[:3, 3].copy()
        hand_T_target = np.eye(4)
        hand_T_target[:3, 3] = [0.0, 0.0, 0.05]
        return {"hand": (world_T_hand @ hand_T_target)[None], "gripper": np.array([moved[0]])}


def test_every_output_is_compared_in_the_closed_loop_and_blamed_by_name():
    # Every single call holds (the first call after reset reads no motion); the rollouts from o
    # and g o command different widths. The hand is executed and holds; the gripper is NO.
    # Planted fault (run by hand): a closed loop of the executed pose output alone gave the
    # gripper no closed-loop row and the report's closed-loop summary yes.
    policy = GripperFromWorldMotion()
    report = handcentric.audit_policy(policy, groups=["rotation"], views=["eye_in_hand"],
                                      cases=20, episodes=4, episode_length=4, reset=policy.reset,
                                      history=0, outputs={"hand": "pose", "gripper": "invariant"},
                                      quiet=True)
    loops = {c["output"]: c for c in report["checks"] if c["mode"] == "closed_loop"}
    assert loops["hand"]["equivariant"] is True
    assert loops["gripper"]["equivariant"] is False
    assert loops["gripper"]["note"] == "hand executed, gripper compared"
    # Step 1 reads no motion (fresh after reset): the widths part at step 2.
    assert "at step 2 of 4 the policy returns pose 1 of the chunk compared" in \
        loops["gripper"]["witness"]["detail"]
    assert report["summary"]["eye_in_hand"]["closed_loop"]["rotation"] is False
    gripper = report["outputs"]["gripper"]["summary"]["eye_in_hand"]
    assert gripper["closed_loop"]["rotation"] is False
    assert all(c["equivariant"] for c in report["checks"] if c["mode"] != "closed_loop")
