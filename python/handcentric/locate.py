"""handcentric.locate: where a policy breaks the symmetry, module by module or stage by stage.

A NO from audit_policy says that a(g o, n) != g a(o, n), not where. In a hand-centric pipeline
the network sees invariant inputs, so every activation after the hand-frame representation must
be invariant under g, and every world-frame pose before it and after the decoder must move with
g. locate asks the policy the audit's own pointwise cases (the same o, g, noise, rounding
perturbations, batches, cameras and rng= seeding: _core._locate_cases, python/locate.cpp) and
records, while it answers, the output of every submodule of a torch module (module=) or of every
stage of a pipeline (stages=). Each output is then decided as the audit decides a pointwise case
(docs/AUDIT.md, "Tolerances and rounding", steps 1 and 2), with the activation's own size in
place of the scene's length:

    invariant    |a(g o) - a(o)|_inf <= REL (1 + c), c = max(|a(o)|_inf, |a(g o)|_inf), or
                 within 8 r with r <= sqrt(u) (1 + c), r the activation's own response to the
                 audit's rounding perturbations of o and g o (two draws per side);
    equivariant  (outputs declared "poses": every (..., 4, 4) array in them) the same with
                 d(g A(o), A(g o)) = |R - R'|_F + |p - p'| per pose and c = max(L, largest
                 translation of the poses), L the scene's length scale; the other arrays of such
                 an output must be invariant;
    coupled      (batched calls) a row's output changed when the same observations were asked
                 in the reverse order or the first half alone, beyond the preflight's
                 64 * 2^-24 (1 + c).

REL and u are the audit's for `precision` (or `tolerance`); a NaN fails every comparison.
Not done here: the audit's step 3 (moving a failing case off the case to tell a bin edge from a
breaking), so a network that bins or thresholds (argmax, rounding) can show a break at an edge.

Beside it: lie_derivatives(...), the layerwise Lie derivative at the identity on the profiles'
scenes (_core._lie_derivative_cases); locate_text, locate_json and locate_figure (the extension
handcentric._figure), the result as a table, as JSON and as a figure.
"""

from collections import OrderedDict

from . import _core

KINDS = ("features", "poses")
_EXPECTED = {"features": "invariant", "poses": "equivariant"}
_SCALE_FLOOR = 1.0  # the "1 +" of REL (1 + c), as the audit's REL (1 + L)


def _np():
    import numpy
    return numpy


class _Leaves:
    """The arrays of one output (a tensor, an array, or a tuple / list / dict of them), in a
    fixed order, as float64 NumPy arrays on the CPU."""

    @staticmethod
    def of(value):
        np = _np()
        out = []

        def walk(v):
            if isinstance(v, dict):
                for key in v:
                    walk(v[key])
            elif isinstance(v, (tuple, list)):
                for item in v:
                    walk(item)
            elif isinstance(v, np.ndarray):
                out.append(np.array(v, dtype=np.float64))
            elif hasattr(v, "detach") and hasattr(v, "cpu"):  # a torch tensor
                out.append(v.detach().cpu().double().numpy())
        walk(value)
        return out


def _spread(stage, value):
    """The next stage called on a stage's output: a tuple as positional arguments, a dict as
    keywords, anything else as one argument."""
    if isinstance(value, tuple):
        return stage(*value)
    if isinstance(value, dict):
        return stage(**value)
    return stage(value)


def _shape_text(leaves):
    return ", ".join(str(tuple(a.shape)) for a in leaves) or "no arrays"


class _Ask:
    def __init__(self, label, cases):
        self.label = label
        self.cases = list(cases)
        self.offset = 0
        self.rows = {case: OrderedDict() for case in self.cases}  # case -> key -> leaves
        self.unsplit = set()  # keys of outputs not split by row: the batch kept whole


class _Recorder:
    """What the watched outputs were, per question (on_ask) and per case."""

    def __init__(self, stacked, strict_rows, describe):
        self.stacked = stacked
        self.strict_rows = strict_rows  # stages: an output without one row per case is an error
        self.describe = describe  # key -> "stage 'x'" / "module 'x'"
        self.asks = []
        self.order = []  # keys in the order their outputs were first seen
        self.seen = set()
        self.open = None  # the rows of the call being answered, or None outside calls
        self.counts = {}
        self.reduce = None  # called with the asks of one batch once it is complete
        self.rules = None  # called with the tolerance rules before the first question
        self.about = {}  # (label, case) -> {g, length_scale, ...} of the questions that say

    def on_ask(self, label, cases, about):
        if label == "rules":
            self.rules(about)
            return
        if label in ("o", "plus"):  # the first question of a batch: the one before is done
            self.flush()
        for case, c in zip(cases, about or ()):
            self.about[label, case] = c
        self.asks.append(_Ask(label, cases))

    def flush(self):
        if self.asks:
            asks, self.asks = self.asks, []
            self.reduce(asks)

    def begin_call(self, args, kwargs):
        ask = self.asks[-1]
        rows = 1
        if self.stacked:
            history = args[0] if args else kwargs.get("history")
            rows = int(history.shape[0])
        cases = ask.cases[ask.offset:ask.offset + rows]
        ask.offset += rows
        self.open = (ask, cases)
        self.counts = {}

    def end_call(self):
        self.open = None

    def record(self, name, value):
        if self.open is None:
            return
        ask, cases = self.open
        call = self.counts.get(name, 0)
        self.counts[name] = call + 1
        key = (name, call)
        if key not in self.seen:
            self.seen.add(key)
            self.order.append(key)
        leaves = _Leaves.of(value)
        if not self.stacked:
            ask.rows[cases[0]][key] = leaves
            return
        if all(a.ndim >= 1 and a.shape[0] == len(cases) for a in leaves):
            for i, case in enumerate(cases):
                ask.rows[case][key] = [a[i] for a in leaves]
            return
        if self.strict_rows:
            raise _core.ShapeError(
                "%s returned %s for a batch of %d observations; expected a leading axis of %d "
                "(one row per observation) on every array" % (
                    self.describe(key), _shape_text(leaves), len(cases), len(cases)))
        ask.rows[cases[0]][key] = leaves  # the whole batch, as the first case's
        ask.unsplit.add(key)


def _largest(values):
    """The largest of the numbers, 0 for none; NaN wins (no comparison passes on it)."""
    m = 0.0
    for x in values:
        if not (x <= m):
            m = x
    return m


def _is_poses(a):
    return a.ndim >= 2 and a.shape[-2:] == (4, 4)


def _inf_norm(leaves):
    np = _np()
    return _largest(float(np.max(np.abs(a))) for a in leaves if a.size)


def _pose_reach(leaves):
    """The largest translation norm of the poses among the leaves."""
    np = _np()
    return _largest(float(np.max(np.linalg.norm(a[..., :3, 3], axis=-1)))
                    for a in leaves if a.size and _is_poses(a))


def _difference(a, b, poses=False, g=None):
    """The largest difference between two outputs' leaves: |x - y|_inf per leaf; with `poses`,
    each (..., 4, 4) leaf compared pose by pose, |R_x' - R_y|_F + |p_x' - p_y| with x' = g x (x
    when g is None). Infinite when the leaves' number or shapes differ; NaN propagates."""
    np = _np()
    if len(a) != len(b) or any(x.shape != y.shape for x, y in zip(a, b)):
        return float("inf")

    def one(x, y):
        if poses and _is_poses(x):
            x = x if g is None else np.matmul(g, x)
            return float(np.max(np.linalg.norm(x[..., :3, :3] - y[..., :3, :3], axis=(-2, -1))
                                + np.linalg.norm(x[..., :3, 3] - y[..., :3, 3], axis=-1)))
        return float(np.max(np.abs(x - y)))
    return _largest(one(x, y) for x, y in zip(a, b) if x.size)


class _Row:
    def __init__(self, key, kind):
        self.name, self.call = key
        self.kind = kind
        self.cases = 0
        self.invariant_break = None  # (case, error, tolerance, scale) of the first case broken
        self.equivariant_break = None
        self.coupling_break = None
        self.invariant_error = 0.0  # largest relative error (divided by 1 + c)
        self.equivariant_error = 0.0
        self.coupling_error = 0.0
        self.rounding = 0.0
        self.shape = None
        self.note = ""

    @staticmethod
    def _first(current, case, error, tolerance, scale):
        if current is None or case < current[0]:
            return (case, error, tolerance, scale)
        return current

    def see(self, relation, case, error, tolerance, scale, holds):
        relative = error / (_SCALE_FLOOR + scale) if scale == scale else float("nan")
        if not (relative == relative):
            relative = float("inf")
        attr = relation + "_error"
        setattr(self, attr, max(getattr(self, attr), relative))
        if not holds:
            brk = relation + "_break"
            setattr(self, brk, self._first(getattr(self, brk), case, error, tolerance, scale))

    def verdict(self):
        """What held on every case: a symmetry broken first ("neither"), then rows that change
        with their batch ("coupled"), else the relation that held."""
        equivariant = self.kind == "poses" and self.equivariant_break is None
        if not equivariant and self.invariant_break is not None:
            return "neither"
        if self.coupling_break is not None:
            return "coupled"
        return "equivariant" if equivariant else "invariant"

    def as_dict(self):
        verdict = self.verdict()
        expected = _EXPECTED[self.kind]
        if verdict == "coupled":
            error, witness = self.coupling_error, self.coupling_break
        elif self.kind == "poses":
            error, witness = self.equivariant_error, self.equivariant_break
        else:
            error, witness = self.invariant_error, self.invariant_break
        row = OrderedDict()
        row["name"] = self.name
        row["call"] = self.call
        row["kind"] = self.kind
        row["verdict"] = verdict
        row["breaks"] = verdict != expected
        row["error"] = error
        row["case"] = witness[0] if witness is not None and verdict != expected else None
        row["shape"] = self.shape
        row["rounding_response"] = self.rounding
        if self.note:
            row["note"] = self.note
        return row


class _Decider:
    """Decides every watched output, batch by batch, as the audit decides a pointwise case."""

    def __init__(self, about, kinds_of, describe):
        self.about = about  # ("o", case) -> {g, length_scale, near_identity}
        self.kinds_of = kinds_of
        self.describe = describe
        self.rel = self.u = self.multiple = self.coupling = None
        self.rows = {}

    def set_rules(self, rules):
        self.rel = rules["relative_tolerance"]
        self.u = rules["unit_roundoff"]
        self.multiple = rules["rounding_multiple"]
        self.coupling = rules["coupling_tolerance"]

    def row(self, key):
        if key not in self.rows:
            self.rows[key] = _Row(key, self.kinds_of(key[0]))
        return self.rows[key]

    def holds(self, error, response, scale):
        """The audit's steps 1 and 2 at scale c: the floor REL (1 + c), or the rounding."""
        floor = self.rel * (_SCALE_FLOOR + scale)
        if error <= floor:
            return True, floor
        cap = self.u ** 0.5 * (_SCALE_FLOOR + scale)
        return bool(response <= cap and error <= self.multiple * response), floor

    def decide(self, row, relation, case, sides, perturbed, scale, g=None):
        """One case of one output: the error between the two sides (o against g o; for
        "equivariant" g A(o) against A(g o)), the output's response to the rounding
        perturbations of either side, the floor and the rounding rule at its scale."""
        poses = relation == "equivariant"
        a, b = sides
        error = _difference(a, b, poses, g)
        response = _largest(_difference(side, p, poses) for side, ps in zip(sides, perturbed)
                            for p in ps)
        row.rounding = _largest([row.rounding, response])
        ok, floor = self.holds(error, response, scale)
        row.see(relation, case, error, floor, scale, ok)

    def __call__(self, asks):
        np = _np()
        by_label = {}
        for ask in asks:
            by_label.setdefault(ask.label, []).append(ask)
        (o,), (g_o,) = by_label["o"], by_label["g_o"]
        for case in o.cases:
            g = np.asarray(self.about["o", case]["g"])
            L = float(self.about["o", case]["length_scale"])
            a_rows, b_rows = o.rows[case], g_o.rows[case]
            for key in list(a_rows) + [k for k in b_rows if k not in a_rows]:
                row = self.row(key)
                row.cases += 1
                if key not in a_rows or key not in b_rows:
                    row.note = "called for only one of o and g o in case %d" % case
                    row.see("invariant", case, float("inf"), 0.0, 0.0, False)
                    row.see("equivariant", case, float("inf"), 0.0, 0.0, False)
                    continue
                sides = (a_rows[key], b_rows[key])
                perturbed = [[p.rows[case].get(key, []) for p in by_label.get(label, [])]
                             for label in ("o~", "g_o~")]
                if row.shape is None:
                    row.shape = [list(x.shape) for x in sides[0]]
                if key in o.unsplit:
                    row.note = "not one row per observation: compared batch by batch"
                self.decide(row, "invariant", case, sides, perturbed,
                            _largest(map(_inf_norm, sides)))
                if row.kind != "poses":
                    continue
                if not any(_is_poses(x) for x in sides[0]) or key in o.unsplit:
                    raise _core.ShapeError(
                        "%s is declared 'poses' but returned %s: poses are (..., 4, 4) "
                        "world_T_hand matrices, one row per observation"
                        % (self.describe(key), _shape_text(sides[0])))
                self.decide(row, "equivariant", case, sides, perturbed,
                            _largest([L] + list(map(_pose_reach, sides))), g)
        # The preflight's reorderings: each row against its own first answer.
        for ask in by_label.get("reversed", []) + by_label.get("half", []):
            for case in ask.cases:
                for key, leaves in ask.rows[case].items():
                    first = o.rows[case].get(key)
                    if first is None or key in o.unsplit:
                        continue
                    scale = _largest([_inf_norm(first), _inf_norm(leaves)])
                    error = _difference(first, leaves)
                    tolerance = self.coupling * (_SCALE_FLOOR + scale)
                    self.row(key).see("coupling", case, error, tolerance, scale,
                                      error <= tolerance)


def _check_kind(kind, where):
    if kind not in KINDS:
        raise ValueError("kinds: %r for %s is not a kind; use 'features' (invariant outputs) or "
                         "'poses' (world-frame poses, equivariant)" % (kind, where))
    return kind


def locate(policy=None, module=None, *, stages=None, kinds=None, group="se3", view="eye_in_hand",
           cases=100, seed=1, tolerance=None, precision="float64", noise=256, extra_poses=(),
           scalars=(), rng=None, reset=None, **setup):
    """Where the symmetry breaks: the first module or stage whose output leaks the world frame.

    Either locate(policy, module=net, group=...): the torch module `net` that `policy` calls,
    every submodule watched (net.named_modules(), forward hooks); `kinds={name: "poses"}` declares
    the modules whose outputs are world-frame poses (equivariant), every other module's output
    must be invariant. Or locate(stages=[(name, callable), ...], kinds=...): a pipeline whose
    first stage takes the policy's arguments (history, hand_points, world_points, noise and the
    audit's keywords) and each next stage the output of the one before (a tuple spread as
    arguments, a dict as keywords); the last returns the chunk. kinds: a dict {name: kind} or a
    list with one kind per stage, kind "features" (invariant, the default) or "poses".

    The cases are the audit's pointwise cases for group= and view= (cases=, seed=, noise=,
    precision= or tolerance=, batch_size=, array=, device=, cameras=, history=, hand_points=,
    world_points=, workspace=, observations=, rng=, reset= as audit_policy takes them).
    Returns a dict: "modules" (one row per module and call index, in execution order: name, call,
    kind, verdict "invariant" / "equivariant" / "neither" / "coupled", breaks, error (the largest
    error divided by 1 + the activation's size), case (of the first break), shape,
    rounding_response), "first_break" (the first row in execution order whose verdict is not its
    kind's, its name, or None), "witness" (that row's case and g, and there its error, the
    tolerance it exceeded and the output's size c: case_error, tolerance, scale), "chunk" (the
    policy's own pointwise verdict on the same cases) and the rules used ("tolerance").
    """
    _one_group_and_view(group, view)
    watch = _Watch(policy, module, stages, kinds, setup, "locate")
    decider = _Decider(watch.recorder.about, watch.kind_of, watch.describe)
    watch.recorder.reduce = decider  # each batch decided once answered, its arrays then dropped
    watch.recorder.rules = decider.set_rules
    asked = watch.run(_core._locate_cases, group=group, view=view, cases=cases, seed=seed,
                      tolerance=tolerance, precision=precision, noise=noise,
                      extra_poses=extra_poses, scalars=scalars, rng=rng, reset=reset, **setup)
    return _result(asked, watch.recorder.order, decider, watch.what)


# The audit's keywords that locate and lie_derivatives pass on (python/options.hpp, Setup).
_SETUP = ("batch_size", "array", "device", "quiet", "history", "hand_points", "world_points",
          "chunk", "cameras", "image_size", "channels", "floor", "workspace", "observations")


def _one_group_and_view(group, view):
    if not isinstance(group, str) or not isinstance(view, str):
        raise ValueError("locate looks at one group and one view at a time, got group=%r and "
                         "view=%r" % (group, view))


class _Watch:
    """The policy with its insides watched: module= (a forward hook on every submodule) or
    stages= (the pipeline run stage by stage), `kinds` checked, every output recorded by a
    _Recorder while the audit's questions are asked."""

    def __init__(self, policy, module, stages, kinds, setup, caller):
        if (stages is None) == (module is None):
            raise ValueError("%s takes module= (a torch module the policy calls) or stages= (a "
                             "list of (name, callable)), exactly one of them" % caller)
        for key in setup:
            if key not in _SETUP:
                raise TypeError("%s() got an unexpected keyword argument %r" % (caller, key))
        self.module = module
        if stages is not None:
            if policy is not None:
                raise ValueError("%s(stages=...) builds the policy from its stages: leave the "
                                 "policy out" % caller)
            self.stages = list(stages)
            names = []
            for item in self.stages:
                if (not isinstance(item, (tuple, list)) or len(item) != 2
                        or not isinstance(item[0], str) or not callable(item[1])):
                    raise TypeError("stages must be (name, callable) pairs, got %r" % (item,))
                if item[0] in names:
                    raise ValueError("stages: the name %r is used twice" % item[0])
                names.append(item[0])
            if not names:
                raise ValueError("stages is empty: give at least one (name, callable)")
            if isinstance(kinds, (list, tuple)):
                if len(kinds) != len(names):
                    raise ValueError("kinds has %d entries for %d stages"
                                     % (len(kinds), len(names)))
                kinds = dict(zip(names, kinds))
            self.kinds = dict(kinds or {})
            for name in self.kinds:
                if name not in names:
                    raise ValueError("kinds names %r, which is not a stage (stages: %s)"
                                     % (name, ", ".join(names)))
            self.what = "stage"
        else:
            if not callable(policy):
                raise TypeError("policy must be callable, got a %s" % type(policy).__name__)
            if (not hasattr(module, "named_modules")
                    or not hasattr(module, "register_forward_hook")):
                raise TypeError("module must be a torch.nn.Module, got a %s"
                                % type(module).__name__)
            known = [name for name, _ in module.named_modules()]
            self.kinds = dict(kinds or {})
            for name in self.kinds:
                if name not in known:
                    raise ValueError("kinds names %r, which is not a submodule of %s (see its "
                                     "named_modules())" % (name, type(module).__name__))
            self.what = "module"
            self.policy = policy
        for name, kind in self.kinds.items():
            _check_kind(kind, "%s %r" % (self.what, name))
        self.recorder = _Recorder(setup.get("batch_size") is not None,
                                  strict_rows=stages is not None, describe=self.describe)

    def kind_of(self, name):
        return self.kinds.get(name, "features")

    def describe(self, key):
        name, call = key
        return "%s %r%s" % (self.what, name, " (call %d)" % call if call else "")

    def run(self, questions, **options):
        """questions(watched policy, on_ask, **options), the hooks on only while it runs."""
        recorder = self.recorder
        handles = []
        if self.what == "stage":
            stages = self.stages

            def answer(*args, **kwargs):
                value = stages[0][1](*args, **kwargs)
                recorder.record(stages[0][0], value)
                for name, stage in stages[1:]:
                    value = _spread(stage, value)
                    recorder.record(name, value)
                return value
            answer.__qualname__ = "stages " + " > ".join(name for name, _ in stages)
            inner = answer
        else:
            inner = self.policy
            for name, sub in self.module.named_modules():
                def hook(_module, _inputs, output, name=name):
                    recorder.record(name, output)
                handles.append(_register_hook(sub, name, hook))

        def watched(*args, **kwargs):
            recorder.begin_call(args, kwargs)
            try:
                return inner(*args, **kwargs)
            finally:
                recorder.end_call()
        watched.__qualname__ = getattr(inner, "__qualname__", type(inner).__qualname__)
        try:
            asked = questions(watched, recorder.on_ask, **options)
            recorder.flush()
        finally:
            for handle in handles:
                handle.remove()
        if self.what == "module" and not recorder.order:
            raise ValueError(
                "module=%s was not called while the policy %s answered: it is not part of the "
                "policy's forward pass (pass the torch module the policy calls)"
                % (type(self.module).__name__, asked["policy"]))
        return asked


def _undo(g, leaves):
    """g^-1 applied to the poses among an output's arrays (the others kept)."""
    np = _np()
    inverse = np.linalg.inv(g)
    return [np.matmul(inverse, x) if _is_poses(x) else x for x in leaves]


class _Slopes:
    """The layerwise Lie derivative at the identity, batch by batch: per output and scene,
    D(a(g_h o), a(g_-h o)) / (2 h (1 + c)), as the profiles compute a policy's slope."""

    def __init__(self, about, kind_of, step):
        self.about, self.kind_of, self.step = about, kind_of, step
        self.slopes = {}  # key -> [slope per scene]

    def __call__(self, asks):
        np = _np()
        by_label = {ask.label: ask for ask in asks}
        plus, minus = by_label["plus"], by_label["minus"]
        for case in plus.cases:
            g_plus = np.asarray(self.about["plus", case]["g"])
            g_minus = np.asarray(self.about["minus", case]["g"])
            L = max(self.about["plus", case]["length_scale"],
                    self.about["minus", case]["length_scale"])
            a_rows, b_rows = plus.rows[case], minus.rows[case]
            for key in list(a_rows) + [k for k in b_rows if k not in a_rows]:
                slopes = self.slopes.setdefault(key, [])
                if key not in a_rows or key not in b_rows:
                    slopes.append(float("inf"))
                    continue
                a, b = a_rows[key], b_rows[key]
                if self.kind_of(key[0]) == "poses":
                    # g_h^-1 A(g_h o) against g_-h^-1 A(g_-h o): 0 for an equivariant output.
                    a, b = _undo(g_plus, a), _undo(g_minus, b)
                    scale = _largest([L] + [_pose_reach(a), _pose_reach(b)])
                    d = _difference(a, b, poses=True)
                else:
                    scale = _largest([_inf_norm(a), _inf_norm(b)])
                    d = _difference(a, b)
                slopes.append(_largest([d / (2.0 * self.step * (_SCALE_FLOOR + scale))]))


def lie_derivatives(policy=None, module=None, *, stages=None, kinds=None, group="se3",
                    view="eye_in_hand", scenes=16, seed=1, step=1e-3, precision="float64",
                    noise=256, extra_poses=(), scalars=(), rng=None, reset=None, **setup):
    """The layerwise Lie derivative at the identity (Gruver et al. 2023) of every module or
    stage that locate() watches (the same module=, stages= and kinds=): on the profiles' scenes
    (docs/AUDIT.md, "Profiles": `scenes` scenes from `seed`, each with its unit generator X),
    the central difference |a(exp(hX) o) - a(exp(-hX) o)|_inf / (2 h (1 + c)) of each output
    (for "poses" outputs, exp(-+hX) A(exp(+-hX) o) compared pose by pose), c the output's size.
    Returns {"modules": [{name, call, kind, median, max, moves}], "first_moving": name or None,
    ...}: a row moves when its largest slope is above sqrt(u) (a central difference of rounding
    is about u (1 + c) / h, 1e-13 at float64 with h = 1e-3)."""
    _one_group_and_view(group, view)
    watch = _Watch(policy, module, stages, kinds, setup, "lie_derivatives")
    slopes = _Slopes(watch.recorder.about, watch.kind_of, step)
    watch.recorder.reduce = slopes
    asked = watch.run(_core._lie_derivative_cases, group=group, view=view, scenes=scenes,
                      seed=seed, step=step, precision=precision, noise=noise,
                      extra_poses=extra_poses, scalars=scalars, rng=rng, reset=reset, **setup)
    np = _np()
    floor = asked["unit_roundoff"] ** 0.5
    rows = []
    for key in watch.recorder.order:
        values = slopes.slopes.get(key, [])
        if not values:
            continue
        largest = _largest(values)
        rows.append(OrderedDict(name=key[0], call=key[1], kind=watch.kind_of(key[0]),
                                median=float(np.median(values)), max=largest,
                                moves=not (largest <= floor)))
    first = next((r for r in rows if r["moves"]), None)
    out = OrderedDict((k, asked[k]) for k in ("policy", "group", "view", "seed", "step",
                                                "scenes"))
    out["floor"] = floor
    out["modules"] = rows
    out["first_moving"] = first["name"] if first is not None else None
    return out


def _register_hook(module, name, hook):
    """A forward hook on one submodule (a function of its own, so that a test can replace it)."""
    return module.register_forward_hook(hook)


def _result(asked, order, decider, what):
    np = _np()
    far = [c for c in asked["cases"] if not c["near_identity"]]
    if not far:
        raise _core.Error(
            "locate under %s: no verdict, all %d cases had g near the identity, which can show "
            "no symmetry; run more cases (seed %d)" % (asked["group"], len(asked["cases"]),
                                                      asked["seed"]))
    rows = [decider.rows[key].as_dict() for key in order if key in decider.rows]
    first = next((r for r in rows if r["breaks"]), None)
    witness = None
    if first is not None:
        g = next(c["g"] for c in asked["cases"] if c["case"] == first["case"])
        row = decider.rows[first["name"], first["call"]]
        broken = {"coupled": row.coupling_break, "invariant": row.equivariant_break}.get(
            first["verdict"], row.equivariant_break if row.kind == "poses" else row.invariant_break)
        # In that case: the error and the tolerance it exceeded (REL (1 + c), or the preflight's
        # for coupling), absolute, and the output's size c.
        witness = OrderedDict(name=first["name"], call=first["call"], verdict=first["verdict"],
                              case=first["case"], g=np.asarray(g).ravel().tolist(),
                              error=first["error"], case_error=broken[1], tolerance=broken[2],
                              scale=broken[3])
    # The policy's own answer on the same cases: the audit's distance and floor.
    chunk_error, chunk_case = 0.0, None
    for c in asked["cases"]:
        a = np.matmul(np.asarray(c["g"]), np.asarray(c["chunk_o"]))
        b = np.asarray(c["chunk_g_o"])
        e = _difference([a], [b], poses=True)
        tol = asked["relative_tolerance"] * (1.0 + c["length_scale"])
        relative = e / (1.0 + c["length_scale"])
        chunk_error = _largest([chunk_error, relative])
        if not (e <= tol) and chunk_case is None:
            chunk_case = c["case"]
    out = OrderedDict()
    out["policy"] = asked["policy"]
    out["group"] = asked["group"]
    out["view"] = asked["view"]
    out["seed"] = asked["seed"]
    out["cases"] = len(asked["cases"])
    out["near_identity_cases"] = len(asked["cases"]) - len(far)
    out["watched"] = what + "s"
    out["modules"] = rows
    out["first_break"] = first["name"] if first is not None else None
    out["witness"] = witness
    out["chunk"] = OrderedDict(equivariant=chunk_case is None, error=chunk_error,
                               case=chunk_case)
    out["tolerance"] = OrderedDict(
        relative=asked["relative_tolerance"], unit_roundoff=asked["unit_roundoff"],
        rounding_multiple=asked["rounding_multiple"], coupling=asked["coupling_tolerance"],
        rule="error <= REL (1 + c), or <= %g r with r <= sqrt(u) (1 + c); c the output's size"
        % asked["rounding_multiple"])
    return out


def _number(x):
    return "inf" if x == float("inf") else ("nan" if x != x else "%.3g" % x)


def locate_text(result):
    """The result of locate() as a table: one line per module (or stage) and call, in execution
    order, with its kind, verdict, error and the case of its first break; the breaking row
    marked, then the witness and the policy's own verdict on the same cases."""
    rows = result["modules"]
    width = max([len("%s[%d]" % (r["name"] or "(root)", r["call"])) for r in rows] + [4])
    lines = ["locate %s under %s (%s, seed %d, %d cases): %s" % (
        result["policy"], result["group"], result["view"], result["seed"], result["cases"],
        "first break at %r" % result["first_break"] if result["first_break"] is not None
        else "no %s breaks its kind" % result["watched"][:-1])]
    lines.append("   %-*s  %-8s  %-11s  %-9s  %s" % (width, result["watched"][:-1], "kind",
                                                     "verdict", "error", "case"))
    first = result["witness"]
    for r in rows:
        label = "%s[%d]" % (r["name"] or "(root)", r["call"])
        mark = ">> " if (first is not None and r["name"] == first["name"]
                         and r["call"] == first["call"]) else ("!  " if r["breaks"] else "   ")
        lines.append("%s%-*s  %-8s  %-11s  %-9s  %s" % (
            mark, width, label, r["kind"], r["verdict"], _number(r["error"]),
            "" if r["case"] is None else r["case"]))
    if first is not None:
        np = _np()
        g = np.asarray(first["g"]).reshape(4, 4)
        vector = lambda v: "[%s]" % ", ".join("%.6g" % x for x in v)  # noqa: E731
        lines.append("witness: %s[%d] in case %d, g: r = %s, p = %s; there error %s > "
                     "tolerance %s, the output's size c = %s" % (
                         first["name"] or "(root)", first["call"], first["case"],
                         vector(_core.so3_log(g[:3, :3])), vector(g[:3, 3]),
                         _number(first["case_error"]), _number(first["tolerance"]),
                         _number(first["scale"])))
    chunk = result["chunk"]
    lines.append("the policy's chunk: %s (error %s%s)" % (
        "equivariant" if chunk["equivariant"] else "NOT equivariant", _number(chunk["error"]),
        "" if chunk["case"] is None else ", first broken in case %d" % chunk["case"]))
    lines.append("tolerance: %s; REL = %g, u = %g" % (
        result["tolerance"]["rule"], result["tolerance"]["relative"],
        result["tolerance"]["unit_roundoff"]))
    return "\n".join(lines)


def locate_figure(result, stem):
    """Draws the result of locate() with the project's chart library: stem.png and stem.svg,
    log10 of each row's error (divided by 1 + the output's size) in execution order, the floor
    REL dashed and the first break with a marker of its own; the legend names the rows. Returns
    the two paths. The drawing is the extension handcentric._figure, imported here only."""
    import importlib
    figure = importlib.import_module(__package__ + "._figure")
    rows = result["modules"]
    labels = ["%s[%d] %s" % (r["name"] or "(root)", r["call"], r["verdict"]) for r in rows]
    first = next((i for i, r in enumerate(rows) if r["breaks"]), None)
    title = "locate %s under %s: %s" % (
        result["policy"], result["group"],
        "first break at %s[%d]" % (rows[first]["name"] or "(root)", rows[first]["call"])
        if first is not None else "no break")
    figure.locate_figure(labels, [float(r["error"]) for r in rows], first,
                         result["tolerance"]["relative"], title, str(stem))
    return str(stem) + ".png", str(stem) + ".svg"


def locate_json(result, **dumps):
    """The result of locate() as JSON text: infinite and NaN errors written as the strings
    "inf" and "nan", as the audit's JSON writes them."""
    import json

    def clean(v):
        if isinstance(v, float) and (v != v or v in (float("inf"), float("-inf"))):
            return "nan" if v != v else ("inf" if v > 0 else "-inf")
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v
    return json.dumps(clean(result), **dumps)
