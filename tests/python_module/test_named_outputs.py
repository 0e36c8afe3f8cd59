"""Policies that return a dict of named outputs (outputs={"hand": "pose", "gripper":
"invariant"}): each entry is audited, a pose entry as moving with g, an invariant one as not
changing; a gripper that reads the hand's world height is NO and named; the dict's keys and the
declared names must agree."""
import numpy as np
import pytest

import handcentric
from policies import make_policy

OUTPUTS = {"hand": "pose", "gripper": "invariant"}


def with_gripper(fault=None):
    """The hand-centric test policy, plus a gripper width per step. The width reads the noise and
    the hand's previous pose relative to T_0 (invariant); the fault adds the hand's world height,
    as a gripper head conditioned on the raw proprioception would."""
    inner = make_policy()

    def policy(history, hand_points, world_points, noise):
        chunk = inner(history, hand_points, world_points, noise)
        rel = np.linalg.inv(history[0]) @ history[1] if len(history) > 1 else np.eye(4)
        width = 0.04 + 0.01 * np.tanh(noise[:len(chunk)] + rel[0, 3])
        if fault == "world_height":
            width = width + 0.02 * np.tanh(history[0][2, 3])
        return {"hand": chunk, "gripper": width}
    policy.__qualname__ = "gripper_" + (fault or "hand_centric")
    return policy


def test_each_output_is_a_row_and_the_hand_centric_policy_holds_on_both():
    report = handcentric.audit_policy(with_gripper(), groups=["translation", "se3"], cases=60,
                                      outputs=OUTPUTS, quiet=True)
    assert {c["output"] for c in report["checks"]} == {"hand", "gripper"}
    assert all(c["equivariant"] for c in report["checks"])
    assert report["outputs"]["gripper"]["kind"] == "invariant"
    assert report["summary"]["eye_in_hand"]["pointwise"]["se3"] is True


def test_a_gripper_that_reads_the_world_height_is_no_and_named():
    report = handcentric.audit_policy(with_gripper("world_height"), groups=["translation", "se3"],
                                      cases=60, outputs=OUTPUTS, quiet=True)
    failed = {(c["output"], c["group"]) for c in report["checks"] if not c["equivariant"]}
    assert ("gripper", "translation") in failed and ("gripper", "se3") in failed
    assert not any(output == "hand" for output, _ in failed)
    assert report["outputs"]["hand"]["summary"]["eye_in_hand"]["pointwise"]["se3"] is True
    assert report["summary"]["eye_in_hand"]["pointwise"]["se3"] is False
    with pytest.raises(AssertionError, match="output 'gripper'"):
        handcentric.assert_equivariant(with_gripper("world_height"), "translation", cases=60,
                                       outputs=OUTPUTS, quiet=True)
    handcentric.assert_equivariant(with_gripper(), "se3", cases=60, outputs=OUTPUTS, quiet=True)


def test_an_invariant_output_declared_a_pose_is_refused_not_passed():
    # Declared a pose, the width (a number per step) is not even a chunk of poses: refused, so a
    # wrong kind cannot pass quietly.
    with pytest.raises(handcentric.ShapeError, match=r"\['gripper'\]"):
        handcentric.audit_policy(with_gripper(), groups=["se3"], cases=10, quiet=True,
                                 outputs={"hand": "pose", "gripper": "pose"})


def test_batched_dict_outputs_give_the_unbatched_verdicts():
    inner = with_gripper("world_height")

    def batched(history, hand_points, world_points, noise):
        rows = [inner(history[b], hand_points[b], world_points[b], noise[b])
                for b in range(len(history))]
        return {k: np.stack([r[k] for r in rows]) for k in rows[0]}
    batched.__qualname__ = inner.__qualname__
    setup = dict(groups=["translation"], views=["eye_in_hand"], cases=30, outputs=OUTPUTS,
                 quiet=True)
    one = handcentric.audit_policy(inner, **setup)
    many = handcentric.audit_policy(batched, batch_size=32, **setup)
    assert one == many
    assert not one["summary"]["eye_in_hand"]["pointwise"]["translation"]


def test_keys_and_declared_outputs_must_agree_and_kinds_are_named():
    def extra(*args):
        out = with_gripper()(*args)
        out["terminate"] = 0.0
        return out
    with pytest.raises(ValueError, match=r"entry 'terminate' that outputs= does not name"):
        handcentric.audit_policy(extra, cases=10, outputs=OUTPUTS, quiet=True)
    with pytest.raises(ValueError, match=r"has no entry 'flag', which outputs= names"):
        handcentric.audit_policy(with_gripper(), cases=10, quiet=True,
                                 outputs=dict(OUTPUTS, flag="invariant"))
    with pytest.raises(ValueError, match=r"outputs\[\"gripper\"\] is 'width'"):
        handcentric.audit_policy(with_gripper(), outputs={"hand": "pose", "gripper": "width"})
    with pytest.raises(ValueError, match="names no \"pose\" output"):
        handcentric.audit_policy(with_gripper(), outputs={"gripper": "invariant"})
    with pytest.raises(TypeError, match="say what each entry is: outputs="):
        handcentric.audit_policy(with_gripper(), cases=10, quiet=True)
    with pytest.raises(TypeError, match="outputs must be a dict"):
        handcentric.audit_policy(with_gripper(), outputs=["hand"])
