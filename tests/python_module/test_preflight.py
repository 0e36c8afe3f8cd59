"""The preflight of a whole policy (props/preflight.hpp): policies shaped like the ones public code
ships (own noise, state between calls, batch statistics) get no verdict that blames g for them.

Each planted policy below is a correct hand-centric policy (policies.make_policy) with one
thing added, as in the public code the audit is run on:
  - own noise: Diffusion Policy's predict_action draws torch.randn inside (its noise argument
    unused); LeRobot's DDPM scheduler draws fresh noise at every step.
  - a history buffer: the previous call's hand pose kept and used (a warm start).
  - an action queue: LeRobot's select_action pops the next step of a stored plan.
  - a batch norm in train mode: the rows of a batch normalized together.
"""
import math

import numpy as np
import pytest

import handcentric
from policies import K, inverse, make_policy, pose_matrix

torch = pytest.importorskip("torch")

base = make_policy()


def rows_of(policy):
    """A policy of one observation called row by row on stacked arrays."""
    def batched(history, hand_points, world_points, noise, **kw):
        return np.stack([policy(history[i], hand_points[i], world_points[i], noise[i])
                         for i in range(len(noise))])
    batched.__qualname__ = policy.__qualname__
    return batched


def own_noise(source, frame):
    """The correct policy plus 1 cm noise per step that it draws itself from `source` ("numpy",
    "torch" or "generator"), added in the hand frame (still equivariant for the same draws) or
    in the world frame (not, under rotations)."""
    def policy(history, hand_points, world_points, noise, generator=None):
        chunk = base(history, hand_points, world_points, noise)
        if source == "numpy":
            step = np.random.normal(size=(K, 3))
        else:
            step = torch.randn(K, 3, generator=generator, dtype=torch.float64).numpy()
        step = 0.01 * step
        if frame == "hand":
            chunk[:, :3, 3] += step @ history[0][:3, :3].T  # R_0 (hand-frame step)
        else:
            chunk[:, :3, 3] += step
        return chunk
    policy.__qualname__ = "own_noise_%s_%s" % (source, frame)
    return policy


def test_a_policy_that_draws_its_own_noise_gets_no_pointwise_verdict_and_is_told_why():
    report = handcentric.audit_policy(own_noise("numpy", "hand"), groups=["se3"], cases=40,
                                      quiet=True)
    pre = report["preflight"]
    assert pre["repeatable"] is False
    assert pre["draws"] == ["NumPy's global generator"]
    assert 'rng="torch"' in pre["note"] and "noise argument" in pre["note"]
    assert pre["repeat_difference"] > 1e-3
    assert {c["mode"] for c in report["checks"]} == {"distribution"}
    assert all(c["equivariant"] for c in report["checks"])  # the law needs no pairing
    with pytest.raises(handcentric.OwnRandomnessError, match="NumPy's global generator"):
        handcentric.assert_equivariant(own_noise("numpy", "hand"), "se3", cases=20, quiet=True)


def test_a_deterministic_policy_passes_the_preflight_with_a_few_calls():
    report = handcentric.audit_policy(base, groups=["se3"], cases=20, quiet=True)
    pre = report["preflight"]
    assert pre["repeatable"] is True and pre["note"] == ""
    assert pre["draws"] == [] and pre["repeat_difference"] == 0.0


@pytest.mark.parametrize("source", ["numpy", "torch", "generator"])
def test_rng_pairs_the_policys_own_draws_and_the_verdict_is_then_about_g(source):
    rng = source
    handcentric.assert_equivariant(own_noise(source, "hand"), "se3", cases=40, rng=rng,
                                   quiet=True)
    # The planted fault: the same draws added in the world frame. Paired, the rotation moves them
    # differently on the two sides: NO, now that the draws are the same.
    with pytest.raises(AssertionError):
        handcentric.assert_equivariant(own_noise(source, "world"), "rotation", cases=40, rng=rng,
                                       quiet=True)


def test_rng_pairs_rows_of_a_batched_torch_policy_drawing_batch_shaped_noise():
    def policy(history, hand_points, world_points, noise):
        B = history.shape[0]
        chunk = rows_of(base)(history.numpy(), hand_points.numpy(), world_points.numpy(),
                              noise.numpy())
        step = 0.01 * torch.randn(B, K, 3, dtype=torch.float64).numpy()  # (B, ...) draws
        chunk[:, :, :3, 3] += np.einsum("bij,bkj->bki", history[:, 0, :3, :3].numpy(), step)
        return chunk
    handcentric.assert_equivariant(policy, "se3", cases=40, rng="torch", batch_size=16,
                                   array="torch", quiet=True)
    with pytest.raises(handcentric.OwnRandomnessError):
        handcentric.assert_equivariant(policy, "se3", cases=40, batch_size=16, array="torch",
                                       quiet=True)


class HistoryBuffer:
    """Remembers the hand pose of the previous call and moves its plan by the step since then."""

    def __init__(self):
        self.previous = None

    def reset(self):
        self.previous = None

    def __call__(self, history, hand_points, world_points, noise):
        chunk = base(history, hand_points, world_points, noise)
        if self.previous is not None:
            chunk[:, :3, 3] += 0.1 * (history[0][:3, 3] - self.previous)
        self.previous = history[0][:3, 3].copy()
        return chunk


def test_a_policy_that_remembers_the_previous_call_is_an_error_naming_state_and_reset():
    for batch_size in (None, 16):
        policy = HistoryBuffer()
        fn = policy if batch_size is None else rows_of_stateful(policy)
        with pytest.raises(handcentric.StatefulPolicyError, match="previous call.*reset="):
            handcentric.audit_policy(fn, groups=["translation"], cases=20, batch_size=batch_size,
                                     quiet=True)
    # The fix it names: reset before every call makes it a function of its inputs.
    policy = HistoryBuffer()
    handcentric.assert_equivariant(policy, "se3", cases=40, reset=policy.reset, quiet=True)


def rows_of_stateful(policy):
    def batched(history, hand_points, world_points, noise, **kw):
        return np.stack([policy(history[i], hand_points[i], world_points[i], noise[i])
                         for i in range(len(noise))])
    return batched


class ActionQueue:
    """Plans once, then answers each call with the plan shifted one step further (the next
    action of a stored chunk), as LeRobot's select_action pops its queue."""

    def __init__(self, period=K):
        self.plan, self.step, self.period = None, 0, period

    def __call__(self, history, hand_points, world_points, noise):
        if self.plan is None:
            self.plan = base(history, hand_points, world_points, noise)
        self.step += 1
        return np.roll(self.plan, -(self.step % self.period), axis=0)


def test_an_action_queue_is_an_error_naming_state_not_a_verdict_blaming_g():
    # Its plan has K = 4 steps and the preflight asks 4 rows at a time: the repeats come back in
    # phase, the three rows asked between Q and A put them out of it.
    with pytest.raises(handcentric.StatefulPolicyError, match="earlier calls.*action queue"):
        handcentric.audit_policy(ActionQueue(), cases=20, quiet=True)
    # One step per call with a plan of 3: out of phase at once.
    with pytest.raises(handcentric.StatefulPolicyError, match="at every call.*without drawing"):
        handcentric.audit_policy(ActionQueue(period=3), cases=20, quiet=True)


def batch_norm_policy(frame):
    """A torch policy whose features pass a batch norm in train mode (statistics of the batch):
    hand-frame features (the step since T_-1 in the hand frame) or world positions."""
    norm = torch.nn.BatchNorm1d(3, affine=False).train()

    def policy(history, hand_points, world_points, noise):
        T0 = history[:, 0]
        if frame == "hand":
            x = torch.einsum("bji,bj->bi", T0[:, :3, :3], history[:, 1, :3, 3] - T0[:, :3, 3])
        else:
            x = T0[:, :3, 3]
        feature = norm(x.float()).double()
        step = torch.zeros(len(T0), K, 4, 4, dtype=torch.float64)
        step[:, :, :3, :3] = torch.eye(3, dtype=torch.float64)
        step[:, :, 3, 3] = 1.0
        step[:, :, :3, 3] = 0.01 * feature[:, None, :]
        return T0[:, None] @ step
    policy.__qualname__ = "batch_norm_" + frame
    return policy


@pytest.mark.parametrize("frame", ["hand", "world"])
def test_batch_statistics_are_an_error_naming_the_batch_not_a_verdict(frame):
    with pytest.raises(handcentric.BatchCouplingError, match="batch.*eval"):
        handcentric.audit_policy(batch_norm_policy(frame), groups=["se3"], cases=20,
                                 batch_size=16, array="torch", history=1, quiet=True)


def test_a_pointwise_yes_says_what_it_could_have_missed():
    report = handcentric.audit_policy(base, groups=["se3"], views=["eye_in_hand"], cases=100,
                                      quiet=True)
    (point,) = [c for c in report["checks"] if c["mode"] == "pointwise"]
    assert point["equivariant"]
    assert point["detectable_frequency"] == pytest.approx(1 - 0.01 ** (1 / point["cases"]))
    assert point["detectable_frequency"] == pytest.approx(4.6 / point["cases"], rel=0.05)


def test_detect_sets_the_cases_from_the_frequency_asked_for():
    # detect=0.05: ceil(ln 0.01 / ln 0.95) = 90 cases drawn per pointwise cell (far ones and
    # those with g near the identity); mutant: detect= read but not applied -> 1000 cases.
    asked = []

    def counted(history, hand_points, world_points, noise):
        asked.append(1)
        return base(history, hand_points, world_points, noise)
    report = handcentric.audit_policy(counted, groups=["se3"], views=["eye_in_hand"],
                                      detect=0.05, quiet=True)
    assert report["detect"] == {"frequency": 0.05, "cases": 90}
    (point,) = [c for c in report["checks"] if c["mode"] == "pointwise"]
    assert point["equivariant"]
    assert point["cases"] + point["near_identity_cases"] == 90
    assert len(asked) < 2 * 90 + 100  # o and g o per case, the preflight, no 1000 cases
    for bad, error, match in [(dict(detect=0.01, cases=200), ValueError, "give one of them"),
                              (dict(detect=1.5), ValueError, "detect=1.5 is not a frequency"),
                              (dict(detect=1e-9), ValueError, "above the bound"),
                              (dict(detect=True), TypeError, "detect must be a frequency"),
                              (dict(detect="0.01"), TypeError, "detect must be a frequency")]:
        with pytest.raises(error, match=match):
            handcentric.audit_policy(base, groups=["se3"], quiet=True, **bad)


def test_rng_and_reset_are_refused_by_name():
    with pytest.raises(ValueError, match="rng='cuda' is not a mode"):
        handcentric.audit_policy(base, rng="cuda", quiet=True)
    with pytest.raises(TypeError, match="reset must be None or a callable"):
        handcentric.audit_policy(base, reset=3, quiet=True)


def test_the_command_line_takes_rng_and_reset_and_prints_the_preflight(tmp_path, capsys):
    """python -m handcentric audit-policy: --rng and --reset as audit_policy's rng= and reset=;
    a policy with its own noise and no --rng gets the one line instead of pointwise rows."""
    from handcentric import __main__ as cli
    (tmp_path / "shipped.py").write_text(
        "import sys\n"
        "sys.path.insert(0, %r)\n"
        "from test_preflight import HistoryBuffer, own_noise\n"
        "noisy = own_noise('numpy', 'hand')\n"
        "stateful = HistoryBuffer()\n"
        "reset = stateful.reset\n" % str(__import__("os").path.dirname(__file__)))
    target = str(tmp_path / "shipped.py")
    common = ["--group", "se3", "--view", "eye_in_hand", "--cases", "20", "--quiet"]
    assert cli.main(["audit-policy", target + ":noisy"] + common) == 0
    out = capsys.readouterr().out
    assert "no pointwise verdict:" in out and "pointwise" not in out.split("no pointwise")[0]
    assert cli.main(["audit-policy", target + ":noisy", "--rng", "numpy"] + common) == 0
    out = capsys.readouterr().out
    assert "pointwise" in out and "NO" not in out
    assert cli.main(["audit-policy", target + ":stateful"] + common) == 1
    assert "previous call" in capsys.readouterr().err
    assert cli.main(["audit-policy", target + ":stateful", "--reset", target + ":reset"]
                    + common) == 0
