"""precision= (props/audit.hpp, Precision): a policy computed in float32, bfloat16 or float16 is
audited at that precision's floor, with the rounding probe at float32's unit and the output pose
check at the precision's own; names refused in the caller's spelling.

The pipeline: a hand-centric policy whose network runs in bfloat16 on hand-frame features (as
openpi's Pi0 runs its network in bfloat16), its 6D rotations decoded in float32, the chunk
composed with T_0 in float64 and returned rounded to bfloat16 (`cast`). The planted fault: 2 cm
added along world x after decoding (a world-frame leak): translation-equivariant, nothing else.
"""
import numpy as np
import pytest

import handcentric

torch = pytest.importorskip("torch")

K = 4


def bf16_pipeline(leak=0.0, cast=True):
    generator = torch.Generator().manual_seed(0)
    w1 = (0.3 * torch.randn(32, 20, generator=generator, dtype=torch.float64)).bfloat16()
    w2 = (0.1 * torch.randn(9 * K, 32, generator=generator, dtype=torch.float64)).bfloat16()

    def policy(history, hand_points, world_points, noise):
        T0 = history[:, 0]
        R0, p0 = T0[:, :3, :3], T0[:, :3, 3]
        R_rel = R0.transpose(1, 2) @ history[:, 1, :3, :3]  # T_0^-1 T_-1, in float64
        p_rel = (R0.transpose(1, 2) @ (history[:, 1, :3, 3] - p0)[..., None])[..., 0]
        x = torch.cat([R_rel.reshape(-1, 9), p_rel, noise[:, :8]], 1).bfloat16()
        y = (torch.tanh(x @ w1.T) @ w2.T).reshape(-1, K, 9).float()  # the network in bf16
        a = y[..., 3:6] + torch.tensor([1.0, 0.0, 0.0])
        b = y[..., 6:9] + torch.tensor([0.0, 1.0, 0.0])
        a = a / a.norm(dim=-1, keepdim=True)
        b = b - (a * b).sum(-1, keepdim=True) * a
        b = b / b.norm(dim=-1, keepdim=True)
        R_k = torch.stack([a, b, torch.cross(a, b, dim=-1)], -1).double()
        out = torch.zeros(len(T0), K, 4, 4, dtype=torch.float64)
        out[..., :3, :3] = R0[:, None] @ R_k
        step = (0.05 * y[..., :3]).double()[..., None]  # in the hand frame
        out[..., :3, 3] = p0[:, None] + (R0[:, None] @ step)[..., 0]
        out[..., :3, 3] += torch.tensor([leak, 0.0, 0.0], dtype=torch.float64)
        out[..., 3, 3] = 1.0
        return out.bfloat16().double() if cast else out
    policy.__qualname__ = "bf16_pipeline"
    return policy


def audit(policy, **kw):
    return handcentric.audit_policy(policy, batch_size=256, array="torch", history=1, quiet=True,
                                    **kw)


def test_a_bfloat16_pipeline_is_yes_everywhere_at_bfloat16_and_its_leak_is_no():
    right = audit(bf16_pipeline(), precision="bfloat16")
    assert all(c["equivariant"] for c in right["checks"])
    leaky = audit(bf16_pipeline(leak=0.02), precision="bfloat16")
    for view in ("eye_in_hand", "third_person"):
        for mode in ("pointwise", "distribution"):
            cells = leaky["summary"][view][mode]
            assert cells == {"translation": True, "rotation": False, "se2": False, "se3": False,
                             "c8": False}, (view, mode)


def test_the_rounding_probe_stays_at_float32_so_a_leak_behind_a_bf16_network_is_not_excused():
    """The planted fault: the leak behind the bf16 network, poses returned in float64, at
    precision float32 -> NO; at bfloat16 it must stay NO pointwise too. (With the rounding probe
    moving inputs by units of 2^-8, the network's response excused the 2 cm leak: pointwise
    "yes" under rotation beside an in-distribution NO. That mutant of probe_unit_roundoff was run:
    this test and the two above fail.)"""
    leaky = audit(bf16_pipeline(leak=0.02, cast=False), precision="bfloat16", groups=["rotation"])
    assert [c["equivariant"] for c in leaky["checks"]] == [False] * 4


def test_bf16_poses_stop_a_float64_audit_with_a_hint_and_pass_at_bfloat16():
    with pytest.raises(ValueError, match="rotation block is not a rotation.*precision="):
        audit(bf16_pipeline(), groups=["se3"])
    audit(bf16_pipeline(), groups=["se3"], precision="bfloat16")


def test_a_float32_pose_pipeline_passes_the_pose_check_at_float32():
    """A 6D rotation orthonormalized in float32 is ~1e-6 off a rotation: within 2 sqrt(2^-24)."""
    base = bf16_pipeline(cast=False)

    def float32_poses(*args):
        return base(*args).float().double()
    float32_poses.__qualname__ = "float32_poses"
    handcentric.assert_equivariant(float32_poses, "se3", precision="float32", batch_size=256,
                                   array="torch", history=1, quiet=True)


@pytest.mark.parametrize("name", ["half", "fp16", "float128"])
def test_an_unknown_precision_is_refused_in_pythons_spelling(name):
    with pytest.raises(ValueError, match="unknown precision '%s'.*bfloat16" % name) as error:
        audit(bf16_pipeline(), precision=name)
    assert "--precision" not in str(error.value)
    with pytest.raises(ValueError, match="tolerance must be") as error:
        audit(bf16_pipeline(), tolerance=2.0)
    assert "--tolerance" not in str(error.value)
