"""serve_policy(..., rng=, device=): a policy's own generator seeded before each observation's
call, by the one implementation the in-process audit uses too (handcentric_plugin.seeding).

A stand-in torch module records the device a generator is made on, so that the device handling
is tested on a machine without a GPU; the real torch, where it imports, checks the seeds.
"""
import importlib.util
import os
import sys
import types

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_handcentric_plugin import PYTHON_DIR, hp, random_scene, request, run_serve  # noqa: E402

seeding = hp.seeding


class FakeGenerator:
    def __init__(self, device="cpu"):
        self.device, self.seed = device, None

    def manual_seed(self, seed):
        self.seed = seed
        return self


def fake_torch(monkeypatch):
    """A torch module with Generator and manual_seed only, recording what they were given."""
    torch = types.SimpleNamespace(Generator=FakeGenerator, seeds=[])
    torch.manual_seed = torch.seeds.append
    monkeypatch.setitem(sys.modules, "torch", torch)
    return torch


@pytest.mark.parametrize("device, expected", [(None, "cpu"), ("cuda:1", "cuda:1")])
def test_a_generator_is_made_on_the_policys_device(monkeypatch, device, expected):
    fake_torch(monkeypatch)
    keywords = seeding.seed_before_call("generator", 12345, device)
    assert keywords["generator"].device == expected and keywords["generator"].seed == 12345


def test_torch_mode_seeds_through_torch_manual_seed(monkeypatch):
    # torch.manual_seed seeds the CPU generator and every CUDA device's (queued until CUDA
    # initialises): the one call covers a policy on any device.
    torch = fake_torch(monkeypatch)
    assert seeding.seed_before_call("torch", 7) == {} and torch.seeds == [7]


def test_serve_policy_passes_its_device_to_the_generator(monkeypatch):
    fake_torch(monkeypatch)
    seen = []

    def policy(history, hand_points, world_points, noise, generator=None):
        seen.append(generator)
        return np.array([history[0]])

    noise = [0.5, -1.0, 2.0]
    line = request(random_scene(np.random.default_rng(20)), 1, noise=noise)
    as_policy = types.SimpleNamespace(serve=hp.serve_policy)  # run_serve's helper.serve
    answers, status, err = run_serve([line, line], policy, helper=as_policy, rng="generator",
                                     device="cuda:1", noise=len(noise))
    assert status == 0, err
    assert "hello" in answers[0] and "chunk" in answers[1] and len(seen) == 1
    assert seen[0].device == "cuda:1"
    assert seen[0].seed == hp.policy._noise_seed(np.array(noise))


def test_a_mode_that_is_not_known_is_refused():
    with pytest.raises(ValueError, match="is not a mode"):
        hp.serve_policy(lambda *a: None, rng="cuda")


@pytest.mark.skipif(importlib.util.find_spec("torch") is None, reason="no torch")
def test_the_real_torch_is_seeded_alike_for_the_same_seed():
    import torch
    draws = []
    for mode in ("torch", "generator"):
        for _ in range(2):
            keywords = seeding.seed_before_call(mode, 2 ** 62 + 3)
            draws.append(torch.randn(4, dtype=torch.float64, **keywords).tolist())
    assert draws[0] == draws[1] and draws[2] == draws[3]
    assert torch.initial_seed() == 2 ** 62 + 3


def test_the_in_process_audit_seeds_with_the_same_function():
    # handcentric/_rng.py, loaded alone: `import handcentric` would need the compiled extension.
    path = os.path.join(PYTHON_DIR, "handcentric", "_rng.py")
    spec = importlib.util.spec_from_file_location("handcentric_rng_under_test", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.seed_before_call is seeding.seed_before_call
    assert module.RNG_MODES is seeding.RNG_MODES
