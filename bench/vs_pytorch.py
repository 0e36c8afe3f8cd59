#!/usr/bin/python3
"""PyTorch side of bench/vs_pytorch.sh: the same flow-matching MLP as bench_policy.cpp.

57 inputs (24 noisy action + 1 time + 32 observation) -> 256 -> 256 -> 256 -> 24, SiLU, Adam
(lr 1e-3), batch 256, float32, eq. (5) loss. Prints one JSON line:
  {"threads": T, "train_samples_per_s": best over repetitions, \
"sample_us": median 10-step Euler at batch 1}
"""
import argparse
import json
import time

import torch


def network():
    return torch.nn.Sequential(
        torch.nn.Linear(57, 256), torch.nn.SiLU(),
        torch.nn.Linear(256, 256), torch.nn.SiLU(),
        torch.nn.Linear(256, 256), torch.nn.SiLU(),
        torch.nn.Linear(256, 24))


def train_rate(net, optimizer, seconds, batch=256):
    actions = torch.randn(4096, 24)
    observations = torch.randn(4096, 32)
    steps = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        index = torch.randint(0, 4096, (batch,))
        a, o = actions[index], observations[index]
        eps = torch.randn_like(a)
        t = torch.rand(batch, 1)
        x_t = t * a + (1 - t) * eps                      # eq. (5)
        loss = ((net(torch.cat([x_t, t, o], 1)) - (a - eps)) ** 2).mean()
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()
        steps += 1
    return steps * batch / (time.perf_counter() - start)


def sample_us(net, repeats=2000):
    o = torch.randn(1, 32)
    times = []
    with torch.no_grad():
        for _ in range(repeats):
            start = time.perf_counter()
            x = torch.randn(1, 24)
            for n in range(10):
                t = torch.full((1, 1), n / 10.0)
                x = x + net(torch.cat([x, t, o], 1)) / 10.0
            times.append(time.perf_counter() - start)
    times.sort()
    return 1e6 * times[len(times) // 2]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--repetitions", type=int, default=3)
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    net = network()
    optimizer = torch.optim.Adam(net.parameters(), lr=1e-3)
    train_rate(net, optimizer, 1.0)  # warm-up
    best = max(train_rate(net, optimizer, args.seconds) for _ in range(args.repetitions))
    print(json.dumps({"threads": args.threads, "train_samples_per_s": best,
                      "sample_us": sample_us(net)}))


if __name__ == "__main__":
    main()
