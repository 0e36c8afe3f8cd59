"""serve_policy(..., stages=[(name, kind), ...]): a policy that names the stages of its pipeline
(handcentric_plugin/interface.py): the hello declares them in order, a request with "stages":
true is answered with every stage's value beside the chunk (one row each when batched), other
requests with the chunk alone, and a policy that returns the wrong stages exits 1 naming them.
The audit's side is tests/props/test_pipe_locate.cpp."""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_handcentric_plugin import hp, random_pose  # noqa: E402
from test_policy_interface import policy_request, serve_lines  # noqa: E402

STAGES = [("to_hand", "features"), ("decode", "poses")]


def staged_policy(history, hand_points, world_points, noise):
    T = np.asarray(history)
    step = np.linalg.norm(T[..., 0, :3, 3] - T[..., -1, :3, 3], axis=-1)[..., None]
    features = np.concatenate([step, np.asarray(noise)[..., :2]], axis=-1)
    chunk = np.stack([T[..., 0, :, :]] * 2, axis=-3)
    return chunk, {"decode": chunk, "to_hand": features}


def matrices(poses):
    return [np.asarray(p).ravel().tolist() for p in poses]


# Mutant: loop.py's single-request answer passing with_stages=False (no "stages" ever sent).
def test_the_hello_names_the_stages_and_a_staged_request_gets_them_in_order():
    rng = np.random.default_rng(2)
    history = matrices([random_pose(rng), random_pose(rng)])
    answers, status, err = serve_lines(
        staged_policy, [policy_request(0, history), policy_request(1, history, stages=True),
                        policy_request(2, history)], stages=STAGES)
    assert status == 0, err
    assert answers[0]["hello"]["stages"] == [{"name": "to_hand", "kind": "features"},
                                             {"name": "decode", "kind": "poses"}]
    staged = answers[1]
    assert list(staged["stages"]) == ["to_hand", "decode"]
    assert len(staged["stages"]["to_hand"]) == 3
    assert len(staged["stages"]["decode"]) == 2 and len(staged["stages"]["decode"][0]) == 16
    assert staged["chunk"] == staged["stages"]["decode"]
    assert "stages" not in answers[2]


# Mutant: interface.answers adding the stages to every item of a batch (not only those asked).
def test_a_batched_line_answers_the_stages_of_the_items_that_ask():
    rng = np.random.default_rng(3)
    history = matrices([random_pose(rng), random_pose(rng)])
    line = {"id": 1, "protocol": 2, "batch": [policy_request(0, history, stages=True),
                                              policy_request(0, history)]}
    for item in line["batch"]:
        del item["id"], item["protocol"]
    answers, status, err = serve_lines(staged_policy, [policy_request(0, history), line],
                                       stages=STAGES, batched=True, batch_size=4)
    assert status == 0, err
    first, second = answers[1]["batch"]
    assert list(first["stages"]) == ["to_hand", "decode"] and "stages" not in second
    assert first["chunk"] == second["chunk"]


# Mutant: policy.py's joined() without its pair branch (a batched rng= policy's (answer, stages)
# rows are not joined back into one batch).
def test_a_batched_policy_with_its_own_rng_returns_its_stages_row_by_row():
    rng = np.random.default_rng(5)
    history = matrices([random_pose(rng), random_pose(rng)])
    line = {"id": 1, "protocol": 2, "batch": [policy_request(0, history, stages=True),
                                              policy_request(0, history, stages=True)]}
    for item in line["batch"]:
        del item["id"], item["protocol"]
    answers, status, err = serve_lines(staged_policy, [policy_request(0, history), line],
                                       stages=STAGES, batched=True, batch_size=4, rng="numpy")
    assert status == 0, err
    first, second = answers[1]["batch"]
    assert first["stages"] == second["stages"] and len(first["stages"]["decode"]) == 2


@pytest.mark.parametrize("stages, says", [
    ([("a", "pose")], "kind 'pose'; a stage is \"poses\""),
    ([("a", "poses"), ("a", "features")], "names 'a' twice"),
    ([], "stages= is empty"),
    (["a"], "each stage is a pair (name, kind)"),
])
def test_bad_stages_are_refused_naming_the_value(stages, says):
    with pytest.raises(ValueError, match=None) as error:
        serve_lines(staged_policy, [], stages=stages)
    assert says in str(error.value)


def test_a_policy_returning_other_stages_exits_1_naming_them():
    rng = np.random.default_rng(4)
    history = matrices([random_pose(rng)])

    def missing(history, hand_points, world_points, noise):
        chunk, values = staged_policy(history, hand_points, world_points, noise)
        del values["decode"]
        return chunk, values
    _, status, err = serve_lines(missing, [policy_request(0, history),
                                           policy_request(1, history, stages=True)],
                                 stages=STAGES)
    assert status == 1
    assert "stages= declares ['to_hand', 'decode']" in err

    def chunk_only(history, hand_points, world_points, noise):
        return staged_policy(history, hand_points, world_points, noise)[0]
    _, status, err = serve_lines(chunk_only, [policy_request(0, history),
                                              policy_request(1, history)], stages=STAGES)
    assert status == 1
    assert "returns the pair (its answer, {stage: value})" in err
