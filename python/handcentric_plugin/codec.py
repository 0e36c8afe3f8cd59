"""Encoded arrays: the "base64" form of a batched line's arrays, both ways.

An array is {"dtype": "float64" | "float32" | "uint8", "shape": [...], "data": base64 of its
elements, row-major, little-endian} (docs/AUDIT.md, "Encoded numbers"). The audit uses it when
our hello offers it ("encodings"), and marks each such line "encoding": "base64"; we answer a
line in the encoding it came in, so that an audit that does not know the encoding gets JSON
numbers, as before. The rest of the package sees NumPy arrays only: this module is where bytes
become numbers (and back), with the checks that name a bad field. Needs NumPy.
"""
import base64
import binascii
import json
import math

from ._numpy import np
from .protocol import _Malformed, _item, _matrix

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
