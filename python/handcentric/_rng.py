"""A policy's own random draws, seen and controlled (used by the extension; no public names).

The audit pairs a(o, n) with a(g o, n): that blames g only when the policy's answer is the same
function of (o, n) on both sides. A policy that draws from torch's, NumPy's or Python's global
generator inside (Diffusion Policy's predict_action draws torch.randn) is not; with rng= the
audit seeds the generator alike before each call (seed_before_call), and without it the preflight
watches which generators a call advanced (snapshot, advanced) to say why answers differ.

The seeding itself is the plug-in helper's (handcentric_plugin.seeding): one implementation for
the audit in process and over the pipe (serve_policy(rng=...)), kept in the helper because a
plug-in runs without the compiled extension that this package needs.
"""
import sys

# seed_before_call is called by the extension (callables.cpp), not here.
from handcentric_plugin.seeding import RNG_MODES, seed_before_call  # noqa: F401


def _torch():
    return sys.modules.get("torch")


def _numpy():
    return sys.modules.get("numpy")


def snapshot():
    """The states of the global generators that are loaded (only modules already imported are
    looked at: a policy that draws from torch has imported it)."""
    states = {}
    torch = _torch()
    if torch is not None:
        states["torch's CPU generator"] = torch.get_rng_state()
        if torch.cuda.is_available() and torch.cuda.is_initialized():
            states["torch's CUDA generators"] = torch.cuda.get_rng_state_all()
    numpy = _numpy()
    if numpy is not None:
        states["NumPy's global generator"] = numpy.random.get_state()
    import random
    states["Python's random module"] = random.getstate()
    return states


def _same(a, b):
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    torch = _torch()
    if torch is not None and isinstance(a, torch.Tensor):
        return bool(torch.equal(a, b))
    numpy = _numpy()
    if numpy is not None and isinstance(a, numpy.ndarray):
        return bool(numpy.array_equal(a, b))
    return a == b


def advanced(before):
    """The names of the generators whose state differs from `before` (a snapshot()). A module
    first imported during the call is not counted: its import is not a draw."""
    after = snapshot()
    return [name for name, state in after.items()
            if name in before and not _same(before[name], state)]


def check_mode(rng):
    if rng is None:
        return ""
    if rng not in RNG_MODES:
        raise ValueError(
            "rng=%r is not a mode; use one of %s (torch's generators, NumPy's global one, or a "
            "seeded torch.Generator passed as generator=), or None" % (rng, ", ".join(
                '"%s"' % m for m in RNG_MODES)))
    if rng in ("torch", "generator") and _torch() is None:
        try:
            import torch  # noqa: F401
        except ImportError as e:
            raise ImportError('rng="%s" needs torch, which %s cannot import: %s'
                              % (rng, sys.executable, e)) from None
    return rng
