"""The PyTorch example as a test (ctest label python): the hand-centric flow policy passes
assert_equivariant at float32 precision in every group, the absolute one fails with a witness."""
import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
import handcentric  # noqa: E402
import flow_policy  # noqa: E402

CASES = 200


@pytest.fixture(scope="module")
def policies():
    flow_policy.torch.set_num_threads(1)
    return flow_policy.train_both(demos=10, steps=600)


@pytest.mark.parametrize("group", handcentric.GROUPS)
def test_hand_centric_flow_policy_is_equivariant_at_float32(policies, group):
    handcentric.assert_equivariant(policies[0], group, precision="float32", cases=CASES,
                                   **flow_policy.AUDIT)


def test_hand_centric_flow_policy_is_not_exact_at_float64(policies):
    # Its decoder runs in float32: the float64 tolerance must see that, and say so.
    with pytest.raises(AssertionError, match="float32"):
        handcentric.assert_equivariant(policies[0], "rotation", cases=CASES, views="eye_in_hand",
                                       **flow_policy.AUDIT)


@pytest.mark.parametrize("group", ["translation", "rotation", "se3"])
def test_absolute_flow_policy_fails_with_a_witness(policies, group):
    with pytest.raises(AssertionError) as failure:
        handcentric.assert_equivariant(policies[1], group, precision="float32", cases=CASES,
                                       **flow_policy.AUDIT)
    assert "shrunk witness" in str(failure.value)
    assert "python: FlowPolicy: not equivariant under " + group in str(failure.value)
