"""A policy that fails to answer (NaN, an exception, a tuple or a dict) is named where it failed:
the case, the seed and the observation, or the preflight's observations; never a bare "flat index
131". Each planted policy is the correct one of policies.py failing on a part of the scenes only.
"""
import numpy as np
import pytest

import handcentric
from policies import make_policy

base = make_policy()


def far_out(history):
    return np.linalg.norm(history[0][:3, 3]) > 3.0  # hands beyond 3 m: a few cases of 40


def nan_beyond_3m(history, hand_points, world_points, noise):
    chunk = base(history, hand_points, world_points, noise)
    if far_out(history):
        chunk[1, 0, 3] = np.nan
    return chunk


def raises_beyond_3m(history, hand_points, world_points, noise):
    if far_out(history):
        raise ZeroDivisionError("the planted failure")
    return base(history, hand_points, world_points, noise)


def stacked(policy):
    def batched(history, hand_points, world_points, noise):
        return np.stack([policy(history[i], hand_points[i], world_points[i], noise[i])
                         for i in range(len(noise))])
    return batched


@pytest.mark.parametrize("batch_size", [None, 64])
def test_a_nan_names_the_case_the_seed_and_the_observation(batch_size):
    fn = nan_beyond_3m if batch_size is None else stacked(nan_beyond_3m)
    with pytest.raises(ValueError) as error:
        handcentric.audit_policy(fn, groups=["se3"], cases=40, seed=3, batch_size=batch_size,
                                 quiet=True)
    text = str(error.value)
    assert "non-finite number" in text
    assert "seed 3" in text and "the same seed asks them again" in text
    assert "raised in case " in text or "raised in the preflight" in text
    assert "T_0 = (p = " in text
    if batch_size is not None:
        assert "the chunk returned by policy" in text and "[0]" in text  # the row, asked alone


def test_an_exception_keeps_its_type_and_traceback_and_gets_a_note_naming_the_case():
    with pytest.raises(ZeroDivisionError, match="the planted failure") as error:
        handcentric.audit_policy(raises_beyond_3m, groups=["se3"], cases=40, seed=3, quiet=True)
    notes = getattr(error.value, "__notes__", [])
    assert len(notes) == 1 and notes[0].startswith("handcentric: raised in ")
    assert "seed 3" in notes[0] and "T_0 = (p = " in notes[0]


@pytest.mark.parametrize("batch_size", [None, 8])
def test_a_tuple_or_a_dict_says_what_a_chunk_must_be(batch_size):
    def with_gripper(history, hand_points, world_points, noise):
        if batch_size is None:
            return base(history, hand_points, world_points, noise), 0.5
        return stacked(base)(history, hand_points, world_points, noise), np.zeros(len(noise))

    def as_dict(history, hand_points, world_points, noise):
        return {"hand": with_gripper(history, hand_points, world_points, noise)[0],
                "gripper": 0.5}
    for fn, said in ((with_gripper, "is a tuple of 2 items"),
                     (as_dict, "with keys ['hand', 'gripper']")):
        with pytest.raises(TypeError) as error:
            handcentric.audit_policy(fn, groups=["se3"], cases=10, batch_size=batch_size,
                                     quiet=True)
        text = str(error.value)
        assert said in text and "outputs={name: \"pose\" or \"invariant\"}" in text
        assert "raised in the preflight" in text
