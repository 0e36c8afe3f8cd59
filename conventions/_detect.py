#!/usr/bin/env python3
"""`handcentric conventions --detect FILE` runs this: the detector of python/handcentric/detect.py
(handcentric.detect_convention) on a file of recorded episodes, loaded from the source tree
without the compiled extension (it needs NumPy and the plug-in helper only), so that the command
works with the interpreter that runs the plug-ins. Not a plug-in (the `_` files are not rows).

    python3 conventions/_detect.py episodes.npz --plugins conventions [--declared pos_euler_xyz]

Prints the ranking and the best fit's verdict; a bad input is one line on stderr, exit 1."""
import importlib.util
import os
import sys

PYTHON = os.path.normpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), os.pardir,
                                       "python"))
sys.path.insert(0, PYTHON)  # handcentric_plugin, which the detector imports

if __name__ == "__main__":
    spec = importlib.util.spec_from_file_location(
        "handcentric_detect", os.path.join(PYTHON, "handcentric", "detect.py"))
    detect = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(detect)
    sys.exit(detect.main(sys.argv[1:]))
