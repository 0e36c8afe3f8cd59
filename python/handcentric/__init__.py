"""Audit action representations and whole policies for equivariance under global rigid
transforms, in process, on Python callables and NumPy arrays (docs/AUDIT_YOUR_POLICY.md).

Everything public comes from the compiled extension handcentric._core (python/module.cpp);
`python -m handcentric` is the command line (__main__.py); handcentric.plugin is the --exec
plug-in helper (handcentric_plugin). Importing the package does not import NumPy: without it,
the audits raise ImportError when called (the extension says so), not at import."""
from . import _core
from ._core import *  # noqa: F401,F403  (every public name of the extension)
from ._core import __version__  # noqa: F401  (a dunder: not part of `import *`)

# Derived from the extension, so that a function added to _core is exported without an edit here.
__all__ = sorted(name for name in dir(_core) if not name.startswith("_"))
