#!/usr/bin/env python3
"""A plug-in that writes 40 numbered lines to stderr, then raises inside encode.

What the audit should find: the plug-in exits with status 1 before answering request 0, and its
error message quotes the END of stderr: the last line of the traceback,
"RuntimeError: stderr_long: planted failure after 40 lines", must be in it (line 1 of the 40
need not be). The helper prints the full traceback and exits with status 1.
"""
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "..", "python")))  # the helper
import handcentric_plugin as hp  # noqa: E402


def encode(history, chunk, hand_points, world_points):
    for i in range(1, 41):
        sys.stderr.write("stderr_long: line %d of 40\n" % i)
    raise RuntimeError("stderr_long: planted failure after 40 lines")


if __name__ == "__main__":
    hp.serve(encode)
