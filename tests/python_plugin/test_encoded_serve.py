"""The base64 encoding of batched lines (docs/AUDIT.md, "Encoded numbers"): serve(...,
batched=True) offers it in its hello, answers an encoded line with encoded arrays whose numbers
are the text answers' bit for bit, answers a text line as before byte for byte, and refuses a
bad encoded array (malformed base64, a length that is not the shape's, a wrong or unknown dtype,
NaN, a wrong shape) with one line naming the item and the field. Mutant twins (test_mutant_*)
plant a fault each check must flag."""
import base64
import contextlib
import io
import json
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_batched_serve import PROBE, batched, item, repr_py, scenes  # noqa: E402
from test_handcentric_plugin import hp, random_pose, run_serve  # noqa: E402


def encode_array(a, dtype="float64"):
    """An array in the encoded form, written here independently of the helper."""
    a = np.ascontiguousarray(a, dtype={"float64": "<f8", "float32": "<f4", "uint8": "u1"}[dtype])
    return {"dtype": dtype, "shape": list(a.shape), "data": base64.b64encode(a.tobytes()).decode()}


def decode_array(value):
    dtype = {"float64": "<f8", "float32": "<f4", "uint8": "u1"}[value["dtype"]]
    return np.frombuffer(base64.b64decode(value["data"]), dtype=dtype).reshape(value["shape"])


def encoded_item(scene, **fields):
    """One scene of an encoded batched line."""
    out = {key: encode_array(np.asarray(scene[key]).reshape(-1, *shape))
           for key, shape in (("history", (4, 4)), ("chunk", (4, 4)), ("hand_points", (3,)),
                              ("world_points", (3,)))}
    out.update(fields)
    return out


def encoded_line(rid, scene_list, **fields):
    return {"id": rid, "protocol": 2, "encoding": "base64",
            "batch": [encoded_item(s, **fields) for s in scene_list]}


def as_numbers(answer):
    """An encoded answer's arrays as the lists of numbers a text answer holds."""
    return {key: decode_array(value).ravel().tolist() for key, value in answer.items()}


def raw_serve(lines, encode, **kwargs):
    """serve() on these lines: (its output text, exit status, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    status = 0
    with contextlib.redirect_stderr(err):
        try:
            hp.serve(encode, stdin=io.StringIO("".join(json.dumps(r) + "\n" for r in lines)),
                     stdout=out, **kwargs)
        except SystemExit as exit_:
            status = exit_.code
    return out.getvalue(), status, err.getvalue()


# Two shapes in one line, so that the answers' order and the grouping are exercised too.
MIXED = [s for pair in zip(scenes(3, seed=5, H=2, K=3, hand=2, world=2),
                           scenes(3, seed=6, H=0, K=1, hand=0, world=0)) for s in pair]


def encoded_equals_text():
    """The answers to an encoded line, decoded, are the text answers to the same scenes, every
    number the same double."""
    text, status, err = run_serve([PROBE, batched(1, MIXED)], repr_py.encode_batch, batched=True)
    assert status == 0, err
    coded, status, _ = run_serve([PROBE, encoded_line(1, MIXED)], repr_py.encode_batch,
                                 batched=True)
    if status != 0:
        return False
    answers = coded[1]["batch"]
    return all(isinstance(v, dict) for a in answers for v in a.values()) and \
        [as_numbers(a) for a in answers] == text[1]["batch"]


def test_the_hello_offers_base64_when_batched_and_only_then():
    for kwargs, offered in [({"batched": True}, ["base64"]), ({}, None),
                            ({"batched": True, "encoding": None}, None),
                            ({"hello": True}, None)]:
        encode = repr_py.encode_batch if kwargs.get("batched") else repr_py.encode
        answers, status, err = run_serve([PROBE], encode, **kwargs)
        assert status == 0, err
        assert answers[0].get("hello", {}).get("encodings") == offered, kwargs


def test_an_encoded_line_is_answered_with_the_text_answers_bit_for_bit():
    assert encoded_equals_text()


def test_mutant_helper_that_rounds_its_encoded_answers_to_float32_is_caught(monkeypatch):
    exact = hp.codec._encode_array
    monkeypatch.setattr(hp.codec, "_encode_array",
                        lambda a: exact(a.astype(np.float32).astype(np.float64)))
    assert not encoded_equals_text()


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the garbage numbers it reads
def test_mutant_helper_that_reads_the_bytes_big_endian_is_caught(monkeypatch):
    monkeypatch.setitem(hp.codec._DTYPES, "float64", ">f8")
    assert not encoded_equals_text()


def test_a_text_line_gets_the_text_answer_byte_for_byte_from_a_helper_that_offers_base64():
    # An audit that does not know the encoding sends JSON numbers: the answer line is the one
    # of a helper that offers nothing, byte for byte.
    lines = [PROBE, batched(1, MIXED), batched(2, MIXED[:1])]
    offering, status, err = raw_serve(lines, repr_py.encode_batch, batched=True)
    assert status == 0, err
    plain, status, err = raw_serve(lines, repr_py.encode_batch, batched=True, encoding=None)
    assert status == 0, err
    assert offering.splitlines()[1:] == plain.splitlines()[1:]
    assert "dtype" not in offering


def test_extra_poses_and_scalars_arrive_from_an_encoded_line():
    seen = {}

    def encode(history, chunk, hand_points, world_points, extra_poses, scalars):
        seen.update(poses=extra_poses, scalars=scalars, history=history)
        return np.zeros((len(history), 6))

    rng = np.random.default_rng(8)
    starts = [random_pose(rng) for _ in range(2)]
    batch = scenes(2, H=1, K=1)
    line = {"id": 1, "protocol": 2, "encoding": "base64", "batch": [
        encoded_item(s, extra_poses={"start": encode_array(T)}, scalars={"gripper": 0.25 * i})
        for i, (s, T) in enumerate(zip(batch, starts))]}
    answers, status, err = run_serve([PROBE, line], encode, batched=True,
                                     extra_poses=["start"], scalars=["gripper"])
    assert status == 0, err
    assert np.array_equal(seen["poses"]["start"], np.stack(starts))
    assert np.array_equal(seen["scalars"]["gripper"], [0.0, 0.25])
    assert np.array_equal(seen["history"], np.stack([s["history"] for s in batch]))
    seen["history"][0, 0, 0] = 5.0  # the arrays are the function's own: writable
    assert answers[1]["batch"][0]["actions"] == encode_array(np.zeros(6))


def test_a_batched_policy_gets_encoded_noise_and_answers_encoded_chunks():
    def policy(history, hand_points, world_points, noise):
        out = np.repeat(history[:, :1], 2, axis=1)
        out[:, 1, :3, 3] += noise[:, :3]
        return out

    batch = scenes(3, H=1, K=1)
    noise = [np.array([float(i), 0.5, 0.0, 5.0]) for i in range(3)]
    items = [dict(encoded_item(s), noise=encode_array(n)) for s, n in zip(batch, noise)]
    for i in items:
        del i["chunk"]  # a policy's observation has none
    line = {"id": 1, "protocol": 2, "encoding": "base64", "batch": items}
    answers, status, err = run_serve([dict(PROBE, noise=[0.0] * 4), line], None, batched=True,
                                     _policy=policy, _noise=4)
    assert status == 0, err
    for s, n, a in zip(batch, noise, answers[1]["batch"]):
        expected = np.stack([s["history"][0], s["history"][0]])
        expected[1, :3, 3] += n[:3]
        assert a["chunk"]["shape"] == [2, 4, 4]
        assert np.array_equal(decode_array(a["chunk"]), expected)


def test_encoded_arrays_carry_float32_and_uint8_images_too():
    # What a later image field will send: the dtype travels with each array.
    rng = np.random.default_rng(9)
    images = [rng.integers(0, 256, size=(48, 64, 3)).astype(np.uint8),
              rng.normal(size=(48, 64)).astype(np.float32)]
    for image in images:
        value = hp.codec._encode_array(image)
        assert value == encode_array(image, value["dtype"])
        back = hp.codec._decode_array(value, "'image'", dtypes=("float32", "uint8"))
        assert back.dtype == image.dtype and np.array_equal(back, image)
    malformed = hp.protocol._Malformed
    with pytest.raises(malformed, match="'image' has dtype float64; it must be uint8"):
        hp.codec._decode_array(encode_array(np.zeros((2, 2))), "'image'", dtypes=("uint8",))


def spoiled(field="history", **change):
    """An encoded line of 3 scenes whose item 1 has `field` changed as `change` says."""
    line = encoded_line(1, scenes(3, H=1, K=2))
    value = line["batch"][1][field]
    for key, new in change.items():
        value[key] = new(value[key]) if callable(new) else new
    return line


def with_nan(data):
    a = np.frombuffer(base64.b64decode(data), "<f8").copy()
    a[5] = np.nan
    return base64.b64encode(a.tobytes()).decode()


@pytest.mark.parametrize("line, message", [
    (spoiled(data=lambda d: d[:8] + "*" + d[9:]),
     "batch[1]: 'history' has \"data\" that is not standard base64"),
    (spoiled(data=lambda d: d[:-4]),
     "batch[1]: 'history' of shape [2, 4, 4] and dtype float64 needs 256 bytes, but \"data\" "
     "holds 255"),
    (spoiled(dtype="float32", data=lambda d: base64.b64encode(
        np.zeros(32, "<f4").tobytes()).decode()),
     "batch[1]: 'history' has dtype float32; it must be float64"),
    (spoiled(dtype="float16"), "batch[1]: 'history' has dtype 'float16'; an encoded array's "
                               "dtype is one of float64, float32, uint8"),
    (spoiled(data=with_nan), "batch[1]: 'history' has a non-finite number at (0, 1, 1): nan"),
    (spoiled(shape=[2, 16], data=lambda d: d),
     "batch[1]: 'history' has shape [2, 16]; it must be (n, 4, 4) with n >= 1"),
    (spoiled(field="hand_points", shape=[3, 2]),
     "batch[1]: 'hand_points' has shape [3, 2]; it must be (n, 3)"),
    (spoiled(shape="2x4x4"), "batch[1]: 'history' has shape '2x4x4', not a list of at most 8"),
    (dict(spoiled(), batch=[dict(i, history={"data": ""}) for i in spoiled()["batch"]]),
     "batch[0]: 'history' = {\"data\": \"\"} is not an encoded array"),
    (dict(encoded_line(1, scenes(1)), encoding="zstd"),
     "a line in encoding \"zstd\", which the plug-in did not offer (its hello offers "
     "['base64'])"),
    (dict(item(scenes(1)[0]), id=1, encoding="base64"), "an encoded line that is not batched"),
])
def test_bad_encoded_requests_exit_2_with_one_line_naming_item_and_field(line, message):
    _, status, err = run_serve([PROBE, line], repr_py.encode_batch, batched=True)
    assert status == 2 and message in err and err.count("\n") == 1, err


def test_an_encoded_line_to_a_helper_that_did_not_offer_it_exits_2():
    _, status, err = run_serve([PROBE, encoded_line(1, scenes(2))], repr_py.encode_batch,
                               batched=True, encoding=None)
    assert status == 2 and "which the plug-in did not offer (its hello offers [])" in err


def test_an_unknown_encoding_is_a_value_error_naming_the_choices():
    with pytest.raises(ValueError, match="encoding must be one of 'base64', or None"):
        hp.serve(repr_py.encode_batch, batched=True, encoding="zstd")


def camera_policy_answers(images_of_item):
    """serve_policy(..., cameras=...) on one batched line of 2 scenes whose items carry
    images_of_item(i): (answers, status, stderr). The policy returns T_0 moved by the image's
    mean along x, so an image that arrived is seen in the answer."""
    def policy(history, hand_points, world_points, noise, images):
        out = history[:, :1].copy()
        out[:, 0, 0, 3] += images["eye_in_hand"].reshape(len(out), -1).mean(axis=1)
        return out

    batch = scenes(2, H=0, K=1)
    items = [dict(encoded_item(s), noise=encode_array(np.zeros(1))) for s in batch]
    for i, it in enumerate(items):
        del it["chunk"]
        it.update(images_of_item(i))
    line = {"id": 1, "protocol": 2, "encoding": "base64", "batch": items}
    out, err = io.StringIO(), io.StringIO()
    status = 0
    lines = [dict(PROBE, noise=[0.0]), line]
    with contextlib.redirect_stderr(err):
        try:
            hp.serve_policy(policy, noise=1, batched=True, cameras=("eye_in_hand",),
                            stdin=io.StringIO("".join(json.dumps(r) + "\n" for r in lines)),
                            stdout=out)
        except SystemExit as exit_:
            status = exit_.code
    return [json.loads(x) for x in out.getvalue().splitlines()], status, err.getvalue()


def test_a_policy_with_cameras_declares_them_and_gets_each_items_image():
    image = [np.full((4, 3, 2), float(i + 1), np.float32) for i in range(2)]
    answers, status, err = camera_policy_answers(
        lambda i: {"images": {"eye_in_hand": encode_array(image[i], "float32")}})
    assert status == 0, err
    assert answers[0]["hello"]["cameras"] == {"views": ["eye_in_hand"]}
    moved = [decode_array(a["chunk"])[0, 0, 3] for a in answers[1]["batch"]]
    shift = [m - s["history"][0][0, 3] for m, s in zip(moved, scenes(2, H=0, K=1))]
    assert shift == pytest.approx([1.0, 2.0])  # each item its own image


@pytest.mark.parametrize("images, message", [
    ({}, "'images' must hold one encoded image per camera"),
    ({"images": {"third_person": None}}, "'images' must hold one encoded image per camera"),
    ({"images": {"eye_in_hand": encode_array(np.zeros((1, 2, 2)))}}, "must be float32"),
])
def test_a_request_without_the_declared_images_exits_2_naming_the_item(images, message):
    answers, status, err = camera_policy_answers(lambda i: images)
    assert status == 2
    assert message in err and "batch[0]" in err
