"""The closed loop on the user's recorded episodes (observations= whose observations carry an
"episode" index, with episodes=N): each episode is replayed as recorded by a fresh policy, and g
times it by another, one g per episode. A running sum of world positions kept across calls passes
every single-call check and is NO here; LeRobot's action queue of hand-centric chunks holds. Bad
episode indices are refused in one line."""
import numpy as np
import pytest

import handcentric
from policies import make_policy
from test_closed_loop import QueuePolicy
from test_observations import inverse, pose


def recorded(count=3, steps=6, seed=2):
    """`count` episodes of `steps` observations: a hand moving smoothly in a 1 m cell, its
    history (T_t, T_t-1), two eye-in-hand points; episodes numbered 7, 8, ..."""
    rng = np.random.default_rng(seed)
    out = []
    for e in range(count):
        T = pose(handcentric.so3_exp(rng.normal(size=3)), rng.uniform(-0.5, 0.5, 3))
        step = pose(handcentric.so3_exp(0.1 * rng.normal(size=3)), 0.02 * rng.normal(size=3))
        for _ in range(steps):
            out.append({"history": np.stack([T, T @ inverse(step)]),
                        "hand_points": rng.uniform(-0.1, 0.1, (2, 3)), "episode": 7 + e})
            T = T @ step
    return out


class RunningSum:
    """Steps 1 cm along its own x, shifted along world x by 0.05 times the x of the sum of the
    hand's world positions at the earlier calls since reset: a state in world coordinates, zero
    at the first call after a reset."""

    def __init__(self):
        self.reset()

    def reset(self):
        self.sum = np.zeros(3)

    def __call__(self, history, hand_points, world_points, noise):
        T0 = history[0]
        out = T0 @ pose(np.eye(3), [0.01, 0.0, 0.0])
        out[0, 3] += 0.05 * self.sum[0]
        self.sum = self.sum + T0[:3, 3]
        return out[None]


def loops(report):
    return [c for c in report["checks"] if c["mode"] == "closed_loop"]


def test_a_world_frame_running_sum_passes_single_calls_and_is_no_on_recorded_episodes():
    # Mutants seen failing here (run by hand, reverted): a reset before every step of the replay
    # (props/src/checks/recorded_episodes.cpp: the sum stays zero, the loop says yes); the
    # recorded observations read as one episode (RecordedObservations::episodes()).
    policy = RunningSum()
    report = handcentric.audit_policy(policy, groups=["translation"], cases=30,
                                      observations=recorded(), episodes=3, reset=policy.reset,
                                      quiet=True)
    single = [c for c in report["checks"] if c["mode"] != "closed_loop"]
    assert single and all(c["equivariant"] for c in single)
    [loop] = loops(report)
    assert loop["equivariant"] is False
    assert "closed loop, recorded episode 7 (1 of 3, observations 0 to 5 of a Python iterable)" \
        in loop["witness"]["detail"]
    assert "at step 2 of 6" in loop["witness"]["detail"]


def test_an_action_queue_holds_on_recorded_episodes_each_replayed_as_recorded():
    # Mutants seen failing here (run by hand, reverted): the g side not reset between episodes
    # (its queue carries the last episode's chunk over); one g per step instead of per episode.
    policy = QueuePolicy()
    report = handcentric.audit_policy(policy, groups=["se3"], cases=30, observations=recorded(),
                                      episodes=3, reset=policy.reset, quiet=True)
    [loop] = loops(report)
    assert loop["equivariant"] is True and loop["cases"] + loop["near_identity_cases"] == 3
    assert "3 recorded episodes of 6 steps (a Python iterable)" in loop["note"]
    assert "not the executed trajectory" in loop["note"]


def test_an_npz_with_an_episode_array_gives_the_dicts_verdicts(tmp_path):
    data = recorded(2, 4)
    np.savez(tmp_path / "log.npz", history=np.stack([d["history"] for d in data]),
             hand_points=np.stack([d["hand_points"] for d in data]),
             episode=np.array([d["episode"] for d in data]))
    policy = RunningSum()
    common = dict(groups=["translation"], cases=20, episodes=2, reset=policy.reset, quiet=True)
    from_file = handcentric.audit_policy(policy, observations=str(tmp_path / "log.npz"), **common)
    from_dicts = handcentric.audit_policy(policy, observations=data, **common)
    assert loops(from_file)[0]["witness"]["after"] == loops(from_dicts)[0]["witness"]["after"]


def with_episodes(values):
    data = recorded(1, len(values))
    for d, e in zip(data, values):
        d["episode"] = e
    return data


@pytest.mark.parametrize("observations, keywords, message", [
    (with_episodes([0, 0, 1.5]), {"episodes": 1}, r"'episode' is 1\.5; an episode index is an "
                                                  "integer"),
    (with_episodes([0, 1, 0]), {"episodes": 1}, "observation 2 is of episode 0, which ended at "
                                                "observation 0: keep each episode's observations "
                                                "together"),
    (with_episodes([0, 0, 1]), {"episodes": 2}, "recorded episode 1 of a Python iterable has 1 "
                                                "observations, fewer than the 2 poses of its "
                                                "history"),
    (recorded(2, 3), {"episodes": 3}, "episodes=3 but the observations of a Python iterable "
                                      "record 2 episodes: give episodes= from 1 to 2"),
    (recorded(2, 3), {}, r"carry an 'episode' index \(2 episodes\), which only the closed loop "
                         r"replays: give audit_policy\(..., episodes=N\)"),
    (recorded(2, 3), {"episodes": 2, "episode_length": 5}, "episode_length=5 with the recorded "
                                                           "episodes of a Python iterable"),
])
def test_bad_episode_indices_are_refused_in_one_line(observations, keywords, message):
    policy = QueuePolicy()
    with pytest.raises(ValueError, match=message) as error:
        handcentric.audit_policy(policy, groups=["se3"], cases=10, observations=observations,
                                 reset=policy.reset, quiet=True, **keywords)
    assert "\n" not in str(error.value)


def test_assert_equivariant_refuses_recorded_episodes():
    with pytest.raises(ValueError, match="only the closed loop replays"):
        handcentric.assert_equivariant(make_policy(), "se3", cases=10, observations=recorded(),
                                       quiet=True)
