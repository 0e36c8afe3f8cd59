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

The geometry helpers (rotation_vector, rotation_matrix, inverse, relative_pose, relative_points,
pose_vector, pose_matrix, and for batched plug-ins batch_relative_pose and batch_relative_points)
need NumPy; serve() does not (unless batched).

The package, one job a module (standard library only; NumPy where said):
  protocol  the protocol's version and bounds, reading request lines, writing answer lines
  codec     the base64 form of arrays (encoded batched lines), decoding and encoding
  batch     a batched line's scenes grouped by shape, stacked, and the results split per scene
  loop      serve(): the loop over stdin and the answer to each kind of request
  policy    serve_policy(): a whole policy, its cameras, rng= and reset= (episodes)
  interface a policy's own interface on the wire: state_format=, action_format=, outputs=,
            hands= (requests read in its layouts, per hand; answers written as its outputs),
            and the stages of its pipeline (stages=[("to_hand", "features"), ("decode",
            "poses")]: the policy returns (its answer, {stage: output}); `handcentric audit
            --policy-exec CMD --locate` asks for them and names the first stage that breaks)
  seeding   a policy's own generator seeded before a call (shared with handcentric's _rng)
  geometry  the SE(3) helpers above
  formats   pose layouts: 4x4 poses as the vectors shipped policies speak (quaternions, 6D,
            Euler angles, ...), both ways; the audit's action_format= and state_format=
Names with a leading underscore are the package's own, shared between its modules; the public
names are those imported here.
"""
from . import formats
from .codec import ENCODINGS
from .geometry import (batch_relative_points, batch_relative_pose, inverse, pose_matrix,
                       pose_vector, relative_points, relative_pose, rotation_matrix,
                       rotation_vector)
from .loop import serve
from .policy import serve_policy
from .protocol import MAX_BATCH, PROTOCOL

__all__ = ["ENCODINGS", "MAX_BATCH", "PROTOCOL", "batch_relative_points", "batch_relative_pose",
           "formats", "inverse", "pose_matrix", "pose_vector", "relative_points",
           "relative_pose", "rotation_matrix", "rotation_vector", "serve", "serve_policy"]
