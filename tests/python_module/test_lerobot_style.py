"""examples/lerobot_style/: a policy with LeRobot's interface (select_action(batch), reset(), its
own torch noise, an action queue) audited as it is through handcentric.lerobot_policy, in the
example's one call. Small counts: each test runs in a few seconds."""
import os
import sys

import numpy as np
import pytest

import handcentric

torch = pytest.importorskip("torch")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..",
                                "examples", "lerobot_style"))
from audit import audit  # noqa: E402
from policy import STATE, WRIST, HandCentricPolicy  # noqa: E402


def verdicts(report):
    return {(c.get("output"), c["group"], c["mode"]): c["equivariant"]
            for c in report["checks"]}


def test_the_hand_centric_policy_holds_under_se3_in_every_call_and_in_closed_loop():
    report = audit(HandCentricPolicy(), groups=("se3",), cases=8, episodes=3, episode_length=8)
    assert verdicts(report) == {
        ("hand", "se3", "pointwise"): True, ("hand", "se3", "distribution"): True,
        ("hand", "se3", "closed_loop"): True,
        ("gripper", "se3", "pointwise"): True, ("gripper", "se3", "distribution"): True,
        ("gripper", "se3", "closed_loop"): True}
    # rng="torch" gave the policy's own draws a seed: pointwise verdicts, not only the law.
    assert report["preflight"]["repeatable"]


def test_world_frame_motion_in_the_observation_queue_is_no_in_closed_loop_only():
    # After reset() the queue holds one observation copied, so the world-frame displacement is 0
    # in every single call: only a rollout, which moves the hand, sees it.
    # (Under translation it holds throughout: the README's run; one group keeps this test short.)
    report = audit(HandCentricPolicy(fault="world_velocity"), groups=("rotation",), cases=4,
                   episodes=3, episode_length=6)
    seen = verdicts(report)
    assert seen.pop(("hand", "rotation", "closed_loop")) is False
    # The gripper comes from the same network, which reads the displacement: NO too.
    assert seen.pop(("gripper", "rotation", "closed_loop")) is False
    assert seen == {("hand", "rotation", "pointwise"): True,
                    ("hand", "rotation", "distribution"): True,
                    ("gripper", "rotation", "pointwise"): True,
                    ("gripper", "rotation", "distribution"): True}
    failed = [c for c in report["checks"] if c["mode"] == "closed_loop" and not c["equivariant"]]
    assert "closed loop, episode" in failed[0]["witness"]["detail"]


def test_a_reset_that_keeps_the_action_queue_is_refused_not_judged():
    # The mutant of reset(): the observations cleared, the queued actions of the last episode
    # kept. Each call then depends on the calls before it, which the preflight sees.
    policy = HandCentricPolicy()
    policy.reset = policy._observations.clear
    with pytest.raises(handcentric.StatefulPolicyError):
        audit(policy, groups=("translation",), cases=4, episodes=2, episode_length=4)


def test_the_adapter_passes_the_state_image_and_action_as_lerobot_does():
    seen = {}

    class Recorder:
        def select_action(self, batch):
            seen.update(batch)
            rows = batch[STATE].shape[0]
            return torch.arange(8 * rows, dtype=torch.float32).reshape(rows, 8)

    call = handcentric.lerobot_policy(Recorder(), state=STATE, scalars=("gripper",),
                                      images={"eye_in_hand": WRIST},
                                      action={"hand": 7, "gripper": 1})
    history = np.zeros((2, 1, 7))
    history[:, 0, 3] = 1
    image = np.ones((2, 4, 6, 8), dtype=np.float32)
    out = call(history, np.zeros((2, 0, 3)), np.zeros((2, 0, 3)), np.zeros((2, 1)),
               scalars={"gripper": np.array([0.25, 0.5])}, images={"eye_in_hand": image})
    assert seen[STATE].shape == (2, 8) and seen[STATE].dtype == torch.float32
    assert seen[STATE][:, 7].tolist() == [0.25, 0.5] and seen[STATE][0, 3] == 1
    assert seen[WRIST].shape == (2, 4, 6, 8)
    assert out["hand"].shape == (2, 1, 7) and out["gripper"].shape == (2, 1, 1)
    assert out["gripper"][:, 0, 0].tolist() == [7, 15]
    # One observation per call (no batch_size): LeRobot's batch axis of one, added and removed.
    single = call(history[0], np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(1),
                  scalars={"gripper": 0.25}, images={"eye_in_hand": image[0]})
    assert single["hand"].shape == (1, 7)


def test_the_adapter_names_what_is_missing():
    with pytest.raises(TypeError, match="select_action"):
        handcentric.lerobot_policy(lambda history: history)
    call = handcentric.lerobot_policy(HandCentricPolicy(), action={"hand": 7, "gripper": 2})
    with pytest.raises(ValueError, match="camera 'eye_in_hand'"):
        handcentric.lerobot_policy(HandCentricPolicy(), images={"eye_in_hand": WRIST})(
            np.zeros((1, 7)), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(1))
    with pytest.raises(ValueError, match="history of shape"):
        call(np.zeros((1, 1, 4, 4)), None, None, None)
    with pytest.raises(ValueError, match="a history per hand"):
        call({"left": np.zeros((1, 7)), "right": np.zeros((1, 7))}, None, None, None)
    too_wide = handcentric.lerobot_policy(HandCentricPolicy(), scalars=("gripper",),
                                          images={"eye_in_hand": WRIST},
                                          action={"hand": 7, "gripper": 2})
    with pytest.raises(ValueError, match="8 numbers per action, action=.* adds up to 9"):
        too_wide(np.r_[0, 0, 0, 1, 0, 0, 0.0][None], np.zeros((0, 3)), np.zeros((0, 3)),
                 np.zeros(1), scalars={"gripper": 0.5},
                 images={"eye_in_hand": np.zeros((4, 24, 32), dtype=np.float32)})
