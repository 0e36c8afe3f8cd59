"""SE(3) helpers for writing a plug-in: rotation vectors, relative poses and points (NumPy).

They are not used by the loop: they are the formulas most representations are made of, written
once with care for accuracy (near angle 0 and pi, large translations) and for speed on stacks of
poses. They keep the dtype of their input, so a float32 plug-in stays float32. serve() does not
need NumPy; these do, and say so when it is missing.
"""
from ._numpy import np


def _need_numpy():
    if np is None:
        raise ImportError("handcentric_plugin's geometry helpers need NumPy")


def _real(x):
    """x as an array of floats: float32 stays float32, integers become float64."""
    x = np.asarray(x)
    if x.dtype == np.float64 or x.dtype == np.float32:  # most calls: no type promotion to work out
        return x
    return x.astype(np.result_type(x, np.float32), copy=False)


def rotation_vector(R):
    """r(R) = angle * axis with angle in [0, pi]; accurate near 0 and near pi. R may be one
    (3, 3) matrix or a stack (..., 3, 3): a stack is done in one pass (a plug-in's time goes
    into per-pose Python calls otherwise)."""
    _need_numpy()
    R = _real(R)
    shape = R.shape[:-2]
    R = R.reshape(-1, 3, 3)
    w = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]],
                 axis=-1)  # 2 sin axis
    # np.clip and np.linalg.norm spelt out (the same operations): on the few rows of a plug-in's
    # call, their argument checks cost more than the arithmetic.
    cos_angle = np.minimum(np.maximum(0.5 * (R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2] - 1), -1), 1)
    sin_angle = 0.5 * np.sqrt(np.add.reduce(w * w, axis=-1))
    angle = np.arctan2(sin_angle, cos_angle)  # atan2 stays accurate where acos and asin are not
    small = angle < 1e-6  # first order, error O(angle^3): r = vee(R - R^T) / 2
    # w / (2 sin) loses digits only as sin -> 0, i.e. near pi; each row is computed as it would
    # be alone, and a small row's sin (perhaps 0) is not divided by.
    scale = angle / (2 * np.where(small, 1, sin_angle))
    out = np.where(small[:, None], 0.5 * w, scale[:, None] * w)
    middle = ~small & (angle < 0.5 * np.pi)
    large = ~small & ~middle
    if large.any():
        # Past pi/2, read the axis off the symmetric part instead: (R + R^T) / 2 - cos I =
        # (1 - cos) axis axis^T exactly, with 1 - cos >= 1, in its largest column; the sign from
        # w. (Using 1 + R_ii instead of R_ii - cos would leave an error of (pi - angle)^2 / 2.)
        Rl = R[large]
        n = np.arange(len(Rl))
        i = np.argmax(np.diagonal(Rl, axis1=1, axis2=2), axis=1)
        column = 0.5 * (Rl[n, :, i] + Rl[n, i, :])
        column[n, i] = Rl[n, i, i] - cos_angle[large]
        axis = column / np.linalg.norm(column, axis=-1, keepdims=True)
        sign = np.where(np.einsum("ij,ij->i", axis, w[large]) < 0, -1, 1).astype(axis.dtype)
        out[large] = (angle[large] * sign)[:, None] * axis
    return out.reshape(shape + (3,))


def rotation_matrix(r):
    """exp([r]x) (Rodrigues), accurate near 0."""
    _need_numpy()
    r = _real(r)
    angle = np.linalg.norm(r)
    K = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]], dtype=r.dtype)
    if angle < 1e-4:  # Taylor: the next terms are below 1e-18
        a, b = 1 - angle ** 2 / 6, 0.5 - angle ** 2 / 24
    else:  # 1 - cos written as 2 sin^2(angle/2): no cancellation
        a, b = np.sin(angle) / angle, 2 * (np.sin(angle / 2) / angle) ** 2
    return np.eye(3, dtype=r.dtype) + a * K + b * (K @ K)


def inverse(T):
    """T^-1 = [R^T, -R^T p] of a rigid transform."""
    _need_numpy()
    T = _real(T)
    out = np.eye(4, dtype=T.dtype)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -(T[:3, :3].T @ T[:3, 3])
    return out


def relative_pose(T0, T):
    """T0^-1 T, with the translation as R0^T (p - p0): subtracting first keeps the digits that
    R0^T p - R0^T p0 loses when both translations are large. T may be a stack (..., 4, 4)."""
    _need_numpy()
    T0, T = _real(T0), _real(T)
    out = np.zeros(T.shape, dtype=np.result_type(T0, T))
    out[..., :3, :3] = T0[:3, :3].T @ T[..., :3, :3]
    # row: (p - p0)^T R0 = (R0^T (p - p0))^T
    out[..., :3, 3] = (T[..., :3, 3] - T0[:3, 3]) @ T0[:3, :3]
    out[..., 3, 3] = 1
    return out


def batch_relative_pose(T0, T):
    """relative_pose for a batch: T0 (B,4,4) and T (B,n,4,4) -> (B,n,4,4), row b is
    relative_pose(T0[b], T[b]) with the same operations (a batched plug-in answers as the
    unbatched one does, to the last bit)."""
    _need_numpy()
    T0, T = _real(T0), _real(T)
    out = np.zeros(T.shape, dtype=np.result_type(T0, T))
    out[..., :3, :3] = np.swapaxes(T0[:, :3, :3], -1, -2)[:, None] @ T[..., :3, :3]
    out[..., :3, 3] = (T[..., :3, 3] - T0[:, None, :3, 3]) @ T0[:, :3, :3]
    out[..., 3, 3] = 1
    return out


def batch_relative_points(T0, points):
    """relative_points for a batch: T0 (B,4,4), points (B,n,3) -> (B,n,3)."""
    _need_numpy()
    T0, points = _real(T0), _real(points)
    return (points - T0[:, None, :3, 3]) @ T0[:, :3, :3]


def relative_points(T0, points):
    """World points q, (n,3), in the frame of T0: R0^T (q - p0)."""
    _need_numpy()
    T0, points = _real(T0), _real(points)
    return (points - T0[:3, 3]) @ T0[:3, :3]  # row i: (q_i - p0)^T R0 = (R0^T (q_i - p0))^T


def pose_vector(T):
    """[translation, rotation vector] of a rigid transform: 6 numbers (a stack (..., 4, 4)
    gives (..., 6))."""
    _need_numpy()
    T = _real(T)
    return np.concatenate([T[..., :3, 3], rotation_vector(T[..., :3, :3])], axis=-1)


def pose_matrix(v):
    """The inverse of pose_vector: 6 numbers [t, r] -> [[exp(r), t], [0, 1]]."""
    _need_numpy()
    v = _real(v)
    out = np.eye(4, dtype=v.dtype)
    out[:3, :3] = rotation_matrix(v[3:6])
    out[:3, 3] = v[:3]
    return out
