"""handcentric.detect_convention: which convention recorded episodes are in.

Users record world-frame hand poses and the action vectors their pipeline wrote, and often do not
know (or mis-declare) the frame, the rotation layout, or whether the actions are targets or
steps. Every candidate here is a decoding (world_T_hand_t, a_t) -> a predicted next pose, and
the candidates are ranked by how far that prediction lands from the next recorded pose,
world_T_hand_{t+1}, in metres and radians:

  conventions  every plug-in of conventions/ (docs/CONVENTIONS.md's rows). A plug-in only
               encodes, so its decoding is found numerically: the pose T nearest the recorded
               next pose with encode(world_T_hand_t, T) = a_t (Gauss-Newton from the recorded
               pose, central differences); a step whose action no nearby pose reproduces is
               counted as unexplained.
  layouts      every pose layout of handcentric_plugin.formats, in the frames world, base (with
               world_T_base) and hand now, as
                 absolute         a = layout(F_T_hand_{t+1})                 (F = world, base)
                 step             a = layout(step), step = [p_{t+1} - p_t, R_{t+1} R_t^T] in F
                 hand             a = layout(hand_t_T_hand_{t+1})            (the hand-centric step)
                 component-wise   a = layout(F_T_hand_{t+1}) - layout(F_T_hand_t)

Candidates that predict the same poses on the data (UMI's rel and delta on one-step chunks, a
row and the layout it writes) cannot be told apart by them: they share one entry, the others
named in `same_as`. Flags name what a user should know about a fit: rotations differenced
component-wise (Euler angles, rotation vectors or quaternion components subtracted, which is not
a rotation and breaks equivariance), action columns the fit ignores (a gripper), steps it cannot
explain, and a declared layout the data contradict.

This module needs NumPy and handcentric_plugin only (not the compiled extension), so that
`handcentric conventions --detect` runs it through conventions/_detect.py with the interpreter
that runs the plug-ins.
"""
import importlib.util
import json
import os
import sys

import numpy as np

from handcentric_plugin import formats

KEYS = ("state", "action", "episode")
MODES = ("absolute", "step", "hand", "component-wise")
_ROTATION_TOLERANCE = 1e-3  # |R^T R - I|: a recorded pose that is not a rotation is refused
_SAME = 1e-9  # per-step residuals this close: the two candidates predict the same poses
_EXPLAINED = 1e-6  # an action reproduced to this (times 1 + |a|) counts as explained
_FD_STEP = 1e-3  # m and rad: large enough for plug-ins computed in float32
# The plug-ins whose rotation part is a difference of rotation coordinates, not a rotation.
_COMPONENT_WISE = {
    "octo_bridge_euler_diff": "Euler angles subtracted component-wise",
    "openpi_delta_actions": "rotation vectors subtracted component-wise",
    "openpi_libero_pi0": "the state's rotation vector subtracted from the step's",
}


class DetectError(ValueError):
    """Recorded episodes that cannot be read as state (N, 4, 4), action (N, d), episode (N,):
    the message names the value and the fix in one line."""


def _layouts():
    """Every layout of formats.FORMATS except "matrix": the Euler ones with every axis order,
    extrinsic (lowercase) and intrinsic (uppercase)."""
    euler = [a + b + c for a in "xyz" for b in "xyz" for c in "xyz" if a != b and b != c]
    return [name for name in formats.FORMATS if name != "matrix" and "<" not in name] + \
        ["pos_euler_" + axes for axes in euler] + ["pos_euler_" + axes.upper() for axes in euler]


LAYOUTS = tuple(_layouts())


def _default_plugins():
    """conventions/ of the source tree: beside python/ (the sources) or above build/python."""
    here = os.path.dirname(os.path.realpath(__file__))
    for up in (2, 3):
        folder = os.path.join(here, *([os.pardir] * up), "conventions")
        if os.path.isfile(os.path.join(folder, "_geometry.py")):
            return os.path.normpath(folder)
    return None


def load_episodes(path):
    """(state, action, episode, world_T_base or None) of a .npz (arrays of those names) or a
    .jsonl (one object per line with those keys); DetectError naming the file otherwise."""
    fix = "give state (N, 4, 4), action (N, d) and episode (N,)"
    if not os.path.isfile(path):
        raise DetectError("cannot read %r: no such file; %s in a .npz or .jsonl" % (path, fix))
    if path.endswith(".npz"):
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {key: data[key] for key in data.files}
        except (OSError, ValueError) as e:
            raise DetectError("cannot read %r as a .npz (%s); %s as arrays of those names"
                              % (path, e, fix)) from None
    elif path.endswith(".jsonl"):
        rows = []
        with open(path) as lines:
            for number, line in enumerate(lines, 1):
                if not line.strip():
                    continue
                try:
                    rows.append(json.loads(line))
                except ValueError as e:
                    raise DetectError("%s line %d is not JSON (%s); write one object per line "
                                      "with keys state, action, episode" % (path, number, e)) \
                        from None
                if not isinstance(rows[-1], dict):
                    raise DetectError("%s line %d is not a JSON object; write one object per "
                                      "line with keys state, action, episode" % (path, number))
        for number, row in enumerate(rows, 1):
            missing = [key for key in KEYS if key not in row]
            if missing:
                raise DetectError("%s line %d has no %r; %s" % (path, number, missing[0], fix))
        try:
            arrays = {key: np.array([row[key] for row in rows], dtype=float) for key in KEYS}
        except ValueError as e:
            raise DetectError("%s: the lines' values do not stack into arrays (%s); every line "
                              "needs state 4x4 and action of one length d" % (path, e)) from None
        if rows and "world_T_base" in rows[0]:
            arrays["world_T_base"] = np.array(rows[0]["world_T_base"], dtype=float)
    else:
        raise DetectError("cannot read %r: not a .npz or .jsonl; %s" % (path, fix))
    for key in KEYS:
        if key not in arrays:
            raise DetectError("%s has no array %r; %s" % (path, key, fix))
    return arrays["state"], arrays["action"], arrays["episode"], arrays.get("world_T_base")


def _finite(name, values):
    """DetectError naming the first NaN or infinity of values (a NaN would rank as anything)."""
    bad = ~np.isfinite(values)
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        raise DetectError("%s%s is %s; drop or repair the record %d"
                          % (name, list(index), values[index], index[0]))


def _checked(state, action, episode, world_T_base):
    """The inputs as float64 / int64 arrays, or DetectError naming the value and the fix."""
    state = np.asarray(state, dtype=float)
    action = np.asarray(action, dtype=float)
    episode_values = np.asarray(episode)
    if state.ndim != 3 or state.shape[1:] != (4, 4):
        raise DetectError("state has shape %s; it must be (N, 4, 4): world_T_hand of each record"
                          % (state.shape,))
    if action.ndim != 2:
        raise DetectError("action has shape %s; it must be (N, d): one action vector per record"
                          % (action.shape,))
    if episode_values.ndim != 1:
        raise DetectError("episode has shape %s; it must be (N,): one integer per record"
                          % (episode_values.shape,))
    sizes = {"state": len(state), "action": len(action), "episode": len(episode_values)}
    if len(set(sizes.values())) != 1:
        raise DetectError("the records disagree on N: %s; give one state, action and episode "
                          "per record" % ", ".join("%s %d" % item for item in sizes.items()))
    if not np.all(np.round(episode_values.astype(float)) == episode_values.astype(float)):
        raise DetectError("episode holds a non-integer value; give each record's episode as an "
                          "integer")
    episode = episode_values.astype(np.int64)
    _finite("state", state)
    _finite("action", action)
    rotation_error = np.abs(np.swapaxes(state[:, :3, :3], 1, 2) @ state[:, :3, :3] - np.eye(3))
    bottom_error = np.abs(state[:, 3] - [0, 0, 0, 1])
    wrong = (rotation_error.max(axis=(1, 2)) > _ROTATION_TOLERANCE) | \
        (bottom_error.max(axis=1) > _ROTATION_TOLERANCE)
    if wrong.any():
        raise DetectError("state[%d] is not a rigid pose (rotation not orthonormal or last row "
                          "not 0 0 0 1); give world_T_hand as 4x4 homogeneous matrices"
                          % int(np.argmax(wrong)))
    if world_T_base is not None:
        world_T_base = np.asarray(world_T_base, dtype=float)
        if world_T_base.shape != (4, 4) or not np.all(np.isfinite(world_T_base)):
            raise DetectError("world_T_base has shape %s; it must be one finite 4x4 pose"
                              % (world_T_base.shape,))
    pairs = np.flatnonzero(episode[1:] == episode[:-1])
    if len(pairs) == 0:
        raise DetectError("no episode has two consecutive records; the fit needs each action's "
                          "next pose (records of one episode in order)")
    return state, action, episode, world_T_base, pairs


def _angle(R):
    """Rotation angles of a stack of rotations, accurate near 0 (atan2 of sin and cos)."""
    skew = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                     R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    trace = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    return np.arctan2(np.linalg.norm(skew, axis=-1) / 2, (trace - 1) / 2)


def _residuals(predicted, world_T_next):
    """Per-step distances (m, rad) of predicted poses from the recorded next poses."""
    metres = np.linalg.norm(predicted[:, :3, 3] - world_T_next[:, :3, 3], axis=-1)
    turn = np.swapaxes(predicted[:, :3, :3], 1, 2) @ world_T_next[:, :3, :3]
    return metres, _angle(turn)


def _pose(R, p):
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = R, p, 1
    return T


def _rigid_inverse(T):
    R_t = np.swapaxes(T[..., :3, :3], -1, -2)
    return _pose(R_t, -(R_t @ T[..., :3, 3:])[..., 0])


def _exp(w):
    """exp([w]x) of a stack of small rotation vectors (Rodrigues)."""
    angle = np.linalg.norm(w, axis=-1)[..., None, None]
    K = np.zeros(w.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    K = K - np.swapaxes(K, -1, -2)
    safe = np.where(angle < 1e-12, 1.0, angle)
    a = np.where(angle < 1e-12, 1.0, np.sin(safe) / safe)
    b = np.where(angle < 1e-12, 0.5, (1 - np.cos(safe)) / safe ** 2)
    return np.eye(3) + a * K + b * (K @ K)


def _nudge(T, delta):
    """T moved by the world-frame twist delta = (v, w): [exp(w) R, p + v]."""
    return _pose(_exp(delta[:, 3:]) @ T[:, :3, :3], T[:, :3, 3] + delta[:, :3])


def _after_step(frame_T_now, step):
    """The pose a step [p_{t+1} - p_t, R_{t+1} R_t^T] (in the frame F) leads to."""
    return _pose(step[:, :3, :3] @ frame_T_now[:, :3, :3], frame_T_now[:, :3, 3] + step[:, :3, 3])


def _component_wise_flag(layout):
    return ("rotation differenced component-wise (%s numbers subtracted): not a rotation; "
            "breaks equivariance" % layout)


def _layout_candidates(world_T_now, world_T_next, action, frames):
    """(name, layout, predicted world_T_next or None) of every layout, frame and mode."""
    out = []
    for layout in LAYOUTS:
        n = formats.width(layout)
        if action.shape[1] < n:
            continue
        a = action[:, :n]
        for frame, world_T_frame in frames:
            frame_T_world = _rigid_inverse(world_T_frame)
            frame_T_now = frame_T_world @ world_T_now
            for mode in MODES:
                if mode == "hand" and frame != "world":
                    continue  # hand_t_T_hand_{t+1} is the same in every frame
                name = "%s %s" % (layout, "hand" if mode == "hand" else frame + " " + mode)
                try:
                    if mode == "absolute":
                        frame_T_next = formats.decode(a, layout)
                    elif mode == "hand":
                        frame_T_next = frame_T_now @ formats.decode(a, layout)
                    elif mode == "step":
                        frame_T_next = _after_step(frame_T_now, formats.decode(a, layout))
                    else:
                        frame_T_next = formats.decode(formats.encode(frame_T_now, layout) + a,
                                                      layout)
                    predicted = world_T_frame @ frame_T_next
                except ValueError:
                    predicted = None  # the numbers are not poses in this layout at all
                out.append((name, layout, mode, predicted))
    return out


def _load_plugins(folder):
    """{stem: (encode_batch, extra pose names)} of every plug-in of folder."""
    names = sorted(f[:-3] for f in os.listdir(folder) if f.endswith(".py") and f[0] != "_")
    if folder not in sys.path:
        sys.path.insert(0, folder)  # the plug-ins import _geometry from their folder
    out = {}
    for name in names:
        spec = importlib.util.spec_from_file_location("handcentric_convention_" + name,
                                                      os.path.join(folder, name + ".py"))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        source = open(os.path.join(folder, name + ".py")).read()
        extra = tuple(e for e in ("base", "start") if '"%s"' % e in source.split("serve(")[-1])
        out[name] = (module.encode_batch, extra)
    return out


def _convention_fit(encode_batch, extra, world_T_now, world_T_next, action, start, base,
                    iterations=3):
    """(per-step m, rad, unexplained mask, width) of a plug-in's numerical decoding."""
    B = len(world_T_now)
    history = world_T_now[:, None]
    no_points = np.zeros((B, 0, 3))
    keywords = {}
    if extra:
        keywords = {"extra_poses": {"start": start, "base": np.broadcast_to(base, (B, 4, 4))},
                    "scalars": {}}

    def encode(T):
        return np.asarray(encode_batch(history, T[:, None], no_points, no_points, **keywords)[0],
                          dtype=float)

    recorded = encode(world_T_next)
    width = recorded.shape[1]
    if width > action.shape[1]:
        return None
    a = action[:, :width]
    T = world_T_next.copy()
    for iteration in range(iterations):
        miss = a - (recorded if iteration == 0 else encode(T))
        if np.all(np.abs(miss) <= _EXPLAINED * (1 + np.abs(a))):
            break
        J = np.empty((B, width, 6))
        for k in range(6):
            h = np.zeros((B, 6))
            h[:, k] = _FD_STEP
            J[:, :, k] = (encode(_nudge(T, h)) - encode(_nudge(T, -h))) / (2 * _FD_STEP)
        delta = (np.linalg.pinv(J) @ miss[..., None])[..., 0]
        delta = np.clip(delta, -0.5, 0.5)  # a linearization far from T is no guide
        T = _nudge(T, delta)
    miss = a - encode(T)
    unexplained = np.any(np.abs(miss) > 1e-3 * (1 + np.abs(a)), axis=1)
    metres, radians = _residuals(T, world_T_next)
    return metres, radians, unexplained, width


def _theory(mode, frame):
    """The groups leaving a layout candidate's actions invariant, and why (Theorem 1's
    reasoning: only quantities in the hand's frame, or in a frame moving with g, are
    invariant)."""
    if mode == "hand":
        return "actions: all (hand_t_T_hand_{t+1} is the same after any global g)"
    if frame == "base":
        return ("actions: all if the base moves with g (a mobile base, or a rig moved as a "
                "whole); none if it is fixed in the world")
    if mode == "absolute":
        return "actions: none (world-frame coordinates)"
    if mode == "step":
        return "actions: translation (a world-frame step turns with a global rotation)"
    return "actions: translation, and NOT a rotation step (coordinates subtracted)"


def _verdict(best, folder):
    """The best fit's verdict row: the table's row for a convention, the theory for a layout."""
    if best["kind"] == "layout":
        return "%s: %s" % (best["convention"], best["theory"])
    docs = os.path.join(folder, os.pardir, "docs", "CONVENTIONS.md")
    source = open(os.path.join(folder, best["convention"] + ".py")).read()
    expect = [line.strip() for line in source.splitlines() if line.startswith("Expect")]
    row = ""
    if os.path.isfile(docs):
        prefix = "| [%s]" % best["convention"].replace("_", "\\_")
        for line in open(docs):
            if line.startswith(prefix):
                cells = [cell.strip() for cell in line.split("|")[1:-1]]
                plain = [_strip_links(cell) for cell in cells[:7]]
                row = ("eye-in-hand row of docs/CONVENTIONS.md (actions · target law · "
                       "observation): translation %s | rotation %s | se2 %s | se3 %s | c8 %s | "
                       "injective: %s" % tuple(plain[1:7]))
                break
    theory = "expected " + expect[0][len("Expect"):].strip() if expect else ""
    return "; ".join(part for part in ("%s: %s" % (best["convention"], theory), row) if part)


def _strip_links(cell):
    """"[NO](#anchor) · yes" -> "NO · yes"."""
    out, i = "", 0
    while i < len(cell):
        if cell[i] == "[":
            close = cell.index("](", i)
            out += cell[i + 1:close]
            i = cell.index(")", close) + 1
        else:
            out += cell[i]
            i += 1
    return out.replace("\\_", "_")


def detect_convention(state, action, episode, *, world_T_base=None, plugins=None, declared=None,
                      top=None, max_steps=2000, audit=False):
    """Rank every convention of conventions/ and every pose layout (frames world, base, hand;
    absolute, step or component-wise) by how well its decoding of each recorded action
    reproduces the next recorded pose.

    state (N, 4, 4) world_T_hand per record; action (N, d) as recorded; episode (N,) integers
    (consecutive records of one episode are steps); world_T_base (4, 4) adds the base frame;
    plugins the folder of convention plug-ins (default: the source tree's conventions/);
    declared a layout or candidate name the user believes the data are in (flagged when the data
    contradict it); top keeps the first entries only; max_steps bounds the steps fitted (evenly
    spaced over the records: the numerical decodings cost about a second per 1000 steps);
    audit=True audits a best fit that is a layout (audit_layout, the compiled extension) into its
    entry's "audit".

    Returns a list, best first, of dicts: convention (a row's name or "LAYOUT FRAME MODE"),
    kind ("convention" or "layout"), residual_m and residual_rad (mean over steps), flags (list
    of strings), same_as (candidates predicting the same poses), theory (layouts); the first
    also has verdict (its row of docs/CONVENTIONS.md or, for a layout, the groups leaving it
    invariant). Raises DetectError (a ValueError) naming a bad input and its fix."""
    state, action, episode, world_T_base, pairs = _checked(state, action, episode, world_T_base)
    folder = plugins if plugins is not None else _default_plugins()
    if folder is None or not os.path.isdir(folder):
        raise DetectError("no folder of convention plug-ins at %r; pass plugins= (the "
                          "repository's conventions/)" % (folder,))
    if len(pairs) > max_steps:
        pairs = pairs[np.unique(np.linspace(0, len(pairs) - 1, max_steps).astype(int))]
    world_T_now, world_T_next, a = state[pairs], state[pairs + 1], action[pairs]
    first_of_episode = {}
    for i, e in enumerate(episode):
        first_of_episode.setdefault(int(e), i)
    start = state[[first_of_episode[int(e)] for e in episode[pairs]]]
    base = world_T_base if world_T_base is not None else np.eye(4)
    step_m = max(float(np.mean(np.linalg.norm(world_T_next[:, :3, 3] - world_T_now[:, :3, 3],
                                              axis=-1))), 1e-4)
    step_rad = max(float(np.mean(_angle(np.swapaxes(world_T_now[:, :3, :3], 1, 2) @
                                        world_T_next[:, :3, :3]))), 1e-3)
    entries = []

    def add(name, kind, metres, radians, unexplained, width, flags, theory=None):
        flags = list(flags)
        if width < action.shape[1]:
            flags.append("reads columns 0..%d of %d (the others, e.g. a gripper, not fitted)"
                         % (width - 1, action.shape[1]))
        if unexplained.any():
            flags.append("%d of %d steps unexplained (no pose near the recorded one encodes to "
                         "the action)" % (int(unexplained.sum()), len(unexplained)))
        entries.append({"convention": name, "kind": kind,
                        "residual_m": float(np.mean(metres)),
                        "residual_rad": float(np.mean(radians)), "flags": flags,
                        "same_as": [], "theory": theory,
                        "_key": (float(np.mean(unexplained)),
                                 float(np.mean(metres)) / step_m +
                                 float(np.mean(radians)) / step_rad),
                        "_steps": np.concatenate([metres, radians])})

    for name, (encode_batch, extra) in _load_plugins(folder).items():
        fit = _convention_fit(encode_batch, extra, world_T_now, world_T_next, a, start, base)
        if fit is None:
            continue
        flags = [_COMPONENT_WISE[name] + ": not a rotation; breaks equivariance"] \
            if name in _COMPONENT_WISE else []
        add(name, "convention", *fit, flags)
    frames = [("world", np.eye(4))] + ([("base", world_T_base)] if world_T_base is not None
                                       else [])
    for name, layout, mode, predicted in _layout_candidates(world_T_now, world_T_next, a, frames):
        if predicted is None:
            continue
        metres, radians = _residuals(predicted, world_T_next)
        flags = [_component_wise_flag(layout)] if mode == "component-wise" else []
        add(name, "layout", metres, radians, np.zeros(len(metres), bool), formats.width(layout),
            flags, theory=_theory(mode, name.split()[1]))
    entries.sort(key=lambda entry: entry["_key"])
    merged = []
    for entry in entries:
        twin = next((m for m in merged if np.max(np.abs(m["_steps"] - entry["_steps"])) <= _SAME
                     and m["_key"][0] == entry["_key"][0]), None)
        if twin is None:
            merged.append(entry)
        else:
            twin["same_as"].append(entry["convention"])
    if declared is not None:
        _flag_declared(merged, declared)
    best = merged[0]
    best["verdict"] = _verdict(best, folder)
    if audit and best["kind"] == "layout":
        best["audit"] = audit_layout(best["convention"])
    for entry in merged:
        del entry["_key"], entry["_steps"]
    return merged[:top] if top else merged


def _flag_declared(merged, declared):
    """Flags the best fit when it is not what the user declared (a layout or a full name)."""
    def names(entry):
        return [entry["convention"]] + entry["same_as"]

    def matches(name):
        return name == declared or name.split()[0] == declared

    best = merged[0]
    if any(matches(name) for name in names(best)):
        return
    found = next((m for m in merged if any(matches(name) for name in names(m))), None)
    if found is None:
        raise DetectError("declared %r is no candidate; name a layout (%s, ...) or a "
                          "convention of the table" % (declared, ", ".join(LAYOUTS[:5])))
    best["flags"].append("mis-declared: the data were declared %s, but fit %s (%.3g m, %.3g rad "
                         "against %.3g m, %.3g rad)"
                         % (declared, best["convention"], best["residual_m"],
                            best["residual_rad"], found["residual_m"], found["residual_rad"]))
    found["flags"].append("declared, but %s fits better" % best["convention"])


def layout_encoder(name):
    """(encode_batch, extra pose names) of a layout candidate "LAYOUT FRAME MODE" (or "LAYOUT
    hand") as a plug-in of conventions/ would write it, for the audit of the best fit: the
    actions of a chunk, each pose k against pose k-1 (k = 1..K, pose 0 the hand now) in the
    steps; the observation the hand now in the same layout and frame, with the points in that
    frame (the hand's for "hand"). The base, when named, is an extra pose that moves with g."""
    parts = name.split()
    layout, frame = parts[0], parts[1]
    mode = "hand" if frame == "hand" else (parts[2] if len(parts) == 3 else None)
    if layout not in LAYOUTS or mode not in MODES or frame not in ("world", "base", "hand"):
        raise DetectError("%r is no layout candidate; write LAYOUT FRAME MODE, e.g. "
                          "'pos_euler_xyz world step' or 'pos_quat_wxyz hand'" % name)

    def encode_batch(history, chunk, hand_points, world_points, extra_poses=None, scalars=None):
        B, K = chunk.shape[:2]
        world_T_frame = extra_poses["base"] if frame == "base" else np.broadcast_to(np.eye(4),
                                                                                   (B, 4, 4))
        if frame == "hand":
            world_T_frame = history[:, 0]
        frame_T_world = _rigid_inverse(world_T_frame)[:, None]
        poses = frame_T_world @ np.concatenate([history[:, :1], chunk], axis=1)
        before, after = poses[:, :-1], poses[:, 1:]
        if mode in ("absolute", "hand"):
            actions = formats.encode(after, layout)
        elif mode == "step":
            step = _pose(after[..., :3, :3] @ np.swapaxes(before[..., :3, :3], -1, -2),
                         after[..., :3, 3] - before[..., :3, 3])
            actions = formats.encode(step, layout)
        else:
            actions = formats.encode(after, layout) - formats.encode(before, layout)
        points = (frame_T_world[:, 0, :3, :3] @ np.swapaxes(world_points, 1, 2) +
                  frame_T_world[:, 0, :3, 3:])
        observation = np.concatenate([formats.encode(poses[:, 0], layout),
                                      hand_points.reshape(B, -1),
                                      np.swapaxes(points, 1, 2).reshape(B, -1)], axis=1)
        return actions.reshape(B, -1), observation

    return encode_batch, (("base",) if frame == "base" else ())


def audit_layout(name, cases=50, seed=1):
    """The eye-in-hand verdict row of a layout candidate, audited in process by
    handcentric.audit (the compiled extension) as the command audits it through the pipe: per
    group, actions (pointwise) · target law (in distribution) · observation (pointwise)."""
    import handcentric
    encode_batch, extra = layout_encoder(name)

    def actions(history, chunk, hand_points, world_points, **poses):
        return encode_batch(history, chunk, hand_points, world_points, **poses)[0]

    def observation(history, hand_points, world_points, **poses):
        # The observation does not read the chunk: the hand now stands in for it.
        return encode_batch(history, history[:, :1], hand_points, world_points, **poses)[1]

    result = handcentric.audit(actions, observation, views=("eye_in_hand",), cases=cases,
                               seed=seed, extra_poses=extra, batch_size=256, quiet=True)
    cells = {(c["component"], c["mode"], c["group"]): "yes" if c["invariant"] else "NO"
             for c in result["checks"]}
    return " | ".join(
        "%s %s" % (group, " · ".join(cells.get(key + (group,), "-") for key in (
            ("actions", "pointwise"), ("flow_target", "distribution"),
            ("observation", "pointwise"))))
        for group in handcentric.GROUPS)


def detect_text(ranking, count=10):
    """The ranking as lines: rank, candidate, residuals, flags; then the best fit's verdict."""
    lines = ["rank  residual_m  residual_rad  convention"]
    for rank, entry in enumerate(ranking[:count], 1):
        also = " (= %s)" % ", ".join(entry["same_as"]) if entry["same_as"] else ""
        lines.append("%4d  %10.3g  %12.3g  %s%s" % (rank, entry["residual_m"],
                                                    entry["residual_rad"], entry["convention"],
                                                    also))
        lines.extend("                              ! " + flag for flag in entry["flags"])
    lines.append("best fit: %s" % ranking[0]["convention"])
    lines.append("verdict: %s" % ranking[0]["verdict"])
    if "audit" in ranking[0]:
        lines.append("audit of %s (eye-in-hand, 50 cases per cell; actions · target law · "
                     "observation): %s" % (ranking[0]["convention"], ranking[0]["audit"]))
    return "\n".join(lines)


def main(argv=None, prog="handcentric conventions --detect"):
    """FILE [--plugins DIR] [--declared NAME] [--world-T-base-from FILE] [--top K] [--json]:
    prints the ranking; a bad input is one line on stderr and exit 1."""
    import argparse
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument("file")
    parser.add_argument("--plugins")
    parser.add_argument("--declared")
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--best-out", metavar="PATH",
                        help="also write the best fit's name to PATH (for the command's audit)")
    parser.add_argument("--audit", action="store_true",
                        help="audit a best-fitting layout in process (the compiled extension)")
    parser.add_argument("--serve", action="store_true",
                        help="FILE is a layout candidate's name: serve it as a plug-in")
    args = parser.parse_args(argv)
    if args.serve:
        from handcentric_plugin import serve
        encode_batch, extra = layout_encoder(args.file)
        serve(encode_batch, batched=True, batch_size=256, extra_poses=extra)
        return 0
    try:
        state, action, episode, world_T_base = load_episodes(args.file)
        ranking = detect_convention(state, action, episode, world_T_base=world_T_base,
                                    plugins=args.plugins, declared=args.declared,
                                    audit=args.audit)
    except DetectError as e:
        print(str(e), file=sys.stderr)
        return 1
    if args.best_out:
        with open(args.best_out, "w") as out:
            out.write(ranking[0]["convention"] + "\n")
    if args.json:
        print(json.dumps(ranking[:args.top], indent=1))
    else:
        print(detect_text(ranking, args.top))
    return 0
