"""The --exec plug-in helper under the package's name: `from handcentric import plugin` gives
the public functions and constants of the top-level module handcentric_plugin
(python/handcentric_plugin.py; `import handcentric_plugin` works as well). The helper stays a
top-level, standard-library-only module so that a plug-in can import it without the compiled
extension; this module re-exports it rather than copying it."""
import types

import handcentric_plugin

# The helper's public names (not the standard modules it imports), as the same objects.
__all__ = sorted(name for name, value in vars(handcentric_plugin).items()
                 if not name.startswith("_") and not isinstance(value, types.ModuleType))
globals().update((name, getattr(handcentric_plugin, name)) for name in __all__)
