#!/usr/bin/python3
"""PyTorch side of bench/vs_pytorch_conv.sh: the image encoder and MLP of bench_conv.cpp.

RGB-D 4 x 48 x 64 -> Conv2d 16, 32, 32 (3x3, stride 2, padding 1), SiLU after each -> flatten
(1536) -> 256 -> 256 -> 24 (SiLU), MSE to a fixed target, Adam (lr 1e-3), float32; one fixed
batch of images, as bench_conv.cpp trains on. `--network default`: the image policies' default
encoder instead (bench_conv.cpp's BM_default_encoder_train_step: 6 x 48 x 64 -> Conv2d 8, 16,
16, 16 -> flatten (192) -> the same head). Prints one JSON line per batch size and memory
format (contiguous NCHW, channels_last NHWC):
  {"threads": T, "batch": B, "format": F, "train_samples_per_s": best over repetitions,
   "train_samples_per_cpu_s": the same per second of process CPU time,
   "forward_ms": the encoder's forward alone, median, "blas": the BLAS library torch loaded}
"""
import argparse
import json
import time

import torch


# (input channels, the layers' filters, features after flatten) of each network.
NETWORKS = {"bench": (4, [16, 32, 32], 32 * 6 * 8), "default": (6, [8, 16, 16, 16], 16 * 3 * 4)}


def encoder(network):
    channels, filters, _ = NETWORKS[network]
    layers = []
    for out in filters:
        layers += [torch.nn.Conv2d(channels, out, 3, stride=2, padding=1), torch.nn.SiLU()]
        channels = out
    return torch.nn.Sequential(*layers, torch.nn.Flatten())


def head(network):
    return torch.nn.Sequential(
        torch.nn.Linear(NETWORKS[network][2], 256), torch.nn.SiLU(),
        torch.nn.Linear(256, 256), torch.nn.SiLU(),
        torch.nn.Linear(256, 24))


def train_rate(net, optimizer, images, target, seconds):
    """Samples per second of wall time, and per second of this process's CPU time (on a shared
    machine the wall time includes the waits for a core)."""
    steps = 0
    start, cpu_start = time.perf_counter(), time.process_time()
    while time.perf_counter() - start < seconds:
        loss = torch.nn.functional.mse_loss(net(images), target)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()
        steps += 1
    samples = steps * images.shape[0]
    return samples / (time.perf_counter() - start), samples / (time.process_time() - cpu_start)


def forward_ms(cnn, images, repeats=20):
    times = []
    with torch.no_grad():
        for _ in range(repeats):
            start = time.perf_counter()
            cnn(images)
            times.append(time.perf_counter() - start)
    times.sort()
    return 1e3 * times[len(times) // 2]


def blas_library():
    """The BLAS this process loaded (torch's Linear layers run on it, its convolutions on
    oneDNN)."""
    with open("/proc/self/maps") as maps:
        paths = {line.split()[-1] for line in maps if "blas" in line and "/" in line}
    return sorted(paths)[0] if paths else "unknown"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--batch", type=int, nargs="+", default=[64, 256])
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--repetitions", type=int, default=3)
    parser.add_argument("--network", choices=sorted(NETWORKS), default="bench")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    for batch in args.batch:
        # Both memory formats: oneDNN trains faster on channels_last (NHWC) here, and the
        # comparison is against PyTorch's best.
        for layout in ("contiguous", "channels_last"):
            torch.manual_seed(0)
            cnn = encoder(args.network)
            net = torch.nn.Sequential(cnn, head(args.network))
            images = torch.randn(batch, NETWORKS[args.network][0], 48, 64)
            if layout == "channels_last":
                net = net.to(memory_format=torch.channels_last)
                images = images.contiguous(memory_format=torch.channels_last)
            optimizer = torch.optim.Adam(net.parameters(), lr=1e-3)
            target = torch.randn(batch, 24)
            train_rate(net, optimizer, images, target, 1.0)  # warm-up
            rates = [train_rate(net, optimizer, images, target, args.seconds)
                     for _ in range(args.repetitions)]
            print(json.dumps({"network": args.network, "threads": args.threads, "batch": batch,
                              "format": layout,
                              "train_samples_per_s": max(wall for wall, _ in rates),
                              "train_samples_per_cpu_s": max(cpu for _, cpu in rates),
                              "forward_ms": forward_ms(cnn, images), "blas": blas_library()}),
                  flush=True)

if __name__ == "__main__":
    main()
