"""handcentric.equivariance_profile: the error against the size of g, for built-ins, Python
representations and policies, batched or not; bad arguments named at once."""
import numpy as np
import pytest

import handcentric
from policies import absolute_actions, hand_centric_actions, make_policy


def test_builtin_profiles_have_the_shapes_of_their_symmetries():
    flat = handcentric.equivariance_profile("hand_centric", "se3", scenes=6)
    assert max(flat["pointwise"]["max"]) < 1e-10
    assert flat["distribution"] is None
    assert flat["unit"] == "rad and m"
    relative = handcentric.equivariance_profile("relative", "rotation", scenes=6)
    medians = relative["pointwise"]["median"]
    assert medians[-1] > 100 * medians[0] > 0
    assert relative["lie_derivative"]["median"] > 1e-4
    law = handcentric.equivariance_profile("actionflow", "rotation", scenes=4)
    assert law["distribution"]["method"] == "exact_gaussian"
    assert max(law["distribution"]["max"]) < 1e-9 < law["pointwise"]["median"][-1]


def test_python_representation_and_policy():
    absolute = handcentric.equivariance_profile(absolute_actions, "translation", scenes=4,
                                                sizes=[0.01, 0.1, 1.0])
    assert absolute["sizes"] == [0.01, 0.1, 1.0]
    assert absolute["pointwise"]["median"][2] > 50 * absolute["pointwise"]["median"][0] > 0
    same = handcentric.equivariance_profile(hand_centric_actions, "se3", scenes=4)
    assert max(same["pointwise"]["max"]) < 1e-10
    policy = handcentric.equivariance_profile(make_policy(), "se3", noise=20, scenes=3,
                                              samples=4, sizes=[0.1, 1.0])
    assert max(policy["pointwise"]["max"]) < 1e-9
    assert policy["component"] == "policy"
    world = handcentric.equivariance_profile(make_policy("world_noise"), "rotation", noise=20,
                                             scenes=3, samples=4, sizes=[0.01, 1.0])
    assert world["pointwise"]["median"][1] > 10 * world["pointwise"]["median"][0] > 0


def test_batch_size_gives_the_same_numbers_in_fewer_calls():
    calls = []

    def stacked(history, chunk, hand_points, world_points):
        calls.append(len(history))
        return np.stack([hand_centric_actions(h, c, p, w)
                         for h, c, p, w in zip(history, chunk, hand_points, world_points)])

    one = handcentric.equivariance_profile(hand_centric_actions, "rotation", scenes=5,
                                           sizes=[0.1, 1.0], history=1, chunk=3, hand_points=0)
    batched = handcentric.equivariance_profile(stacked, "rotation", scenes=5, sizes=[0.1, 1.0],
                                               batch_size=64, history=1, chunk=3, hand_points=0)
    assert batched["pointwise"] == one["pointwise"]
    assert batched["lie_derivative"]["median"] == one["lie_derivative"]["median"]
    assert max(calls) > 1  # stacked: several scenes per call


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="se4"):
        handcentric.equivariance_profile("relative", "se4")
    with pytest.raises(ValueError, match="scenes 0"):
        handcentric.equivariance_profile("relative", "rotation", scenes=0)
    with pytest.raises(ValueError, match="size -1"):
        handcentric.equivariance_profile("relative", "rotation", sizes=[-1])
    with pytest.raises(TypeError, match="sizes"):
        handcentric.equivariance_profile("relative", "rotation", sizes=["a"])
    with pytest.raises(ValueError, match="view 'top'"):
        handcentric.equivariance_profile("relative", "rotation", view="top")
    with pytest.raises(TypeError, match="callable"):
        handcentric.equivariance_profile(3, "rotation")
    with pytest.raises(ValueError, match="observation="):
        handcentric.equivariance_profile(hand_centric_actions, "rotation",
                                         component="observation")
    with pytest.raises(ValueError, match="workspace"):
        handcentric.equivariance_profile("relative", "rotation",
                                         workspace=((-1, -1, -1), (1, 1, 1)))
