#!/usr/bin/env python3
"""A small flow-matching policy in PyTorch, trained on `handcentric demos` output twice: once on
hand-centric actions and observations, once on absolute ones; then audited with
handcentric.assert_equivariant (docs/AUDIT_YOUR_POLICY.md walks through it).

  hand-centric  observation: the eye-in-hand points (hand frame at T_0)
                actions:     T_0^-1 T_k as [p, r(R)]       decode: T_k = T_0 exp(a_k)
  absolute      observation: [p_0, r(R_0)] and the points (world frame)
                actions:     T_k as [p, r(R)]              decode: T_k = exp(a_k)

Both are rectified flows (x_t = t a + (1 - t) eps, target a - eps) sampled with Euler steps from
eps = the audit's noise, computed in float32 end to end: the hand-centric policy is equivariant
up to float32 rounding in every group (Theorem 1 of "Guaranteed SE(3)-Equivariant Control via
Hand-Centric Behavior Cloning"), so it is audited with precision="float32"; the absolute one is
equivariant under nothing, and the audit shows a shrunk witness.

Run from the repository (after building; the module and the CLI come from build/):
    PYTHONPATH=build/python /usr/bin/python3 examples/python_torch/flow_policy.py
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
import torch

import handcentric

K = 8            # poses per chunk
EULER_STEPS = 10
HERE = os.path.dirname(os.path.realpath(__file__))


def rotation_matrices(r):
    """Rodrigues' formula on (..., 3) rotation vectors, in the dtype of r (float32 here)."""
    theta = r.norm(dim=-1, keepdim=True)[..., None]                     # (..., 1, 1)
    zero = torch.zeros_like(r[..., 0])
    hat = torch.stack([zero, -r[..., 2], r[..., 1],
                       r[..., 2], zero, -r[..., 0],
                       -r[..., 1], r[..., 0], zero], dim=-1).reshape(r.shape[:-1] + (3, 3))
    small = theta < 1e-4
    safe = torch.where(small, torch.ones_like(theta), theta)
    a = torch.where(small, 1 - theta ** 2 / 6, torch.sin(safe) / safe)
    b = torch.where(small, 0.5 - theta ** 2 / 24, (1 - torch.cos(safe)) / safe ** 2)
    eye = torch.eye(3, dtype=r.dtype).expand(hat.shape)
    return eye + a * hat + b * hat @ hat


def poses(actions):
    """(K, 6) [p, r] -> (K, 4, 4) poses, float32."""
    T = torch.zeros(actions.shape[0], 4, 4, dtype=actions.dtype)
    T[:, :3, :3] = rotation_matrices(actions[:, 3:])
    T[:, :3, 3] = actions[:, :3]
    T[:, 3, 3] = 1.0
    return T


class VelocityField(torch.nn.Module):
    def __init__(self, observation_size):
        super().__init__()
        self.net = torch.nn.Sequential(
            torch.nn.Linear(6 * K + 1 + observation_size, 128), torch.nn.SiLU(),
            torch.nn.Linear(128, 128), torch.nn.SiLU(),
            torch.nn.Linear(128, 6 * K))

    def forward(self, x, t, observation):
        return self.net(torch.cat([x, t, observation], dim=-1))


class FlowPolicy:
    """A trained velocity field with its representation; called as the audit calls a policy."""

    def __init__(self, hand_centric):
        self.hand_centric = hand_centric
        self.name = "hand_centric" if hand_centric else "absolute"
        self.field = VelocityField(6 if hand_centric else 12)

    def observation(self, history, hand_points):
        if self.hand_centric:
            return hand_points[:2].reshape(-1)                         # invariant by construction
        return handcentric.encode_observation("absolute", history[:1], hand_points[:2])

    def actions(self, history, chunk):
        name = "hand_centric" if self.hand_centric else "absolute"
        return handcentric.encode_actions(name, history[:1], chunk)

    def train(self, scenes, steps, seed):
        torch.manual_seed(seed)
        n = len(scenes["history"])
        obs = torch.tensor(np.stack([self.observation(scenes["history"][i],
                                                      scenes["hand_points"][i])
                                     for i in range(n)]), dtype=torch.float32)
        act = torch.tensor(np.stack([self.actions(scenes["history"][i], scenes["chunk"][i])
                                     for i in range(n)]), dtype=torch.float32)
        optimizer = torch.optim.Adam(self.field.parameters(), lr=2e-3)
        for step in range(steps):
            batch = torch.randint(0, n, (256,))
            a, o = act[batch], obs[batch]
            eps = torch.randn_like(a)
            t = torch.rand(len(batch), 1)
            loss = ((self.field(t * a + (1 - t) * eps, t, o) - (a - eps)) ** 2).mean()   # eq. (5)
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
        return float(loss)

    @torch.no_grad()
    def __call__(self, history, hand_points, world_points, noise):
        """The audit's batched signature (batch_size=B, array="torch"): float64 tensors history
        (B, 1, 4, 4), hand_points (B, 2, 3) (the audit is given history=0, hand_points=2, the
        demos' sizes) and noise (B, d) -> the world-frame chunks (B, K, 4, 4)."""
        B = len(history)
        if self.hand_centric:
            o = hand_points[:, :2].reshape(B, -1).float()                # invariant by construction
        else:
            o = torch.tensor(np.stack([self.observation(h, p) for h, p in
                                       zip(history.numpy(), hand_points.numpy())]),
                             dtype=torch.float32)
        x = noise[:, :6 * K].float()                                     # the audit's noise: eps
        for i in range(EULER_STEPS):
            t = torch.full((B, 1), i / EULER_STEPS)
            x = x + self.field(x, t, o) / EULER_STEPS
        chunk = poses(x.reshape(B * K, 6)).reshape(B, K, 4, 4)
        if self.hand_centric:
            chunk = history[:, :1].float() @ chunk                     # T_k = T_0 hand0_T_handk
        return chunk


# How the audit calls FlowPolicy: stacked torch tensors, the demos' sizes (one pose, two points).
AUDIT = dict(batch_size=256, array="torch", history=0, hand_points=2)


def make_demos(path, n, cli):
    subprocess.run([cli, "demos", "--n", str(n), "--dist", "train", "--seed", "1", "--out", path],
                   check=True, stdout=subprocess.DEVNULL)


def find_cli():
    for candidate in (os.environ.get("HANDCENTRIC_CLI"), shutil.which("handcentric"),
                      os.path.join(HERE, "..", "..", "build", "apps", "handcentric")):
        if candidate and os.path.isfile(candidate):
            return candidate
    sys.exit("flow_policy.py: no `handcentric` program; build it (scripts/build.sh) "
             "or set HANDCENTRIC_CLI")


def train_both(demos=20, steps=1500, seed=0):
    """(hand-centric policy, absolute policy), trained on the same demos and seed."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "demos.jsonl")
        make_demos(path, demos, find_cli())
        scenes = handcentric.training_scenes(path, history=0, chunk=K)
    trained = []
    for hand_centric in (True, False):
        policy = FlowPolicy(hand_centric)
        start = time.time()
        loss = policy.train(scenes, steps, seed)
        print("%-12s %d scenes, %d steps, final loss %.4f, %.1f s"
              % (policy.name, len(scenes["history"]), steps, loss, time.time() - start))
        trained.append(policy)
    return trained


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--demos", type=int, default=20)
    parser.add_argument("--steps", type=int, default=1500)
    parser.add_argument("--cases", type=int, default=1000)
    args = parser.parse_args()
    torch.set_num_threads(1)  # deterministic and quick at batch 1
    hand_centric, absolute = train_both(args.demos, args.steps)
    for group in handcentric.GROUPS:
        handcentric.assert_equivariant(hand_centric, group, precision="float32", cases=args.cases,
                                       **AUDIT)
        print("hand_centric: equivariant under %s (float32 precision, both views)" % group)
    try:
        handcentric.assert_equivariant(absolute, "se3", precision="float32", cases=args.cases,
                                       **AUDIT)
    except AssertionError as failure:
        print("absolute: not equivariant:\n%s" % failure)
    else:
        sys.exit("absolute: unexpectedly equivariant under se3")


if __name__ == "__main__":
    main()
