"""observations=: audits on the user's own recorded observations. The same data as a list of
dicts, a .jsonl file and .npz files written by NumPy (np.savez and np.savez_compressed) give the
same verdicts and witnesses; held arrays reach the policy unchanged (float32 kept); a world-frame
part filed under "held" (the planted fault) turns a yes into a NO; bad data are refused in one
line. The pipe side (held arrays over --policy-exec) is in tests/props/test_cli.cpp."""
import json

import numpy as np
import pytest

import handcentric


def pose(R, t):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = t
    return T


def inverse(T):
    return pose(T[:3, :3].T, -T[:3, :3].T @ T[:3, 3])


def recorded(count=24, goal_held=False, seed=5):
    """A robot's log in a 1 m cell: the hand's history and chunk, a goal pose, a gripper width
    and a float32 wrist image (3, 4, 5)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        T0 = pose(handcentric.so3_exp(rng.normal(size=3)), rng.uniform(-0.6, 0.6, 3))
        step = pose(handcentric.so3_exp(0.05 * rng.normal(size=3)), 0.01 * rng.normal(size=3))
        goal = pose(handcentric.so3_exp([0, 0, rng.uniform(-3, 3)]), rng.uniform(-0.6, 0.6, 3))
        item = {"history": np.stack([T0, T0 @ inverse(step)]),
                "chunk": np.stack([T0 @ step, T0 @ step @ step]),
                "scalars": {"gripper": float(rng.uniform(0.1, 1.0))},
                "held": {"wrist": rng.random((3, 4, 5)).astype(np.float32)}}
        if goal_held:
            item["held"]["goal"] = goal  # the planted fault: a world-frame pose filed as held
        else:
            item["extra_poses"] = {"goal": goal}
        out.append(item)
    return out


SEEN = []


def goal_policy(history, hand_points, world_points, noise, extra_poses, scalars, held):
    """Batched: steps toward the goal as seen from the hand, scaled by the gripper width and the
    image's mean; equivariant when everything it reads moves as declared."""
    SEEN.append((held["wrist"].dtype, held["wrist"].shape))
    goal = held["goal"] if "goal" in held else extra_poses["goal"]
    out = []
    for b in range(len(history)):
        T0 = history[b, 0]
        hand_goal = inverse(T0) @ goal[b]
        gain = 0.1 * scalars["gripper"][b] * float(held["wrist"][b].mean())
        step = pose(handcentric.so3_exp(0.1 * handcentric.so3_log(hand_goal[:3, :3])
                                        + [0, 0, 0.01 * noise[b, 0]]), gain * hand_goal[:3, 3])
        out.append(np.stack([T0 @ step, T0 @ step @ step]))
    return np.stack(out)


def audit(observations, **kw):
    return handcentric.audit_policy(goal_policy, observations=observations, cases=120,
                                    batch_size=64, noise=4, quiet=True, **kw)


def test_a_policy_on_its_own_data_is_equivariant_and_a_misfiled_goal_is_caught():
    SEEN.clear()
    report = audit(recorded())
    assert report["observations"] == {"source": "a Python iterable", "count": 24}
    assert {c["view"] for c in report["checks"]} == {"eye_in_hand"}  # no world points
    assert all(c["equivariant"] for c in report["checks"]), report["checks"]
    assert all("24 recorded observations" in c["note"] for c in report["checks"])
    assert SEEN and all(dtype == np.float32 and shape[1:] == (3, 4, 5) for dtype, shape in SEEN)
    wrong = audit(recorded(goal_held=True))
    assert not any(c["equivariant"] for c in wrong["checks"])


def same_checks(a, b):
    def strip(report):
        return json.dumps([{k: v for k, v in c.items() if k != "note"} for c in report["checks"]],
                          sort_keys=True)
    return strip(a) == strip(b)


def test_files_written_by_numpy_and_json_lines_give_the_dicts_verdicts(tmp_path):
    data = recorded(12)
    from_dicts = audit(data)
    arrays = {"history": np.stack([d["history"] for d in data]),
              "chunk": np.stack([d["chunk"] for d in data]),
              "extra_poses/goal": np.stack([d["extra_poses"]["goal"] for d in data]),
              "scalars/gripper": np.array([d["scalars"]["gripper"] for d in data]),
              "held/wrist": np.stack([d["held"]["wrist"] for d in data])}
    np.savez(tmp_path / "log.npz", **arrays)
    np.savez_compressed(tmp_path / "log_compressed.npz", **arrays)
    with open(tmp_path / "log.jsonl", "w") as f:
        for d in data:
            f.write(json.dumps({"history": d["history"].tolist(), "chunk": d["chunk"].tolist(),
                                "extra_poses": {"goal": d["extra_poses"]["goal"].tolist()},
                                "scalars": d["scalars"],
                                "held": {"wrist": handcentric_encoded(d["held"]["wrist"])}})
                    + "\n")
    for name in ("log.npz", "log_compressed.npz", "log.jsonl"):
        report = audit(str(tmp_path / name))
        assert report["observations"]["count"] == 12
        assert same_checks(report, from_dicts), name
    # The planted fault: a file whose goal moved by 1 cm gives other witnesses or errors.
    arrays["extra_poses/goal"][:, 0, 3] += 0.01
    np.savez(tmp_path / "moved.npz", **arrays)
    moved = handcentric.audit_policy(goal_policy, observations=str(tmp_path / "moved.npz"),
                                     cases=120, batch_size=64, noise=4, quiet=True, seed=1)
    assert all(c["equivariant"] for c in moved["checks"])
    assert not same_checks(moved, from_dicts)


def handcentric_encoded(array):
    """The pipe's encoded array form, which JSON Lines files may use for images."""
    import base64
    little = np.ascontiguousarray(array).astype(array.dtype.newbyteorder("<"))
    return {"dtype": str(array.dtype), "shape": list(array.shape),
            "data": base64.b64encode(little.tobytes()).decode()}


def test_representation_audits_read_the_recorded_chunks():
    data = recorded(16)

    def hand_centric(history, chunk, hand_points, world_points, **kw):
        return np.concatenate([handcentric.se3_log(inverse(history[0]) @ T) for T in chunk])

    def absolute(history, chunk, hand_points, world_points, **kw):
        return np.concatenate([handcentric.se3_log(T) for T in chunk])
    good = handcentric.audit(hand_centric, observations=data, cases=100, quiet=True)
    bad = handcentric.audit(absolute, observations=data, cases=100, quiet=True)
    assert all(c["invariant"] for c in good["checks"])
    assert not any(c["invariant"] for c in bad["checks"] if c["component"] == "actions")
    for d in data:
        del d["chunk"]
    with pytest.raises(ValueError, match="record no action chunk"):
        handcentric.audit(hand_centric, observations=data, cases=100, quiet=True)


@pytest.mark.parametrize("observations, message", [
    ({"history": np.eye(4)[None]}, "is one dict"),
    (42, "a path or an iterable of dicts"),
    ([np.eye(4)], "not a dict"),
    ([{"chunk": np.eye(4)[None]}], "no 'history'"),
    ([{"history": np.eye(4)}], r"expected \(n, 4, 4\)"),
    ([{"history": 2 * np.eye(4)[None]}], "not a rigid transform"),
    ([{"history": np.eye(4)[None], "held": {"x": [np.nan]}}], "non-finite"),
    ([{"history": np.eye(4)[None], "speed": [1.0]}], "part 'speed'"),
    ([], "are empty"),
    ("no_such_file.npz", "cannot open"),
    ("data.csv", "neither .jsonl nor .npz"),
])
def test_bad_observations_are_refused_in_one_line(observations, message):
    with pytest.raises((ValueError, TypeError, OSError, RuntimeError), match=message):
        handcentric.audit_policy(goal_policy, observations=observations, cases=10, quiet=True)


def test_sizes_and_names_that_contradict_the_data_are_refused():
    with pytest.raises(ValueError, match="the data's sizes are used"):
        audit(recorded(4), history=2)
    with pytest.raises(ValueError, match="extra_poses names 'start'"):
        audit(recorded(4), extra_poses=["start"])


def test_a_corrupt_npz_is_refused(tmp_path):
    data = recorded(3)
    np.savez_compressed(tmp_path / "log.npz", history=np.stack([d["history"] for d in data]))
    raw = (tmp_path / "log.npz").read_bytes()
    (tmp_path / "cut.npz").write_bytes(raw[: len(raw) // 2])
    middle = len(raw) // 3  # inside the deflated data: the CRC check must see it
    flipped = raw[:middle] + bytes([raw[middle] ^ 0xFF]) + raw[middle + 1:]
    (tmp_path / "flipped.npz").write_bytes(flipped)
    for name in ("cut.npz", "flipped.npz"):
        with pytest.raises((ValueError, OSError, RuntimeError), match="observations file"):
            audit(str(tmp_path / name))
