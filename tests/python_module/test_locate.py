"""handcentric.locate: where a policy breaks the symmetry. Small torch policies (float64, a few
hundred weights) with one planted fault each, located at the module or stage that plants it:
a world-frame bias added in the second layer, a normalizer fit in world coordinates placed
before the hand frame, an encoder branch on a camera fixed in the world, batch norm in training
mode, an un-normalizer that adds the world mean back after the decoder; a block called at every
sampling step gets a row per call. The layerwise Lie derivative at the identity agrees on
every fault but batch norm. Mutant twins (test_mutant_*): a hook that skips a module, a stage
marked with the wrong kind, a Lie derivative that does not move the poses back. Bad input: one
line naming the value."""
import importlib
import json
import re

import numpy as np
import pytest

import handcentric
locate_module = importlib.import_module("handcentric.locate")  # the module, not the function

torch = pytest.importorskip("torch")

H, POINTS, NOISE, K = 1, 2, 4, 3
FEATURES = 12 + 3 * POINTS + NOISE  # T_0^-1 T_-1 as [p, R], the hand points, the noise
SHAPES = dict(history=H, hand_points=POINTS, noise=NOISE, quiet=True)


def hand_frame(history, hand_points, noise):
    """The invariant inputs: T_0^-1 T_-1 (12 numbers), the eye-in-hand points, the noise."""
    T0 = history[:, 0]
    relative = torch.linalg.solve(T0, history[:, 1])
    return torch.cat([relative[:, :3, 3], relative[:, :3, :3].reshape(-1, 9),
                      hand_points.reshape(len(T0), -1), noise], dim=1)


def decode(T0, steps):
    """T_k = T_0 [I, p_k]: the hand-frame steps (B, K, 3) as world poses (B, K, 4, 4)."""
    local = torch.eye(4, dtype=torch.float64).repeat(len(steps), K, 1, 1)
    local[:, :, :3, 3] = steps.reshape(-1, K, 3)
    return T0[:, None] @ local


class WorldBiased(torch.nn.Linear):
    """A linear layer that adds W p_0, the hand's WORLD position: the planted leak."""

    def __init__(self, n_in, n_out):
        super().__init__(n_in, n_out)
        self.world = torch.nn.Parameter(0.1 * torch.randn(n_out, 3))

    def forward(self, h, p0):
        return super().forward(h) + p0 @ self.world.T


class Mlp(torch.nn.Module):
    """fc1 > act1 > [bn] > fc2 > act2 > fc3: hand-frame features in, hand-frame steps out."""

    def __init__(self, fault=None):
        super().__init__()
        torch.manual_seed(0)
        self.fault = fault
        self.fc1 = torch.nn.Linear(FEATURES, 16)
        self.act1 = torch.nn.Tanh()
        if fault == "batch_norm":
            self.bn = torch.nn.BatchNorm1d(16)
        self.fc2 = WorldBiased(16, 16) if fault == "world_bias" else torch.nn.Linear(16, 16)
        self.act2 = torch.nn.Tanh()
        self.fc3 = torch.nn.Linear(16, 3 * K)
        self.double()
        self.train(fault == "batch_norm")

    def forward(self, x, p0):
        h = self.act1(self.fc1(x))
        if self.fault == "batch_norm":
            h = self.bn(h)
        h = self.fc2(h, p0) if self.fault == "world_bias" else self.fc2(h)
        return 0.1 * self.fc3(self.act2(h))


class MlpPolicy:
    """An outer hand-centric policy around the network (Theorem 1's setting)."""

    def __init__(self, fault=None):
        self.net = Mlp(fault)

    @torch.no_grad()
    def __call__(self, history, hand_points, world_points, noise):
        one = history.dim() == 3  # one observation per call: add the batch axis
        if one:
            history, hand_points, noise = history[None], hand_points[None], noise[None]
        chunk = decode(history[:, 0], self.net(hand_frame(history, hand_points, noise),
                                               history[:, 0, :3, 3]))
        return chunk[0] if one else chunk


def run(policy, **kw):
    options = dict(SHAPES, group="se3", cases=6, batch_size=8, array="torch")
    options.update(kw)
    return handcentric.locate(policy, module=policy.net, **options)


def rows(result):
    return {(r["name"], r["call"]): r for r in result["modules"]}


def test_a_hand_centric_policy_has_every_module_invariant():
    result = run(MlpPolicy())
    assert [r["name"] for r in result["modules"]] == ["fc1", "act1", "fc2", "act2", "fc3", ""]
    assert all(r["verdict"] == "invariant" and r["kind"] == "features"
               for r in result["modules"])
    assert result["first_break"] is None and result["witness"] is None
    assert result["chunk"]["equivariant"]
    assert max(r["error"] for r in result["modules"]) < 1e-12


def world_bias_is_located(**kw):
    """The world-frame bias of the second layer: fc1 and act1 invariant, fc2 the first break,
    in the first case, with everything after it broken too."""
    result = run(MlpPolicy("world_bias"), **kw)
    by = rows(result)
    return (by[("fc1", 0)]["verdict"] == "invariant" and by[("act1", 0)]["verdict"] == "invariant"
            and result["first_break"] == "fc2" and result["witness"]["case"] == 1
            and by[("fc2", 0)]["verdict"] == "neither" and by[("fc2", 0)]["error"] > 1e-3
            and by[("fc3", 0)]["breaks"] and not result["chunk"]["equivariant"])


def test_a_world_frame_bias_in_the_second_layer_is_located_there():
    assert world_bias_is_located()


def test_located_one_observation_per_call_as_batched():
    assert world_bias_is_located(batch_size=None)


def test_mutant_a_hook_that_skips_a_module_misplaces_the_break(monkeypatch):
    register = locate_module._register_hook

    class Skipped:
        def remove(self):
            pass

    monkeypatch.setattr(locate_module, "_register_hook", lambda module, name, hook: (
        Skipped() if name == "fc2" else register(module, name, hook)))
    assert not world_bias_is_located()


class FarFromTheOrigin(MlpPolicy):
    """Pushed 1 cm along world x when the hand is more than 2 m out along x: broken only on
    some of the cases, so the number of the first broken case says whose cases they are."""

    @torch.no_grad()
    def __call__(self, history, hand_points, world_points, noise):
        chunk = super().__call__(history, hand_points, world_points, noise).clone()
        chunk[:, :, 0, 3] += 0.01 * (history[:, 0, 0, 3] > 2.0).double()[:, None]
        return chunk


def test_the_cases_are_the_audits_own():
    """The policy's own verdict on locate's cases breaks at the case where audit_policy's
    pointwise check first fails, with the same seed (the audit's numbering, from 1): case 17
    here, 16 cases that hold before it."""
    policy = FarFromTheOrigin()
    audit = handcentric.audit_policy(policy, groups="translation", views="eye_in_hand",
                                     cases=20, seed=1, batch_size=8, array="torch", **SHAPES)
    pointwise = next(c for c in audit["checks"] if c["mode"] == "pointwise")
    result = run(policy, group="translation", cases=20, seed=1)
    assert not pointwise["equivariant"] and pointwise["failed_at_case"] == 17
    assert result["chunk"]["case"] == 17 and result["first_break"] is None  # outside the net
    # Cases from elsewhere (here the next seed's) would not pass this check: the first is broken.
    assert run(policy, group="translation", cases=20, seed=2)["chunk"]["case"] == 1


def test_a_block_called_at_every_step_gets_a_row_per_call():
    """A denoiser's block at three sampling steps, the world position added before the last."""

    class Steps(torch.nn.Module):
        def __init__(self):
            super().__init__()
            torch.manual_seed(1)
            self.inp = torch.nn.Linear(FEATURES, 3 * K)
            self.block = torch.nn.Sequential(torch.nn.Linear(3 * K, 3 * K), torch.nn.Tanh())
            self.double()

        def forward(self, x, p0):
            a = self.inp(x)
            for step in range(3):
                if step == 2:
                    a = a + p0.repeat(1, K)  # the leak: at the last step only
                a = a + 0.1 * self.block(a)
            return 0.1 * a

    policy = MlpPolicy()
    policy.net = Steps()
    result = run(policy)
    by = rows(result)
    assert [(r["name"], r["call"]) for r in result["modules"]][:4] == [
        ("inp", 0), ("block.0", 0), ("block.1", 0), ("block", 0)]
    for call in (0, 1):
        assert by[("block", call)]["verdict"] == "invariant"
    assert by[("block", 2)]["verdict"] == "neither"
    assert result["first_break"] == "block.0" and result["witness"]["call"] == 2


def test_batch_norm_in_training_mode_is_named_as_coupling_the_rows():
    result = run(MlpPolicy("batch_norm"))
    by = rows(result)
    assert by[("fc1", 0)]["verdict"] == "invariant"
    assert by[("bn", 0)]["verdict"] == "coupled"
    assert result["first_break"] == "bn"
    with pytest.raises(handcentric.BatchCouplingError):
        handcentric.audit_policy(MlpPolicy("batch_norm"), groups="se3", cases=4, batch_size=8,
                                 array="torch", **SHAPES)


class DrawsItsOwnNoise(MlpPolicy):
    """Adds torch.randn to the hidden layer (as a sampler that draws its own noise does)."""

    def __init__(self):
        super().__init__()
        self.net.act1.register_forward_hook(lambda m, i, out: out + 0.1 * torch.randn_like(out))


def test_a_policy_that_draws_its_own_noise_is_seeded_alike_for_o_and_g_o():
    policy = DrawsItsOwnNoise()
    assert run(policy, rng="torch")["first_break"] is None
    unseeded = run(policy)  # other draws for g o than for o: act1 is where they enter
    assert unseeded["first_break"] == "act1"


def test_a_float32_pipeline_holds_at_float32_rounding_and_not_at_float64s():
    """The hand frame taken in float32: o and g o differ by float32 rounding (1e-7 relative),
    which the float64 floor calls a break at the first layer and precision="float32" does not:
    the audit's own rule (docs/AUDIT.md, "Tolerances and rounding")."""
    net = Mlp().float()

    def policy(history, hand_points, world_points, noise):
        x = hand_frame(history.float(), hand_points.float(), noise.float())
        return decode(history[:, 0], net(x, None).double())

    with torch.no_grad():
        assert handcentric.locate(policy, module=net, precision="float32", group="se3", cases=6,
                                  batch_size=8, array="torch", **SHAPES)["first_break"] is None
        at_float64 = handcentric.locate(policy, module=net, group="se3", cases=6, batch_size=8,
                                        array="torch", **SHAPES)
    assert at_float64["first_break"] == "fc1" and at_float64["modules"][0]["error"] < 1e-6


class TwoCameras(torch.nn.Module):
    """An encoder per camera, their features joined: the hand camera's branch sees an image
    that g leaves alone, the world camera's one that g moves."""

    def __init__(self):
        super().__init__()
        torch.manual_seed(2)

        def branch():
            return torch.nn.Sequential(torch.nn.Conv2d(1, 4, 3, stride=2), torch.nn.Tanh(),
                                       torch.nn.AdaptiveAvgPool2d(1), torch.nn.Flatten())
        self.hand = branch()
        self.world = branch()
        self.head = torch.nn.Linear(8, 3 * K)
        self.double()

    def forward(self, hand_image, world_image):
        return 0.1 * self.head(torch.cat([self.hand(hand_image), self.world(world_image)], 1))


class CameraPolicy:
    def __init__(self):
        self.net = TwoCameras()

    @torch.no_grad()
    def __call__(self, history, hand_points, world_points, noise, images):
        steps = self.net(images["eye_in_hand"].double(), images["third_person"].double())
        return decode(history[:, 0], steps)


def test_an_encoder_branch_on_a_world_fixed_camera_is_located_at_its_first_layer():
    policy = CameraPolicy()
    result = run(policy, view="third_person", world_points=2, cameras=("eye_in_hand",
                 "third_person"), image_size=(32, 24), channels="depth")
    by = rows(result)
    assert all(by[(name, 0)]["verdict"] == "invariant"
               for name in ("hand.0", "hand.1", "hand.2", "hand.3", "hand"))
    assert result["first_break"] == "world.0"
    assert by[("head", 0)]["breaks"]


class NotANumber(torch.nn.Module):
    """An activation that is NaN in every row, cleaned up by the next step."""

    def forward(self, h):
        return h + float("nan")


def test_a_nan_activation_fails_every_comparison():
    class Masked(Mlp):
        def __init__(self):
            super().__init__()
            self.nan = NotANumber()

        def forward(self, x, p0):
            h = self.act1(self.fc1(x))
            return 0.1 * self.fc3(self.act2(self.fc2(torch.nan_to_num(self.nan(h), nan=0.0))))

    policy = MlpPolicy()
    policy.net = Masked()
    result = run(policy)
    by = rows(result)
    assert result["first_break"] == "nan"
    assert by[("nan", 0)]["verdict"] == "neither" and by[("nan", 0)]["error"] == float("inf")
    assert by[("fc2", 0)]["verdict"] == "invariant" and result["chunk"]["equivariant"]


# Stages of a pipeline: each a callable on the output of the one before.

NET = Mlp()
MEAN = torch.tensor([0.3, -0.2, 0.5], dtype=torch.float64)  # "fit" on the demos, in world axes
SCALE = torch.tensor([1.0, 2.0, 0.5], dtype=torch.float64)


def to_hand(history, hand_points, world_points, noise):
    return hand_frame(history, hand_points, noise), history[:, 0]


def normalize_features(x, T0):
    return x / 2.0, T0  # fit on hand-frame features: invariant


def network(x, T0):
    return NET(x, None), T0


def decode_stage(steps, T0):
    return decode(T0, steps)


def normalize_world(history, hand_points, world_points, noise):
    """The fault: positions normalized per world axis before the hand frame is taken."""
    history = history.clone()
    history[..., :3, 3] = (history[..., :3, 3] - MEAN) / SCALE
    return history, hand_points, world_points, noise


def unnormalize_world(chunk):
    """The fault: the world mean added back to the decoded chunk."""
    chunk = chunk.clone()
    chunk[..., :3, 3] += MEAN
    return chunk


HAND_CENTRIC = [("to_hand", to_hand), ("normalize", normalize_features), ("network", network),
                ("decode", decode_stage)]
# to_hand, normalize and network pass T_0 on beside their features: "poses" (every 4x4 array
# moves with g, the rest is invariant).
HAND_CENTRIC_KINDS = ["poses", "poses", "poses", "poses"]


def run_stages(stages, kinds, **kw):
    options = dict(SHAPES, group="se3", cases=6, batch_size=8, array="torch")
    options.update(kw)
    with torch.no_grad():
        return handcentric.locate(stages=stages, kinds=kinds, **options)


def hand_centric_stages_hold(kinds=HAND_CENTRIC_KINDS):
    result = run_stages(HAND_CENTRIC, kinds)
    return (result["first_break"] is None and [r["name"] for r in result["modules"]]
            == ["to_hand", "normalize", "network", "decode"]
            and all(r["verdict"] == "equivariant" for r in result["modules"]))


def test_a_hand_centric_pipeline_has_every_stage_as_declared():
    assert hand_centric_stages_hold()


def test_mutant_a_stage_marked_with_the_wrong_kind_breaks():
    assert not hand_centric_stages_hold(["poses", "poses", "poses", "features"])
    result = run_stages(HAND_CENTRIC, {"decode": "features"})  # a dict; the others: features
    assert result["first_break"] == "to_hand"  # it passes T_0 on, not invariant


def test_a_normalizer_fit_in_world_coordinates_before_the_hand_frame_is_located():
    stages = [("normalize", normalize_world)] + [s for s in HAND_CENTRIC if s[0] != "normalize"]
    result = run_stages(stages, ["poses"] * 4)
    assert result["first_break"] == "normalize"
    assert result["modules"][0]["verdict"] == "neither"
    assert all(r["breaks"] for r in result["modules"])  # everything after it inherits the leak


def test_an_unnormalizer_adding_the_world_mean_after_the_decoder_is_located():
    result = run_stages(HAND_CENTRIC + [("unnormalize", unnormalize_world)], ["poses"] * 5)
    assert result["first_break"] == "unnormalize"
    assert [r["breaks"] for r in result["modules"]] == [False] * 4 + [True]
    # A constant world offset commutes with translations: not a break there.
    assert run_stages(HAND_CENTRIC + [("unnormalize", unnormalize_world)], ["poses"] * 5,
                      group="translation")["first_break"] is None


def test_the_table_and_the_json_name_the_break():
    result = run(MlpPolicy("world_bias"))
    text = handcentric.locate_text(result)
    assert ">> fc2[0]" in text and "neither" in text
    # The tolerance REL (1 + c) follows the output's size c in that case (its noise's answer).
    assert "witness: fc2[0] in case 1, g: r = [" in text
    assert re.search(r"> tolerance 1\.\d\de-09, the output's size c = 0\.\d+", text)
    assert "NOT equivariant" in text
    back = json.loads(handcentric.locate_json(result))
    assert back["first_break"] == "fc2" and back["modules"][2]["name"] == "fc2"


WORLD_BIAS_POLICY = MlpPolicy("world_bias")
UNNORMALIZED = HAND_CENTRIC + [("unnormalize", unnormalize_world)]
CLI_OPTIONS = ["--group", "se3", "--cases", "6", "--batch-size", "8", "--array", "torch",
               "--history", str(H), "--hand-points", str(POINTS), "--noise", str(NOISE),
               "--quiet"]


def test_python_m_handcentric_locate_prints_the_table_and_the_json(capsys):
    from handcentric import __main__ as cli
    assert cli.main(["locate", "test_locate:WORLD_BIAS_POLICY", "--module", "net"]
                    + CLI_OPTIONS) == 0
    assert ">> fc2[0]" in capsys.readouterr().out
    assert cli.main(["locate", "test_locate:UNNORMALIZED", "--kinds", "poses,poses,poses,"
                     "poses,poses", "--json"] + CLI_OPTIONS) == 0
    assert json.loads(capsys.readouterr().out)["first_break"] == "unnormalize"
    with pytest.raises(SystemExit) as stop:
        cli.main(["locate", "test_locate:WORLD_BIAS_POLICY"] + CLI_OPTIONS)
    assert stop.value.code == 2 and "--module" in capsys.readouterr().err


# Beside the Lie derivative: the same models, the layerwise slope at the identity along the
# profiles' generators.

def planted(fault):
    """(policy or None, module or None, stages or None, kinds, extra keywords) of a fault."""
    if fault in ("hand_centric", "world_bias", "batch_norm"):
        policy = MlpPolicy(None if fault == "hand_centric" else fault)
        return dict(policy=policy, module=policy.net), {}
    if fault == "camera":
        policy = CameraPolicy()
        return dict(policy=policy, module=policy.net), dict(
            view="third_person", world_points=2, cameras=("eye_in_hand", "third_person"),
            image_size=(32, 24), channels="depth")
    if fault == "normalize":
        stages = [("normalize", normalize_world)] + [s for s in HAND_CENTRIC
                                                     if s[0] != "normalize"]
    elif fault == "unnormalize":
        stages = UNNORMALIZED
    else:
        stages = HAND_CENTRIC
    return dict(stages=stages, kinds=["poses"] * len(stages)), {}


def both_ways(fault):
    target, extra = planted(fault)
    options = dict(SHAPES, group="se3", batch_size=8, array="torch", **extra)
    with torch.no_grad():
        located = handcentric.locate(cases=6, **target, **options)
        slopes = handcentric.lie_derivatives(scenes=6, **target, **options)
    return located, slopes


def agree(located, slopes):
    """The first break is the first output whose slope is not zero, and the outputs that break
    are those whose slope is not zero."""
    broken = [(r["name"], r["call"]) for r in located["modules"] if r["breaks"]]
    moving = [(r["name"], r["call"]) for r in slopes["modules"] if r["moves"]]
    return located["first_break"] == slopes["first_moving"] and broken == moving


@pytest.mark.parametrize("fault", ["hand_centric", "hand_centric_stages", "world_bias",
                                   "normalize", "unnormalize", "camera"])
def test_the_layerwise_lie_derivative_agrees_on_every_planted_fault(fault):
    located, slopes = both_ways(fault)
    assert agree(located, slopes)
    assert [r["name"] for r in located["modules"]] == [r["name"] for r in slopes["modules"]]


def test_batch_norm_coupling_is_where_the_two_disagree():
    located, slopes = both_ways("batch_norm")
    assert located["first_break"] == "bn" and slopes["first_moving"] is None
    assert max(r["max"] for r in slopes["modules"]) < 1e-9


def test_mutant_a_lie_derivative_that_does_not_move_the_poses_back_disagrees(monkeypatch):
    monkeypatch.setattr(locate_module, "_undo", lambda g, leaves: leaves)
    located, slopes = both_ways("hand_centric_stages")
    assert not agree(located, slopes)
    assert slopes["first_moving"] == "to_hand"  # it passes T_0 on: moves with g


VERMILLION = "rgb(83.529412%,36.862745%,0%)"  # chart_colour(1) in Cairo's SVG: the first break


def first_break_is_marked(result, stem):
    """The figure's SVG draws a mark in the first break's colour exactly when there is one."""
    png, svg = handcentric.locate_figure(result, stem)
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    with open(svg) as f:
        return (VERMILLION in f.read()) == (result["first_break"] is not None)


def test_the_figure_marks_the_first_break(tmp_path):
    assert first_break_is_marked(run(MlpPolicy("world_bias")), tmp_path / "bias")
    assert first_break_is_marked(run(MlpPolicy()), tmp_path / "hand_centric")


def test_drawing_leaves_the_audits_own_errors_alone(tmp_path):
    """handcentric._figure translates no exception of _core's (pybind11 shares translators
    between modules): after a figure, a wrong shape is still ShapeError, a wrong dtype still
    TypeError; and a figure that cannot be written is an OSError naming its path."""
    handcentric.locate_figure(run(MlpPolicy()), tmp_path / "figure")
    with pytest.raises(handcentric.ShapeError):
        handcentric.audit(lambda history, chunk, hand, world: np.zeros((3, 4)), cases=2,
                          quiet=True)
    with pytest.raises(TypeError, match="dtype <U1"):
        handcentric.audit(lambda history, chunk, hand, world: ["a"], cases=2, quiet=True)
    with pytest.raises(OSError, match="no_such_folder"):
        handcentric.locate_figure(run(MlpPolicy()), tmp_path / "no_such_folder" / "figure")


def test_mutant_a_figure_that_does_not_mark_the_break_is_caught(monkeypatch, tmp_path):
    figure = importlib.import_module("handcentric._figure")
    draw = figure.locate_figure
    monkeypatch.setattr(figure, "locate_figure", lambda labels, errors, first, *rest: draw(
        labels, errors, None, *rest))
    assert not first_break_is_marked(run(MlpPolicy("world_bias")), tmp_path / "bias")


# Bad input: one line naming the value.

def one_line(excinfo):
    return "\n" not in str(excinfo.value)


def test_a_module_outside_the_forward_pass_is_refused():
    policy = MlpPolicy()
    with pytest.raises(ValueError, match="not part of the policy's forward pass") as e:
        handcentric.locate(policy, module=Mlp("batch_norm"), cases=2, array="torch", **SHAPES)
    assert one_line(e) and "Mlp" in str(e.value)


@pytest.mark.parametrize("kinds, message", [
    ({"fc2": "vector"}, "'vector' for module 'fc2' is not a kind"),
    ({"fc9": "poses"}, "'fc9', which is not a submodule of Mlp"),
])
def test_an_unknown_kind_or_module_is_refused(kinds, message):
    policy = MlpPolicy()
    with pytest.raises(ValueError, match=message) as e:
        handcentric.locate(policy, module=policy.net, kinds=kinds, cases=2, array="torch",
                           **SHAPES)
    assert one_line(e)


@pytest.mark.parametrize("kw, message", [
    (dict(group="se4"), "se4"),
    (dict(group="all"), "one group and one view"),
    (dict(view=("eye_in_hand", "third_person")), "one group and one view"),
    (dict(batchsize=8), "unexpected keyword argument 'batchsize'"),
])
def test_a_bad_group_or_view_is_refused_in_one_line(kw, message):
    policy = MlpPolicy()
    with pytest.raises((ValueError, TypeError), match=message) as e:
        handcentric.locate(policy, module=policy.net, cases=2, array="torch", **SHAPES, **kw)
    assert one_line(e)


def test_a_stage_that_returns_the_wrong_shape_is_refused():
    def flat(x, T0):
        return NET(x, None).reshape(-1, 3), T0  # (B K, 3): no row per observation

    stages = [("to_hand", to_hand), ("network", flat), ("decode", decode_stage)]
    with pytest.raises(handcentric.ShapeError,
                       match=r"stage 'network' returned \(18, 3\), \(6, 4, 4\) for a batch of 6"):
        run_stages(stages, ["poses"] * 3)


def test_a_stage_declared_poses_without_poses_is_refused():
    def steps(history, hand_points, world_points, noise):
        return NET(hand_frame(history, hand_points, noise), None)

    def at_origin(steps):
        return decode(torch.eye(4, dtype=torch.float64).repeat(len(steps), 1, 1), steps)

    with pytest.raises(handcentric.ShapeError, match="stage 'network' is declared 'poses'") as e:
        run_stages([("network", steps), ("decode", at_origin)], ["poses", "poses"])
    assert one_line(e)
