"""Seeding a policy's own generator before a call, for rng="torch", "numpy" or "generator".

The audit pairs a(o, n) with a(g o, n): a policy that draws random numbers of its own answers
the same function of (o, n) on both sides only when its generator is seeded alike before each
call. This is the one implementation of that seeding, used over the pipe (serve_policy(rng=...))
and in process (handcentric/_rng.py imports it), so that the two cannot drift apart. It lives in
the helper rather than in the handcentric package because a plug-in must run without the compiled
extension, which `import handcentric` needs; handcentric_plugin is always installed beside it.
Standard library only: torch and NumPy are imported when a mode asks for them.
"""
RNG_MODES = ("torch", "numpy", "generator")


def seed_before_call(rng, seed, device=None):
    """Seeds the generator of mode `rng` with `seed` (0 <= seed < 2**63); returns the keywords
    the call gets ({"generator": g} for "generator", else {}). device: where the policy draws,
    a torch device or its name (None: the CPU); "generator" makes its torch.Generator there,
    since torch refuses a CPU generator for a draw on a GPU."""
    if rng == "torch":
        import torch
        # The CPU generator and every CUDA device's: torch.manual_seed seeds the devices of an
        # initialised CUDA now, and otherwise queues the seed for CUDA's lazy initialisation;
        # without a GPU it seeds the CPU alone.
        torch.manual_seed(seed)
        return {}
    if rng == "numpy":
        import numpy
        numpy.random.seed(seed % (1 << 32))  # the global generator takes a 32-bit seed
        return {}
    if rng == "generator":
        import torch
        generator = torch.Generator(device=device if device is not None else "cpu")
        generator.manual_seed(seed)
        return {"generator": generator}
    return {}
