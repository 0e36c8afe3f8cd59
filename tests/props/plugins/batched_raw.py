#!/usr/bin/env python3
"""A batching plug-in written against the protocol itself (no helper), for the --exec and
--policy-exec batch framing: its hello declares "batch": 4, then it answers every batched line,
misbehaving in the way argv[1] names.

  right         six zeros per scene (a policy: the chunk T_1 = T_0), every answer in order
  short         one answer too few in each batch of more than one scene
  item_shape    the second item of each batch has no "actions" (a policy: no "chunk")
  unbatched     answers a batched line as a single request ({"id", "actions"}), no "batch"
  slow          as right, after sleeping 0.5 s per scene of a batch of more than one
The b64_* modes also offer "encodings": ["base64"], check that each batched line comes encoded,
and answer with encoded arrays; the second item of a batch of more than one is spoiled:
  b64_right     no spoiling: float64 zeros of shape [6] (a policy: T_0 as [1, 4, 4])
  b64_base64    "data" that is not base64 (a '!' in it)
  b64_length    one element too few for the shape
  b64_dtype     float32 bytes, declared "float32"
  b64_unknown   dtype "float16"
  b64_nan       a NaN among the numbers
  b64_shape     actions of shape [2, 3] (a policy: a chunk of shape [1, 16])
A line of the wrong form (encoded when not offered, or text when offered) exits with status 3.
argv[2] == "policy": a policy plug-in (for --policy-exec).
"""
import json
import sys
import time

mode = sys.argv[1]
policy = sys.argv[2:] == ["policy"]
encoded = mode.startswith("b64_")
if encoded:  # only then: the timeout test's first answer is due 0.04 s after the start
    import base64
    import struct


def array(numbers, shape, dtype="float64", fmt="<d"):
    data = b"".join(struct.pack(fmt, x) for x in numbers)
    return {"dtype": dtype, "shape": shape, "data": base64.b64encode(data).decode()}


def pose(scene):
    """T_0 of a scene, as 16 numbers, in either form."""
    history = scene["history"]
    if isinstance(history, dict):
        return list(struct.unpack("<16d", base64.b64decode(history["data"])[:128]))
    return history[0]


def answer(scene, spoil=False):
    if not encoded:
        return {"chunk": [pose(scene)]} if policy else {"actions": [0.0] * 6}
    numbers, shape = (pose(scene), [1, 4, 4]) if policy else ([0.0] * 6, [6])
    value = array(numbers, shape)
    if spoil and mode == "b64_base64":
        value["data"] = value["data"][:4] + "!" + value["data"][5:]
    elif spoil and mode == "b64_length":
        value = array(numbers[:-1], shape)
    elif spoil and mode == "b64_dtype":
        value = array(numbers, shape, "float32", "<f")
    elif spoil and mode == "b64_unknown":
        value["dtype"] = "float16"
    elif spoil and mode == "b64_nan":
        value = array(numbers[:2] + [float("nan")] + numbers[3:], shape)
    elif spoil and mode == "b64_shape":
        value["shape"] = [1, 16] if policy else [2, 3]
    return {"chunk" if policy else "actions": value}


def wrong_form(request):
    """Why a batched line is not in the form this plug-in asked for, or None."""
    if request.get("encoding") != ("base64" if encoded else None):
        return "encoding %r" % request.get("encoding")
    if encoded and not all(isinstance(item["history"], dict) for item in request["batch"]):
        return "an item whose history is not encoded"
    return None


first = True
for line in sys.stdin:
    request = json.loads(line)
    if first:
        first = False
        hello = {"protocol": 2, "batch": 4}
        if encoded:
            hello["encodings"] = ["base64"]
        reply = {"id": request["id"], "hello": hello}
    elif "batch" not in request:
        reply = dict(answer(request), id=request["id"])  # decode and flow stay single
    else:
        if wrong_form(request):
            sys.exit("batched_raw.py: a batched line with %s" % wrong_form(request))
        scenes = request["batch"]
        answers = [answer(scene, spoil=i == 1) for i, scene in enumerate(scenes)]
        if mode == "short" and len(answers) > 1:
            answers.pop()
        if mode == "item_shape" and len(answers) > 1:
            answers[1] = {"nothing": 1}
        if mode == "slow" and len(scenes) > 1:
            time.sleep(0.5 * len(scenes))
        reply = {"id": request["id"], "batch": answers}
        if mode == "unbatched":
            reply = dict(answers[0], id=request["id"])
    sys.stdout.write(json.dumps(reply) + "\n")
    sys.stdout.flush()
