"""pytest suite for `import handcentric` (python/module.cpp). Every check that can pass is also run
on a planted fault (policies.py) and must fail there, with a witness in its message."""
import json
import os
import subprocess
import sys
import traceback

import numpy as np
import pytest

import handcentric
import policies
from policies import make_policy, noise_recording_policy

CASES = 200  # per pointwise cell: enough for every planted fault, fast enough for CI
HERE = os.path.dirname(os.path.realpath(__file__))


# ---------------------------------------------------------------------------------------------
# Whole policies (eq. 4)

@pytest.mark.parametrize("group", handcentric.GROUPS)
def test_hand_centric_policy_is_equivariant_in_every_group(group):
    handcentric.assert_equivariant(make_policy(), group, cases=CASES)


def test_world_noise_fails_pointwise_under_rotation_with_a_witness():
    with pytest.raises(AssertionError) as failure:
        handcentric.assert_equivariant(make_policy("world_noise"), "rotation", cases=CASES)
    message = str(failure.value)
    assert "not equivariant under rotation (pointwise" in message
    assert "shrunk witness" in message and "g" in message
    assert "mode='distribution'" in message  # the hint: it may hold in law


def test_world_noise_is_equivariant_in_distribution_under_rotation_and_pointwise_under_translation(
):
    policy = make_policy("world_noise")
    handcentric.assert_equivariant(policy, "rotation", mode="distribution", cases=CASES,
                                   views="eye_in_hand")
    handcentric.assert_equivariant(policy, "translation", cases=CASES)


def test_forgetting_T0_fails_even_under_translation():
    with pytest.raises(AssertionError, match="not equivariant under translation"):
        handcentric.assert_equivariant(make_policy("forgets_T0"), "translation", cases=CASES)


def test_history_in_the_wrong_order_is_invisible_to_the_policy_audit():
    # Every pose of the history moves with g, so taking the oldest for the newest keeps eq. (4):
    # this documents the limit. The representation test below catches the same fault.
    handcentric.assert_equivariant(make_policy("wrong_order"), "se3", cases=CASES)


def test_audit_policy_gives_the_json_of_one_policy():
    result = handcentric.audit_policy(make_policy("world_noise"),
                                      groups=("translation", "rotation"),
                                      views="eye_in_hand", cases=CASES)
    assert result["name"] == "python: policy_world_noise"
    summary = result["summary"]["eye_in_hand"]
    assert summary["pointwise"] == {"translation": True, "rotation": False}
    assert summary["distribution"] == {"translation": True, "rotation": True}
    failed = [c for c in result["checks"] if not c["equivariant"]]
    assert len(failed) == 1 and failed[0]["witness"] is not None
    assert len(failed[0]["witness"]["g"]) == 16


def test_policy_float32_rounding_passes_at_float32_precision_only():
    good = make_policy()

    def float32_policy(history, hand_points, world_points, noise):
        return good(history, hand_points, world_points, noise).astype(np.float32)  # rounded once

    with pytest.raises(AssertionError, match="float32"):
        handcentric.assert_equivariant(float32_policy, "rotation", cases=CASES, views="eye_in_hand")
    handcentric.assert_equivariant(float32_policy, "rotation", cases=CASES, precision="float32")


# ---------------------------------------------------------------------------------------------
# Representations

def test_hand_centric_representation_is_invariant_everywhere():
    result = handcentric.audit(policies.hand_centric_actions, policies.hand_centric_observation,
                               decode=policies.hand_centric_decode, cases=CASES)
    assert result["injective"] is True
    assert all(c["invariant"] for c in result["checks"]), (
        [c for c in result["checks"] if not c["invariant"]])
    components = {c["component"] for c in result["checks"]}
    assert components == {"actions", "observation", "flow_input", "flow_target"}


def test_absolute_actions_fail_under_rotation_with_a_shrunk_witness():
    with pytest.raises(AssertionError) as failure:
        handcentric.assert_invariant(policies.absolute_actions, "rotation", cases=CASES)
    message = str(failure.value)
    assert "actions not invariant under rotation" in message
    assert "before" in message and "after" in message
    handcentric.assert_invariant(policies.hand_centric_actions, "se3", cases=CASES)


def test_assert_invariant_reads_observation_and_flow_components():
    handcentric.assert_invariant(policies.hand_centric_observation, "se3", "observation",
                                 cases=CASES)

    def world_observation(history, hand_points, world_points):
        return np.concatenate([history[0][:3, 3], hand_points.ravel()])

    with pytest.raises(AssertionError, match="observation not invariant under translation"):
        handcentric.assert_invariant(world_observation, "translation", "observation", cases=CASES)
    with pytest.raises(AssertionError, match="flow_input not invariant"):
        handcentric.assert_invariant(policies.hand_centric_actions, "translation", "flow_input",
                                     observation=world_observation, cases=CASES)
    handcentric.assert_invariant(policies.hand_centric_actions, "se3", "flow_target",
                                 observation=world_observation, cases=CASES)


def test_history_in_the_wrong_order_fails_the_round_trip():
    good = handcentric.audit(policies.hand_centric_actions, decode=policies.hand_centric_decode,
                             groups="se3", views="third_person", cases=CASES)
    assert good["injective"] is True
    bad = handcentric.audit(policies.wrong_order_actions, decode=policies.hand_centric_decode,
                            groups="se3", views="third_person", cases=CASES)
    assert bad["injective"] is not True
    assert bad["injectivity"]["round_trip_failure"] is not None


def test_in_process_audit_equals_the_pipe_audit():
    cli = os.environ.get("HANDCENTRIC_CLI")
    if not cli:
        pytest.skip("HANDCENTRIC_CLI is not set (ctest sets it)")
    env = dict(os.environ)
    command = "%s %s" % (sys.executable, os.path.join(HERE, "pipe_twin.py"))
    out = subprocess.run([cli, "audit", "--exec", command, "--json", "--cases", "100",
                          "--seed", "3"],
                         check=True, capture_output=True, text=True, env=env).stdout
    piped = json.loads(out)["representations"][0]
    here = handcentric.audit(policies.hand_centric_actions, policies.hand_centric_observation,
                             cases=100, seed=3)
    piped.pop("name"), here.pop("name")
    assert here == piped


def test_same_seed_same_witness():
    runs = [handcentric.audit(policies.absolute_actions, groups="rotation", views="eye_in_hand",
                              cases=CASES, seed=5) for _ in range(2)]
    assert runs[0] == runs[1]
    assert runs[0]["checks"][0]["witness"] is not None


def test_the_seed_draws_the_noise_a_policy_is_asked_with():
    # seed= used to seed the cases only: every seed asked the policy with one fixed noise.
    def noises_seen(seed):
        seen = set()
        handcentric.audit_policy(noise_recording_policy(seen), noise=20, groups="translation",
                                 views="eye_in_hand", cases=10, seed=seed)
        return seen
    assert noises_seen(3) == noises_seen(3)
    # Only the affine probes (the zero vector and the unit vectors) are the same for every seed.
    assert not (noises_seen(3) & noises_seen(4)) - {0.0, 1.0}


# ---------------------------------------------------------------------------------------------
# Errors: Python exceptions, shapes, dtypes, bad options

def test_a_python_exception_surfaces_with_its_traceback():
    def broken_policy(history, hand_points, world_points, noise):
        return 1 / 0

    with pytest.raises(ZeroDivisionError) as failure:
        handcentric.assert_equivariant(broken_policy, "se3", cases=10)
    frames = "".join(traceback.format_tb(failure.value.__traceback__))
    assert "broken_policy" in frames and "return 1 / 0" in frames

    def broken_actions(history, chunk, hand_points, world_points):
        raise KeyError("no such camera")

    with pytest.raises(KeyError, match="no such camera"):
        handcentric.audit(broken_actions, cases=10)


def test_an_exception_raised_late_still_surfaces():
    calls = []

    def flaky(history, chunk, hand_points, world_points):
        calls.append(1)
        if len(calls) > 50:
            raise RuntimeError("late failure")
        return policies.hand_centric_actions(history, chunk, hand_points, world_points)

    with pytest.raises(RuntimeError, match="late failure"):
        handcentric.audit(flaky, cases=CASES)


def test_wrong_shapes_name_the_shape():
    def matrix_actions(history, chunk, hand_points, world_points):
        return np.zeros((3, 4))

    with pytest.raises(handcentric.ShapeError, match=r"shape \(3, 4\); expected a 1-D"):
        handcentric.audit(matrix_actions, cases=10)
    assert issubclass(handcentric.ShapeError, ValueError)

    def flat_chunk(history, hand_points, world_points, noise):
        return np.zeros((policies.K, 3, 4))

    with pytest.raises(handcentric.ShapeError, match=r"shape \(4, 3, 4\); expected \(K, 4, 4\)"):
        handcentric.assert_equivariant(flat_chunk, "se3", cases=10)

    def bad_last_row(history, hand_points, world_points, noise):
        return np.ones((2, 4, 4))

    with pytest.raises(handcentric.ShapeError, match="last row"):
        handcentric.audit_policy(bad_last_row, cases=10)

    with pytest.raises(handcentric.ShapeError,
                       match=r"history has shape \(4, 4\); expected \(H\+1, 4, 4\)"):
        handcentric.encode_actions("hand_centric", np.eye(4), np.eye(4)[None])


def test_wrong_dtypes_and_non_numbers_are_type_errors():
    def text_actions(history, chunk, hand_points, world_points):
        return ["a", "b"]

    with pytest.raises(TypeError, match="dtype <U1"):
        handcentric.audit(text_actions, cases=10)

    def no_return(history, chunk, hand_points, world_points):
        pass

    with pytest.raises(TypeError, match="is None"):
        handcentric.audit(no_return, cases=10)

    def nan_actions(history, chunk, hand_points, world_points):
        return np.full(6, np.nan)

    with pytest.raises(ValueError, match="non-finite"):
        handcentric.audit(nan_actions, cases=10)

    with pytest.raises(TypeError, match="callable"):
        handcentric.audit_policy("not a function")
    with pytest.raises(TypeError, match="observation must be callable or None, got a ndarray"):
        handcentric.audit(policies.hand_centric_actions, np.zeros(3))


def test_bad_options_name_the_value_and_the_choices():
    with pytest.raises(ValueError, match="spin"):
        handcentric.audit(policies.hand_centric_actions, groups="spin")
    with pytest.raises(ValueError, match="eye_in_hand, third_person"):
        handcentric.audit(policies.hand_centric_actions, views="bird")
    with pytest.raises(ValueError, match="cases"):
        handcentric.audit(policies.hand_centric_actions, cases=0)
    with pytest.raises(ValueError, match="unknown precision .float8."):
        handcentric.audit(policies.hand_centric_actions, precision="float8")
    with pytest.raises(ValueError, match="tolerance"):
        handcentric.audit(policies.hand_centric_actions, tolerance=2.0)
    with pytest.raises(ValueError, match="mode"):
        handcentric.assert_equivariant(make_policy(), "se3", mode="sometimes")


# ---------------------------------------------------------------------------------------------
# Built-ins on NumPy

def random_pose(rng):
    return policies.pose_matrix(np.concatenate([rng.normal(size=3), rng.uniform(-1, 1, 3)]))


def test_builtin_hand_centric_matches_the_numpy_one_and_decodes():
    rng = np.random.default_rng(1)
    history = np.stack([random_pose(rng) for _ in range(3)])
    chunk = np.stack([random_pose(rng) for _ in range(4)])
    points = rng.normal(size=(2, 3))
    actions = handcentric.encode_actions("hand_centric", history, chunk, points)
    np.testing.assert_allclose(
        actions, policies.hand_centric_actions(history, chunk, points, np.zeros((0, 3))),
        atol=1e-12)
    np.testing.assert_allclose(handcentric.decode("hand_centric", actions, history[0]), chunk,
                               atol=1e-12)
    observation = handcentric.encode_observation("hand_centric", history, points)
    assert observation.shape == (6 * 3 + 3 * 2,)
    with pytest.raises(ValueError, match="hand_centric"):
        handcentric.encode_actions("handcentric", history, chunk)
    assert "relative_diff" in handcentric.REPRESENTATIONS


def test_exp_and_log_round_trip():
    r = np.array([0.3, -1.2, 2.0])
    np.testing.assert_allclose(handcentric.so3_log(handcentric.so3_exp(r)), r, atol=1e-14)
    twist = np.array([1.0, 2.0, 3.0, 0.1, 0.2, -0.3])
    np.testing.assert_allclose(handcentric.se3_log(handcentric.se3_exp(twist)), twist, atol=1e-14)
    with pytest.raises(handcentric.Error, match="rotation"):
        handcentric.so3_log(np.diag([1.0, 1.0, -1.0]))


def test_demo_files_load_as_numpy(tmp_path):
    cli = os.environ.get("HANDCENTRIC_CLI")
    if not cli:
        pytest.skip("HANDCENTRIC_CLI is not set (ctest sets it)")
    path = str(tmp_path / "demos.jsonl")
    subprocess.run([cli, "demos", "--n", "2", "--dist", "train", "--seed", "1", "--out", path],
                   check=True, capture_output=True)
    demos = handcentric.load_demos(path)
    assert len(demos) == 2
    assert demos[0]["world_T_hole"].shape == (4, 4) and demos[0]["world_T_hand"].shape[1:] == (4, 4)
    scenes = handcentric.training_scenes(path, history=1, chunk=8)
    steps = sum(len(d["world_T_hand"]) for d in demos)
    assert scenes["history"].shape == (steps, 2, 4, 4)
    assert (scenes["chunk"].shape == (steps, 8, 4, 4)
            and scenes["hand_points"].shape == (steps, 2, 3))
    np.testing.assert_array_equal(scenes["history"][0, 0], demos[0]["world_T_hand"][0])
    with pytest.raises(handcentric.Error, match="missing.jsonl"):
        handcentric.load_demos(str(tmp_path / "missing.jsonl"))


def test_options_may_be_given_by_position_as_documented():
    result = handcentric.audit(policies.hand_centric_actions, None, "se3", "eye_in_hand", 20, 2)
    assert result["checks"][0]["seed"] == 2 and {c["group"] for c in result["checks"]} == {"se3"}
    policy = handcentric.audit_policy(make_policy(), "c8", "third_person", 20, 3, None,
                                      "float32", 64)
    assert {(c["group"], c["view"]) for c in policy["checks"]} == {("c8", "third_person")}
