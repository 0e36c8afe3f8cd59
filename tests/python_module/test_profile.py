"""handcentric.equivariance_profile: the error against the size of g, for built-ins, Python
representations and policies, batched or not; bad arguments named at once."""
import numpy as np
import pytest

import handcentric
from policies import (absolute_actions, hand_centric_actions, make_policy,
                      noise_recording_policy)


def test_builtin_profiles_have_the_shapes_of_their_symmetries():
    flat = handcentric.equivariance_profile(representation="hand_centric", group="se3", scenes=6)
    assert max(flat["pointwise"]["max"]) < 1e-10
    assert flat["distribution"] is None
    assert flat["unit"] == "rad and m"
    relative = handcentric.equivariance_profile(representation="relative", group="rotation",
                                                scenes=6)
    medians = relative["pointwise"]["median"]
    assert medians[-1] > 100 * medians[0] > 0
    assert relative["lie_derivative"]["median"] > 1e-4
    law = handcentric.equivariance_profile(representation="actionflow", group="rotation",
                                           scenes=4)
    assert law["distribution"]["method"] == "exact_gaussian"
    assert max(law["distribution"]["max"]) < 1e-9 < law["pointwise"]["median"][-1]


def test_python_representation_and_policy():
    absolute = handcentric.equivariance_profile(representation=absolute_actions,
                                                group="translation", scenes=4,
                                                sizes=[0.01, 0.1, 1.0])
    assert absolute["sizes"] == [0.01, 0.1, 1.0]
    assert absolute["pointwise"]["median"][2] > 50 * absolute["pointwise"]["median"][0] > 0
    same = handcentric.equivariance_profile(representation=hand_centric_actions, group="se3",
                                            scenes=4)
    assert max(same["pointwise"]["max"]) < 1e-10
    policy = handcentric.equivariance_profile(policy=make_policy(), group="se3", noise=20,
                                              scenes=3, samples=4, sizes=[0.1, 1.0])
    assert max(policy["pointwise"]["max"]) < 1e-9
    assert policy["component"] == "policy"
    world = handcentric.equivariance_profile(policy=make_policy("world_noise"), group="rotation",
                                             noise=20, scenes=3, samples=4, sizes=[0.01, 1.0])
    assert world["pointwise"]["median"][1] > 10 * world["pointwise"]["median"][0] > 0


def test_batch_size_gives_the_same_numbers_in_fewer_calls():
    calls = []

    def stacked(history, chunk, hand_points, world_points):
        calls.append(len(history))
        return np.stack([hand_centric_actions(h, c, p, w)
                         for h, c, p, w in zip(history, chunk, hand_points, world_points)])

    one = handcentric.equivariance_profile(representation=hand_centric_actions, group="rotation",
                                           scenes=5, sizes=[0.1, 1.0], history=1, chunk=3,
                                           hand_points=0)
    batched = handcentric.equivariance_profile(representation=stacked, group="rotation", scenes=5,
                                               sizes=[0.1, 1.0], batch_size=64, history=1,
                                               chunk=3, hand_points=0)
    assert batched["pointwise"] == one["pointwise"]
    assert batched["lie_derivative"]["median"] == one["lie_derivative"]["median"]
    assert max(calls) > 1  # stacked: several scenes per call


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="se4"):
        handcentric.equivariance_profile(representation="relative", group="se4")
    with pytest.raises(ValueError, match="scenes 0"):
        handcentric.equivariance_profile(representation="relative", group="rotation", scenes=0)
    with pytest.raises(ValueError, match="size -1"):
        handcentric.equivariance_profile(representation="relative", group="rotation", sizes=[-1])
    with pytest.raises(TypeError, match="sizes"):
        handcentric.equivariance_profile(representation="relative", group="rotation", sizes=["a"])
    with pytest.raises(ValueError, match="view 'top'"):
        handcentric.equivariance_profile(representation="relative", group="rotation", view="top")
    with pytest.raises(TypeError, match="callable"):
        handcentric.equivariance_profile(representation=3, group="rotation")
    with pytest.raises(ValueError, match="observation="):
        handcentric.equivariance_profile(representation=hand_centric_actions, group="rotation",
                                         component="observation")
    with pytest.raises(ValueError, match="workspace"):
        handcentric.equivariance_profile(representation="relative", group="rotation",
                                         workspace=((-1, -1, -1), (1, 1, 1)))


def test_the_map_is_named_by_its_keyword_and_a_policy_needs_its_noise():
    # A policy passed without noise= used to be called as a representation and failed with
    # "expected a 1-D array (n,)", with no word of noise=.
    with pytest.raises(ValueError, match=r"policy=\.\.\.\) needs noise="):
        handcentric.equivariance_profile(policy=make_policy(), group="se3")
    with pytest.raises(ValueError, match="needs one map, got none"):
        handcentric.equivariance_profile(group="se3")
    with pytest.raises(ValueError, match="more than one"):
        handcentric.equivariance_profile(policy=make_policy(), representation="relative",
                                         group="se3", noise=20)
    with pytest.raises(ValueError, match="noise= goes with policy="):
        handcentric.equivariance_profile(representation="relative", group="se3", noise=20)
    with pytest.raises(ValueError, match="needs group="):
        handcentric.equivariance_profile(representation="relative")
    with pytest.raises(TypeError, match="group= is a group's name"):
        handcentric.equivariance_profile(representation="relative", group=3)
    with pytest.raises(TypeError, match="policy= takes a callable"):
        handcentric.equivariance_profile(policy="relative", group="se3", noise=20)


def test_the_positional_form_still_works_with_a_deprecation_warning():
    with pytest.warns(DeprecationWarning, match="policy=f"):
        old = handcentric.equivariance_profile("relative", "rotation", scenes=3, sizes=[0.1])
    new = handcentric.equivariance_profile(representation="relative", group="rotation", scenes=3,
                                           sizes=[0.1])
    assert old == new
    # Without noise= the positional callable is taken as a representation: when that fails (here
    # the policy's own ValueError, called with a representation's arguments), a note says how to
    # pass a policy.
    with pytest.warns(DeprecationWarning):
        with pytest.raises(ValueError) as raised:
            handcentric.equivariance_profile(make_policy(), "se3", scenes=2, sizes=[0.1])
    assert any("policy= with noise=" in note for note in raised.value.__notes__)


def test_the_seed_draws_the_policys_noise_too():
    def noises_seen(seed):
        seen = set()
        handcentric.equivariance_profile(policy=noise_recording_policy(seen), group="rotation",
                                         noise=20, scenes=2, samples=4, sizes=[1.0], seed=seed)
        return seen
    assert noises_seen(1) == noises_seen(1)
    # Only the affine probes (the zero vector and the unit vectors) are the same for every seed.
    assert not (noises_seen(1) & noises_seen(2)) - {0.0, 1.0}
