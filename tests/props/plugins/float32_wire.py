#!/usr/bin/env python3
"""The Python example (examples/python_representation/repr.py) served batched with base64, with
a planted fault in the encoding: every array it encodes is rounded to float32 first (a lossy
wire). The test that the base64 audit gives the text audit's JSON byte for byte must tell it
apart."""
import importlib.util
import os
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "python"))  # the helper
import numpy as np  # noqa: E402
import handcentric_plugin as hp  # noqa: E402

spec = importlib.util.spec_from_file_location(
    "repr_example", os.path.join(ROOT, "examples", "python_representation", "repr.py"))
example = importlib.util.module_from_spec(spec)
spec.loader.exec_module(example)

# The helper writes every encoded answer with codec._encode_array, looked up at each call.
exact = hp.codec._encode_array
hp.codec._encode_array = lambda a: exact(a.astype(np.float32).astype(np.float64))

if __name__ == "__main__":
    hp.serve(example.encode_batch, batched=True)
