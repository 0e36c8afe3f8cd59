"""serve_policy(..., state_format=, action_format=, outputs=, hands=, reset=): a policy served in
its own interface (handcentric_plugin/interface.py): the hello declares it, requests are read in
its layouts (per hand), its answers written as its outputs, and reset() runs at an episode's
first step only. The audit's side is tests/props/test_policy_interface.cpp."""
import os
import sys
import types

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_handcentric_plugin import hp, random_pose, run_serve  # noqa: E402

LAYOUT = "pos_quat_xyzw"


def serve_lines(policy, requests, **kwargs):
    """serve_policy in-process on these requests: (answers, exit status, stderr)."""
    return run_serve(requests, policy, helper=types.SimpleNamespace(serve=hp.serve_policy),
                     **kwargs)


def vectors(poses):
    return hp.formats.encode(np.asarray(poses), LAYOUT).tolist()


def policy_request(rid, history, **fields):
    r = {"id": rid, "protocol": 2, "history": history, "hand_points": [], "world_points": [],
         "noise": [0.1, 0.2]}
    r.update(fields)
    return r


def test_the_hello_declares_the_interface_and_answers_speak_it():
    rng = np.random.default_rng(1)
    T = [random_pose(rng), random_pose(rng)]
    seen = []

    def policy(history, hand_points, world_points, noise):
        seen.append(history.shape)
        chunk = hp.formats.decode(history, LAYOUT)[:1] @ np.stack([np.eye(4)] * 3)
        return {"hand": hp.formats.encode(chunk, LAYOUT), "gripper": np.array([0.5, 0.4, 0.3])}
    answers, status, err = serve_lines(
        policy, [policy_request(0, vectors(T)), policy_request(1, vectors(T))],
        state_format=LAYOUT, action_format=LAYOUT,
        outputs={"hand": "pose", "gripper": "invariant"})
    assert status == 0, err
    hello = answers[0]["hello"]
    assert hello["state_format"] == LAYOUT and hello["action_format"] == LAYOUT
    assert list(hello["outputs"]) == ["hand", "gripper"] and "encodings" not in hello
    assert seen == [(2, 7)]
    outputs = answers[1]["outputs"]
    assert len(outputs["hand"]) == 3 and all(len(p) == 7 for p in outputs["hand"])
    assert outputs["gripper"] == pytest.approx([0.5, 0.4, 0.3])


def test_two_hands_get_their_histories_by_name_batched_too():
    # Mutant: every hand read from the first hand's history -> the right hand's chunk is the
    # left's.
    rng = np.random.default_rng(2)
    L, R = [random_pose(rng)], [random_pose(rng)]
    seen = []

    def policy(history, hand_points, world_points, noise):
        seen.append({h: np.shape(v) for h, v in history.items()})
        B = len(noise)
        return {"left": np.repeat(history["left"][:, :1], 2, axis=1),
                "right": np.repeat(history["right"][:, :1], 2, axis=1), "gripper": np.zeros(B)}
    item = {"history": {"left": vectors(L), "right": vectors(R)}, "hand_points": [],
            "world_points": [], "noise": [0.0]}
    answers, status, err = serve_lines(
        policy, [{"id": 0, "protocol": 2, **item},
                 {"id": 1, "protocol": 2, "batch": [item, item]}],
        state_format=LAYOUT, action_format=LAYOUT, hands=("left", "right"),
        outputs={"gripper": "invariant"}, batched=True)
    assert status == 0, err
    assert answers[0]["hello"]["hands"] == ["left", "right"]
    assert seen == [{"left": (2, 1, 7), "right": (2, 1, 7)}]
    first = answers[1]["batch"][0]["outputs"]
    assert first["right"][0] == pytest.approx(vectors(R)[0])
    # A history without the second hand is refused naming the hands.
    answers, status, err = serve_lines(
        policy, [{"id": 0, "protocol": 2, **item},
                 {"id": 1, "protocol": 2, **dict(item, history={"left": vectors(L)})}],
        state_format=LAYOUT, hands=("left", "right"), outputs={"gripper": "invariant"})
    assert status == 2 and "['left', 'right']" in err


def test_reset_runs_at_an_episodes_first_step_and_before_every_other_call():
    # Mutant: reset() before every call (the episode ignored) -> 4 resets, not 3.
    resets = []

    def policy(history, hand_points, world_points, noise):
        return np.stack([history[0]])
    T = [np.eye(4).ravel().tolist()]
    requests = [policy_request(0, T),
                policy_request(1, T, episode={"index": 0, "step": 0}),
                policy_request(2, T, episode={"index": 0, "step": 1}),
                policy_request(3, T),
                policy_request(4, T, episode={"index": 1, "step": 0})]
    answers, status, err = serve_lines(policy, requests, reset=lambda: resets.append(1))
    assert status == 0, err
    assert answers[0]["hello"]["episodes"] is True
    assert len(resets) == 3  # requests 1, 3 and 4 (request 0 is answered by the hello)


def test_a_chunk_of_vectors_without_action_format_names_the_keyword():
    # Mutant: the hint left out of protocol._chunk's message.
    def policy(history, hand_points, world_points, noise):
        return np.zeros((2, 7))
    T = [np.eye(4).ravel().tolist()]
    _, status, err = serve_lines(policy, [policy_request(0, T), policy_request(1, T)],
                                 hello=True)
    assert status == 1 and "action_format=" in err


@pytest.mark.parametrize("keywords, says", [
    ({"hands": ("left",)}, "two or more distinct hands"),
    ({"hands": "left"}, "two or more distinct hands"),
    ({"outputs": {"hand": "position"}}, "\"pose\" or \"invariant\""),
    ({"outputs": {"gripper": "invariant"}}, "names no \"pose\" output"),
    ({"action_format": "pos_quat"}, "pos_quat"),
    ({"hands": ("l", "r"), "outputs": {"r": "invariant"}}, "is a hand"),
])
def test_a_bad_interface_keyword_is_refused_naming_it(keywords, says):
    with pytest.raises(ValueError, match=says.replace("(", r"\(")):
        serve_lines(lambda *a: None, [], **keywords)
