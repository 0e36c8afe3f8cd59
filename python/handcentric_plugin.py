"""Write a `handcentric audit --exec` plug-in in a few lines.

    import handcentric_plugin as hp

    def encode(history, chunk, hand_points, world_points):
        ...                      # history (H+1,4,4), chunk (K,4,4), points (n,3), (m,3)
        return actions           # or (actions, observation), or {"actions": .., "observation": ..}

    if __name__ == "__main__":
        hp.serve(encode)

The protocol (JSON Lines, docs/AUDIT.md, section "--exec"): the audit writes one request per line
on our stdin, we answer one line per request on stdout, in order, echoing its "id".

  request : {"id": n, "history": [[16 numbers], ...], "chunk": [[16 numbers], ...],
             "hand_points": [[x, y, z], ...], "world_points": [[x, y, z], ...]}
  answer  : {"id": n, "actions": [numbers], "observation": [numbers]}      (observation optional)

Matrices are world_T_hand, 16 numbers, row-major 4x4. `history[0]` is T_0, the hand NOW, then
T_-1, T_-2, ... (newest first); `history[::-1]` gives them oldest first. `chunk` holds T_1..T_K.
`hand_points` are eye-in-hand points (hand frame at T_0), `world_points` world-frame points.

Protocol v2 (the audit adds "protocol": 2 to every request; v1 audits do not; we ignore it):
  hello        when serve() is given decode, flow, extra_poses or scalars (or hello=True), the
               FIRST request is answered with {"id": n, "hello": {"protocol": 2, "extra_poses":
               [names], "scalars": [names], "decode": bool, "flow": bool}} instead of an answer;
               the audit then sends it again with the fields asked for.
  extra_poses  requests carry "extra_poses": {name: [16 numbers]} (world-frame poses that move
               with the global transform: the episode's start pose, a second arm's hand) and
               "scalars": {name: number} (numbers the transform leaves alone: gripper width).
               The functions then get keyword arguments extra_poses={name: (4,4)} and
               scalars={name: float} (both, whenever either list is declared).
  decode       {"id": n, "decode": [actions], "history", "hand_points", "world_points", ...} (no
               chunk) -> {"id": n, "chunk": [[16 numbers], ...]} from decode(actions, history,
               hand_points, world_points) returning the world-frame poses T_1..T_K, (K,4,4).
  flow         a request with "eps": [as many numbers as the actions] and "t": number is answered
               with actions (and observation) plus "flow_input" and "flow_target" from
               flow(history, chunk, hand_points, world_points, eps, t) returning the pair
               (flow_input, flow_target).

Batched (serve(encode, batched=True, batch_size=256), serve_policy(policy, batched=True)): the
hello also says "batch": batch_size, and the audit then sends up to batch_size scenes together,
{"id": n, "batch": [{"history", "chunk", ...}, ...]} (each item the fields of one request, of
any shapes), answered {"id": n, "batch": [{"actions", "observation"}, ...]} in the same order.
serve calls the function once per shape among the items (scenes with the same numbers of poses
and points), so that it always gets stacked arrays. encode gets
stacked arrays with a leading batch axis, history (B,H+1,4,4), chunk (B,K,4,4), hand_points
(B,n,3), world_points (B,m,3) (extra_poses={name: (B,4,4)}, scalars={name: (B,)}), and returns
actions (B,a), or (actions, observation (B,o)), or a dict of them; a policy gets noise (B,d) and
returns (B,K,4,4). decode and flow stay functions of one scene (their requests are not batched);
a flow request's actions come from encode on a batch of one. Batched mode needs NumPy.
The hello also offers "encodings": ["base64"] (unless encoding=None): an audit that takes it
sends its batched lines with "encoding": "base64" and each array as {"dtype": "float64",
"shape": [...], "data": base64 of the little-endian bytes}, and gets the answers' arrays back the
same way: the same doubles, bit for bit, in fewer bytes and less JSON work on both sides. A line
without "encoding" (an older audit) is answered with JSON numbers, as before.

Held arrays: an audit on recorded observations (--observations FILE) whose data carry "held"
arrays (a wrist camera's images, token ids: parts that move with the hand, so g leaves them
alone) sends each request "held": {name: encoded array} in the array's own dtype, and the
functions then get the keyword held={name: array} ((B, ...) stacked when batched).

The functions get NumPy float64 arrays when NumPy imports (empty point lists have shape (0,3)),
nested Python lists otherwise ((H+1) x 4 x 4, K x 4 x 4, n x 3). They may return NumPy arrays of
any real dtype (float32 too), lists or tuples, nested or flat: everything is flattened to Python
floats. They must be functions of their inputs only: the audit asks each distinct scene once.

Failures, so that the audit can say what went wrong (it quotes the tail of our stderr):
  an exception in a user function   full traceback on stderr, exit status 1
  a non-finite or malformed result  one line naming the field and index on stderr, exit status 1
  a malformed request line          one line on stderr, exit status 2
  end of input (the audit is done)  serve() returns, so the script exits with status 0

Output: serve() flushes after every line, so `python3 -u` is not needed. A plug-in that writes
its own loop must flush after each answer (or run under `python3 -u`): on a pipe, Python holds
stdout in an 8 KiB buffer and the audit would wait for an answer that never comes. While a user
function runs, print() goes to stderr, so debugging output cannot corrupt the protocol.

The geometry helpers below (rotation_vector, rotation_matrix, inverse, relative_pose,
relative_points, pose_vector, pose_matrix, and for batched plug-ins batch_relative_pose and
batch_relative_points) need NumPy; serve() does not (unless batched).
"""
import base64
import binascii
import contextlib
import json
import math
import numbers
import struct
import sys
import traceback

try:
    import numpy as np
except ImportError:  # serve() still works, on nested lists
    np = None

PROTOCOL = 2


class _Malformed(Exception):
    """The audit sent a line we cannot read as a request: exit status 2."""


class _BadResult(Exception):
    """A user function returned something we cannot send: exit status 1."""


def _die(status, message):
    sys.stderr.write(message.rstrip("\n") + "\n")
    sys.stderr.flush()
    sys.exit(status)


# ----------------------------------------------------------------------------- reading requests

def _is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _numbers(value, count, what):
    """A JSON list of `count` numbers, as Python floats."""
    if not isinstance(value, list) or len(value) != count or not all(map(_is_number, value)):
        raise _Malformed("%s must be a list of %d numbers" % (what, count))
    return [float(x) for x in value]


def _matrix(value, what):
    """16 row-major numbers -> a (4,4) array, or 4 lists of 4 without NumPy."""
    m = _numbers(value, 16, what)
    return np.array(m).reshape(4, 4) if np is not None else [m[0:4], m[4:8], m[8:12], m[12:16]]


def _fast_array(value, width):
    """value as an (n, width) float64 array when it is a plain list of lists of numbers, else
    None (then the careful path below checks it item by item and names what is wrong). A JSON
    true/false would pass np.array as 1.0/0.0, so a request holding one never takes this path."""
    if np is None or _fast_array.has_booleans:
        return None
    try:
        a = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    # null becomes NaN in np.array: anything non-finite goes the careful way too.
    return a if a.ndim == 2 and a.shape[1] == width and np.isfinite(a).all() else None


_fast_array.has_booleans = True  # set per request by _parse


def _matrices(request, key):
    value = request.get(key)
    if not isinstance(value, list) or not value:
        raise _Malformed("'%s' must be a non-empty list of matrices" % key)
    fast = _fast_array(value, 16)
    if fast is not None:
        return fast.reshape(len(value), 4, 4)
    ms = [_matrix(m, "%s[%d]" % (key, i)) for i, m in enumerate(value)]
    return np.array(ms).reshape(len(ms), 4, 4) if np is not None else ms


def _points(request, key):
    value = request.get(key, [])
    if not isinstance(value, list):
        raise _Malformed("'%s' must be a list of [x, y, z]" % key)
    fast = _fast_array(value, 3) if value else None
    if fast is not None:
        return fast
    ps = [_numbers(p, 3, "%s[%d]" % (key, i)) for i, p in enumerate(value)]
    return np.array(ps).reshape(len(ps), 3) if np is not None else ps


def _named(request, key, names, read):
    """The declared names of request[key] ({name: value}); a missing one is an error."""
    given = request.get(key, {})
    if not isinstance(given, dict):
        raise _Malformed("'%s' must be an object {name: value}" % key)
    missing = [name for name in names if name not in given]
    if missing:
        raise _Malformed("request has no %s %s (the plug-in declared %s; the audit sends them "
                         "after the hello)" % (key, ", ".join(map(repr, missing)), list(names)))
    return {name: read(given[name], "%s[%r]" % (key, name)) for name in names}


def _scalar(value, what):
    if not _is_number(value):
        raise _Malformed("%s must be a number" % what)
    return float(value)


def _parse(line):
    _fast_array.has_booleans = "true" in line or "false" in line
    try:
        request = json.loads(line)
    except ValueError as error:
        raise _Malformed("not JSON (%s)" % error)
    if not isinstance(request, dict):
        raise _Malformed("not a JSON object")
    if not isinstance(request.get("id"), int) or isinstance(request.get("id"), bool):
        raise _Malformed("no integer 'id'")
    return request


# ----------------------------------------------------------------------------- writing answers

def _flatten(value, field):
    """Any nesting of arrays, lists, tuples and real numbers -> a flat list of finite floats."""
    out = []

    def walk(x):
        if np is not None and isinstance(x, np.ndarray):
            if x.dtype.kind in "biuf":  # bool, integers, floats of any width (float32 too)
                out.extend(x.astype(np.float64).ravel().tolist())
            elif x.dtype.kind == "O":
                for item in x.ravel():
                    walk(item)
            else:
                raise _BadResult("'%s' has an array of dtype %s; it must hold real numbers"
                                 % (field, x.dtype))
        elif isinstance(x, (list, tuple)):
            for item in x:
                walk(item)
        elif isinstance(x, numbers.Real):  # Python and NumPy scalars
            out.append(float(x))
        else:
            raise _BadResult("'%s' holds a %s; it must hold real numbers"
                             % (field, type(x).__name__))

    walk(value)
    for i, x in enumerate(out):
        if not math.isfinite(x):
            raise _BadResult("'%s' has a non-finite number at index %d: %r" % (field, i, x))
    return out


def _split_encoded(result):
    """encode's result: actions, (actions, observation) or {"actions", "observation"}."""
    if isinstance(result, dict):
        unknown = set(result) - {"actions", "observation"}
        if "actions" not in result or unknown:
            raise _BadResult("encode returned a dict with keys %s; it needs 'actions' and may "
                             "have 'observation'" % sorted(result))
        return result["actions"], result.get("observation")
    # A tuple of two sequences is (actions, observation); a tuple of numbers is the actions.
    if isinstance(result, tuple) and len(result) == 2 and not isinstance(result[0], numbers.Real):
        return result
    return result, None


def _chunk(result):
    """decode's result -> K lists of 16 numbers, each the matrix of a rigid transform."""
    if np is not None and isinstance(result, np.ndarray) and result.shape[-2:] != (4, 4) \
            and not (result.ndim == 2 and result.shape[1] == 16):
        raise _BadResult("decode returned an array of shape %s; it must be (K, 4, 4)"
                         % (result.shape,))
    flat = _flatten(result, "chunk")
    if not flat or len(flat) % 16:
        raise _BadResult("decode returned %d numbers; it must return K 4x4 matrices" % len(flat))
    chunk = [flat[i:i + 16] for i in range(0, len(flat), 16)]
    for k, m in enumerate(chunk):
        if max(abs(a - b) for a, b in zip(m[12:], (0.0, 0.0, 0.0, 1.0))) > 1e-9:
            raise _BadResult("decode's pose %d has last row %s, not [0, 0, 0, 1]" % (k, m[12:]))
    return chunk


# ----------------------------------------------------------------------------- batched requests

MAX_BATCH = 65536  # the audit's bound on a hello's "batch"
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


def _item(i, read, item):
    """read(item), a malformed item named by its index."""
    try:
        return read(item)
    except _Malformed as error:
        raise _Malformed("batch[%d]: %s" % (i, error))


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
    rows = [[_encode_array(row) for row in a] if encoded else a.tolist() for a in arrays]
    return [dict(zip(("actions", "observation"), answer)) for answer in zip(*rows)]


def _chunks(result, B, encoded=False):
    """A batched policy's result, (B,K,4,4) or (B,K,16) -> B chunks of K lists of 16 numbers
    (encoded: B encoded arrays of shape (K, 4, 4))."""
    a = np.asarray(result)
    shaped = a.ndim == 4 and a.shape[2:] == (4, 4) or a.ndim == 3 and a.shape[2] == 16
    if a.dtype.kind not in "biuf" or not shaped or a.shape[0] != B or a.shape[1] == 0:
        raise _BadResult("the policy returned an array of shape %s and dtype %s for a batch of "
                         "%d observations; it must be (%d, K, 4, 4)"
                         % (a.shape, a.dtype, B, B))
    a = _rows(a, B, "chunk", "the policy").reshape(B, -1, 16)
    off = np.abs(a[:, :, 12:] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=2) > 1e-9
    if off.any():
        i, k = np.argwhere(off)[0]
        raise _BadResult("the policy's pose %d of batch item %d has last row %s, not "
                         "[0, 0, 0, 1]" % (k, i, a[i, k, 12:].tolist()))
    if encoded:
        return [_encode_array(c.reshape(-1, 4, 4)) for c in a]
    return a.tolist()


# ----------------------------------------------------------------------------- encoded arrays
# The "base64" encoding of batched lines (docs/AUDIT.md, "Encoded numbers"): an array is
# {"dtype": "float64" | "float32" | "uint8", "shape": [...], "data": base64 of its elements,
# row-major, little-endian}. The audit uses it when our hello offers it ("encodings"), and marks
# each such line "encoding": "base64"; we answer a line in the encoding it came in, so that an
# audit that does not know the encoding gets JSON numbers, as before.

ENCODINGS = ("base64",)  # what serve(encoding=...) can offer besides JSON numbers
# The dtypes an encoded array may have, as NumPy reads their little-endian bytes.
_DTYPES = {"float64": "<f8", "float32": "<f4", "uint8": "u1"}
_ARRAY_FORM = ('an encoded array is {"dtype": "float64", "shape": [n, ...], "data": "base64 of '
               'the elements, row-major, little-endian"}')


def _b64decode(text):
    """Standard, padded base64 -> bytes; anything else raises ValueError (binascii.Error)."""
    try:
        return binascii.a2b_base64(text, strict_mode=True)
    except TypeError:  # Python < 3.11: no strict_mode
        return base64.b64decode(text, validate=True)


def _decode_array(value, what, dtypes=("float64",)):
    """An encoded array -> a writable NumPy array of its dtype and shape. what: the field, for
    messages ("batch[2]: 'history'"); dtypes: those the field may have."""
    if not isinstance(value, dict) or set(value) != {"dtype", "shape", "data"}:
        raise _Malformed("%s = %.60s is not an encoded array; %s"
                         % (what, json.dumps(value), _ARRAY_FORM))
    dtype, shape, data = value["dtype"], value["shape"], value["data"]
    if not isinstance(dtype, str) or dtype not in _DTYPES:
        raise _Malformed("%s has dtype %r; an encoded array's dtype is one of %s (little-endian)"
                         % (what, dtype, ", ".join(_DTYPES)))
    if dtype not in dtypes:
        raise _Malformed("%s has dtype %s; it must be %s" % (what, dtype, " or ".join(dtypes)))
    if not isinstance(shape, list) or len(shape) > 8 or not all(
            isinstance(d, int) and not isinstance(d, bool) and d >= 0 for d in shape):
        raise _Malformed("%s has shape %r, not a list of at most 8 sizes (integers >= 0)"
                         % (what, shape))
    if not isinstance(data, str):
        raise _Malformed("%s has \"data\" that is not a string; %s" % (what, _ARRAY_FORM))
    try:
        raw = _b64decode(data)
    except ValueError as error:
        raise _Malformed("%s has \"data\" that is not standard base64 (%s): A-Z a-z 0-9 + /, "
                         "padded with = to a multiple of 4 characters" % (what, error))
    size = np.dtype(_DTYPES[dtype]).itemsize
    count = math.prod(shape)
    if len(raw) != count * size:
        raise _Malformed("%s of shape %s and dtype %s needs %d bytes, but \"data\" holds %d; "
                         "send every element, row-major, little-endian"
                         % (what, shape, dtype, count * size, len(raw)))
    return np.frombuffer(bytearray(raw), dtype=_DTYPES[dtype]).reshape(shape)


def _finite(a, what):
    """a, after checking that every number is finite (the protocol's numbers are)."""
    if not np.isfinite(a).all():
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
        raise _Malformed("%s has a non-finite number at %s: %r; the protocol's numbers are "
                         "finite" % (what, index if len(index) > 1 else index[0], a[index]))
    return a


def _encoded_field(value, what, tail, least):
    """A request's encoded array: float64, finite, of shape (n,) + tail with n >= least."""
    a = _finite(_decode_array(value, what), what)
    if a.ndim != 1 + len(tail) or a.shape[1:] != tail or a.shape[0] < least:
        raise _Malformed("%s has shape %s; it must be (%s)%s" % (
            what, list(a.shape), ", ".join(["n"] + [str(d) for d in tail]),
            " with n >= %d" % least if least else ""))
    return a.astype(np.float64, copy=False)


def _pose(value, what):
    """A 4x4 pose in either form (an extra pose)."""
    if isinstance(value, dict):
        a = _finite(_decode_array(value, what), what)
        if a.shape != (4, 4):
            raise _Malformed("%s has shape %s; a pose is (4, 4)" % (what, list(a.shape)))
        return a.astype(np.float64, copy=False)
    return _matrix(value, what)


# The array fields of a request: (tail of the shape, the fewest rows).
_ARRAY_FIELDS = {"history": ((4, 4), 1), "chunk": ((4, 4), 1), "hand_points": ((3,), 0),
                 "world_points": ((3,), 0), "noise": ((), 1)}


def _decoded_column(values, tail, least):
    """Encoded arrays (one field of every item of a line) -> their arrays, views of one buffer
    decoded at once (one finiteness check per line, not per item); None unless every one is a
    plain float64 array of shape (n,) + tail with n >= least (each is then read on its own, so
    that the message names the item)."""
    rows = []
    for v in values:
        shape = v.get("shape") if type(v) is dict else None
        if not (type(shape) is list and len(v) == 3 and v.get("dtype") == "float64"
                and len(shape) == 1 + len(tail) and tuple(shape[1:]) == tail
                and type(shape[0]) is int and shape[0] >= least):
            return None
        rows.append(shape[0])
    try:
        data = bytearray().join(_b64decode(v["data"]) for v in values)
    except (TypeError, ValueError):
        return None
    width = math.prod(tail)
    if len(data) != 8 * width * sum(rows):
        return None
    flat = np.frombuffer(data, dtype=_DTYPES["float64"]).astype(np.float64, copy=False)
    if not np.isfinite(flat).all():
        return None
    out, offset = [], 0
    for n in rows:
        out.append(flat[offset:offset + n * width].reshape((n,) + tail))
        offset += n * width
    return out


def _decoded_items(items):
    """The items of an encoded line with their encoded arrays decoded (NumPy arrays in their
    place), ready to be grouped by shape and stacked."""
    items = [dict(item) for item in items]
    for key, (tail, least) in _ARRAY_FIELDS.items():
        present = [i for i, item in enumerate(items) if isinstance(item.get(key), dict)]
        if not present:
            continue
        column = _decoded_column([items[i][key] for i in present], tail, least)
        for j, i in enumerate(present):
            items[i][key] = column[j] if column is not None else _item(
                i, lambda item: _encoded_field(item[key], "'%s'" % key, tail, least), items[i])
    return items


def _encode_array(a):
    """A NumPy array of float64, float32 or uint8 -> its encoded form (little-endian)."""
    names = {"f8": "float64", "f4": "float32", "u1": "uint8"}
    name = names[a.dtype.kind + str(a.dtype.itemsize)]
    return {"dtype": name, "shape": list(a.shape),
            "data": base64.b64encode(a.astype(_DTYPES[name], copy=False).tobytes())
            .decode("ascii")}


# ----------------------------------------------------------------------------- the loop

def serve_policy(policy, *, extra_poses=(), scalars=(), noise=None, hello=None, batched=False,
                 batch_size=256, encoding="base64", cameras=None, rng=None, reset=None,
                 stdin=None, stdout=None):
    """Answer `handcentric audit --policy-exec` requests: a whole policy (eq. 4 of the paper).

    policy(history, hand_points, world_points, noise) -> (K,4,4) world-frame poses T_1..T_K
    noise: the standard normals the request carries (256 unless `noise=n` asks for n); use them
        as the policy's only randomness, so that one noise vector gives one chunk.
    batched: policy(history (B,H+1,4,4), hand_points (B,n,3), world_points (B,m,3), noise (B,d))
        -> (B,K,4,4), on up to batch_size observations of one shape per call (needs NumPy).
    cameras: what the policy sees, e.g. ("eye_in_hand",) or {"views": ["eye_in_hand"],
        "image_size": [64, 48], "channels": "rgbd", "floor": False} (the defaults but views):
        the audit renders each observation's images and the policy gets images={view: (C,h,w)}
        float32 as a keyword ((B,C,h,w) batched), as audit_policy(..., cameras=...) passes them
        (docs/AUDIT_YOUR_POLICY.md). Needs NumPy.
    rng: None, "torch", "numpy" or "generator": the policy draws random numbers of its own
        (torch.randn inside, a DDPM sampler's per-step noise). Each observation is then asked in
        a call of its own, after seeding that generator from the observation's noise vector
        ("generator": a seeded torch.Generator passed as generator=), so that o and g o, which
        the audit asks with the same noise, get the same draws. Without it the audit's
        preflight finds answers that differ on the same observation and gives no verdict.
    reset: a function of no arguments called before every call (e.g. LeRobot's policy.reset),
        for a policy that keeps state between calls (an action queue, a history).
    extra_poses, scalars, hello, encoding, stdin, stdout: as for serve().
    """
    if rng is not None or reset is not None:
        policy = _paired_policy(policy, rng, reset, batched)
    if cameras is not None:
        if np is None:
            _die(1, "handcentric_plugin: serve_policy(..., cameras=...) needs NumPy, which does "
                    "not import in %s (Debian: python3-numpy)" % sys.executable)
        cameras = dict(cameras) if isinstance(cameras, dict) else {
            "views": [cameras] if isinstance(cameras, str) else list(cameras)}
        if not cameras.get("views") or not all(isinstance(v, str) for v in cameras["views"]):
            raise ValueError("cameras needs at least one view name, e.g. ('eye_in_hand',), "
                             "got %r" % (cameras,))
        hello = True
    serve(None, extra_poses=extra_poses, scalars=scalars, hello=hello, batched=batched,
          batch_size=batch_size, encoding=encoding, stdin=stdin, stdout=stdout, _policy=policy,
          _noise=noise, _cameras=cameras)


def _noise_seed(noise):
    """A seed below 2**63 from the bytes of one noise vector (the same vector, the same seed)."""
    import hashlib
    values = noise.tolist() if hasattr(noise, "tolist") else list(noise)
    digest = hashlib.sha256(struct.pack("<%dd" % len(values), *values)).digest()
    return int.from_bytes(digest[:8], "little") >> 1


def _seed_generator(rng, seed):
    """Seeds the generator of mode `rng`; returns the keywords the call gets."""
    if rng == "torch":
        import torch
        torch.manual_seed(seed)
        return {}
    if rng == "numpy":
        np.random.seed(seed % (1 << 32))
        return {}
    import torch
    generator = torch.Generator()
    generator.manual_seed(seed)
    return {"generator": generator}


def _paired_policy(policy, rng, reset, batched):
    """policy called after reset() and, with rng, one observation per call with its generator
    seeded from that observation's noise (serve_policy's rng= and reset=)."""
    if rng not in (None, "torch", "numpy", "generator"):
        raise ValueError('rng=%r is not a mode; use "torch", "numpy", "generator" or None' % (rng,))
    if rng == "numpy" and np is None:
        raise ValueError('rng="numpy" needs NumPy, which does not import in %s' % sys.executable)
    if reset is not None and not callable(reset):
        raise TypeError("reset must be a function of no arguments (e.g. policy.reset), got %r"
                        % (reset,))

    def one_call(history, hand_points, world_points, noise, kwargs, seed_noise):
        if reset is not None:
            reset()
        extra = _seed_generator(rng, _noise_seed(seed_noise)) if rng is not None else {}
        return policy(history, hand_points, world_points, noise, **dict(kwargs, **extra))

    def call(history, hand_points, world_points, noise, **kwargs):
        if rng is None or not batched:
            return one_call(history, hand_points, world_points, noise, kwargs, noise)

        def row(value, i):
            return {k: row(v, i) for k, v in value.items()} if isinstance(value, dict) \
                else value[i:i + 1]
        def as_numpy(x):  # a torch result, on any device, with or without grad
            return x.detach().cpu().numpy() if hasattr(x, "detach") else np.asarray(x)
        chunks = [as_numpy(one_call(history[i:i + 1], hand_points[i:i + 1],
                                      world_points[i:i + 1], noise[i:i + 1],
                                      {k: row(v, i) for k, v in kwargs.items()}, noise[i]))
                  for i in range(len(noise))]
        return np.concatenate(chunks, axis=0)
    return call


def serve(encode, *, decode=None, flow=None, extra_poses=(), scalars=(), hello=None,
          batched=False, batch_size=256, encoding="base64", stdin=None, stdout=None,
          _policy=None, _noise=None, _cameras=None):
    """Answer the audit's requests until end of input (see the module docstring).

    encode(history, chunk, hand_points, world_points) -> actions | (actions, observation) | dict
    decode(actions, history, hand_points, world_points) -> (K,4,4) world-frame poses T_1..T_K
    flow(history, chunk, hand_points, world_points, eps, t) -> (flow_input, flow_target)
    extra_poses, scalars: names the requests must carry; the functions then get the keyword
        arguments extra_poses={name: (4,4)} and scalars={name: float}.
    hello: None = send the v2 hello when any of the above is declared; True / False force it.
    batched: encode gets up to batch_size scenes of one shape at once, stacked along a leading
        axis: history (B,H+1,4,4), chunk (B,K,4,4), hand_points (B,n,3), world_points (B,m,3),
        extra_poses={name: (B,4,4)}, scalars={name: (B,)}, and returns actions (B,a), or
        (actions, observation (B,o)), or a dict; decode and flow stay per scene. Needs NumPy.
    encoding: with batched=True, the hello offers it ("encodings": ["base64"]) and an audit that
        takes it sends the arrays of its batched lines as base64 of their float64 bytes, answered
        the same way: the same numbers, bit for bit, for less time in JSON on both sides. None:
        numbers as JSON text. An audit that does not know the encoding sends JSON numbers, which
        are answered as such.
    stdin, stdout: text streams (default sys.stdin, sys.stdout).
    """
    if batched:
        if np is None:
            _die(1, "handcentric_plugin: serve(..., batched=True) needs NumPy, which does not "
                    "import in %s (Debian: python3-numpy); or serve unbatched" % sys.executable)
        if isinstance(batch_size, bool) or not isinstance(batch_size, int) \
                or not 1 <= batch_size <= MAX_BATCH:
            raise ValueError("batch_size must be an integer from 1 to %d, got %r"
                             % (MAX_BATCH, batch_size))
        if hello is False:
            raise ValueError("batched=True needs the hello (it declares the batch size)")
        hello = True
    if encoding is not None and encoding not in ENCODINGS:
        raise ValueError("encoding must be one of %s, or None (numbers as JSON text), got %r"
                         % (", ".join(map(repr, ENCODINGS)), encoding))
    stdin = sys.stdin if stdin is None else stdin
    out = sys.stdout if stdout is None else stdout  # taken now: print() is redirected below
    extra_poses, scalars = tuple(extra_poses), tuple(scalars)
    declared = bool(extra_poses or scalars)
    if hello is None:
        hello = declared or decode is not None or flow is not None or _noise is not None
    hello_body = {"protocol": PROTOCOL, "extra_poses": list(extra_poses),
                  "scalars": list(scalars), "decode": decode is not None, "flow": flow is not None}
    if _noise is not None:
        hello_body["noise"] = int(_noise)
    if _cameras is not None:
        hello_body["cameras"] = _cameras
    if batched:
        hello_body["batch"] = batch_size
        if encoding is not None:
            hello_body["encodings"] = [encoding]

    def images_of(item, what):
        """The request's images, {view: float32 (C, h, w)}, checked against the hello's views."""
        value = item.get("images")
        if not isinstance(value, dict) or set(value) != set(_cameras["views"]):
            raise _Malformed("%s: 'images' must hold one encoded image per camera of the hello, "
                             "%s" % (what, list(_cameras["views"])))
        return {view: _finite(_decode_array(image, "%s: images[%r]" % (what, view),
                                            ("float32",)), "images[%r]" % view)
                for view, image in value.items()}

    def held_of(item, what):
        """The request's held arrays (a user's recorded images, ...), {name: array}, or None
        when it has none (then the functions get no held= keyword)."""
        value = item.get("held")
        if value is None:
            return None
        if not isinstance(value, dict) or not value:
            raise _Malformed("%s: 'held' must be an object {name: encoded array}" % what)
        return {name: _finite(_decode_array(array, "%s: held[%r]" % (what, name),
                                            ("float64", "float32", "uint8")), "held[%r]" % name)
                for name, array in value.items()}

    def call(function, request_id, args, named, images=None, held=None):
        kwargs = {"extra_poses": named[0], "scalars": named[1]} if declared else {}
        if images is not None:
            kwargs["images"] = images
        if held is not None:
            kwargs["held"] = held
        try:
            # A stray print() in user code would be read as an answer: send it to stderr.
            with contextlib.redirect_stdout(sys.stderr):
                return function(*args, **kwargs)
        except Exception:
            sys.stderr.write("handcentric_plugin: %s raised on request %d:\n"
                             % (getattr(function, "__name__", "the plug-in"), request_id))
            traceback.print_exc(file=sys.stderr)
            sys.stderr.flush()
            sys.exit(1)

    def answer(request):
        rid = request["id"]
        history = _matrices(request, "history")
        hand_points = _points(request, "hand_points")
        world_points = _points(request, "world_points")
        named = (_named(request, "extra_poses", extra_poses, _matrix),
                 _named(request, "scalars", scalars, _scalar))
        held = held_of(request, "request")
        if _policy is not None:
            if "noise" not in request:
                raise _Malformed("a policy plug-in needs 'noise' in every request (run it with "
                                 "--policy-exec, not --exec)")
            value = request["noise"]
            if not isinstance(value, list) or not value or not all(map(_is_number, value)):
                raise _Malformed("'noise' must be a non-empty list of numbers")
            noise = (np.array(value, dtype=np.float64) if np is not None
                     else [float(x) for x in value])
            images = images_of(request, "request") if _cameras is not None else None
            if batched:  # a batch of one
                stacked = (history[None], hand_points[None], world_points[None], noise[None])
                if images is not None:
                    images = {view: image[None] for view, image in images.items()}
                if held is not None:
                    held = {name: array[None] for name, array in held.items()}
                return {"id": rid, "chunk": _chunks(call(_policy, rid, stacked,
                                                         _stack_named([named]), images, held),
                                                    1)[0]}
            return {"id": rid,
                    "chunk": _chunk(call(_policy, rid,
                                         (history, hand_points, world_points, noise), named,
                                         images, held))}
        if "decode" in request:
            if decode is None:
                raise _Malformed("a decode request, but the plug-in declared no decode")
            actions = request["decode"]
            if not isinstance(actions, list) or not actions or not all(map(_is_number, actions)):
                raise _Malformed("'decode' must be a non-empty list of numbers")
            actions = [float(x) for x in actions]
            if np is not None:
                actions = np.array(actions)
            return {"id": rid, "chunk": _chunk(call(decode, rid, (actions, history, hand_points,
                                                     world_points), named, None, held))}
        chunk = _matrices(request, "chunk")
        if batched:  # a batch of one
            stacked = (history[None], chunk[None], hand_points[None], world_points[None])
            reply = {"id": rid}
            one = None if held is None else {name: a[None] for name, a in held.items()}
            reply.update(_encoded_rows(call(encode, rid, stacked, _stack_named([named]), None,
                                            one), 1)[0])
        else:
            encoded = call(encode, rid, (history, chunk, hand_points, world_points), named,
                           None, held)
            actions, observation = _split_encoded(encoded)
            reply = {"id": rid, "actions": _flatten(actions, "actions")}
            if not reply["actions"]:
                raise _BadResult("encode returned no actions")
            if observation is not None:
                reply["observation"] = _flatten(observation, "observation")
        if "eps" in request or "t" in request:
            if flow is None:
                raise _Malformed("a flow request (eps, t), but the plug-in declared no flow")
            eps = _numbers(request.get("eps"), len(reply["actions"]),
                           "'eps' (as long as the actions)")
            t = _scalar(request.get("t"), "'t'")
            if np is not None:
                eps = np.array(eps)
            pair = call(flow, rid, (history, chunk, hand_points, world_points, eps, t), named,
                        None, held)
            if not isinstance(pair, (tuple, list)) or len(pair) != 2:
                raise _BadResult("flow must return the pair (flow_input, flow_target)")
            reply["flow_input"] = _flatten(pair[0], "flow_input")
            reply["flow_target"] = _flatten(pair[1], "flow_target")
        return reply

    def answer_batch(request):
        rid, items = request["id"], request["batch"]
        if not isinstance(items, list) or not items or not all(isinstance(i, dict)
                                                               for i in items):
            raise _Malformed("'batch' must be a non-empty list of request objects")
        if len(items) > batch_size:
            raise _Malformed("a batch of %d scenes, more than the %d the hello declared"
                             % (len(items), batch_size))
        # The items may be of several shapes: the function is called once per shape (its
        # arrays must be stacked), and the answers go back in the request's order.
        encoded = request.get("encoding") is not None
        if encoded:
            items = _decoded_items(items)
        groups = {}
        for i, item in enumerate(items):
            groups.setdefault((tuple(_rows_of(item.get(key)) for key in _SHAPE_FIELDS),
                               _held_shapes(item.get("held"))), []).append(i)
        answers = [None] * len(items)
        for indices in groups.values():
            for i, answer in zip(indices, answer_group(rid, [items[i] for i in indices],
                                                       encoded, indices)):
                answers[i] = answer
        return {"id": rid, "batch": answers}

    def answer_group(rid, items, encoded, at):
        """The answers to items of one shape, in order (encoded: their arrays encoded); at: the
        items' indices in the line, for messages."""
        B = len(items)
        history = _stacked(items, "history", 16, (4, 4), at)
        hand_points = _stacked(items, "hand_points", 3, (3,), at)
        world_points = _stacked(items, "world_points", 3, (3,), at)
        named = _stack_named([_item(at[i], lambda item: (
            _named(item, "extra_poses", extra_poses, _pose),
            _named(item, "scalars", scalars, _scalar)), items[i]) for i in range(B)])
        held = None
        if "held" in items[0]:
            each = [held_of(item, "batch[%d]" % i) for i, item in zip(at, items)]
            held = {name: np.stack([e[name] for e in each]) for name in each[0]}
        if _policy is not None:
            noise = _stacked(items, "noise", None, (), at)
            images = None
            if _cameras is not None:
                each = [images_of(item, "batch[%d]" % i) for i, item in zip(at, items)]
                images = {view: np.stack([e[view] for e in each]) for view in _cameras["views"]}
            result = call(_policy, rid, (history, hand_points, world_points, noise), named,
                          images, held)
            return [{"chunk": c} for c in _chunks(result, B, encoded)]
        if any("decode" in item or "eps" in item or "t" in item for item in items):
            raise _Malformed("decode and flow requests are not batched")
        chunk = _stacked(items, "chunk", 16, (4, 4), at)
        result = call(encode, rid, (history, chunk, hand_points, world_points), named, None,
                      held)
        return _encoded_rows(result, B, encoded=True) if encoded else _encoded_rows(result, B)

    line_number = 0
    first = True
    while True:
        line = stdin.readline()
        if not line:
            return  # end of input: the audit is done
        line_number += 1
        if not line.strip():
            continue
        rid = None
        try:
            request = _parse(line)
            rid = request["id"]
            if "encoding" in request and request["encoding"] not in hello_body.get("encodings",
                                                                                   ()):
                raise _Malformed("a line in encoding %s, which the plug-in did not offer (its "
                                 "hello offers %s)" % (json.dumps(request["encoding"]),
                                                       hello_body.get("encodings", [])))
            if first and hello:
                reply = {"id": rid, "hello": hello_body}
            elif "batch" in request:
                if not batched:
                    raise _Malformed("a batched request, but the plug-in declared no batch "
                                     "(serve(..., batched=True) does)")
                reply = answer_batch(request)
            elif "encoding" in request:
                raise _Malformed("an encoded line that is not batched; only batched lines are "
                                 "encoded")
            else:
                reply = answer(request)
        except _Malformed as error:
            text = line.strip()
            text = text if len(text) <= 120 else text[:117] + "..."
            _die(2, "handcentric_plugin: malformed request on line %d: %s: %s"
                 % (line_number, error, text))
        except _BadResult as error:
            _die(1, "handcentric_plugin: bad result for request %d: %s" % (rid, error))
        first = False
        out.write(json.dumps(reply, allow_nan=False) + "\n")
        out.flush()  # the audit waits for this line before it sends the next request


# ----------------------------------------------------------------------------- SE(3) helpers
# NumPy only. They keep the dtype of their input, so a float32 plug-in stays float32.

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
