"""A policy plug-in's interface on the wire: pose layouts, hands, named outputs and stages.

serve_policy(policy, state_format=, action_format=, outputs=, hands=, stages=) declares them in
its hello (docs/AUDIT.md, "--exec"), and the audit then speaks the policy's own language:
  state_format   every pose it is sent (history rows, extra poses) is a vector of that layout
                 (formats.py: "pos_quat_xyzw", "pos_rot6d_rows", ...), history (H+1, w);
  action_format  every pose it returns is a vector of that layout, (K, w);
  hands          ("left", "right"): history is {hand: (H+1, w)} and the policy returns one
                 chunk per hand in a dict, under the hands' names;
  outputs        {"hand": "pose", "gripper": "invariant"}: the policy returns a dict; a pose
                 entry is a chunk, an invariant one any numbers that must not change under g;
  stages         [("normalize", "poses"), ("to_hand", "features"), ...]: the stages of its
                 pipeline in execution order. The policy then returns the pair (its answer,
                 {stage: value}), every stage's output for that call; a request with
                 "stages": true (`handcentric audit --policy-exec CMD --locate`) is answered
                 with "stages": {name: value} beside the answer, a "poses" stage's value K poses
                 in the action layout ((B, K, ...) batched), a "features" stage's any numbers
                 ((B, ...) batched). Other requests get the answer alone.
(rng= and reset= are declared by serve_policy itself: policy.py.)
The audit decodes and checks every returned pose (a quaternion off unit norm is refused naming
it). A plug-in with an interface is sent JSON numbers (no base64 offer).
"""
from ._numpy import np
from . import formats
from .protocol import _BadResult, _Malformed, _flatten, _is_number

KINDS = ("pose", "invariant")
STAGE_KINDS = ("poses", "features")


def _stages(stages):
    """stages= checked: a list of (name, kind), names distinct, kinds in STAGE_KINDS."""
    out = []
    for entry in stages:
        if not isinstance(entry, (tuple, list)) or len(entry) != 2 \
                or not isinstance(entry[0], str) or not entry[0]:
            raise ValueError("stages= holds %r; each stage is a pair (name, kind), e.g. "
                             "(\"to_hand\", \"features\")" % (entry,))
        name, kind = entry
        if kind not in STAGE_KINDS:
            raise ValueError("stage %r has kind %r; a stage is \"poses\" (world-frame poses, "
                             "which move with g) or \"features\" (numbers that must not "
                             "change)" % (name, kind))
        if any(name == n for n, _ in out):
            raise ValueError("stages= names %r twice; give each stage a name of its own" % name)
        out.append((name, kind))
    if not out:
        raise ValueError("stages= is empty; name the pipeline's stages, or leave stages= out")
    return tuple(out)


def _vectors(value, width, what):
    """A non-empty list of `width`-number lists -> (n, width) float64."""
    if not isinstance(value, list) or not value:
        raise _Malformed("%s must be a non-empty list of poses of %d numbers" % (what, width))
    for i, row in enumerate(value):
        if not isinstance(row, list) or len(row) != width or not all(map(_is_number, row)):
            raise _Malformed("%s[%d] must be a list of %d numbers" % (what, i, width))
    return np.array(value, dtype=np.float64)


class _Interface:
    """What serve_policy declared beyond protocol 2, and how its requests and answers read."""

    def __init__(self, state_format, action_format, outputs, hands, stages=None):
        if np is None:
            raise ValueError("serve_policy's state_format=, action_format=, outputs=, hands= "
                             "and stages= need NumPy")
        self.stages = _stages(stages) if stages is not None else ()
        self.state = state_format or "matrix"
        self.action = action_format or "matrix"
        self.state_width = formats.width(self.state)    # ValueError naming an unknown layout
        self.action_width = formats.width(self.action)
        if hands is not None:
            if isinstance(hands, str) or len(hands) < 2 or len(set(hands)) != len(hands) \
                    or not all(isinstance(h, str) and h for h in hands):
                raise ValueError("hands must name two or more distinct hands, e.g. "
                                 "hands=(\"left\", \"right\"); got %r" % (hands,))
        self.hands = tuple(hands or ())
        declared = dict(outputs or {})
        for name, kind in declared.items():
            if not isinstance(name, str) or kind not in KINDS:
                raise ValueError("outputs[%r] is %r; an output is \"pose\" or \"invariant\""
                                 % (name, kind))
            if name in self.hands and kind != "pose":
                raise ValueError("outputs[%r] is %r, but %r is a hand: its chunk is a \"pose\""
                                 % (name, kind, name))
        # The hands first, each a pose output, then the other outputs (the audit's order).
        self.outputs = dict([(h, "pose") for h in self.hands] +
                            [(n, k) for n, k in declared.items() if n not in self.hands])
        if self.outputs and "pose" not in self.outputs.values():
            raise ValueError("outputs= names no \"pose\" output; a policy returns its chunk of "
                             "poses beside its invariant outputs")

    def hello_fields(self):
        body = {"state_format": self.state, "action_format": self.action}
        if self.outputs:
            body["outputs"] = self.outputs
        if self.hands:
            body["hands"] = list(self.hands)
        if self.stages:
            body["stages"] = [{"name": n, "kind": k} for n, k in self.stages]
        return body

    # ------------------------------------------------------------------------- requests

    def _one_history(self, value, what):
        a = _vectors(value, self.state_width, what)
        return a.reshape(-1, 4, 4) if self.state == "matrix" else a

    def history(self, item, what="request"):
        """One request's history: (H+1, w), or {hand: (H+1, w)} with hands."""
        value = item.get("history")
        if not self.hands:
            return self._one_history(value, "'history'")
        if not isinstance(value, dict) or set(value) != set(self.hands):
            raise _Malformed("%s: 'history' must be {hand: poses} for the hands %s"
                             % (what, list(self.hands)))
        return {h: self._one_history(value[h], "'history'[%r]" % h) for h in self.hands}

    def stacked_history(self, items, at):
        """The histories of items of one shape, stacked: (B, H+1, w) or {hand: ...}."""
        each = [self.history(item, "batch[%d]" % i) for i, item in zip(at, items)]
        if not self.hands:
            return np.stack(each)
        return {h: np.stack([e[h] for e in each]) for h in self.hands}

    def history_rows(self, item):
        """The numbers of history rows per hand, to group a batch's items by shape."""
        value = item.get("history")
        if isinstance(value, dict):
            return tuple(len(value.get(h, ())) if isinstance(value.get(h), list) else -1
                         for h in self.hands)
        return len(value) if isinstance(value, list) else -1

    def pose(self, value, what):
        """An extra pose in the state layout: (w,) ((4, 4) for matrices)."""
        a = _vectors([value], self.state_width, what)[0]
        return a.reshape(4, 4) if self.state == "matrix" else a

    # ------------------------------------------------------------------------- answers

    def _pose_rows(self, value, field):
        """A chunk in the action layout -> K lists of w numbers."""
        flat = _flatten(value, field)
        w = self.action_width
        if not flat or len(flat) % w:
            raise _BadResult("'%s' has %d numbers; it must be K poses of %d (%s)%s"
                             % (field, len(flat), w, self.action, _layout_hint(value)))
        return [flat[i:i + w] for i in range(0, len(flat), w)]

    def _split_stages(self, result):
        """With stages: the policy's (answer, {stage: value}), checked; without: (result, None)."""
        if not self.stages:
            return result, None
        names = [n for n, _ in self.stages]
        if not isinstance(result, tuple) or len(result) != 2 or not isinstance(result[1], dict):
            raise _BadResult("with stages=%s the policy returns the pair (its answer, {stage: "
                             "value}); it returned a %s" % (names, type(result).__name__))
        if sorted(result[1]) != sorted(names):
            raise _BadResult("the policy's stages are %s; stages= declares %s (return every "
                             "declared stage's value, and no other)" % (sorted(result[1]), names))
        return result[0], {n: _numpy_of(v) for n, v in result[1].items()}

    def answer(self, result, with_stages=False):
        """One observation's answer: {"chunk": rows} or {"outputs": {name: value}}, and with
        with_stages (a request's "stages": true) {"stages": {name: value}} in stages= order."""
        result, values = self._split_stages(result)
        if not self.outputs:
            out = {"chunk": self._pose_rows(_numpy_of(result), "chunk")}
        else:
            entries = self._entries(result)
            out = {"outputs": {name: self._pose_rows(entries[name], name) if kind == "pose"
                               else _flatten(entries[name], name)
                               for name, kind in self.outputs.items()}}
        if with_stages:
            out["stages"] = {name: self._pose_rows(values[name], "stages[%r]" % name)
                             if kind == "poses" else _flatten(values[name], "stages[%r]" % name)
                             for name, kind in self._asked_stages()}
        return out

    def _asked_stages(self):
        if not self.stages:
            raise _Malformed("a request with \"stages\": true, but serve_policy was given no "
                             "stages=")
        return self.stages

    def answers(self, result, B, with_stages=()):
        """A batched call's answers, one per observation; with_stages[i]: observation i's
        request asked for the stages."""
        result, values = self._split_stages(result)
        out = self._batched_answers(result, B)
        if any(with_stages):
            columns = {}
            for name, kind in self._asked_stages():
                field = "stages[%r]" % name
                if kind == "poses":
                    columns[name] = self._batched_poses(values[name], B, field)
                    continue
                a = np.asarray(values[name], dtype=np.float64)
                if a.ndim == 0 or a.shape[0] != B:
                    raise _BadResult("%s has shape %s for a batch of %d observations; return "
                                     "(%d, ...)" % (field, a.shape, B, B))
                columns[name] = [_flatten(a[i], field) for i in range(B)]
            for i, asked in enumerate(with_stages):
                if asked:
                    out[i]["stages"] = {name: columns[name][i] for name, _ in self.stages}
        return out

    def _batched_answers(self, result, B):
        if not self.outputs:
            return [{"chunk": rows} for rows in self._batched_poses(result, B, "chunk")]
        entries = self._entries(result)
        columns = {}
        for name, kind in self.outputs.items():
            if kind == "pose":
                columns[name] = self._batched_poses(entries[name], B, name)
            else:
                a = np.asarray(entries[name], dtype=np.float64)
                if a.ndim == 0 or a.shape[0] != B:
                    raise _BadResult("'%s' has shape %s for a batch of %d observations; "
                                     "return (%d, ...)" % (name, a.shape, B, B))
                columns[name] = [_flatten(a[i], name) for i in range(B)]
        return [{"outputs": {name: columns[name][i] for name in self.outputs}}
                for i in range(B)]

    def _batched_poses(self, value, B, field):
        a = np.asarray(_numpy_of(value))
        if a.dtype.kind not in "biuf" or a.ndim < 2 or a.shape[0] != B:
            raise _BadResult("'%s' has shape %s for a batch of %d observations; return (%d, "
                             "K, %d) (%s)" % (field, a.shape, B, B, self.action_width,
                                              self.action))
        return [self._pose_rows(a[i], field) for i in range(B)]

    def _entries(self, result):
        if not isinstance(result, dict):
            raise _BadResult("the policy returned a %s; with outputs %s it returns a dict of "
                             "them" % (type(result).__name__, list(self.outputs)))
        missing = [n for n in self.outputs if n not in result]
        unknown = [n for n in result if n not in self.outputs]
        if missing or unknown:
            raise _BadResult("the policy's dict has keys %s; the hello declares %s (add an "
                             "unknown key to outputs= as \"pose\" or \"invariant\")"
                             % (sorted(result), list(self.outputs)))
        return {n: _numpy_of(v) for n, v in result.items()}


def _layout_hint(value):
    """For a chunk whose poses are vectors (..., 6 | 7 | 9): the keyword that declares them."""
    shape = getattr(value, "shape", None)
    if shape and shape[-1] in (6, 7, 9):
        return ("; poses of %d numbers are a layout: declare it, serve_policy(..., "
                "action_format=\"pos_quat_xyzw\") or the one the policy uses" % shape[-1])
    return ""


def _numpy_of(value):
    """A torch tensor (on any device, with or without grad) as NumPy; anything else as it is."""
    return value.detach().cpu().numpy() if hasattr(value, "detach") else value
