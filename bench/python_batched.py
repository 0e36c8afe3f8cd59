#!/usr/bin/env python3
"""The default audit of a torch MLP policy in process, one observation per call against batched
(docs/BENCHMARKS.md, "Python, batched").

The policy: a hand-centric outer policy around an MLP (two hidden layers of 256, tanh, float64
so that the audit runs at its default precision) on one CPU thread: the input is the history
pose T_-1 and the eye-in-hand points in the frame of T_0 and the noise; the output, 8 poses
[p, r] in that frame, is mapped back by T_0 (Theorem 1: equivariant for any weights). Both
audits run at the defaults (all groups, both views, pointwise and in distribution, 1000 cases)
on scenes of one shape (history=1, hand_points=2, world_points=4: a network has fixed inputs),
with array="torch"; the batched one with batch_size=256. Their JSON must be the same (the
verdicts, witnesses and errors), which this script checks.

Run from the repository after building:
    PYTHONPATH=build/python /usr/bin/python3 bench/python_batched.py [--repeat N]
"""
import argparse
import json
import time

import torch

import handcentric

K = 8
NOISE = 6 * K


def rotation_matrices(r):
    """Rodrigues' formula on (..., 3) rotation vectors."""
    theta = r.norm(dim=-1, keepdim=True)[..., None]
    zero = torch.zeros_like(r[..., 0])
    hat = torch.stack([zero, -r[..., 2], r[..., 1],
                       r[..., 2], zero, -r[..., 0],
                       -r[..., 1], r[..., 0], zero], dim=-1).reshape(r.shape[:-1] + (3, 3))
    small = theta < 1e-4
    safe = torch.where(small, torch.ones_like(theta), theta)
    a = torch.where(small, 1 - theta ** 2 / 6, torch.sin(safe) / safe)
    b = torch.where(small, 0.5 - theta ** 2 / 24, (1 - torch.cos(safe)) / safe ** 2)
    return torch.eye(3, dtype=r.dtype).expand(hat.shape) + a * hat + b * hat @ hat


def inverse(T):
    """(..., 4, 4) rigid transforms inverted."""
    out = torch.zeros_like(T)
    Rt = T[..., :3, :3].transpose(-1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -(Rt @ T[..., :3, 3:4])[..., 0]
    out[..., 3, 3] = 1.0
    return out


class MlpPolicy(torch.nn.Module):
    """Batched: history (B, 2, 4, 4), hand_points (B, 2, 3), noise (B, 48) -> (B, 8, 4, 4)."""

    def __init__(self):
        super().__init__()
        torch.manual_seed(0)
        self.net = torch.nn.Sequential(
            torch.nn.Linear(12 + 6 + NOISE, 256), torch.nn.Tanh(),
            torch.nn.Linear(256, 256), torch.nn.Tanh(),
            torch.nn.Linear(256, 6 * K)).double()

    @torch.no_grad()
    def forward(self, history, hand_points, world_points, noise):
        T0 = history[:, 0]
        hand0_T_previous = inverse(T0) @ history[:, 1]
        x = torch.cat([hand0_T_previous[:, :3, :].reshape(-1, 12),
                       hand_points.reshape(-1, 6), noise], dim=1)
        a = 0.1 * self.net(x).reshape(-1, K, 6)
        hand0_T_handk = torch.zeros(a.shape[0], K, 4, 4, dtype=a.dtype)
        hand0_T_handk[..., :3, :3] = rotation_matrices(a[..., 3:])
        hand0_T_handk[..., :3, 3] = a[..., :3]
        hand0_T_handk[..., 3, 3] = 1.0
        return T0[:, None] @ hand0_T_handk


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    torch.set_num_threads(1)
    model = MlpPolicy()

    def one(history, hand_points, world_points, noise):
        return model(history[None], hand_points[None], world_points[None], noise[None])[0]

    common = dict(noise=NOISE, array="torch", history=1, hand_points=2, world_points=4,
                  quiet=True)
    results = {}
    for name, fn, extra in [("one per call", one, {}),
                            ("batched (256)", model, {"batch_size": 256})]:
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            report = handcentric.audit_policy(fn, **common, **extra)
            times.append(time.perf_counter() - start)
        results[name] = (min(times), report)
        print("%-14s %6.2f s  (best of %d)" % (name, min(times), args.repeat))
    a, b = (results[k][1] for k in results)
    same = json.dumps(a["checks"], sort_keys=True) == json.dumps(b["checks"], sort_keys=True)
    verdicts = sum(check["equivariant"] for check in b["checks"])
    print("same checks: %s; %d of %d equivariant" % (same, verdicts, len(b["checks"])))
    ratio = results["batched (256)"][0] / results["one per call"][0]
    print("batched / one per call = %.3f" % ratio)


if __name__ == "__main__":
    main()
