"""handcentric.detect_convention (python/handcentric/detect.py): episodes recorded under each
convention of conventions/ and under pose layouts in each frame and mode are named first, with
residuals of zero; a mis-declared Euler order and a component-wise "relative" are named; bad
input is a one-line DetectError naming the value. Mutant twins (test_mutant_*): plug-ins called
with the history and the chunk swapped, a step composed on the wrong side, Euler axes read
extrinsic for intrinsic, no component-wise flag, no finiteness check."""
import os

import numpy as np
import pytest

import handcentric
from handcentric import detect as detect_module
from handcentric.__main__ import main
from handcentric_plugin import formats

PLUGINS = os.path.normpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), os.pardir,
                                        os.pardir, "conventions"))
CONVENTIONS = sorted(f[:-3] for f in os.listdir(PLUGINS) if f.endswith(".py") and f[0] != "_")
EXACT = 1e-9  # m and rad: a decoding that reproduces the recorded poses
LOAD_PLUGINS = detect_module._load_plugins  # the recording's, whatever a mutant patches


def episodes(seed=0, count=2, length=10):
    """world_T_hand of `count` episodes, each a random start and random steps (1 cm, 0.05 rad):
    (N, 4, 4) and the episode of each record."""
    rng = np.random.default_rng(seed)
    states, episode = [], []
    for e in range(count):
        world_T_hand = detect_module._pose(detect_module._exp(rng.normal(size=(1, 3)))[0],
                                           rng.normal(size=3) * 0.3 + [0.2, 0.0, 1.0])
        for _ in range(length):
            states.append(world_T_hand)
            episode.append(e)
            twist = np.concatenate([rng.normal(size=3) * 0.01, rng.normal(size=3) * 0.05])
            world_T_hand = detect_module._nudge(world_T_hand[None], twist[None])[0]
    return np.array(states), np.array(episode)


def next_index(episode):
    """Each record's next record in its episode (the last one: itself, a hold)."""
    index = np.arange(len(episode)) + 1
    index[-1] = len(episode) - 1
    index[:-1][episode[1:] != episode[:-1]] -= 1
    return index


def recorded_by_plugin(name, state, episode):
    """The actions the plug-in `name` writes for each record and its next pose."""
    encode_batch, extra = LOAD_PLUGINS(PLUGINS)[name]
    following = state[next_index(episode)]
    starts = {int(e): int(np.argmax(episode == e)) for e in set(episode.tolist())}
    keywords = {"extra_poses": {"start": state[[starts[int(e)] for e in episode]],
                                "base": np.broadcast_to(np.eye(4), state.shape)},
                "scalars": {}} if extra else {}
    no_points = np.zeros((len(state), 0, 3))
    return encode_batch(state[:, None], following[:, None], no_points, no_points, **keywords)[0]


def recorded_in_layout(layout, frame, mode, state, episode, world_T_base=np.eye(4)):
    """The actions of `layout` in `frame` and `mode` (detect.py's docstring)."""
    frame_T_hand = detect_module._rigid_inverse(world_T_base) @ state
    frame_T_next = frame_T_hand[next_index(episode)]
    if mode == "absolute":
        return formats.encode(frame_T_next, layout)
    if mode == "hand":
        return formats.encode(detect_module._rigid_inverse(frame_T_hand) @ frame_T_next, layout)
    if mode == "step":
        step = detect_module._pose(
            frame_T_next[:, :3, :3] @ np.swapaxes(frame_T_hand[:, :3, :3], 1, 2),
            frame_T_next[:, :3, 3] - frame_T_hand[:, :3, 3])
        return formats.encode(step, layout)
    return formats.encode(frame_T_next, layout) - formats.encode(frame_T_hand, layout)


def named_first(ranking, name):
    """The first entry is `name` (or predicts the same poses) and reproduces them exactly."""
    best = ranking[0]
    return (name == best["convention"] or name in best["same_as"]) and \
        best["residual_m"] < EXACT and best["residual_rad"] < EXACT


def convention_named_first(name):
    state, episode = episodes(seed=len(name))
    action = recorded_by_plugin(name, state, episode)
    return named_first(handcentric.detect_convention(state, action, episode, plugins=PLUGINS),
                       name)


@pytest.mark.parametrize("name", CONVENTIONS)
def test_every_convention_is_named_first(name):
    assert convention_named_first(name)


def test_mutant_plugins_called_with_history_and_chunk_swapped(monkeypatch):
    load = detect_module._load_plugins

    def swapped(folder):
        return {name: (lambda h, c, *rest, _f=f, **kw: _f(c, h, *rest, **kw), extra)
                for name, (f, extra) in load(folder).items()}

    monkeypatch.setattr(detect_module, "_load_plugins", swapped)
    assert not convention_named_first("droid_cartesian_velocity")


LAYOUT_CASES = [
    ("pos_quat_xyzw", "world", "absolute"), ("pos_quat_wxyz", "world", "step"),
    ("pos_axis_angle", "world", "step"), ("pos_axis_angle", "world", "hand"),
    ("pos_rot6d_cols", "world", "absolute"), ("pos_rot6d_rows", "base", "absolute"),
    ("pos_euler_xyz", "world", "absolute"), ("pos_euler_ZYX", "world", "hand"),
    ("pos_euler_zxz", "base", "step"), ("pos_euler_YXZ", "world", "absolute"),
]
WORLD_T_BASE = detect_module._pose(detect_module._exp(np.array([[0.3, -0.2, 1.1]]))[0],
                                   np.array([0.5, -0.4, 0.1]))


def layout_named_first(layout, frame, mode, declared=None):
    state, episode = episodes(seed=7)
    action = recorded_in_layout(layout, frame, mode, state, episode,
                                WORLD_T_BASE if frame == "base" else np.eye(4))
    name = "%s %s" % (layout, "hand" if mode == "hand" else frame + " " + mode)
    ranking = handcentric.detect_convention(state, action, episode, plugins=PLUGINS,
                                            world_T_base=WORLD_T_BASE, declared=declared)
    return named_first(ranking, name), ranking


@pytest.mark.parametrize("layout,frame,mode", LAYOUT_CASES)
def test_every_layout_frame_and_mode_is_named_first(layout, frame, mode):
    assert layout_named_first(layout, frame, mode)[0]


def test_mutant_a_step_composed_on_the_hand_side(monkeypatch):
    monkeypatch.setattr(detect_module, "_after_step", lambda now, step: detect_module._pose(
        now[:, :3, :3] @ step[:, :3, :3], now[:, :3, 3] + step[:, :3, 3]))
    assert not layout_named_first("pos_axis_angle", "world", "step")[0]


def misdeclared_euler_order_is_named():
    """Recorded as extrinsic z-y-x, declared x-y-z: the fit names zyx and flags the
    declaration, naming both."""
    found, ranking = layout_named_first("pos_euler_zyx", "world", "absolute",
                                        declared="pos_euler_xyz")
    flags = " ".join(ranking[0]["flags"])
    return found and ranking[0]["convention"].startswith("pos_euler_zyx ") and \
        "mis-declared" in flags and "pos_euler_xyz" in flags


def test_a_misdeclared_euler_order_is_named():
    assert misdeclared_euler_order_is_named()


class SwappedEuler:
    """formats with the Euler layouts of one direction (encode or decode) read extrinsic for
    intrinsic and back ("pos_euler_xyz" as "pos_euler_XYZ"): the classic bug."""
    width, FORMATS = staticmethod(formats.width), formats.FORMATS

    def __init__(self, direction):
        self.direction = direction

    def _call(self, direction, value, name):
        if direction == self.direction and name.startswith("pos_euler_"):
            name = "pos_euler_" + name[len("pos_euler_"):].swapcase()
        return getattr(formats, direction)(value, name)

    def encode(self, T, name):
        return self._call("encode", T, name)

    def decode(self, v, name):
        return self._call("decode", v, name)


def test_mutant_euler_axes_read_extrinsic_for_intrinsic(monkeypatch):
    monkeypatch.setattr(detect_module, "formats", SwappedEuler("decode"))
    assert not misdeclared_euler_order_is_named()


def component_wise_is_flagged(layout):
    """Euler angles (or quaternion components) of the next pose minus the current's: named,
    and flagged component-wise."""
    found, ranking = layout_named_first(layout, "world", "component-wise")
    return found and any("component-wise" in flag and layout in flag
                         for flag in ranking[0]["flags"])


@pytest.mark.parametrize("layout", ["pos_euler_xyz", "pos_quat_wxyz"])
def test_a_component_wise_relative_is_flagged(layout):
    assert component_wise_is_flagged(layout)


def test_a_component_wise_convention_is_flagged():
    state, episode = episodes()
    action = recorded_by_plugin("octo_bridge_euler_diff", state, episode)
    best = handcentric.detect_convention(state, action, episode, plugins=PLUGINS)[0]
    assert best["convention"] == "octo_bridge_euler_diff"
    assert any("Euler angles subtracted component-wise" in flag for flag in best["flags"])


def test_mutant_no_component_wise_flag(monkeypatch):
    monkeypatch.setattr(detect_module, "_component_wise_flag", lambda layout: "")
    assert not component_wise_is_flagged("pos_euler_xyz")


def test_the_best_fit_carries_its_verdict_row():
    state, episode = episodes()
    action = recorded_by_plugin("umi_relative", state, episode)
    best = handcentric.detect_convention(state, action, episode, plugins=PLUGINS)[0]
    # umi_relative, lerobot_relative_ee, umi_trained and the rows layout in the hand frame
    # write the same numbers for one-step chunks: one entry.
    assert {"umi_relative", "lerobot_relative_ee"} <= set([best["convention"]] + best["same_as"])
    assert "actions: all" in best["verdict"]
    assert "se3 yes · yes · yes" in best["verdict"]
    assert set(best) >= {"convention", "residual_m", "residual_rad", "flags"}


def bad_inputs():
    state, episode = episodes(count=1, length=4)
    action = np.zeros((4, 6))
    nan_action = action.copy()
    nan_action[2, 4] = np.nan
    skewed = state.copy()
    skewed[1, 0, 0] = 3.0
    return [
        ("state", dict(state=state[:, :3], action=action, episode=episode), "(N, 4, 4)"),
        ("action", dict(state=state, action=action[:, 0], episode=episode), "(N, d)"),
        ("N", dict(state=state, action=action[:3], episode=episode), "action 3"),
        ("action[2, 4]", dict(state=state, action=nan_action, episode=episode), "repair"),
        ("state[1]", dict(state=skewed, action=action, episode=episode), "rigid pose"),
        ("episode", dict(state=state, action=action, episode=np.arange(4)), "consecutive"),
    ]


@pytest.mark.parametrize("value,inputs,fix", bad_inputs(), ids=[c[0] for c in bad_inputs()])
def test_bad_input_is_a_one_line_error_naming_the_value(value, inputs, fix):
    with pytest.raises(handcentric.DetectError) as error:
        handcentric.detect_convention(plugins=PLUGINS, **inputs)
    message = str(error.value).replace(", ", ",").replace(" ", "")
    assert "\n" not in str(error.value)
    assert value.replace(", ", ",").replace(" ", "") in message and fix.replace(" ", "") in \
        str(error.value).replace(" ", "")


def nan_is_refused():
    """A NaN in the actions is a DetectError naming it (not a ranking, nor another error)."""
    value, inputs, fix = bad_inputs()[3]
    try:
        handcentric.detect_convention(plugins=PLUGINS, **inputs)
    except handcentric.DetectError as e:
        return value in str(e)
    except Exception:
        return False
    return False


def test_mutant_no_finiteness_check_lets_a_nan_through(monkeypatch):
    assert nan_is_refused()
    monkeypatch.setattr(detect_module, "_finite", lambda name, values: None)
    assert not nan_is_refused()


def test_files_missing_keys_or_unreadable(tmp_path):
    state, episode = episodes(count=1, length=4)
    np.savez(tmp_path / "no_episode.npz", state=state, action=np.zeros((4, 6)))
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    (tmp_path / "line.jsonl").write_text('{"state": 1, "action": [0]}\n')
    for name, words in (("no_episode.npz", "no array 'episode'"), ("junk.npz", "cannot read"),
                        ("line.jsonl", "line 1 has no 'episode'"),
                        ("absent.npz", "no such file"), ("data.csv", "not a .npz or .jsonl")):
        if name == "data.csv":
            (tmp_path / name).write_text("1,2\n")
        with pytest.raises(handcentric.DetectError, match=words):
            handcentric.load_episodes(str(tmp_path / name))


def test_python_m_handcentric_conventions_detect(tmp_path, capsys):
    """`python -m handcentric conventions --detect` (its main, in process): the ranking, the
    best fit's audit, and a bad file as one line on stderr, exit 1."""
    state, episode = episodes()
    action = recorded_in_layout("pos_quat_xyzw", "world", "hand", state, episode)
    path = tmp_path / "episodes.jsonl"
    path.write_text("".join('{"state": %s, "action": %s, "episode": %d}\n'
                            % (s.tolist(), a.tolist(), e)
                            for s, a, e in zip(state, action, episode)))
    assert main(["conventions", "--detect", str(path), "--plugins", PLUGINS]) == 0
    out = capsys.readouterr().out
    assert "best fit: pos_quat_xyzw hand" in out
    assert "audit of pos_quat_xyzw hand (eye-in-hand" in out and "se3 yes · yes · yes" in out
    assert main(["conventions", "--detect", str(tmp_path / "absent.npz")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no such file" in err


def served_as_recorded(layout, frame, mode):
    """The layout candidate served for the command's audit (detect.layout_encoder) writes, for a
    one-step chunk, the numbers the detector decodes."""
    state, episode = episodes(seed=5, count=1, length=6)
    world_T_base = WORLD_T_BASE if frame == "base" else np.eye(4)
    name = "%s %s" % (layout, "hand" if mode == "hand" else frame + " " + mode)
    encode_batch, extra = detect_module.layout_encoder(name)
    B = len(state) - 1
    no_points = np.zeros((B, 0, 3))
    served, _ = encode_batch(state[:-1, None], state[1:, None], no_points, no_points,
                             extra_poses={"base": np.broadcast_to(world_T_base, (B, 4, 4))},
                             scalars={})
    recorded = recorded_in_layout(layout, frame, mode, state, episode, world_T_base)[:-1]
    return extra == (("base",) if frame == "base" else ()) and np.allclose(served, recorded,
                                                                          atol=1e-12)


@pytest.mark.parametrize("layout,frame,mode", LAYOUT_CASES)
def test_a_layout_is_served_as_it_is_detected(layout, frame, mode):
    assert served_as_recorded(layout, frame, mode)


def test_mutant_a_served_euler_layout_with_its_axes_swapped(monkeypatch):
    monkeypatch.setattr(detect_module, "formats", SwappedEuler("encode"))
    assert not served_as_recorded("pos_euler_xyz", "world", "absolute")


def test_a_bad_layout_name_is_refused():
    with pytest.raises(handcentric.DetectError, match="LAYOUT FRAME MODE"):
        detect_module.layout_encoder("pos_euler_xyz sideways")


def base_layout_audits_invariant():
    """A layout in the frame of a base that moves with g: every cell yes (the command's
    audit of a best fit, in process)."""
    row = detect_module.audit_layout("pos_rot6d_rows base absolute", cases=10)
    return all(cell.split(" ", 1)[1] == "yes · yes · yes" for cell in row.split(" | "))


def test_a_layout_in_a_base_that_moves_with_g_audits_invariant():
    assert base_layout_audits_invariant()


def test_mutant_a_base_that_stays_put(monkeypatch):
    encoder = detect_module.layout_encoder

    def fixed_base(name):
        encode_batch, extra = encoder(name)

        def encode(history, chunk, hand_points, world_points, extra_poses=None, scalars=None):
            base = np.broadcast_to(WORLD_T_BASE, (len(history), 4, 4))
            return encode_batch(history, chunk, hand_points, world_points, {"base": base})
        return encode, extra

    monkeypatch.setattr(detect_module, "layout_encoder", fixed_base)
    assert not base_layout_audits_invariant()
