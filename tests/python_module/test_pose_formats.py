"""Policies that speak pose vectors (action_format=, state_format=): the layouts' one definition
in C++ and the plug-in helper's NumPy one agree both ways; a hand-centric policy in quaternions is
equivariant; one that reads its Euler angles in another order than it declares is not; wrong
shapes, unknown names and numbers that contradict their layout are refused with the fix."""
import numpy as np
import pytest

import handcentric
from handcentric_plugin import formats
from policies import make_policy

FORMATS = ["matrix", "pos_quat_xyzw", "pos_quat_wxyz", "pos_axis_angle", "pos_rot6d_rows",
           "pos_rot6d_cols"] + ["pos_euler_" + a for a in
                                ("xyz", "zyx", "xzx", "ZYX", "XYZ", "ZXZ", "yzx", "YXY")]


def random_poses(n, seed):
    rng = np.random.default_rng(seed)
    T = np.tile(np.eye(4), (n, 1, 1))
    for i in range(n):
        T[i, :3, :3] = handcentric.so3_exp(rng.normal(size=3) * 1.5)
        T[i, :3, 3] = rng.normal(size=3)
    return T


def disagreement(py_encode, py_decode, name, poses):
    """The largest difference between the C++ layout and the Python one, both ways: the vectors
    each encodes, and the poses each decodes from the other's vectors."""
    v_cpp, v_py = handcentric.encode_pose(poses, name), py_encode(poses, name)
    back_py = py_decode(v_cpp, name)
    back_cpp = handcentric.decode_pose(v_py, name)
    return max(np.abs(v_cpp - v_py).max(), np.abs(back_py - poses).max(),
               np.abs(back_cpp - poses).max())


@pytest.mark.parametrize("name", FORMATS)
def test_the_cpp_and_python_layouts_agree_both_ways(name):
    poses = random_poses(64, 3)
    assert disagreement(formats.encode, formats.decode, name, poses) < 1e-12


def test_mutant_a_python_layout_with_its_quaternion_reversed_disagrees():
    def reversed_quaternion(T, name):
        v = formats.encode(T, name)
        v[..., 3:] = v[..., :2:-1]
        return v
    assert disagreement(reversed_quaternion, formats.decode, "pos_quat_xyzw",
                        random_poses(8, 4)) > 0.1


def in_layout(policy, state_format, action_format):
    """`policy` on 4x4 poses, wrapped to take its history in `state_format` and return its chunk
    in `action_format`, as a shipped policy that speaks vectors does."""
    def wrapped(history, hand_points, world_points, noise):
        seen.append(np.shape(history))
        chunk = policy(formats.decode(history, state_format), hand_points, world_points, noise)
        return formats.encode(chunk, action_format)
    seen = []
    wrapped.seen = seen
    wrapped.__qualname__ = "policy_in_" + action_format
    return wrapped


def test_a_hand_centric_policy_in_quaternions_is_se3_equivariant():
    policy = in_layout(make_policy(), "pos_quat_xyzw", "pos_quat_xyzw")
    handcentric.assert_equivariant(policy, "se3", cases=100, state_format="pos_quat_xyzw",
                                   action_format="pos_quat_xyzw", quiet=True)
    assert policy.seen[0][-1] == 7  # the history came as (H+1, 7)


def test_history_and_chunk_may_speak_different_layouts_and_extra_poses_the_states():
    inner = make_policy()
    seen = {}

    def policy(history, hand_points, world_points, noise, extra_poses, scalars):
        seen["history"], seen["base"] = np.shape(history), np.shape(extra_poses["base"])
        T = formats.decode(history, "pos_axis_angle")
        return formats.encode(inner(T, hand_points, world_points, noise), "pos_quat_wxyz")
    handcentric.assert_equivariant(policy, "se3", cases=50, quiet=True, extra_poses=["base"],
                                   state_format="pos_axis_angle", action_format="pos_quat_wxyz")
    assert seen == {"history": seen["history"][:1] + (6,), "base": (6,)}


def test_a_batched_policy_in_6d_rows_gets_stacked_vectors_and_is_equivariant():
    inner = make_policy()

    def batched(history, hand_points, world_points, noise):
        assert history.shape[-1] == 9
        T = formats.decode(history, "pos_rot6d_rows")
        chunks = [inner(T[b], hand_points[b], world_points[b], noise[b]) for b in range(len(T))]
        return formats.encode(np.stack(chunks), "pos_rot6d_rows")
    handcentric.assert_equivariant(batched, "se3", cases=100, batch_size=32, quiet=True,
                                   state_format="pos_rot6d_rows", action_format="pos_rot6d_rows")


def test_euler_angles_read_in_another_order_than_declared_break_rotations_only():
    # The policy's own code reads and writes extrinsic "xyz" (DROID's SciPy "xyz"); its wrapper
    # declares intrinsic "XYZ": every pose it sees and returns is misread, and the misreading
    # does not commute with a rotation of the world. Translations still commute.
    policy = in_layout(make_policy(), "pos_euler_xyz", "pos_euler_xyz")
    declared = dict(state_format="pos_euler_XYZ", action_format="pos_euler_XYZ", quiet=True)
    with pytest.raises(AssertionError):
        handcentric.assert_equivariant(policy, "rotation", cases=100, **declared)
    handcentric.assert_equivariant(policy, "translation", cases=100, **declared)
    # Declared as it is, the same policy holds.
    handcentric.assert_equivariant(policy, "se3", cases=100, quiet=True,
                                   state_format="pos_euler_xyz", action_format="pos_euler_xyz")


def test_a_pose_vector_chunk_without_action_format_names_the_keyword():
    policy = in_layout(make_policy(), "matrix", "pos_quat_wxyz")
    with pytest.raises(handcentric.ShapeError,
                       match=r"shape \(4, 7\).*action_format= one of pos_quat_xyzw, pos_quat_wxyz"):
        handcentric.audit_policy(policy, groups=["se3"], cases=10, quiet=True)
    six = in_layout(make_policy(), "matrix", "pos_rot6d_cols")
    with pytest.raises(handcentric.ShapeError, match=r"\(4, 9\).*pos_rot6d_rows, pos_rot6d_cols"):
        handcentric.audit_policy(six, groups=["se3"], cases=10, quiet=True)


def test_a_chunk_of_the_wrong_width_for_its_declared_layout_is_refused():
    policy = in_layout(make_policy(), "matrix", "pos_axis_angle")
    with pytest.raises(handcentric.ShapeError, match=r'\(4, 6\).*"pos_quat_xyzw" has 7'):
        handcentric.audit_policy(policy, groups=["se3"], cases=10, quiet=True,
                                 action_format="pos_quat_xyzw")


def test_a_quaternion_off_unit_norm_is_refused_naming_the_pose_and_its_norm():
    inner = in_layout(make_policy(), "matrix", "pos_quat_xyzw")

    def unnormalized(*args):
        chunk = inner(*args)
        chunk[..., 3:] *= 1.5
        return chunk
    with pytest.raises(ValueError, match=r"\[0\] = .*not a pose in pos_quat_xyzw.*norm 1\.5"):
        handcentric.audit_policy(unnormalized, groups=["se3"], cases=10, quiet=True,
                                 action_format="pos_quat_xyzw")


def test_unknown_pose_formats_are_refused_naming_the_keyword_and_value():
    with pytest.raises(ValueError, match=r"action_format='quat' is not a pose format.*quat_wxyz"):
        handcentric.audit_policy(make_policy(), action_format="quat", quiet=True)
    with pytest.raises(ValueError, match=r"state_format='pos_euler_xxz'.*twice in a row"):
        handcentric.assert_equivariant(make_policy(), "se3", state_format="pos_euler_xxz")
    with pytest.raises(TypeError, match="action_format must be a pose format name"):
        handcentric.audit_policy(make_policy(), action_format=7, quiet=True)
    with pytest.raises(ValueError, match="not a pose format"):
        formats.width("quat")
