"""Pose layouts: a pose world_T_hand as the flat vector a shipped policy speaks (NumPy).

The same layouts, names and choices as the audit's action_format= / state_format= (the C++
definition, core/include/handcentric/core/pose_format.hpp, holds the table); the tests hold the
two to each other both ways. For a plug-in or a policy wrapper that must turn 4x4 poses into
the vectors its code expects, or back:

    formats.encode(T, "pos_quat_xyzw")     # (..., 4, 4) -> (..., 7)
    formats.decode(v, "pos_euler_xyz")     # (..., 6) -> (..., 4, 4)

Layouts: "matrix" (the (..., 4, 4) poses themselves), "pos_quat_xyzw", "pos_quat_wxyz" (7),
"pos_axis_angle" (6), "pos_rot6d_rows", "pos_rot6d_cols" (9), "pos_euler_<axes>" (6; SciPy's
spelling: lowercase about the fixed axes, uppercase about the moving ones). Encoding picks the
quaternion with w >= 0 and SciPy's Euler ranges (the third angle 0 at gimbal lock); decoding
normalizes a quaternion and orthonormalizes 6D vectors (Gram-Schmidt), after refusing numbers
more than LAYOUT_TOLERANCE from what the layout says.
"""
from ._numpy import np
from .geometry import rotation_matrix, rotation_vector

LAYOUT_TOLERANCE = 1e-2
_WIDTHS = {"matrix": 16, "pos_quat_xyzw": 7, "pos_quat_wxyz": 7, "pos_axis_angle": 6,
           "pos_rot6d_rows": 9, "pos_rot6d_cols": 9}
_EULER = "pos_euler_"
FORMATS = tuple(_WIDTHS) + (_EULER + "<axes>",)


def _euler_axes(name):
    """(axes, intrinsic) of "pos_euler_<axes>", or ValueError naming the value."""
    axes = name[len(_EULER):]
    rule = ("<axes> is three of x, y, z as SciPy spells them, no axis twice in a row: lowercase "
            "extrinsic, uppercase intrinsic, e.g. pos_euler_xyz")
    if len(axes) != 3 or not (axes.islower() or axes.isupper()) or \
            any(a not in "xyz" for a in axes.lower()) or axes[0] == axes[1] or axes[1] == axes[2]:
        raise ValueError("pose format %r: %s" % (name, rule))
    return tuple("xyz".index(a) for a in axes.lower()), axes.isupper()


def width(name):
    """The numbers per pose of layout `name`; ValueError for an unknown name."""
    if name.startswith(_EULER):
        _euler_axes(name)
        return 6
    if name not in _WIDTHS:
        raise ValueError("%r is not a pose format; the formats are %s" % (name, ", ".join(FORMATS)))
    return _WIDTHS[name]


def _axis_rotation(axis, angle):
    """(..., 3, 3) rotations about `axis` by `angle` (...)."""
    u, w = (axis + 1) % 3, (axis + 2) % 3
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., axis, axis] = 1
    out[..., u, u] = out[..., w, w] = np.cos(angle)
    out[..., w, u] = np.sin(angle)
    out[..., u, w] = -np.sin(angle)
    return out


def _angle_about(axis, M):
    u, w = (axis + 1) % 3, (axis + 2) % 3
    return np.arctan2(M[..., w, u], M[..., u, u])


def _intrinsic_angles(R, axes):
    """(..., 3) angles with R = R_i(a) R_j(b) R_k(c); the C++ intrinsic_angles, row by row."""
    i, j, k = axes
    third = 3 - i - j
    s = 1.0 if (j - i) % 3 == 1 else -1.0
    if k != i:  # three different axes
        lock_measure = np.hypot(R[..., i, i], R[..., i, j])
        b = np.arctan2(s * R[..., i, k], lock_measure)
        a = np.arctan2(-s * R[..., j, k], R[..., k, k])
    else:
        lock_measure = np.hypot(R[..., i, j], R[..., i, third])
        b = np.arctan2(lock_measure, R[..., i, i])
        a = np.arctan2(R[..., j, i], -s * R[..., third, i])
    locked = lock_measure < 1e-9
    a = np.where(locked, _angle_about(i, R @ np.swapaxes(_axis_rotation(j, b), -1, -2)), a)
    first_two = _axis_rotation(i, a) @ _axis_rotation(j, b)
    c = np.where(locked, 0.0, _angle_about(k, np.swapaxes(first_two, -1, -2) @ R))
    return np.stack([a, b, c], axis=-1)


def _quaternion_wxyz(R):
    """(..., 4) unit quaternions (w, x, y, z) with w >= 0 of rotations R (..., 3, 3), by the
    largest of 1 + trace and 1 + 2 R_ii - trace (no loss of digits near 180 degrees)."""
    t = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    candidates = np.stack([1 + t, 1 + 2 * R[..., 0, 0] - t, 1 + 2 * R[..., 1, 1] - t,
                           1 + 2 * R[..., 2, 2] - t], axis=-1)
    pick = np.argmax(candidates, axis=-1)
    q = np.empty(R.shape[:-2] + (4,))
    big = 0.5 * np.sqrt(np.take_along_axis(candidates, pick[..., None], -1)[..., 0])
    quarter = 0.25 / big
    d = {  # each quaternion component from the picked one
        "wx": (R[..., 2, 1] - R[..., 1, 2]) * quarter,
        "wy": (R[..., 0, 2] - R[..., 2, 0]) * quarter,
        "wz": (R[..., 1, 0] - R[..., 0, 1]) * quarter,
        "xy": (R[..., 0, 1] + R[..., 1, 0]) * quarter,
        "xz": (R[..., 0, 2] + R[..., 2, 0]) * quarter,
        "yz": (R[..., 1, 2] + R[..., 2, 1]) * quarter}
    rows = [np.stack([big, d["wx"], d["wy"], d["wz"]], -1),
            np.stack([d["wx"], big, d["xy"], d["xz"]], -1),
            np.stack([d["wy"], d["xy"], big, d["yz"]], -1),
            np.stack([d["wz"], d["xz"], d["yz"], big], -1)]
    for n in range(4):
        q[pick == n] = rows[n][pick == n]
    return np.where(q[..., :1] < 0, -q, q)


def encode(T, name):
    """Poses T (..., 4, 4) as vectors (..., width(name)) in layout `name`."""
    n = width(name)
    T = np.asarray(T, dtype=np.float64)
    if name == "matrix":  # the poses themselves, (..., 4, 4), as the audit passes them
        return T.copy()
    R, p = T[..., :3, :3], T[..., :3, 3]
    if name.startswith(_EULER):
        axes, intrinsic = _euler_axes(name)
        if intrinsic:
            tail = _intrinsic_angles(R, axes)
        else:  # extrinsic (a, b, c) about (i, j, k) = intrinsic (c, b, a) about (k, j, i)
            tail = _intrinsic_angles(R, axes[::-1])[..., ::-1]
    elif name == "pos_axis_angle":
        tail = rotation_vector(R)
    elif name == "pos_rot6d_rows":
        tail = np.concatenate([R[..., 0, :], R[..., 1, :]], axis=-1)
    elif name == "pos_rot6d_cols":
        tail = np.concatenate([R[..., :, 0], R[..., :, 1]], axis=-1)
    else:
        q = _quaternion_wxyz(R)
        tail = q if name == "pos_quat_wxyz" else np.concatenate([q[..., 1:], q[..., :1]], -1)
    out = np.concatenate([p, tail], axis=-1)
    assert out.shape[-1] == n
    return out


def _contradicted(v, name, bad, wrong):
    """ValueError naming the first vector of v where `bad` holds, with its numbers."""
    bad = np.asarray(bad)
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0]) if bad.ndim else ()
        raise ValueError("pose %s = %s is not a pose in %s: %s"
                         % (list(index), v[index].tolist(), name, wrong))


def decode(v, name):
    """Vectors v (..., width(name)) in layout `name` as poses (..., 4, 4); ValueError for a
    vector whose numbers contradict the layout."""
    n = width(name)
    v = np.asarray(v, dtype=np.float64)
    if name == "matrix":
        if v.shape[-2:] != (4, 4):
            raise ValueError("poses of shape %s; matrix poses are (..., 4, 4)" % (v.shape,))
        return v.copy()
    if v.shape[-1:] != (n,):
        raise ValueError("pose vectors of shape %s; %s has %d numbers per pose"
                         % (v.shape, name, n))
    if not np.all(np.isfinite(v)):
        raise ValueError("pose vectors in %s have a non-finite number" % name)
    out = np.zeros(v.shape[:-1] + (4, 4))
    out[..., :3, 3] = v[..., :3]
    out[..., 3, 3] = 1
    tail = v[..., 3:]
    if name.startswith(_EULER):
        axes, intrinsic = _euler_axes(name)
        R = np.broadcast_to(np.eye(3), v.shape[:-1] + (3, 3))
        for m, axis in enumerate(axes):
            turn = _axis_rotation(axis, tail[..., m])
            R = R @ turn if intrinsic else turn @ R
    elif name == "pos_axis_angle":
        flat = tail.reshape(-1, 3)
        R = np.stack([rotation_matrix(r) for r in flat]).reshape(v.shape[:-1] + (3, 3))
    elif name.startswith("pos_quat"):
        q = tail if name == "pos_quat_wxyz" else np.concatenate([tail[..., 3:], tail[..., :3]], -1)
        norm = np.linalg.norm(q, axis=-1)
        _contradicted(v, name, np.abs(norm - 1) > LAYOUT_TOLERANCE,
                      "its quaternion's norm is not 1; normalize it as your decoder does")
        w, x, y, z = np.moveaxis(q / norm[..., None], -1, 0)
        R = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
                     -1).reshape(v.shape[:-1] + (3, 3))
    else:
        a, b = tail[..., :3], tail[..., 3:]
        na, nb = np.linalg.norm(a, axis=-1), np.linalg.norm(b, axis=-1)
        dot = np.einsum("...i,...i->...", a, b)
        _contradicted(v, name, (np.abs(na - 1) > LAYOUT_TOLERANCE) |
                      (np.abs(nb - 1) > LAYOUT_TOLERANCE) | (np.abs(dot) > LAYOUT_TOLERANCE),
                      "its two vectors are not orthonormal; orthonormalize them as your decoder "
                      "does (Gram-Schmidt)")
        e1 = a / na[..., None]
        e2 = b - np.einsum("...i,...i->...", e1, b)[..., None] * e1
        e2 = e2 / np.linalg.norm(e2, axis=-1, keepdims=True)
        M = np.stack([e1, e2, np.cross(e1, e2)], axis=-1)  # columns
        R = np.swapaxes(M, -1, -2) if name == "pos_rot6d_rows" else M
    out[..., :3, :3] = R
    return out
