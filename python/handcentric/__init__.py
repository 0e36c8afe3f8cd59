"""Audit action representations and whole policies for equivariance under global rigid
transforms, in process, on Python callables and NumPy arrays (docs/AUDIT_YOUR_POLICY.md).

Everything public comes from the compiled extension handcentric._core (python/module.cpp);
`python -m handcentric` is the command line (__main__.py); handcentric.plugin is the --exec
plug-in helper (handcentric_plugin). Importing the package does not import NumPy: without it,
the audits raise ImportError when called (the extension says so), not at import."""
import importlib

try:
    # (`from . import _core` would turn a missing extension into a vaguer ImportError.)
    _core = importlib.import_module(__name__ + "._core")
except ModuleNotFoundError as e:
    if e.name != __name__ + "._core":
        raise
    # The source folder python/ on sys.path instead of the build tree or an installed package.
    raise ImportError(
        "handcentric's compiled extension _core is not beside %s: put build/python on "
        "PYTHONPATH after `cmake --build build --target handcentric_python`, or `pip install .` "
        "(docs/AUDIT_YOUR_POLICY.md)" % __path__[0]) from None
del importlib
from ._core import *  # noqa: F401,F403  (every public name of the extension)
from ._core import __version__  # noqa: F401  (a dunder: not part of `import *`)

from .locate import (lie_derivatives, locate, locate_figure,  # noqa: E402  (on top of _core)
                     locate_json, locate_text)
from .lerobot import lerobot_policy  # noqa: E402

_DETECT = ("DetectError", "detect_convention", "detect_text", "load_episodes")


def __getattr__(name):
    """detect.py's names, imported when first used: it imports NumPy, which importing the
    package does not."""
    if name in _DETECT:
        from . import detect
        return getattr(detect, name)
    raise AttributeError("module %r has no attribute %r" % (__name__, name))


# Derived from the extension, so that a function added to _core is exported without an edit here;
# and the functions written in Python (locate.py, lerobot.py, detect.py).
__all__ = sorted([name for name in dir(_core) if not name.startswith("_")]
                 + ["lie_derivatives", "locate", "locate_figure", "locate_json", "locate_text",
                    "lerobot_policy"]
                 + list(_DETECT))
