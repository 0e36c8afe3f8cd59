#!/usr/bin/env python3
"""The cost of a Python callable under the audit, in process (`import handcentric`) and over the
`--exec` pipe, and the time of a whole default in-process audit (docs/BENCHMARKS.md, "Python").

  1. The same trivial representation (zeros, 6 numbers per pose) audited on one cell set (se3,
     eye-in-hand) in process and through `--exec`, at 1000 and at 1 case: the difference over
     the difference in calls is the cost of one more call, the checks' own work included, with
     the start-up (the plug-in's interpreter and NumPy, the handshake) taken out. The callable's
     own time, measured alone, is printed beside.
  2. handcentric.audit of a NumPy hand-centric representation (actions and observation, on
     handcentric_plugin's vectorized helpers) at the defaults: 1000 cases, all five groups, both
     views, pointwise and in distribution, injectivity. The goal is under 5 s.

Run from the repository after building (module, CLI):
    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py build/apps/handcentric
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import handcentric
import handcentric_plugin as hp

CLI = sys.argv[1] if len(sys.argv) > 1 else "build/apps/handcentric"
calls = 0


def zeros(history, chunk, hand_points, world_points):
    global calls
    calls += 1
    return np.zeros(6 * len(chunk))


PLUGIN = r'''
import atexit, os, sys
sys.path.insert(0, %r)
import numpy as np
import handcentric_plugin as hp
calls = 0
def zeros(history, chunk, hand_points, world_points):
    global calls
    calls += 1
    return np.zeros(6 * len(chunk))
atexit.register(lambda: open(%r, "w").write(str(calls)))
hp.serve(zeros)
'''


def wall(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def best_of(n, function):
    return min((wall(function) for _ in range(n)), key=lambda r: r[0])


def run_cli(*args):
    return subprocess.run([CLI, "audit", *args, "--json"], check=True, capture_output=True,
                          text=True).stdout


def hand_centric_actions(history, chunk, hand_points, world_points):
    return hp.pose_vector(hp.relative_pose(history[0], chunk)).ravel()


def hand_centric_observation(history, hand_points, world_points):
    T0 = history[0]
    return np.concatenate([hp.pose_vector(hp.relative_pose(T0, history)).ravel(),
                           hand_points.ravel(), hp.relative_points(T0, world_points).ravel()])


def in_process(cases):
    global calls
    calls = 0
    seconds, _ = best_of(3, lambda: handcentric.audit(zeros, groups="se3", views="eye_in_hand",
                                                      cases=cases, seed=1))
    return seconds, calls // 3


def piped(cases, folder, helper):
    script, count = os.path.join(folder, "zeros.py"), os.path.join(folder, "calls")
    with open(script, "w") as out:
        out.write(PLUGIN % (os.path.abspath(helper), count))
    command = "%s %s" % (sys.executable, script)
    seconds, _ = best_of(3, lambda: run_cli("--exec", command, "--group", "se3",
                                            "--view", "eye_in_hand",
                                            "--cases", str(cases), "--seed", "1"))
    return seconds, int(open(count).read())


def main():
    helper = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "python")
    args = (np.stack([np.eye(4)] * 3), np.stack([np.eye(4)] * 8), np.zeros((2, 3)),
            np.zeros((0, 3)))
    alone_s, _ = best_of(3, lambda: [zeros(*args) for _ in range(10000)])
    print("the callable alone: %.2f us per call" % (1e6 * alone_s / 10000))
    rows = [("in process", in_process)]
    with tempfile.TemporaryDirectory() as folder:
        rows.append(("--exec pipe", lambda cases: piped(cases, folder, helper)))
        for name, run in rows:
            (big_s, big_calls), (small_s, small_calls) = run(1000), run(1)
            print("%-12s se3, eye_in_hand: 1000 cases %.3f s, %d calls; 1 case %.3f s, %d calls; "
                  "%.1f us per further call (best of 3)"
                  % (name, big_s, big_calls, small_s, small_calls,
                     1e6 * (big_s - small_s) / (big_calls - small_calls)))
    seconds, result = best_of(3, lambda: handcentric.audit(hand_centric_actions,
                                                           hand_centric_observation))
    holds = all(c["invariant"] for c in result["checks"])
    print("default in-process audit of a NumPy hand-centric representation (1000 cases, 5 groups, "
          "2 views, %d checks, all invariant: %s): %.2f s (best of 3; goal < 5 s)"
          % (len(result["checks"]), holds, seconds))


if __name__ == "__main__":
    main()
