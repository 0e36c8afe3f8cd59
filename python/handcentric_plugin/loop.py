"""serve(): the loop that answers the audit's request lines until end of input.

The loop reads a line, answers it (the hello, a request, a batched line) and writes the answer,
flushed; a malformed line or an unsendable result ends the plug-in with one line on stderr and
the exit status the audit expects. _Server holds what serve() was given and answers each kind of
request; reading and writing the JSON is the protocol module's, the arrays of batched lines the
batch and codec modules'. serve_policy (policy) runs this same loop with a policy in place of
encode. (The module is not called serve: a submodule of that name would be bound to the
package's attribute `serve` whenever it is first imported, where the function belongs.)
"""
import contextlib
import json
import sys
import traceback

from ._numpy import np
from .batch import _chunks, _encoded_rows, _groups, _stack_named, _stacked
from .codec import ENCODINGS, _decode_array, _decoded_items, _finite, _pose
from .protocol import (MAX_BATCH, _BadResult, _Malformed, _chunk, _die, _flatten, _hello,
                       _is_number, _item, _line, _matrices, _matrix, _named, _numbers, _parse,
                       _points, _scalar, _split_encoded)


def serve(encode, *, decode=None, flow=None, extra_poses=(), scalars=(), hello=None,
          batched=False, batch_size=256, encoding="base64", stdin=None, stdout=None,
          _policy=None, _noise=None, _cameras=None, _interface=None, _rng=None,
          _episodes=False):
    """Answer the audit's requests until end of input (see the package docstring).

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
        _check_batched(batch_size, hello)
        hello = True
    if encoding is not None and encoding not in ENCODINGS:
        raise ValueError("encoding must be one of %s, or None (numbers as JSON text), got %r"
                         % (", ".join(map(repr, ENCODINGS)), encoding))
    stdin = sys.stdin if stdin is None else stdin
    out = sys.stdout if stdout is None else stdout  # taken now: print() is redirected below
    server = _Server(encode, decode, flow, tuple(extra_poses), tuple(scalars),
                     batch_size if batched else None, _policy, _cameras, _interface)
    if hello is None:
        hello = server.declared or decode is not None or flow is not None or _noise is not None
    # A policy with an interface (interface.py) is sent JSON numbers: no encoding offered.
    hello_body = _hello(server.extra_poses, server.scalars, decode is not None, flow is not None,
                        _noise, _cameras, server.batch_size,
                        encoding if _interface is None else None)
    if _interface is not None:
        hello_body.update(_interface.hello_fields())
    if _rng is not None:
        hello_body["rng"] = _rng
    if _episodes:
        hello_body["episodes"] = True
    server.episodes = _episodes
    _loop(server, stdin, out, hello_body, hello)


def _check_batched(batch_size, hello):
    """serve(batched=True)'s preconditions: NumPy, a batch size in range, the hello."""
    if np is None:
        _die(1, "handcentric_plugin: serve(..., batched=True) needs NumPy, which does not "
                "import in %s (Debian: python3-numpy); or serve unbatched" % sys.executable)
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) \
            or not 1 <= batch_size <= MAX_BATCH:
        raise ValueError("batch_size must be an integer from 1 to %d, got %r"
                         % (MAX_BATCH, batch_size))
    if hello is False:
        raise ValueError("batched=True needs the hello (it declares the batch size)")


# ----------------------------------------------------------------------------- the loop

def _loop(server, stdin, out, hello_body, hello):
    """Answer each non-blank line in order, the first with the hello when there is one."""
    line_number = 0
    first = True
    while True:
        line = stdin.readline()
        if not line:
            return  # end of input: the audit is done
        line_number += 1
        if not line.strip():
            continue
        reply = _answer_line(server, line, line_number, hello_body, first and hello)
        first = False
        out.write(_line(reply))
        out.flush()  # the audit waits for this line before it sends the next request


def _answer_line(server, line, line_number, hello_body, say_hello):
    """The answer to one line; a line we cannot read exits 2, a result we cannot send 1."""
    rid = None
    try:
        request = _parse(line)
        rid = request["id"]
        return _reply(server, request, hello_body, say_hello)
    except _Malformed as error:
        text = line.strip()
        text = text if len(text) <= 120 else text[:117] + "..."
        _die(2, "handcentric_plugin: malformed request on line %d: %s: %s"
             % (line_number, error, text))
    except _BadResult as error:
        _die(1, "handcentric_plugin: bad result for request %d: %s" % (rid, error))


def _reply(server, request, hello_body, say_hello):
    """The answer to a parsed line: the hello, a batched line's or a single request's."""
    offered = hello_body.get("encodings", ())
    if "encoding" in request and request["encoding"] not in offered:
        raise _Malformed("a line in encoding %s, which the plug-in did not offer (its hello "
                         "offers %s)" % (json.dumps(request["encoding"]),
                                         hello_body.get("encodings", [])))
    if say_hello:
        return {"id": request["id"], "hello": hello_body}
    if "batch" in request:
        if server.batch_size is None:
            raise _Malformed("a batched request, but the plug-in declared no batch "
                             "(serve(..., batched=True) does)")
        return server.answer_batch(request)
    if "encoding" in request:
        raise _Malformed("an encoded line that is not batched; only batched lines are encoded")
    return server.answer(request)


# ----------------------------------------------------------------------------- the answers

class _Server:
    """What serve() was given, and the answer to each kind of request.

    batch_size is None when the plug-in is not batched; policy, with encode None, makes it a
    policy plug-in (serve_policy), and cameras the views its requests carry images of."""

    def __init__(self, encode, decode, flow, extra_poses, scalars, batch_size, policy,
                 cameras, interface=None):
        self.encode, self.decode, self.flow = encode, decode, flow
        self.extra_poses, self.scalars = extra_poses, scalars
        self.declared = bool(extra_poses or scalars)
        self.batch_size, self.policy, self.cameras = batch_size, policy, cameras
        self.interface = interface  # interface.py's _Interface of a policy, or None
        self.episodes = False  # serve_policy's reset=: requests may carry "episode"

    def images_of(self, item, what):
        """The request's images, {view: float32 (C, h, w)}, checked against the hello's views."""
        value = item.get("images")
        if not isinstance(value, dict) or set(value) != set(self.cameras["views"]):
            raise _Malformed("%s: 'images' must hold one encoded image per camera of the hello, "
                             "%s" % (what, list(self.cameras["views"])))
        return {view: _finite(_decode_array(image, "%s: images[%r]" % (what, view),
                                            ("float32",)), "images[%r]" % view)
                for view, image in value.items()}

    @staticmethod
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

    def call(self, function, request_id, args, named, images=None, held=None, episode=None):
        """function(*args, keywords); an exception in it prints its traceback and exits 1.
        episode: the request's "episode", for serve_policy's reset= (not the user's keyword)."""
        kwargs = {"extra_poses": named[0], "scalars": named[1]} if self.declared else {}
        if self.episodes:
            kwargs["_episode"] = episode
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

    def answer(self, request):
        """The answer to one request of a single scene: a policy's, a decode's or encode's."""
        rid = request["id"]
        interface = self.interface
        history = _matrices(request, "history") if interface is None else \
            interface.history(request)
        hand_points = _points(request, "hand_points")
        world_points = _points(request, "world_points")
        named = (_named(request, "extra_poses", self.extra_poses,
                        _matrix if interface is None else interface.pose),
                 _named(request, "scalars", self.scalars, _scalar))
        held = self.held_of(request, "request")
        scene = (history, hand_points, world_points)
        if self.policy is not None:
            return dict({"id": rid}, **self.policy_answer(request, scene, named, held))
        if "decode" in request:
            return {"id": rid, "chunk": self.decoded_chunk(request, scene, named, held)}
        chunk = _matrices(request, "chunk")
        reply = {"id": rid}
        reply.update(self.encoded(rid, (history, chunk, hand_points, world_points), named, held))
        if "eps" in request or "t" in request:
            reply.update(self.flowed(request, (history, chunk, hand_points, world_points),
                                     len(reply["actions"]), named, held))
        return reply

    def policy_answer(self, request, scene, named, held):
        """The policy's answer for one observation: {"chunk": K lists of 16 numbers}, or as its
        interface says (interface.py)."""
        rid = request["id"]
        if "noise" not in request:
            raise _Malformed("a policy plug-in needs 'noise' in every request (run it with "
                             "--policy-exec, not --exec)")
        value = request["noise"]
        if not isinstance(value, list) or not value or not all(map(_is_number, value)):
            raise _Malformed("'noise' must be a non-empty list of numbers")
        noise = np.array(value, dtype=np.float64) if np is not None else [float(x) for x in value]
        images = self.images_of(request, "request") if self.cameras is not None else None
        episode = request.get("episode")
        interface = self.interface
        if self.batch_size is None:
            result = self.call(self.policy, rid, scene + (noise,), named, images, held, episode)
            return {"chunk": _chunk(result)} if interface is None else \
                interface.answer(result, request.get("stages") is True)
        # Batched: a batch of one.
        stacked = tuple({k: v[None] for k, v in a.items()} if isinstance(a, dict) else a[None]
                        for a in scene + (noise,))
        if images is not None:
            images = {view: image[None] for view, image in images.items()}
        if held is not None:
            held = {name: array[None] for name, array in held.items()}
        result = self.call(self.policy, rid, stacked, _stack_named([named]), images, held,
                           episode)
        return {"chunk": _chunks(result, 1)[0]} if interface is None else \
            interface.answers(result, 1, [request.get("stages") is True])[0]

    def decoded_chunk(self, request, scene, named, held):
        """decode's chunk for a decode request, K lists of 16 numbers."""
        if self.decode is None:
            raise _Malformed("a decode request, but the plug-in declared no decode")
        actions = request["decode"]
        if not isinstance(actions, list) or not actions or not all(map(_is_number, actions)):
            raise _Malformed("'decode' must be a non-empty list of numbers")
        actions = [float(x) for x in actions]
        if np is not None:
            actions = np.array(actions)
        return _chunk(self.call(self.decode, request["id"], (actions,) + scene, named, None,
                                held))

    def encoded(self, rid, args, named, held):
        """encode's {"actions": [...], "observation": [...]} for one scene."""
        if self.batch_size is not None:  # a batch of one
            one = None if held is None else {name: a[None] for name, a in held.items()}
            return _encoded_rows(self.call(self.encode, rid, tuple(a[None] for a in args),
                                           _stack_named([named]), None, one), 1)[0]
        actions, observation = _split_encoded(self.call(self.encode, rid, args, named, None,
                                                        held))
        reply = {"actions": _flatten(actions, "actions")}
        if not reply["actions"]:
            raise _BadResult("encode returned no actions")
        if observation is not None:
            reply["observation"] = _flatten(observation, "observation")
        return reply

    def flowed(self, request, args, actions, named, held):
        """flow's {"flow_input", "flow_target"} for a flow request (eps, t) on `actions`
        numbers."""
        if self.flow is None:
            raise _Malformed("a flow request (eps, t), but the plug-in declared no flow")
        eps = _numbers(request.get("eps"), actions, "'eps' (as long as the actions)")
        t = _scalar(request.get("t"), "'t'")
        if np is not None:
            eps = np.array(eps)
        pair = self.call(self.flow, request["id"], args + (eps, t), named, None, held)
        if not isinstance(pair, (tuple, list)) or len(pair) != 2:
            raise _BadResult("flow must return the pair (flow_input, flow_target)")
        return {"flow_input": _flatten(pair[0], "flow_input"),
                "flow_target": _flatten(pair[1], "flow_target")}

    def answer_batch(self, request):
        """The answer to a batched line: its items answered in order, one call per shape."""
        rid, items = request["id"], request["batch"]
        if not isinstance(items, list) or not items or not all(isinstance(i, dict)
                                                               for i in items):
            raise _Malformed("'batch' must be a non-empty list of request objects")
        if len(items) > self.batch_size:
            raise _Malformed("a batch of %d scenes, more than the %d the hello declared"
                             % (len(items), self.batch_size))
        # The items may be of several shapes: the function is called once per shape (its
        # arrays must be stacked), and the answers go back in the request's order.
        encoded = request.get("encoding") is not None
        if encoded:
            items = _decoded_items(items)
        answers = [None] * len(items)
        rows = self.interface.history_rows if self.interface is not None else None
        for indices in _groups(items, rows):
            for i, answer in zip(indices, self.answer_group(rid, [items[i] for i in indices],
                                                            encoded, indices)):
                answers[i] = answer
        return {"id": rid, "batch": answers}

    def answer_group(self, rid, items, encoded, at):
        """The answers to items of one shape, in order (encoded: their arrays encoded); at: the
        items' indices in the line, for messages."""
        B = len(items)
        interface = self.interface
        history = _stacked(items, "history", 16, (4, 4), at) if interface is None else \
            interface.stacked_history(items, at)
        hand_points = _stacked(items, "hand_points", 3, (3,), at)
        world_points = _stacked(items, "world_points", 3, (3,), at)
        named = _stack_named([_item(at[i], lambda item: (
            _named(item, "extra_poses", self.extra_poses,
                   _pose if interface is None else interface.pose),
            _named(item, "scalars", self.scalars, _scalar)), items[i]) for i in range(B)])
        held = None
        if "held" in items[0]:
            each = [self.held_of(item, "batch[%d]" % i) for i, item in zip(at, items)]
            held = {name: np.stack([e[name] for e in each]) for name in each[0]}
        if self.policy is not None:
            noise = _stacked(items, "noise", None, (), at)
            images = None
            if self.cameras is not None:
                each = [self.images_of(item, "batch[%d]" % i) for i, item in zip(at, items)]
                images = {view: np.stack([e[view] for e in each])
                          for view in self.cameras["views"]}
            result = self.call(self.policy, rid, (history, hand_points, world_points, noise),
                               named, images, held, items[0].get("episode"))
            if interface is not None:
                return interface.answers(result, B, [item.get("stages") is True
                                                     for item in items])
            return [{"chunk": c} for c in _chunks(result, B, encoded)]
        if any("decode" in item or "eps" in item or "t" in item for item in items):
            raise _Malformed("decode and flow requests are not batched")
        chunk = _stacked(items, "chunk", 16, (4, 4), at)
        result = self.call(self.encode, rid, (history, chunk, hand_points, world_points), named,
                           None, held)
        return _encoded_rows(result, B, encoded=True) if encoded else _encoded_rows(result, B)
