"""workspace=: a policy that clips world positions to its +-1 m box is equivariant inside the box
and not beyond; the note of each verdict says where it was decided; bad boxes are refused."""
import numpy as np
import pytest

import handcentric


def clipping_policy(history, hand_points, world_points, noise):
    # A straight hand-centric chunk from the hand's position clipped to +-1 m (a normalizer fit
    # on its cell): equivariant while the hand is inside the box.
    T0 = history[0].copy()
    T0[:3, 3] = np.clip(T0[:3, 3], -1.0, 1.0)
    step = np.eye(4)
    step[:3, 3] = [0.02, 0.0, 0.01 * noise[0]]
    return np.stack([T0 @ step, T0 @ step @ step])


def test_a_clipping_policy_is_equivariant_inside_its_box_only():
    kw = dict(groups=("translation", "se3"), views="eye_in_hand", cases=150, noise=1,
              quiet=True)
    inside = handcentric.audit_policy(clipping_policy, workspace=((-1, -1, -1), (1, 1, 1)), **kw)
    pointwise = [c for c in inside["checks"] if c["mode"] == "pointwise"]
    assert pointwise and all(c["equivariant"] for c in pointwise)
    assert all("inside the workspace" in c["note"] for c in pointwise)
    anywhere = handcentric.audit_policy(clipping_policy, **kw)
    assert not any(c["equivariant"] for c in anywhere["checks"] if c["mode"] == "pointwise")


@pytest.mark.parametrize("box, message", [
    (((-1, -1), (1, 1)), "shape"),
    (((1, -1, 0), (-1, 1, 1)), "along x"),
    (((-1, -1, 0), (1, 1, float("nan"))), "finite|not a number|NaN|nan"),
])
def test_bad_workspaces_are_refused_in_one_line(box, message):
    with pytest.raises(ValueError, match=message):
        handcentric.audit_policy(clipping_policy, workspace=box, cases=1, quiet=True)
