"""The line protocol: its version and bounds, reading request lines, writing answer lines.

One JSON object per line each way (docs/AUDIT.md, section "--exec"). This module knows the
field names and the checks a request's JSON numbers must pass, and turns a user function's
result into the numbers of an answer; it does no I/O but for the one-line messages of _die.
The base64 form of arrays (codec), the stacking of batches (batch) and the loops that read
stdin (serve) are kept apart so that each can be read and tested on its own.

Names with a leading underscore are the package's own, shared between its modules; the public
ones are re-exported by the package (handcentric_plugin/__init__.py).
"""
import json
import math
import numbers
import sys

from ._numpy import np

PROTOCOL = 2
MAX_BATCH = 65536  # the audit's bound on a hello's "batch"


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


def _item(i, read, item):
    """read(item), a malformed item of a batched line named by its index."""
    try:
        return read(item)
    except _Malformed as error:
        raise _Malformed("batch[%d]: %s" % (i, error))


# ----------------------------------------------------------------------------- writing answers

def _hello(extra_poses, scalars, decode, flow, noise, cameras, batch_size, encoding):
    """The body of the hello answer: what the plug-in declares (batch_size None: unbatched)."""
    body = {"protocol": PROTOCOL, "extra_poses": list(extra_poses), "scalars": list(scalars),
            "decode": decode, "flow": flow}
    if noise is not None:
        body["noise"] = int(noise)
    if cameras is not None:
        body["cameras"] = cameras
    if batch_size is not None:
        body["batch"] = batch_size
        if encoding is not None:
            body["encodings"] = [encoding]
    return body


def _line(reply):
    """An answer as the line the audit reads: JSON without NaN or infinity, then a newline."""
    return json.dumps(reply, allow_nan=False) + "\n"


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
        hint = ("; poses of %d numbers are a layout: a policy declares it, serve_policy(..., "
                "action_format=\"pos_quat_xyzw\") or the one it uses" % result.shape[-1]
                if result.ndim == 2 and result.shape[-1] in (6, 7, 9) else "")
        raise _BadResult("decode returned an array of shape %s; it must be (K, 4, 4)%s"
                         % (result.shape, hint))
    flat = _flatten(result, "chunk")
    if not flat or len(flat) % 16:
        raise _BadResult("decode returned %d numbers; it must return K 4x4 matrices" % len(flat))
    chunk = [flat[i:i + 16] for i in range(0, len(flat), 16)]
    for k, m in enumerate(chunk):
        if max(abs(a - b) for a, b in zip(m[12:], (0.0, 0.0, 0.0, 1.0))) > 1e-9:
            raise _BadResult("decode's pose %d has last row %s, not [0, 0, 0, 1]" % (k, m[12:]))
    return chunk
