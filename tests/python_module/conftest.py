"""The module under test comes from PYTHONPATH (ctest sets it to the build tree's python/ folder);
the CLI, for the tests that compare with it, from HANDCENTRIC_CLI."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
