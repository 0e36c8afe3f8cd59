#!/usr/bin/env python3
"""Planted faults for the --exec pipe: a plug-in that misbehaves in the way argv[1] names.

  not_json      answers a line that is not JSON
  wrong_id      answers with id + 1
  nan           answers an action that is NaN (Python's json writes the token NaN)
  big           answers an action of 1e999 (parses to infinity)
  length        answers 6 numbers, then 7 for a scene of the same shape
  exit_early    answers once, then prints to stderr and exits with status 3
  silent        reads requests and never answers (the --timeout must fire)
  constant      (not a fault) answers six zeros and no observation: invariant under everything
"""
import json
import sys

mode = sys.argv[1]
count = 0
for line in sys.stdin:
    request = json.loads(line)
    count += 1
    actions = [0.0] * 6
    reply_id = request["id"]
    if mode == "not_json":
        sys.stdout.write("actions: 1 2 3\n")
    elif mode == "silent":
        continue
    elif mode == "exit_early" and count == 2:
        sys.stderr.write("faulty plug-in: giving up on request %d\n" % request["id"])
        sys.exit(3)
    else:
        if mode == "wrong_id":
            reply_id += 1
        if mode == "nan":
            actions[2] = float("nan")
        if mode == "length" and count == 2:
            actions.append(1.0)
        text = json.dumps({"id": reply_id, "actions": actions})
        if mode == "big":
            text = text.replace("0.0]", "1e999]")
        sys.stdout.write(text + "\n")
    sys.stdout.flush()
