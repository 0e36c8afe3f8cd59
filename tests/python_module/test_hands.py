"""Two hands (hands=("left", "right")): history is a dict of histories, the policy returns a
chunk per hand, each audited (verdicts per hand). A bimanual policy that reads the right hand in
the left hand's frame (UMI's robot1_eef_pos_wrt0) is equivariant; reading the right hand's world
position is NO under translation, on the right hand's output."""
import numpy as np
import pytest

import handcentric
from policies import make_policy

HANDS = ("left", "right")


def bimanual(fault=None):
    inner = make_policy()

    def policy(history, hand_points, world_points, noise):
        left, right = history["left"], history["right"]
        left_chunk = inner(left, hand_points, world_points, noise)
        # The right hand in the left hand's frame now: invariant under any g.
        right_in_left = np.linalg.inv(left[0]) @ right[0]
        # The right hand moves as the left does, from where it is, nudged by where it sits
        # relative to the left hand.
        step = np.eye(4)
        step[:3, 3] = 0.01 * np.tanh(right_in_left[:3, 3])
        right_chunk = right[0] @ step @ np.linalg.inv(left[0]) @ left_chunk
        if fault == "right_world_x":
            right_chunk[:, 0, 3] += 0.02 * np.tanh(right[0][0, 3])
        return {"left": left_chunk, "right": right_chunk}
    policy.__qualname__ = "bimanual_" + (fault or "wrt")
    return policy


def test_history_is_a_dict_of_hands_whose_histories_move_together():
    seen = []

    def policy(history, hand_points, world_points, noise):
        seen.append({k: np.shape(v) for k, v in history.items()})
        return bimanual()(history, hand_points, world_points, noise)
    handcentric.assert_equivariant(policy, "se3", cases=30, hands=HANDS, quiet=True)
    assert set(seen[0]) == set(HANDS) and seen[0]["left"] == seen[0]["right"]


def test_the_right_hand_in_the_left_frame_is_se3_equivariant_on_both_hands():
    report = handcentric.audit_policy(bimanual(), groups=["translation", "se3"], cases=60,
                                      hands=HANDS, quiet=True)
    assert {c["output"] for c in report["checks"]} == set(HANDS)
    assert all(c["equivariant"] for c in report["checks"])


def test_reading_the_right_hand_world_position_is_no_under_translation_on_the_right_hand():
    report = handcentric.audit_policy(bimanual("right_world_x"), groups=["translation"],
                                      views=["eye_in_hand"], cases=60, hands=HANDS, quiet=True)
    verdicts = {(c["output"], c["mode"]): c["equivariant"] for c in report["checks"]}
    assert verdicts[("left", "pointwise")] and not verdicts[("right", "pointwise")]
    witness = next(c for c in report["checks"] if not c["equivariant"])["witness"]
    assert "hand:right" in str(witness)


def test_mutant_a_right_hand_history_that_does_not_move_with_g_is_caught():
    # The mutant policy ignores the history it is given for the right hand and uses a fixed
    # world pose instead: it is no longer equivariant, and the audit says so.
    def fixed_right(history, hand_points, world_points, noise):
        history = dict(history, right=np.tile(np.eye(4), (len(history["right"]), 1, 1)))
        return bimanual()(history, hand_points, world_points, noise)
    with pytest.raises(AssertionError, match="output 'right'"):
        handcentric.assert_equivariant(fixed_right, "translation", cases=30, hands=HANDS,
                                       quiet=True)


def test_hands_are_named_once_and_are_poses():
    with pytest.raises(TypeError, match="hands must be a sequence of names"):
        handcentric.audit_policy(bimanual(), hands="left", quiet=True)
    with pytest.raises(ValueError, match="names 1 hand"):
        handcentric.audit_policy(bimanual(), hands=("left",), quiet=True)
    with pytest.raises(ValueError, match="'left' twice"):
        handcentric.audit_policy(bimanual(), hands=("left", "left"), quiet=True)
    with pytest.raises(ValueError, match=r"'right' is a hand: its chunk is a \"pose\""):
        handcentric.audit_policy(bimanual(), hands=HANDS, outputs={"right": "invariant"},
                                 quiet=True)

    def one_chunk(history, hand_points, world_points, noise):
        return {"left": bimanual()(history, hand_points, world_points, noise)["left"]}
    with pytest.raises(ValueError, match="has no entry 'right'"):
        handcentric.audit_policy(one_chunk, groups=["se3"], cases=10, hands=HANDS, quiet=True)
