"""serve(..., batched=True) and serve_policy(..., batched=True): the hello declares the batch,
a batched line is answered by one line of answers in the request's order, each the unbatched
answer bit for bit, the functions get stacked arrays, and bad batches and results are one-line
errors. Mutant twins (test_mutant_*) plant a fault each check must flag."""
import json
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_handcentric_plugin import (REPR, hp, load, random_pose, random_scene,  # noqa: E402
                                     request, run_serve)

repr_py = load(REPR, "repr_batched_under_test")
PROBE = {"id": 0, "protocol": 2, "history": [np.eye(4).ravel().tolist()],
         "chunk": [np.eye(4).ravel().tolist()], "hand_points": [], "world_points": []}


def item(scene, **fields):
    """One scene of a batched request: the fields of a single request, without id."""
    r = request(scene, **fields)
    del r["id"], r["protocol"]
    return r


def batched(rid, scenes, **fields):
    return {"id": rid, "protocol": 2, "batch": [item(s, **fields) for s in scenes]}


def scenes(count, seed=1, **shape):
    rng = np.random.default_rng(seed)
    return [random_scene(rng, **shape) for _ in range(count)]


def framing_holds(helper=hp):
    """A batch of 5 scenes after the hello: one answer line, 5 items in order, each equal to
    the unbatched example's answer to that scene; a single request after it as well."""
    batch = scenes(5, H=2, K=3, hand=2, world=2)
    try:
        answers, status, err = run_serve([PROBE, batched(1, batch), request(batch[3], 2)],
                                         repr_py.encode_batch, helper=helper, batched=True)
    except Exception:  # a helper that crashes does not frame anything
        return False
    single = [run_serve([request(s, 7)], repr_py.encode)[0][0] for s in batch]
    for a in single:
        del a["id"]
    return (status == 0 and len(answers) == 3 and answers[0]["hello"]["batch"] == 256
            and answers[1] == {"id": 1, "batch": single}
            and answers[2] == dict(single[3], id=2))


def test_a_batch_is_answered_in_order_with_the_unbatched_answers():
    assert framing_holds()


def test_mutant_helper_that_reverses_the_rows_is_caught(monkeypatch):
    rows = hp.loop._encoded_rows
    monkeypatch.setattr(hp.loop, "_encoded_rows", lambda result, B: rows(result, B)[::-1])
    assert not framing_holds()


def test_mutant_helper_that_drops_the_last_answer_is_caught(monkeypatch):
    rows = hp.loop._encoded_rows
    monkeypatch.setattr(hp.loop, "_encoded_rows", lambda result, B: rows(result, B)[:-1])
    assert not framing_holds()


def test_the_function_gets_stacked_arrays_with_a_leading_batch_axis():
    seen = {}

    def encode(history, chunk, hand_points, world_points, extra_poses, scalars):
        seen.update(history=history, chunk=chunk, hand=hand_points, world=world_points,
                    poses=extra_poses, scalars=scalars)
        return np.zeros((len(history), 6))

    rng = np.random.default_rng(3)
    starts = [random_pose(rng) for _ in range(3)]
    lines = [PROBE] + [{"id": 1, "protocol": 2, "batch": [
        item(s, extra_poses={"start": T.ravel().tolist()}, scalars={"gripper": 0.5 * i})
        for i, (s, T) in enumerate(zip(scenes(3, H=1, K=4, hand=0, world=2), starts))]}]
    answers, status, err = run_serve(lines, encode, batched=True, batch_size=8,
                                     extra_poses=["start"], scalars=["gripper"])
    assert status == 0, err
    assert answers[0]["hello"]["batch"] == 8
    assert [len(a["actions"]) for a in answers[1]["batch"]] == [6, 6, 6]
    assert seen["history"].shape == (3, 2, 4, 4) and seen["chunk"].shape == (3, 4, 4, 4)
    assert seen["hand"].shape == (3, 0, 3) and seen["world"].shape == (3, 2, 3)
    assert np.array_equal(seen["poses"]["start"], np.stack(starts))
    assert np.array_equal(seen["scalars"]["gripper"], [0.0, 0.5, 1.0])


@pytest.mark.parametrize("result, message", [
    (lambda B: np.zeros((B - 1, 6)), "of shape (2, 6) for a batch of 3 scenes"),
    (lambda B: np.full((B, 6), np.nan), "'actions' of batch item 0 has a non-finite number"),
    (lambda B: (np.zeros((B, 6)), np.zeros(B + 1)), "'observation' of shape (4,)"),
    (lambda B: np.zeros((B, 0)), "no actions"),
])
def test_bad_batched_results_exit_1_with_one_line(result, message):
    answers, status, err = run_serve([PROBE, batched(1, scenes(3))],
                                     lambda history, *a: result(len(history)), batched=True)
    assert status == 1 and message in err and err.count("\n") == 1
    assert len(answers) == 1  # the hello only


@pytest.mark.parametrize("lines, kwargs, message", [
    ([PROBE, batched(1, scenes(3))], {"batch_size": 2}, "more than the 2 the hello declared"),
    ([PROBE, {"id": 1, "batch": []}], {}, "non-empty list"),
])
def test_bad_batched_requests_exit_2_with_one_line(lines, kwargs, message):
    _, status, err = run_serve(lines, lambda h, *a: np.zeros((len(h), 6)), batched=True, **kwargs)
    assert status == 2 and message in err and err.count("\n") == 1


def test_a_batched_request_to_an_unbatched_plugin_says_so():
    _, status, err = run_serve([batched(1, scenes(2))], repr_py.encode)
    assert status == 2 and "declared no batch" in err


def test_batched_mode_without_numpy_says_it_needs_numpy(monkeypatch):
    monkeypatch.setattr(hp.loop, "np", None)  # where serve() looks for NumPy
    _, status, err = run_serve([PROBE], lambda *a: None, batched=True)
    assert status == 1 and "needs NumPy" in err


def test_batched_policy_gets_noise_rows_and_answers_chunks_in_order():
    def policy(history, hand_points, world_points, noise):
        out = np.repeat(history[:, :1], 2, axis=1)  # K = 2 poses, T_0 twice ...
        out[:, 1, :3, 3] += noise[:, :3]  # ... the second moved by the row's own noise
        return out

    batch = scenes(3, H=1, K=1)
    noise = [[float(i), 0.0, 0.0, 5.0] for i in range(3)]
    line = {"id": 1, "protocol": 2, "batch": [dict(item(s), noise=n)
                                              for s, n in zip(batch, noise)]}
    probe = dict(PROBE, noise=[0.0] * 4)
    out = []
    answers, status, err = run_serve([probe, line], None, batched=True, _policy=policy, _noise=4)
    assert status == 0, err
    assert answers[0]["hello"] == dict(answers[0]["hello"], batch=256, noise=4)
    for i, (s, a) in enumerate(zip(batch, answers[1]["batch"])):
        T0 = s["history"][0]
        moved = T0.copy()
        moved[0, 3] += i
        out.append(a["chunk"] == [T0.ravel().tolist(), moved.ravel().tolist()])
    assert out == [True, True, True]


def test_a_batched_policy_returning_a_wrong_shape_exits_1():
    line = {"id": 1, "batch": [dict(item(s), noise=[0.0]) for s in scenes(2)]}
    _, status, err = run_serve([dict(PROBE, noise=[0.0]), line], None, batched=True,
                               _policy=lambda h, *a: np.zeros((len(h), 4, 4)), _noise=1)
    assert status == 1 and "must be (2, K, 4, 4)" in err


def test_flow_and_decode_requests_stay_single_in_batched_mode():
    scene = scenes(1, H=1, K=2)[0]

    def encode_batch(history, chunk, hand_points, world_points):
        return np.zeros((len(history), 6 * chunk.shape[1]))

    flow_request = request(scene, 1, eps=[1.0] * 12, t=0.5)
    decode_request = request(scene, 2, decode=[0.0] * 12)
    del decode_request["chunk"]
    answers, status, err = run_serve(
        [PROBE, flow_request, decode_request], encode_batch, batched=True,
        flow=lambda h, c, hp_, wp, eps, t: (eps * t, eps),
        decode=lambda a, h, hp_, wp: np.stack([h[0]] * 2))
    assert status == 0, err
    assert answers[1] == {"id": 1, "actions": [0.0] * 12, "flow_input": [0.5] * 12,
                          "flow_target": [1.0] * 12}
    assert answers[2] == {"id": 2, "chunk": [scene["history"][0].ravel().tolist()] * 2}


def test_a_batch_of_several_shapes_calls_the_function_once_per_shape_in_order():
    # The audit sends up to batch_size scenes of any shapes in one line; the helper stacks the
    # scenes of each shape and answers in the request's order, each answer the unbatched one.
    mixed = [s for pair in zip(scenes(3, seed=2, H=1, K=2), scenes(3, seed=3, H=0, K=5))
             for s in pair]
    calls = []

    def recording(history, chunk, hand_points, world_points):
        calls.append((history.shape[:2], chunk.shape[:2]))
        return repr_py.encode_batch(history, chunk, hand_points, world_points)
    answers, status, err = run_serve([PROBE, batched(1, mixed)], recording, batched=True)
    single = [run_serve([request(s, 7)], repr_py.encode)[0][0] for s in mixed]
    for a in single:
        del a["id"]
    assert status == 0, err
    assert answers[1] == {"id": 1, "batch": single}
    assert sorted(calls) == [((3, 1), (3, 5)), ((3, 2), (3, 2))]  # (B, H+1), (B, K)


def test_mutant_that_answers_a_mixed_batch_in_shape_order_is_caught(monkeypatch):
    # The planted fault: the answers grouped by shape instead of put back in the request's order.
    mixed = [s for pair in zip(scenes(2, seed=2, K=2), scenes(2, seed=3, K=5)) for s in pair]
    single = [run_serve([request(s, 7)], repr_py.encode)[0][0] for s in mixed]
    for a in single:
        del a["id"]
    rows = hp.loop._encoded_rows
    order = []

    def grouped(result, B):
        out = rows(result, B)
        order.extend(out)
        return out
    monkeypatch.setattr(hp.loop, "_encoded_rows", grouped)
    answers, status, _ = run_serve([PROBE, batched(1, mixed)], repr_py.encode_batch, batched=True)
    assert answers[1]["batch"] == single           # the helper itself puts them back in order
    assert order != single                         # which the shape order alone would not
