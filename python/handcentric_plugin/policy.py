"""serve_policy(): a whole policy behind `handcentric audit --policy-exec`, and its rng=/reset=.

A policy plug-in is served by the same loop as a representation (loop.serve), with the policy in
place of encode; what is particular to policies is here: the cameras of the hello, and the
wrapper that calls reset() and seeds the policy's own generator before each observation's call
(seeding.seed_before_call, the implementation the in-process audit uses too).
"""
import struct
import sys

from ._numpy import np
from .protocol import _die
from .seeding import RNG_MODES, seed_before_call
from .interface import _Interface
from .loop import serve


def serve_policy(policy, *, extra_poses=(), scalars=(), noise=None, hello=None, batched=False,
                 batch_size=256, encoding="base64", cameras=None, rng=None, device=None,
                 reset=None, action_format=None, state_format=None, outputs=None, hands=None,
                 stages=None, stdin=None, stdout=None):
    """Answer `handcentric audit --policy-exec` requests: a whole policy (eq. 4 of the paper).

    policy(history, hand_points, world_points, noise) -> (K,4,4) world-frame poses T_1..T_K
    noise: the standard normals the request carries (256 unless `noise=n` asks for n); use them
        as the policy's only randomness, so that one noise vector gives one chunk.
    batched: policy(history (B,H+1,4,4), hand_points (B,n,3), world_points (B,m,3), noise (B,d))
        -> (B,K,4,4), on up to batch_size observations of one shape per call (needs NumPy).
    cameras: what the policy sees, e.g. ("eye_in_hand",) or {"views": ["eye_in_hand"],
        "image_size": [64, 48], "channels": "rgbd", "floor": False} (the defaults but views):
        the audit renders each observation's images and the policy gets images={view: (C,h,w)}
        float32 as a keyword ((B,C,h,w) batched), as audit_policy(..., cameras=...) passes them
        (docs/AUDIT_YOUR_POLICY.md). Needs NumPy.
    rng: None, "torch", "numpy" or "generator": the policy draws random numbers of its own
        (torch.randn inside, a DDPM sampler's per-step noise). Each observation is then asked in
        a call of its own, after seeding that generator from the observation's noise vector
        ("generator": a seeded torch.Generator passed as generator=), so that o and g o, which
        the audit asks with the same noise, get the same draws. Without it the audit's
        preflight finds answers that differ on the same observation and gives no verdict.
        "torch" seeds torch's CPU generator and every CUDA device's, as the in-process audit does.
    device: the torch device the policy draws on (e.g. "cuda"; None: the CPU), as
        audit_policy's device=: rng="generator" makes its torch.Generator there (torch refuses
        a CPU generator for a draw on a GPU). The other modes do not need it.
    reset: a function of no arguments (e.g. LeRobot's policy.reset), for a policy that keeps
        state between calls (an action queue, a history). The hello then declares "episodes":
        a request of the audit's closed loop (`handcentric audit --episodes N`) carries
        "episode": {"index", "step"}, and reset() runs at its step 0 only, so the policy keeps
        its state through the episode; every other request is a call of its own, reset() first.
    action_format, state_format: the layouts of the poses the policy returns and is given
        (formats.py: "pos_quat_xyzw", "pos_rot6d_rows", "pos_euler_xyz", ...; default
        "matrix"): history is then (H+1, w) ((B, H+1, w) batched), each extra pose (w,), and
        the policy returns (K, w) ((B, K, w)). The audit decodes every pose and refuses one that
        contradicts its layout (a quaternion off unit norm), naming it.
    outputs: {"hand": "pose", "gripper": "invariant"}: the policy returns a dict of these; each
        is audited on its own (a pose chunk moves with g, invariant numbers must not change).
    hands: ("left", "right"): history is {hand: (H+1, w)} and the policy returns one chunk per
        hand in its dict, under the hands' names (verdicts per hand).
    stages: [("normalize", "poses"), ("to_hand", "features"), ...]: the stages of the policy's
        pipeline, in execution order, each producing world-frame "poses" (which must move with
        g) or "features" (which must not change). The policy then returns the pair (its answer,
        {stage: value}) on every call, each stage's output for that call (a "poses" value
        (K, 4, 4) or (K, w) in the action layout, (B, K, ...) batched; a "features" value any
        numbers, (B, ...) batched); `handcentric audit --policy-exec CMD --locate` asks for them
        and names the first stage that breaks its kind (interface.py).
    With any of these five the requests carry JSON numbers (no base64 offer).
    extra_poses, scalars, hello, encoding, stdin, stdout: as for serve().
    """
    interface = None
    if action_format is not None or state_format is not None or outputs is not None \
            or hands is not None or stages is not None:
        interface = _Interface(state_format, action_format, outputs, hands, stages)
        hello = True
    if rng is not None or reset is not None:
        policy = _paired_policy(policy, rng, reset, batched, device)
        hello = True
    if cameras is not None:
        if np is None:
            _die(1, "handcentric_plugin: serve_policy(..., cameras=...) needs NumPy, which does "
                    "not import in %s (Debian: python3-numpy)" % sys.executable)
        cameras = dict(cameras) if isinstance(cameras, dict) else {
            "views": [cameras] if isinstance(cameras, str) else list(cameras)}
        if not cameras.get("views") or not all(isinstance(v, str) for v in cameras["views"]):
            raise ValueError("cameras needs at least one view name, e.g. ('eye_in_hand',), "
                             "got %r" % (cameras,))
        hello = True
    serve(None, extra_poses=extra_poses, scalars=scalars, hello=hello, batched=batched,
          batch_size=batch_size, encoding=encoding, stdin=stdin, stdout=stdout, _policy=policy,
          _noise=noise, _cameras=cameras, _interface=interface, _rng=rng,
          _episodes=reset is not None)


def _noise_seed(noise):
    """A seed below 2**63 from the bytes of one noise vector (the same vector, the same seed)."""
    import hashlib
    values = noise.tolist() if hasattr(noise, "tolist") else list(noise)
    digest = hashlib.sha256(struct.pack("<%dd" % len(values), *values)).digest()
    return int.from_bytes(digest[:8], "little") >> 1


def _paired_policy(policy, rng, reset, batched, device=None):
    """policy called after reset() and, with rng, one observation per call with its generator
    seeded from that observation's noise (serve_policy's rng=, device= and reset=)."""
    if rng is not None and rng not in RNG_MODES:
        raise ValueError('rng=%r is not a mode; use "torch", "numpy", "generator" or None' % (rng,))
    if rng == "numpy" and np is None:
        raise ValueError('rng="numpy" needs NumPy, which does not import in %s' % sys.executable)
    if reset is not None and not callable(reset):
        raise TypeError("reset must be a function of no arguments (e.g. policy.reset), got %r"
                        % (reset,))

    def one_call(history, hand_points, world_points, noise, kwargs, seed_noise, episode):
        # A closed-loop request past its episode's first step keeps the state (no reset).
        if reset is not None and not (isinstance(episode, dict) and episode.get("step", 0) > 0):
            reset()
        extra = (seed_before_call(rng, _noise_seed(seed_noise), device)
                 if rng is not None else {})
        return policy(history, hand_points, world_points, noise, **dict(kwargs, **extra))

    def call(history, hand_points, world_points, noise, _episode=None, **kwargs):
        if rng is None or not batched:
            return one_call(history, hand_points, world_points, noise, kwargs, noise, _episode)

        def row(value, i):
            return {k: row(v, i) for k, v in value.items()} if isinstance(value, dict) \
                else value[i:i + 1]

        def as_numpy(x):  # a torch result, on any device, with or without grad
            return x.detach().cpu().numpy() if hasattr(x, "detach") else np.asarray(x)

        def joined(parts):  # the rows' results, one batch again (a dict of outputs, a pair)
            if isinstance(parts[0], tuple):
                return tuple(joined([p[i] for p in parts]) for i in range(len(parts[0])))
            if isinstance(parts[0], dict):
                return {k: joined([p[k] for p in parts]) for k in parts[0]}
            return np.concatenate([as_numpy(p) for p in parts], axis=0)
        return joined([one_call(row(history, i), hand_points[i:i + 1], world_points[i:i + 1],
                                noise[i:i + 1], {k: row(v, i) for k, v in kwargs.items()},
                                noise[i], _episode)
                       for i in range(len(noise))])
    return call
