#!/usr/bin/env python3
"""What an audit of a real-size policy costs: rows asked, calls, wall time, and the guarantees
the verdicts state (docs/BENCHMARKS.md, "Audit cost of a real-size policy").

Two policies, both hand-centric (Theorem 1: equivariant for any weights):
  unet     a Diffusion-Policy-style temporal UNet, written here after the published
           architecture (ConditionalUnet1D: residual 1D conv blocks, GroupNorm + Mish, FiLM
           on the observation feature and the diffusion-step embedding; down_dims (64, 128,
           256), kernel 5, horizon 16), fixed random weights (seeded), float32, sampled by DDIM
           in 10 steps from the audit's noise (16 x 9 = 144 numbers). Its observation is the
           history T_0^-1 T_-1 and the eye-in-hand points, in the hand frame at T_0; its 16
           actions (position + 6D rows) are decoded in float64, T_k = T_0 [GS(6D), p].
  trivial  affine in its noise: T_k = T_0 [R_k, c_k + 0.01 n_k] with fixed R_k, c_k and n_k
           the k-th triple of the noise, asked with 256 noise numbers (the default) and 144.
The UNet runs in float32, so its audits pass precision="float32" (docs/AUDIT.md, "Tolerances
and rounding"): at the default float64 floor, 1e-9 (1 + L), the network's own float32 rounding,
which differs with the batch a row rides in (o and g o are asked in different batches),
is a "NO" pointwise, and each failing check then shrinks its witness one row per call
(--unet-precision float64 shows it). The trivial policy is float64 and audited at float64.
Each is audited, batch_size=256, array="torch", on scenes of one shape (history=1,
hand_points=3, world_points=4), by
  assert_equivariant(policy, "se3")     pointwise, both views (it returns no report)
  audit_policy(policy, groups=["se3"])  pointwise and in distribution, both views
  audit_policy(policy)                  every group, both views, both modes
through a wrapper that counts the calls and the rows (observations) it receives.

The guarantees are read from each audit's JSON: a pointwise "yes" states
`detectable_frequency` (the smallest frequency of violating draws found with 99% probability);
an in-distribution "yes" by the tests states `detectable_shift` and `detectable_scale_ratio`,
one decided exactly (`exact_gaussian`) states neither (it compares the Gaussian laws exactly).
assert_equivariant decides the same pointwise cases (the same seed and classifier with the
in-distribution checks off), so its guarantee is that of the se3 audit's pointwise checks.

Where the rows go. Each row is attributed from what the policy is given, which is exact and
costs nothing: the view from the world points (the eye-in-hand view has none), the preflight
as the first calls (27 rows in 7 calls and 6 rows in 2 more when batched, docs/AUDIT.md), the
mode from the order and the noise (a view's in-distribution checks run after its pointwise ones
and begin with an affine probe, the zero noise vector; their rows are those probes, zero and
unit vectors, or fresh draws). A pointwise "yes" gives the cell's law (method
"from_pointwise", docs/AUDIT.md), so by default the in-distribution checks ask rows only where
the pointwise check fails; each audit_policy is also run with test_law=True, which tests every
cell's law, the audit as it was before. The group cannot be read from a row: the checks
of one view and mode run one group after another and share cached answers (every check draws
its scenes from the same seed, so a(o, n) asked by one group is not asked again by the next).
The trivial policy is cheap, so it is also audited one group at a time, which gives each
group's cost alone; their sum against the whole audit shows what the groups share. The UNet's
se3 audit is that group alone.

Run from the repository (after building the module):
    PYTHONPATH=build/python /usr/bin/python3 bench/audit_cost.py [--quick] [--json FILE]
        [--only unet|trivial]
--quick: a tiny UNet and 20 cases, a smoke test of a few seconds (its times mean nothing).
"""
import argparse
import json
import math
import sys
import time

import numpy as np
import torch

import handcentric

HORIZON = 16
ACTION_DIMS = 9                  # position + the first two rows of R (6D)
UNET_NOISE = HORIZON * ACTION_DIMS
SHAPE = dict(history=1, hand_points=3, world_points=4)
GROUPS = ("translation", "rotation", "se2", "se3", "c8")
PREFLIGHT_CALLS = 9              # 7 calls + 2 for a batched policy (docs/AUDIT.md, preflight)


def gram_schmidt(six):
    """(..., 6) two rows -> (..., 3, 3) rotations with those rows orthonormalized first."""
    a = six[..., :3] / six[..., :3].norm(dim=-1, keepdim=True)
    b = six[..., 3:] - (a * six[..., 3:]).sum(-1, keepdim=True) * a
    b = b / b.norm(dim=-1, keepdim=True)
    return torch.stack([a, b, torch.cross(a, b, dim=-1)], dim=-2)


def hand_frame_poses(actions, T0):
    """(B, K, 9) hand-frame [p, 6D] -> (B, K, 4, 4) world poses T_0 [R, p], in float64."""
    a = actions.double()
    local = torch.zeros(a.shape[:-1] + (4, 4), dtype=torch.float64)
    local[..., :3, :3] = gram_schmidt(a[..., 3:])
    local[..., :3, 3] = a[..., :3]
    local[..., 3, 3] = 1.0
    return T0[:, None] @ local


# The network, after real-stanford/diffusion_policy@4bf419aa5a9b25bde5cd1e332b077f45fba190c1:
# diffusion_policy/model/diffusion/conditional_unet1d.py:ConditionalUnet1D (and its
# ConditionalResidualBlock1D), with FiLM scale and bias and a step embedding of 128, as the
# published configurations set them (cond_predict_scale, diffusion_step_embed_dim). Written here
# from that description.

class ConvNormMish(torch.nn.Sequential):
    def __init__(self, channels_in, channels_out, kernel, groups=8):
        super().__init__(torch.nn.Conv1d(channels_in, channels_out, kernel, padding=kernel // 2),
                         torch.nn.GroupNorm(groups, channels_out), torch.nn.Mish())


class FilmResidualBlock(torch.nn.Module):
    """Two conv blocks; the condition scales and shifts the first one's channels (FiLM)."""

    def __init__(self, channels_in, channels_out, condition, kernel):
        super().__init__()
        self.first = ConvNormMish(channels_in, channels_out, kernel)
        self.second = ConvNormMish(channels_out, channels_out, kernel)
        self.film = torch.nn.Sequential(torch.nn.Mish(),
                                        torch.nn.Linear(condition, 2 * channels_out))
        self.skip = (torch.nn.Conv1d(channels_in, channels_out, 1)
                     if channels_in != channels_out else torch.nn.Identity())

    def forward(self, x, condition):
        scale, shift = self.film(condition)[..., None].chunk(2, dim=1)
        return self.second(scale * self.first(x) + shift) + self.skip(x)


def step_embedding(steps, size):
    """Sinusoidal embedding (B,) -> (B, size) of the diffusion step."""
    half = size // 2
    rates = torch.exp(-math.log(10000.0) * torch.arange(half) / (half - 1))
    angle = steps.float()[:, None] * rates[None]
    return torch.cat([angle.sin(), angle.cos()], dim=-1)


class TemporalUnet(torch.nn.Module):
    """(B, horizon, dims) noisy actions, (B,) steps, (B, c) observation -> (B, horizon, dims)."""

    def __init__(self, dims, observation, down_dims, kernel=5, embed=128):
        super().__init__()
        self.embed = embed
        self.step_mlp = torch.nn.Sequential(torch.nn.Linear(embed, 4 * embed), torch.nn.Mish(),
                                            torch.nn.Linear(4 * embed, embed))
        condition = embed + observation
        widths = [dims] + list(down_dims)
        pairs = list(zip(widths[:-1], widths[1:]))
        self.down = torch.nn.ModuleList()
        for level, (a, b) in enumerate(pairs):
            last = level == len(pairs) - 1
            self.down.append(torch.nn.ModuleList([
                FilmResidualBlock(a, b, condition, kernel),
                FilmResidualBlock(b, b, condition, kernel),
                torch.nn.Identity() if last else torch.nn.Conv1d(b, b, 3, stride=2, padding=1)]))
        self.middle = torch.nn.ModuleList([FilmResidualBlock(widths[-1], widths[-1], condition,
                                                             kernel) for _ in range(2)])
        self.up = torch.nn.ModuleList()
        for a, b in reversed(pairs[1:]):
            self.up.append(torch.nn.ModuleList([
                FilmResidualBlock(2 * b, a, condition, kernel),
                FilmResidualBlock(a, a, condition, kernel),
                torch.nn.ConvTranspose1d(a, a, 4, stride=2, padding=1)]))
        self.out = torch.nn.Sequential(ConvNormMish(down_dims[0], down_dims[0], kernel),
                                       torch.nn.Conv1d(down_dims[0], dims, 1))

    def forward(self, x, steps, observation):
        condition = torch.cat([self.step_mlp(step_embedding(steps, self.embed)), observation], -1)
        x = x.transpose(1, 2)
        skips = []
        for first, second, downsample in self.down:
            x = second(first(x, condition), condition)
            skips.append(x)
            x = downsample(x)
        for block in self.middle:
            x = block(x, condition)
        for first, second, upsample in self.up:
            x = torch.cat([x, skips.pop()], dim=1)
            x = upsample(second(first(x, condition), condition))
        return self.out(x).transpose(1, 2)


class DdimSampler:
    """Deterministic DDIM (eta = 0) over a squared-cosine schedule of 100 training steps,
    epsilon prediction, x_0 clipped to [-1, 1] (Diffusion Policy's scheduler settings)."""

    def __init__(self, steps=10, train_steps=100):
        t = torch.arange(train_steps + 1, dtype=torch.float64) / train_steps
        f = torch.cos((t + 0.008) / 1.008 * math.pi / 2) ** 2
        betas = (1 - f[1:] / f[:-1]).clamp(max=0.999)
        self.alpha_bar = torch.cumprod(1 - betas, 0).float()
        self.timesteps = list(range(0, train_steps, train_steps // steps))[::-1]
        self.stride = train_steps // steps

    def sample(self, model, x, observation):
        for t in self.timesteps:
            eps = model(x, torch.full((x.shape[0],), t), observation)
            a = self.alpha_bar[t]
            a_prev = self.alpha_bar[t - self.stride] if t >= self.stride else torch.tensor(1.0)
            x0 = ((x - (1 - a).sqrt() * eps) / a.sqrt()).clamp(-1, 1)
            x = a_prev.sqrt() * x0 + (1 - a_prev).sqrt() * eps
        return x


class UnetPolicy:
    """The hand-centric outer policy: observation in the hand frame at T_0, the UNet's chunk
    mapped back by T_0 (Theorem 1). Batched: (B, ...) float64 tensors -> (B, 16, 4, 4)."""

    def __init__(self, down_dims, embed=128, seed=0):
        torch.manual_seed(seed)
        observation = 9 * SHAPE["history"] + 3 * SHAPE["hand_points"]
        self.net = TemporalUnet(ACTION_DIMS, observation, down_dims, embed=embed).float().eval()
        self.sampler = DdimSampler()
        # The un-normalizer of the actions: 5 cm of position, 6D rows around the identity's,
        # so that Gram-Schmidt never meets near-parallel rows.
        self.scale = torch.tensor([0.05] * 3 + [0.3] * 6)
        self.offset = torch.tensor([0.0] * 3 + [1.0, 0.0, 0.0, 0.0, 1.0, 0.0])

    def parameters(self):
        return sum(p.numel() for p in self.net.parameters())

    @torch.no_grad()
    def __call__(self, history, hand_points, world_points, noise):
        T0 = history[:, 0]
        relative = torch.linalg.solve(T0[:, None], history[:, 1:])        # T_0^-1 T_-k
        past = torch.cat([relative[..., :3, 3], relative[..., :2, :3].flatten(-2)], -1)
        observation = torch.cat([past.flatten(1), hand_points.flatten(1)], -1).float()
        x = noise.float().reshape(-1, HORIZON, ACTION_DIMS)
        actions = self.sampler.sample(self.net, x, observation) * self.scale + self.offset
        return hand_frame_poses(actions, T0)


def trivial_policy(history, hand_points, world_points, noise):
    """Affine in its noise: T_0 [R_k, c_k + 0.01 n_k], R_k a turn of 0.05 k rad about z."""
    k = torch.arange(1, HORIZON + 1, dtype=torch.float64)
    angle = 0.05 * k
    local = torch.zeros(HORIZON, 4, 4, dtype=torch.float64)
    local[:, 0, 0] = local[:, 1, 1] = angle.cos()
    local[:, 0, 1], local[:, 1, 0] = -angle.sin(), angle.sin()
    local[:, 2, 2] = local[:, 3, 3] = 1.0
    local[:, 0, 3] = 0.01 * k
    local = local.expand(noise.shape[0], -1, -1, -1).clone()
    local[..., :3, 3] += 0.01 * noise[:, :3 * HORIZON].reshape(-1, HORIZON, 3)
    return history[:, 0, None] @ local


class Counting:
    """The policy with every call logged: its rows, by view and by the kind of noise."""

    def __init__(self, policy):
        self.policy = policy
        self.law_started = set()  # the views whose in-distribution checks have begun
        self.calls = []           # per call: {(view, kind): rows}

    def __call__(self, history, hand_points, world_points, noise):
        view = "third_person" if world_points.shape[1] > 0 else "eye_in_hand"
        ones = (noise == 1).sum(1) == 1
        unit = ones & ((noise != 0).sum(1) == 1)
        zero = (noise == 0).all(1)
        probes = int((zero | unit).sum())
        # The in-distribution checks of a view begin with an affine probe (zero noise) and run
        # after its pointwise checks: before the first probe a row is pointwise, after it a draw.
        if probes and len(self.calls) >= PREFLIGHT_CALLS:
            self.law_started.add(view)
        rest = "draw" if view in self.law_started else "pointwise"
        kinds = {"probe": probes, rest: noise.shape[0] - probes}
        self.calls.append({(view, kind): n for kind, n in kinds.items() if n})
        return self.policy(history, hand_points, world_points, noise)

    def rows(self):
        return sum(sum(c.values()) for c in self.calls)

    def where(self):
        """Rows and calls per part: the preflight, then each view and mode; the rows of the
        in-distribution checks split into affine probes (zero and unit noise) and draws."""
        parts = {}
        for i, call in enumerate(self.calls):
            if i < PREFLIGHT_CALLS:
                named = {"preflight": sum(call.values())}
            else:
                named = {}
                for (view, kind), rows in call.items():
                    mode = "pointwise" if kind == "pointwise" else "distribution"
                    key = "%s, %s" % (view, mode)
                    named[key] = named.get(key, 0) + rows
                    if mode == "distribution":
                        named[key + ", " + kind] = rows
            for key, rows in named.items():
                entry = parts.setdefault(key, {"rows": 0, "calls": 0})
                entry["rows"] += rows
                entry["calls"] += 1
        return dict(sorted(parts.items()))


def guarantees(report):
    """What the checks of an audit_policy report state they could miss."""
    point = [c for c in report["checks"] if c["mode"] == "pointwise"]
    law = [c for c in report["checks"] if c["mode"] == "distribution"]

    def worst(checks, key):
        values = [c[key] for c in checks if c.get(key) is not None]
        return max(values) if values else None
    return {
        "checks": len(report["checks"]),
        "equivariant": sum(bool(c["equivariant"]) for c in report["checks"]),
        "detect": report.get("detect"),
        "pointwise_drawn_min": min((c["cases"] + c["near_identity_cases"] for c in point),
                                   default=None),
        "pointwise_cases_min": min((c["cases"] for c in point), default=None),
        "detectable_frequency": worst(point, "detectable_frequency"),
        "distribution_methods": sorted({c.get("method") for c in law if c.get("method")}),
        "distribution_cases_min": min((c["cases"] for c in law), default=None),
        "detectable_shift": worst(law, "detectable_shift"),
        "detectable_scale_ratio": worst(law, "detectable_scale_ratio"),
    }


def load():
    """The 1-minute load average: the machine is shared, and a time means little without it."""
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def measure(name, policy, noise, audit, cases, **options):
    """One audit through a fresh counter: rows, calls, wall and what its report states."""
    counting = Counting(policy)
    common = dict(noise=noise, batch_size=256, array="torch", quiet=True, **SHAPE)
    if "detect" not in options:  # detect= sets the cases itself
        common["cases"] = cases
    start = time.perf_counter()
    if audit == "assert_equivariant":
        try:
            handcentric.assert_equivariant(counting, "se3", **common, **options)
            report, held = None, True
        except AssertionError as error:
            report, held = None, "NO: " + str(error).splitlines()[0]
    else:
        report = handcentric.audit_policy(counting, **common, **options)
        held = all(c["equivariant"] for c in report["checks"])
    wall = time.perf_counter() - start
    row = {"policy": name, "noise": noise, "audit": audit, "loadavg_after": load(), "options": {
        k: list(v) if isinstance(v, tuple) else v for k, v in options.items()},
        "rows": counting.rows(), "calls": len(counting.calls), "wall_s": round(wall, 2),
        "held": held, "where": counting.where()}
    if report is not None:
        row["guarantees"] = guarantees(report)
    print("%-8s noise %3d  %-18s %-22s %7d rows %5d calls %8.2f s  %s" % (
        name, noise, audit, json.dumps(row["options"]), row["rows"], row["calls"], wall,
        "holds" if held is True else held), flush=True)
    return row


def suite(name, policy, noise, cases, quick=False, **options):
    """The three audits; --quick asks a UNet for its pointwise one only (the other two ask it
    thousands of rows even at 20 cases, in-distribution cells running at least 10)."""
    runs = [measure(name, policy, noise, "assert_equivariant", cases, **options)]
    if not quick or name == "trivial":
        for law in ({}, {"test_law": True}):
            runs += [measure(name, policy, noise, "audit_policy", cases, groups=("se3",),
                             **law, **options),
                     measure(name, policy, noise, "audit_policy", cases, **law, **options)]
        # The cases a stated frequency needs (detect=): 459 for 1%, against the default 1000's
        # 0.46%; --quick 21 for 20%.
        detect = {"detect": 0.2 if quick else 0.01}
        runs += [measure(name, policy, noise, "audit_policy", cases, groups=("se3",),
                         **detect, **options),
                 measure(name, policy, noise, "audit_policy", cases, **detect, **options)]
    return runs


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a tiny smoke configuration")
    parser.add_argument("--json", metavar="FILE", help="write the numbers there")
    parser.add_argument("--only", choices=("unet", "trivial"))
    parser.add_argument("--unet-precision", default="float32", choices=("float32", "float64"),
                        help="the audits' precision= for the UNet (default float32)")
    parser.add_argument("--threads", type=int, default=2,
                        help="torch's threads (default 2; --quick: 1)")
    args = parser.parse_args()
    # --quick on one thread: a smoke test runs beside other tests, where two threads' barriers
    # wait on each other for whole time slices.
    torch.set_num_threads(1 if args.quick else args.threads)
    cases = 20 if args.quick else 1000
    before = load()
    runs = []
    if args.only != "unet":
        # --quick: the 48 noise numbers the trivial policy reads, so that its affine probes
        # stay few.
        for noise in ((3 * HORIZON,) if args.quick else (256, UNET_NOISE)):
            runs += suite("trivial", trivial_policy, noise, cases, args.quick)
        for group in ((GROUPS[-1],) if args.quick else GROUPS):
            runs.append(measure("trivial", trivial_policy, 3 * HORIZON if args.quick else 256,
                                "audit_policy", cases, groups=(group,)))
    if args.only != "trivial":
        unet = (UnetPolicy((8, 16, 32), embed=16) if args.quick
                else UnetPolicy((64, 128, 256)))
        print("unet: %d parameters" % unet.parameters(), flush=True)
        runs += suite("unet", unet, UNET_NOISE, cases, args.quick,
                      precision=args.unet_precision)
    out = {"quick": args.quick, "loadavg_before": before, "loadavg_after": load(),
           "shape": SHAPE, "cases": cases, "batch_size": 256,
           "torch_threads": torch.get_num_threads(), "runs": runs}
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    return out


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
