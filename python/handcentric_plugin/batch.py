"""Batched lines: grouping a line's scenes by shape, stacking them, and splitting the results.

A batched request holds up to the hello's "batch" scenes of any shapes; a user function gets
stacked arrays (a leading batch axis), so the scenes are grouped by their numbers of poses and
points, each group stacked and answered by one call, and the (B, ...) results cut back into one
answer per scene with every number checked. Kept apart from the loop (serve) because this is
array work on NumPy only, while the loop also serves unbatched plug-ins without NumPy.
"""
# The answers' arrays are written by codec._encode_array, looked up on the module at each call:
# one replacement there (a test's lossy wire) then changes every answer written.
from . import codec
from ._numpy import np
from .codec import _encoded_field
from .protocol import _BadResult, _Malformed, _fast_array, _is_number, _item, _matrices, _points

# What makes two scenes of a batched request stackable: their numbers of poses and points.
_SHAPE_FIELDS = ("history", "chunk", "hand_points", "world_points")


def _rows_of(value):
    """The number of rows of a field, to group the items of a batch: a list's or a decoded
    array's length; -1 for anything else (reading the field then says what is wrong)."""
    if isinstance(value, (list, np.ndarray)):
        return len(value)
    if value is None:
        return 0
    shape = value.get("shape") if isinstance(value, dict) else None
    if isinstance(shape, list) and shape and isinstance(shape[0], int):
        return shape[0]
    return -1


def _held_shapes(value):
    """The names and shapes of a request's held arrays, to group the items of a batch (arrays
    of one name stack only when their shapes agree)."""
    if not isinstance(value, dict):
        return ()
    return tuple(sorted((name, tuple(a["shape"]) if isinstance(a, dict)
                         and isinstance(a.get("shape"), list) else None)
                        for name, a in value.items()))


def _groups(items, history_rows=None):
    """The indices of the items of each shape (numbers of poses and points, held arrays' shapes),
    in the order each shape first appears. history_rows: a policy interface's count of history
    rows (per hand), in place of the field's length."""
    groups = {}
    for i, item in enumerate(items):
        shape = tuple(history_rows(item) if key == "history" and history_rows is not None
                      else _rows_of(item.get(key)) for key in _SHAPE_FIELDS)
        groups.setdefault((shape, _held_shapes(item.get("held"))), []).append(i)
    return list(groups.values())


def _stacked(items, key, width, tail, at=None):
    """The items' `key` stacked along a new leading axis: (B, rows) + tail. width: numbers per
    row (None for a flat vector, the noise). Encoded arrays are decoded into one buffer, and
    JSON numbers read by one np.array on the nested lists, when they are plain finite numbers
    of one shape; else each item is read as a single request is, so that the message names the
    item (by at[i], its index in the line, when the items are a group of it) and the field."""
    B = len(items)
    values = [item.get(key) for item in items]
    least = 0 if width == 3 else 1  # rows: points may have none
    if all(isinstance(v, np.ndarray) for v in values):  # decoded by _decoded_items
        return values[0][None] if B == 1 else np.stack(values)
    if not _fast_array.has_booleans:
        try:
            a = np.array(values, dtype=np.float64)
        except (TypeError, ValueError):
            a = None
        if a is not None and np.isfinite(a).all():
            if width is None and a.ndim == 2 and a.shape[1] > 0:
                return a
            if width is not None and a.ndim == 3 and a.shape[2] == width and \
                    (width == 3 or a.shape[1] > 0):
                return a.reshape((B, a.shape[1]) + tail)
            if width == 3 and a.ndim == 2 and a.shape[1] == 0:  # no points in any scene
                return np.zeros((B, 0, 3))

    def read(item):
        value = item.get(key)
        if isinstance(value, np.ndarray):  # decoded, in a group that mixes the two forms
            return value
        if isinstance(value, dict):
            return _encoded_field(value, "'%s'" % key, tail, least)
        if width is None:
            if not isinstance(value, list) or not value or not all(map(_is_number, value)):
                raise _Malformed("'%s' must be a non-empty list of numbers" % key)
            return np.array(value, dtype=np.float64)
        return _matrices(item, key) if width == 16 else _points(item, key)

    rows = [_item(at[i] if at else i, read, item) for i, item in enumerate(items)]
    if any(r.shape != rows[0].shape for r in rows):
        shapes = sorted(set(r.shape for r in rows))
        raise _Malformed("the scenes of one batch differ in the shape of '%s' (%s); a batch "
                         "holds scenes of one shape" % (key, ", ".join(map(str, shapes))))
    return np.stack(rows)


def _stack_named(named):
    """Per-scene ({pose name: (4,4)}, {scalar name: float}) -> ({name: (B,4,4)}, {name: (B,)})."""
    poses, values = named[0]
    return ({name: np.stack([n[0][name] for n in named]) for name in poses},
            {name: np.array([n[1][name] for n in named], dtype=np.float64) for name in values})


def _rows(value, B, field, function):
    """A batched result -> (B, n) float64, every number finite."""
    a = np.asarray(value)
    if a.dtype.kind not in "biuf":
        raise _BadResult("%s returned '%s' as an array of dtype %s; it must hold real numbers"
                         % (function, field, a.dtype))
    if a.ndim == 0 or a.shape[0] != B:
        raise _BadResult("%s returned '%s' of shape %s for a batch of %d scenes; return an "
                         "array with one row per scene, (%d, ...)"
                         % (function, field, a.shape, B, B))
    a = a.astype(np.float64).reshape(B, -1)
    if not np.isfinite(a).all():
        i, j = np.argwhere(~np.isfinite(a))[0]
        raise _BadResult("'%s' of batch item %d has a non-finite number at index %d: %r"
                         % (field, i, j, a[i, j]))
    return a


def _encoded_arrays(result, B):
    """A batched encode's result -> (actions (B, a), observation (B, o) or None), float64."""
    if isinstance(result, dict):
        unknown = set(result) - {"actions", "observation"}
        if "actions" not in result or unknown:
            raise _BadResult("encode returned a dict with keys %s; it needs 'actions' and may "
                             "have 'observation'" % sorted(result))
        actions, observation = result["actions"], result.get("observation")
    elif isinstance(result, tuple) and len(result) == 2:
        actions, observation = result
    else:
        actions, observation = result, None
    actions = _rows(actions, B, "actions", "encode")
    if actions.shape[1] == 0:
        raise _BadResult("encode returned no actions")
    return actions, None if observation is None else _rows(observation, B, "observation", "encode")


def _encoded_rows(result, B, encoded=False):
    """A batched encode's result -> B answers {"actions": [...], "observation": [...]} (encoded:
    each row an encoded array)."""
    arrays = [a for a in _encoded_arrays(result, B) if a is not None]
    rows = [[codec._encode_array(row) for row in a] if encoded else a.tolist() for a in arrays]
    return [dict(zip(("actions", "observation"), answer)) for answer in zip(*rows)]


def _chunks(result, B, encoded=False):
    """A batched policy's result, (B,K,4,4) or (B,K,16) -> B chunks of K lists of 16 numbers
    (encoded: B encoded arrays of shape (K, 4, 4))."""
    a = np.asarray(result)
    shaped = a.ndim == 4 and a.shape[2:] == (4, 4) or a.ndim == 3 and a.shape[2] == 16
    if a.dtype.kind not in "biuf" or not shaped or a.shape[0] != B or a.shape[1] == 0:
        hint = ("; poses of %d numbers are a layout: declare it, serve_policy(..., "
                "action_format=\"pos_quat_xyzw\") or the one the policy uses" % a.shape[-1]
                if a.ndim == 3 and a.shape[-1] in (6, 7, 9) else "")
        raise _BadResult("the policy returned an array of shape %s and dtype %s for a batch of "
                         "%d observations; it must be (%d, K, 4, 4)%s"
                         % (a.shape, a.dtype, B, B, hint))
    a = _rows(a, B, "chunk", "the policy").reshape(B, -1, 16)
    off = np.abs(a[:, :, 12:] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=2) > 1e-9
    if off.any():
        i, k = np.argwhere(off)[0]
        raise _BadResult("the policy's pose %d of batch item %d has last row %s, not "
                         "[0, 0, 0, 1]" % (k, i, a[i, k, 12:].tolist()))
    if encoded:
        return [codec._encode_array(c.reshape(-1, 4, 4)) for c in a]
    return a.tolist()
