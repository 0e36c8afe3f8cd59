"""Batched callables (batch_size=B): stacked arrays in, one row per scene out; the same verdicts,
witnesses and JSON as one scene per call, bit for bit; torch tensors; arguments refused at once."""
import json
import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import handcentric
from policies import (absolute_actions, hand_centric_actions, hand_centric_observation,
                      make_policy)

HERE = os.path.dirname(os.path.realpath(__file__))
MODULE_DIR = os.path.dirname(os.path.dirname(handcentric.__file__))


def rows(fn, stacked_names, batch_shape_out=None):
    """fn of one scene, called row by row on stacked arrays: the same arithmetic per row as the
    unbatched audit's calls, so the two audits must agree bit for bit."""
    def batched(*arrays, **kw):
        out = [fn(*(a[i] for a in arrays)) for i in range(len(arrays[0]))]
        return np.stack(out)
    batched.__qualname__ = fn.__qualname__  # the same name in both reports
    return batched


def same(a, b):
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


@pytest.mark.parametrize("fault", [None, "world_noise", "forgets_T0"])
def test_a_batched_policy_audit_is_the_unbatched_one_bit_for_bit(fault):
    policy = make_policy(fault)
    one = handcentric.audit_policy(policy, cases=150, quiet=True)
    many = handcentric.audit_policy(rows(policy, 4), cases=150, batch_size=64, quiet=True)
    assert same(one, many)
    assert all(check["equivariant"] for check in one["checks"]) == (fault is None)


def test_a_batched_representation_audit_is_the_unbatched_one_bit_for_bit():
    for actions in (hand_centric_actions, absolute_actions):
        one = handcentric.audit(actions, hand_centric_observation, cases=100, quiet=True)
        many = handcentric.audit(rows(actions, 4), rows(hand_centric_observation, 3), cases=100,
                                 batch_size=100, quiet=True)
        assert same(one, many), actions.__qualname__


def test_the_comparison_sees_a_map_whose_rows_depend_on_their_batch():
    # The planted fault: row i moved by 1e-7 i, so that the answers depend on the batch.
    policy = make_policy()
    plain = rows(policy, 4)

    def biased(history, hand_points, world_points, noise):
        out = plain(history, hand_points, world_points, noise)
        out[:, :, :3, 3] += 1e-7 * np.arange(len(out))[:, None, None]
        return out
    biased.__qualname__ = policy.__qualname__
    one = handcentric.audit_policy(policy, cases=100, quiet=True)
    assert not same(one, handcentric.audit_policy(biased, cases=100, batch_size=64, quiet=True))


def test_the_callable_gets_stacked_arrays_of_one_shape_and_keywords():
    seen = []
    good = make_policy()

    def policy(history, hand_points, world_points, noise, extra_poses, scalars):
        seen.append((history.shape, hand_points.shape, world_points.shape, noise.shape,
                     extra_poses["start"].shape, scalars["gripper"].shape))
        return rows(good, 4)(history, hand_points, world_points, noise)
    handcentric.audit_policy(policy, cases=50, batch_size=32, noise=16, history=2, hand_points=1,
                             world_points=3, extra_poses=["start"], scalars=["gripper"],
                             quiet=True)
    assert seen and max(shape[0][0] for shape in seen) == 32
    for h, p, w, n, e, s in seen:
        B = h[0]
        assert h == (B, 3, 4, 4) and p == (B, 1, 3) and n == (B, 16)
        assert w in ((B, 0, 3), (B, 3, 3))  # eye-in-hand: none; third-person: the fixed 3
        assert e == (B, 4, 4) and s == (B,)


def test_a_vectorized_policy_gets_the_same_verdicts():
    # A truly vectorized hand-centric policy: its float64 arithmetic differs from the per-row
    # one in the last bits, so the witnesses' numbers may differ; the verdicts may not.
    K = 4

    def vectorized(history, hand_points, world_points, noise):
        B = len(history)
        step = np.zeros((B, K, 4, 4))
        step[:, :, :3, :3] = np.eye(3)
        step[:, :, :3, 3] = 0.05 * np.tanh(noise[:, :3 * K].reshape(B, K, 3))
        step[:, :, 3, 3] = 1.0
        return history[:, :1] @ step
    checks = handcentric.audit_policy(vectorized, cases=100, batch_size=256, quiet=True)["checks"]
    assert all(check["equivariant"] for check in checks)


def test_torch_tensors_in_and_out_with_grad():
    torch = pytest.importorskip("torch")
    good = make_policy()
    kinds = set()
    weight = torch.ones((), dtype=torch.float64, requires_grad=True)

    def policy(history, hand_points, world_points, noise):
        kinds.add((type(history).__name__, str(history.device), str(history.dtype)))
        chunk = rows(good, 4)(history.numpy(), hand_points.numpy(), world_points.numpy(),
                              noise.numpy())
        return torch.from_numpy(chunk) * weight  # requires grad: detached by the audit
    report = handcentric.audit_policy(policy, cases=60, batch_size=64, array="torch",
                                      device="cpu", quiet=True)
    assert kinds == {("Tensor", "cpu", "torch.float64")}
    assert all(check["equivariant"] for check in report["checks"])


@pytest.mark.skipif("not __import__('torch').cuda.is_available()"
                    if __import__("importlib").util.find_spec("torch") else "True",
                    reason="no CUDA device here")
def test_cuda_tensors():
    import torch
    good = make_policy()

    def policy(history, hand_points, world_points, noise):
        assert history.is_cuda
        return torch.from_numpy(rows(good, 4)(*(a.cpu().numpy() for a in (
            history, hand_points, world_points, noise)))).cuda()
    handcentric.audit_policy(policy, cases=30, batch_size=64, array="torch", device="cuda",
                             quiet=True)


def test_bad_arguments_are_refused_in_one_line():
    policy = make_policy()
    for value, text in [(0, "below the least value, 1"), (2**40, "MAX_BATCH_SIZE"),
                        (10**6, "MAX_BATCH_SIZE")]:
        with pytest.raises(ValueError, match=text) as error:
            handcentric.audit_policy(policy, batch_size=value)
        assert "\n" not in str(error.value)
    with pytest.raises(TypeError, match="batch_size must be an integer"):
        handcentric.audit_policy(policy, batch_size="64")
    with pytest.raises(ValueError, match="above 2\\*\\*24; use batch_size <= 256"):
        handcentric.audit_policy(policy, batch_size=65536, noise=65536)
    with pytest.raises(ValueError, match='array="jax" is not known'):
        handcentric.audit_policy(policy, array="jax")
    with pytest.raises(ValueError, match='needs array="torch"'):
        handcentric.audit_policy(policy, device="cuda")
    with pytest.raises(ValueError, match="history=65 is above"):
        handcentric.audit_policy(policy, history=65)
    with pytest.raises(ValueError, match="world_points=0 is below"):
        handcentric.audit_policy(policy, world_points=0)


def test_a_batch_of_the_wrong_length_is_a_shape_error():
    good = rows(make_policy(), 4)

    def short(*arrays):
        return good(*arrays)[:-1]
    with pytest.raises(handcentric.ShapeError, match="one chunk per observation"):
        handcentric.audit_policy(short, batch_size=16, quiet=True)

    def flat(history, chunk, hand_points, world_points):
        return rows(hand_centric_actions, 4)(history, chunk, hand_points, world_points).ravel()
    with pytest.raises(handcentric.ShapeError, match="one row per scene"):
        handcentric.audit(flat, batch_size=16, quiet=True)


PROGRESS = r"""
import handcentric
from policies import make_policy
handcentric.audit_policy(make_policy(), cases=50, groups="translation", views="eye_in_hand",
                         quiet=%s)
"""


@pytest.mark.parametrize("quiet", [False, True])
def test_a_progress_line_on_stderr_unless_quiet(quiet):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([MODULE_DIR, HERE]),
               HANDCENTRIC_PROGRESS_AFTER="0")
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(PROGRESS % quiet)], env=env,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    if quiet:
        assert result.stderr == ""
    else:
        # A line while the first check runs (the count of checks is not known yet), and the
        # rows asked, their rate and the time on the last.
        assert "handcentric.audit_policy: first check, " in result.stderr
        assert re.search(r"2 of 2 checks, [1-9]\d* rows asked \(\d+ rows/s\), [\d.]+ s, done",
                         result.stderr), result.stderr
