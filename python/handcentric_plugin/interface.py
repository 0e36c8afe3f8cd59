"""A policy plug-in's interface on the wire: pose layouts, hands and named outputs.

serve_policy(policy, state_format=, action_format=, outputs=, hands=) declares them in its
hello (docs/AUDIT.md, "--exec"), and the audit then speaks the policy's own language:
  state_format   every pose it is sent (history rows, extra poses) is a vector of that layout
                 (formats.py: "pos_quat_xyzw", "pos_rot6d_rows", ...), history (H+1, w);
  action_format  every pose it returns is a vector of that layout, (K, w);
  hands          ("left", "right"): history is {hand: (H+1, w)} and the policy returns one
                 chunk per hand in a dict, under the hands' names;
  outputs        {"hand": "pose", "gripper": "invariant"}: the policy returns a dict; a pose
                 entry is a chunk, an invariant one any numbers that must not change under g.
(rng= and reset= are declared by serve_policy itself: policy.py.)
The audit decodes and checks every returned pose (a quaternion off unit norm is refused naming
it). A plug-in with an interface is sent JSON numbers (no base64 offer).
"""
from ._numpy import np
from . import formats
from .protocol import _BadResult, _Malformed, _flatten, _is_number

KINDS = ("pose", "invariant")


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

    def __init__(self, state_format, action_format, outputs, hands):
        if np is None:
            raise ValueError("serve_policy's state_format=, action_format=, outputs= and "
                             "hands= need NumPy")
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

    def answer(self, result):
        """One observation's answer: {"chunk": rows} or {"outputs": {name: value}}."""
        if not self.outputs:
            return {"chunk": self._pose_rows(_numpy_of(result), "chunk")}
        entries = self._entries(result)
        return {"outputs": {name: self._pose_rows(entries[name], name) if kind == "pose"
                            else _flatten(entries[name], name)
                            for name, kind in self.outputs.items()}}

    def answers(self, result, B):
        """A batched call's answers, one per observation."""
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
