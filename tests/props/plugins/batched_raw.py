#!/usr/bin/env python3
"""A batching plug-in written against the protocol itself (no helper), for the --exec and
--policy-exec batch framing: its hello declares "batch": 4, then it answers every batched line,
misbehaving in the way argv[1] names.

  right         six zeros per scene (a policy: the chunk T_1 = T_0), every answer in order
  short         one answer too few in each batch of more than one scene
  item_shape    the second item of each batch has no "actions" (a policy: no "chunk")
  unbatched     answers a batched line as a single request ({"id", "actions"}), no "batch"
  slow          as right, after sleeping 0.06 s per scene of a batch of more than one
argv[2] == "policy": a policy plug-in (for --policy-exec).
"""
import json
import sys
import time

mode = sys.argv[1]
policy = sys.argv[2:] == ["policy"]


def answer(scene):
    if policy:
        return {"chunk": [scene["history"][0]]}
    return {"actions": [0.0] * 6}


first = True
for line in sys.stdin:
    request = json.loads(line)
    if first:
        first = False
        reply = {"id": request["id"], "hello": {"protocol": 2, "batch": 4}}
    elif "batch" not in request:
        reply = dict(answer(request), id=request["id"])  # decode and flow stay single
    else:
        scenes = request["batch"]
        answers = [answer(scene) for scene in scenes]
        if mode == "short" and len(answers) > 1:
            answers.pop()
        if mode == "item_shape" and len(answers) > 1:
            answers[1] = {"nothing": 1}
        if mode == "slow" and len(scenes) > 1:
            time.sleep(0.06 * len(scenes))
        reply = {"id": request["id"], "batch": answers}
        if mode == "unbatched":
            reply = dict(answers[0], id=request["id"])
    sys.stdout.write(json.dumps(reply) + "\n")
    sys.stdout.flush()
