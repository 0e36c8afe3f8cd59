"""The --exec plug-in helper under the package's name: `from handcentric import plugin` gives
the public functions and constants of the top-level package handcentric_plugin
(python/handcentric_plugin/; `import handcentric_plugin` works as well). The helper stays a
top-level, standard-library-only package so that a plug-in can import it without the compiled
extension; this module re-exports it rather than copying it."""
import handcentric_plugin

# The helper's public names (its __all__, not its modules), as the same objects.
__all__ = sorted(handcentric_plugin.__all__)
globals().update((name, getattr(handcentric_plugin, name)) for name in __all__)
