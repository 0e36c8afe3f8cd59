"""Tests of the helper (the package python/handcentric_plugin/) and of the plug-ins built on it
(protocol v2, Python side).

serve() runs in-process on hand-written request lines (run_serve) or, where pipes, flushing and
exit statuses matter, as a subprocess driven by a tiny fake audit (FakeAudit), which waits for
each answer with a timeout as the C++ audit does with poll().

As in the C++ suites, checks have mutant twins (test_mutant_*): a planted fault that the same
check must flag, so that a check that cannot fail is noticed.
"""
import contextlib
import importlib.util
import io
import json
import math
import os
import select
import shutil
import subprocess
import sys
import textwrap
import time
import types

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
PYTHON_DIR = os.path.join(ROOT, "python")
HELPER_DIR = os.path.join(PYTHON_DIR, "handcentric_plugin")  # the helper, a package
PLUGINS = os.path.join(ROOT, "tests", "props", "plugins")
REPR = os.path.join(ROOT, "examples", "python_representation", "repr.py")
PY = sys.executable  # the interpreter running pytest (/usr/bin/python3 under ctest): has NumPy

sys.path.insert(0, PYTHON_DIR)
import handcentric_plugin as hp  # noqa: E402


def load(path, name):
    """A plug-in file as a module (its serve() call sits behind `if __name__ == "__main__"`)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def plugin(name):
    return os.path.join(PLUGINS, name + ".py")


# ----------------------------------------------------------------------------- scenes

def random_pose(rng, scale=10.0):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    return hp.pose_matrix(np.concatenate([rng.uniform(-scale, scale, 3),
                                          rng.uniform(0, np.pi) * axis]))


def random_scene(rng, H=2, K=3, hand=2, world=0):
    return {"history": np.array([random_pose(rng) for _ in range(H + 1)]),
            "chunk": np.array([random_pose(rng) for _ in range(K)]),
            "hand_points": rng.normal(size=(hand, 3)),
            "world_points": rng.uniform(-10, 10, size=(world, 3))}


def moved(scene, g):
    """g * s: world-frame poses and points move, eye-in-hand points do not."""
    out = dict(scene)
    out["history"] = np.array([g @ T for T in scene["history"]])
    out["chunk"] = np.array([g @ T for T in scene["chunk"]])
    out["world_points"] = scene["world_points"] @ g[:3, :3].T + g[:3, 3]
    return out


def request(scene, rid=0, **fields):
    """The JSON request for a scene (matrices as 16 row-major numbers)."""
    r = {"id": rid, "protocol": 2,
         "history": [T.ravel().tolist() for T in scene["history"]],
         "chunk": [T.ravel().tolist() for T in scene["chunk"]],
         "hand_points": np.asarray(scene["hand_points"]).tolist(),
         "world_points": np.asarray(scene["world_points"]).tolist()}
    r.update(fields)
    return r


def encoded(encode, scene, **kwargs):
    """encode's (actions, observation) on a scene, flattened, as serve() would send them."""
    actions, observation = encode(scene["history"], scene["chunk"], scene["hand_points"],
                                  scene["world_points"], **kwargs)
    flatten = hp.protocol._flatten
    return np.array(flatten(actions, "actions")), np.array(flatten(observation, "o"))


def change(encode, scene, g):
    """The largest change of actions and observation when the scene is moved by g."""
    a, o = encoded(encode, scene)
    ga, go = encoded(encode, moved(scene, g))
    return max(np.abs(a - ga).max(), np.abs(o - go).max())


def length_scale(*scenes):
    return max(max(np.abs(s["history"][:, :3, 3]).max(), np.abs(s["chunk"][:, :3, 3]).max())
               for s in scenes)


# ----------------------------------------------------------------------------- two fake audits

def run_serve(requests, encode, helper=hp, **kwargs):
    """serve() in-process on these requests (dicts or raw lines): (answers, exit status, stderr)."""
    lines = "".join(r if isinstance(r, str) else json.dumps(r) + "\n" for r in requests)
    out, err = io.StringIO(), io.StringIO()
    status = 0
    with contextlib.redirect_stderr(err):
        try:
            helper.serve(encode, stdin=io.StringIO(lines), stdout=out, **kwargs)
        except SystemExit as exit_:
            status = exit_.code
    return [json.loads(line) for line in out.getvalue().splitlines()], status, err.getvalue()


class NoAnswer(Exception):
    pass


class PluginExited(Exception):
    pass


class FakeAudit:
    """Starts a plug-in, writes one request line at a time, waits for one answer line."""

    def __init__(self, argv, env=None):
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, env=env)
        self.pending = b""

    def ask(self, req, timeout=10.0):
        try:
            self.proc.stdin.write((json.dumps(req) + "\n").encode())
            self.proc.stdin.flush()
        except BrokenPipeError:
            raise PluginExited()
        deadline = time.monotonic() + timeout
        while b"\n" not in self.pending:
            left = deadline - time.monotonic()
            if left <= 0:
                raise NoAnswer("no answer within %.1f s" % timeout)
            if select.select([self.proc.stdout], [], [], left)[0]:
                data = os.read(self.proc.stdout.fileno(), 1 << 16)  # no Python buffering here
                if not data:
                    raise PluginExited()
                self.pending += data
        line, self.pending = self.pending.split(b"\n", 1)
        return json.loads(line)

    def finish(self, timeout=10.0):
        """Close its stdin (the audit is done): (exit status, stdout left, stderr)."""
        out, err = self.proc.communicate(timeout=timeout)  # closes stdin, reads to the end
        return self.proc.returncode, (self.pending + out).decode(), err.decode()


def script(tmp_path, name, source):
    """A plug-in written for one test, with the helper on its path."""
    path = tmp_path / name
    path.write_text("import sys\nsys.path.insert(0, %r)\nsys.path.insert(0, %r)\n"
                    % (PYTHON_DIR, PLUGINS) + textwrap.dedent(source))
    return [PY, str(path)]


# ============================================================================= the helper

def test_encode_gets_numpy_arrays_newest_first_row_major():
    seen = {}

    def encode(history, chunk, hand_points, world_points):
        seen.update(history=history, chunk=chunk, hand=hand_points, world=world_points)
        return [1.0]

    T0 = np.eye(4)
    T0[:3, 3] = [1, 2, 3]  # row-major: the translation is entries 3, 7, 11
    T_1 = np.eye(4)
    req = {"id": 7, "history": [T0.ravel().tolist(), T_1.ravel().tolist()],
           "chunk": [np.eye(4).ravel().tolist()] * 3, "hand_points": [],
           "world_points": [[4, 5, 6]]}
    answers, status, _ = run_serve([req], encode)
    assert status == 0 and answers == [{"id": 7, "actions": [1.0]}]
    assert seen["history"].shape == (2, 4, 4) and seen["history"].dtype == np.float64
    assert seen["history"][0][:3, 3].tolist() == [1, 2, 3]  # index 0 is T_0, the hand now
    assert seen["chunk"].shape == (3, 4, 4)
    assert seen["hand"].shape == (0, 3) and seen["world"].shape == (1, 3)


def load_helper(name, monkeypatch):
    """A fresh copy of the helper package under another name: its modules import each other
    relatively, so the copy's modules are its own (they stay in sys.modules under that name,
    where nothing else looks; the package itself is registered until undo)."""
    spec = importlib.util.spec_from_file_location(name, os.path.join(HELPER_DIR, "__init__.py"),
                                                  submodule_search_locations=[HELPER_DIR])
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, name, module)  # the relative imports find it there
    spec.loader.exec_module(module)
    return module


def test_list_path_without_numpy(monkeypatch):
    monkeypatch.setitem(sys.modules, "numpy", None)  # `import numpy` now raises ImportError
    lists = load_helper("handcentric_plugin_lists", monkeypatch)
    assert lists._numpy.np is None  # else this test would prove nothing
    seen = {}

    def encode(history, chunk, hand_points, world_points):
        seen.update(history=history, hand=hand_points, world=world_points)
        return (history[0][0][3], 2), [(0.5,)]  # a tuple of numbers and nested tuples

    req = {"id": 1, "history": [list(range(16))], "chunk": [list(range(16))],
           "hand_points": [[1, 2, 3]], "world_points": []}
    answers, status, _ = run_serve([req], encode, helper=lists)
    assert status == 0 and answers == [{"id": 1, "actions": [3.0, 2.0], "observation": [0.5]}]
    assert seen["history"] == [[[0.0, 1.0, 2.0, 3.0], [4.0, 5.0, 6.0, 7.0], [8.0, 9.0, 10.0, 11.0],
                                [12.0, 13.0, 14.0, 15.0]]]
    assert seen["hand"] == [[1.0, 2.0, 3.0]] and seen["world"] == []
    monkeypatch.undo()
    assert hp._numpy.np is np  # the package the other tests use still has NumPy


@pytest.mark.parametrize("result, actions, observation", [
    (np.array([0.1, 0.2], np.float32), [float(np.float32(0.1)), float(np.float32(0.2))], None),
    (np.array([[1, 2], [3, 4]], dtype=np.int64), [1.0, 2.0, 3.0, 4.0], None),
    (np.array([0.5], dtype=np.float16), [0.5], None),
    ([np.float32(0.25), 1, (2.0, [3.0])], [0.25, 1.0, 2.0, 3.0], None),
    ((np.zeros(2, np.float32), [np.ones(1), 2]), [0.0, 0.0], [1.0, 2.0]),
    ({"actions": [1], "observation": np.array([2.0], np.float32)}, [1.0], [2.0]),
    ((1.0, 2.0), [1.0, 2.0], None),  # a tuple of numbers: the actions, not (actions, observation)
])
def test_results_of_any_real_dtype_and_form_become_python_floats(result, actions, observation):
    answers, status, _ = run_serve([request(random_scene(np.random.default_rng(0)))],
                                   lambda *scene: result)
    assert status == 0
    assert answers[0]["actions"] == actions and answers[0].get("observation") == observation
    assert all(type(x) is float for x in answers[0]["actions"])


def rejects_non_finite(result, field, index):
    """The check: no answer, status 1, and one line on stderr naming the field and the index."""
    try:
        answers, status, err = run_serve([request(random_scene(np.random.default_rng(0)))],
                                         lambda *scene: result)
    except Exception:  # anything else escaping serve() is a failure of the check
        return False
    return (answers == [] and status == 1 and "'%s'" % field in err
            and "index %d" % index in err and err.count("\n") == 1)


@pytest.mark.parametrize("result, field, index", [
    ([0.0, 1.0, 2.0, 3.0, float("nan")], "actions", 4),
    (([1.0], [np.inf]), "observation", 0),
    (np.array([1.0, 2.0, np.inf], dtype=np.float32), "actions", 2),
])
def test_non_finite_results_are_rejected_naming_field_and_index(result, field, index):
    assert rejects_non_finite(result, field, index)


def test_mutant_helper_without_the_finiteness_check_is_caught(monkeypatch):
    # planted: the answers' writer (protocol._flatten) takes every number for finite
    monkeypatch.setattr(hp.protocol, "math", types.SimpleNamespace(isfinite=lambda x: True))
    assert not rejects_non_finite([0.0, 1.0, 2.0, 3.0, float("nan")], "actions", 4)


HELLO = {"protocol": 2, "extra_poses": [], "scalars": [], "decode": False, "flow": False}


@pytest.mark.parametrize("kwargs, hello", [
    ({}, None),
    ({"hello": True}, HELLO),
    ({"decode": lambda *a: None}, dict(HELLO, decode=True)),
    ({"flow": lambda *a: None}, dict(HELLO, flow=True)),
    ({"extra_poses": ["start"]}, dict(HELLO, extra_poses=["start"])),
    ({"scalars": ["gripper", "force"]}, dict(HELLO, scalars=["gripper", "force"])),
    ({"decode": lambda *a: None, "hello": False}, None),
])
def test_hello_answers_the_first_request_only_when_something_is_declared(kwargs, hello):
    scene = random_scene(np.random.default_rng(0))
    fields = {"extra_poses": {"start": np.eye(4).ravel().tolist()},
              "scalars": {"gripper": 0.1, "force": 2.0}}
    answers, status, _ = run_serve([request(scene, 5, **fields), request(scene, 6, **fields)],
                                   lambda *a, **k: [0.0], **kwargs)
    assert status == 0 and len(answers) == 2
    if hello is None:
        assert answers[0] == {"id": 5, "actions": [0.0]}
    else:
        assert answers[0] == {"id": 5, "hello": hello}
    assert answers[1] == {"id": 6, "actions": [0.0]}  # never a second hello


def test_extra_poses_and_scalars_reach_the_functions():
    rng = np.random.default_rng(1)
    start, other = random_pose(rng), random_pose(rng)
    seen = {}

    def encode(history, chunk, hand_points, world_points, extra_poses, scalars):
        seen.update(extra_poses=extra_poses, scalars=scalars)
        return [0.0]

    req = request(random_scene(rng), 1,
                  extra_poses={"start": start.ravel().tolist(), "other": other.ravel().tolist()},
                  scalars={"gripper": 0.04, "unused": 1})
    answers, status, _ = run_serve([req, req], encode, extra_poses=["start"], scalars=["gripper"])
    assert status == 0 and "actions" in answers[1]
    assert list(seen["extra_poses"]) == ["start"]  # only the declared names
    assert seen["extra_poses"]["start"].shape == (4, 4)
    assert np.array_equal(seen["extra_poses"]["start"], start)
    assert seen["scalars"] == {"gripper": 0.04} and type(seen["scalars"]["gripper"]) is float


def test_a_missing_declared_name_is_a_clear_error():
    req = request(random_scene(np.random.default_rng(1)), 1, scalars={"gripper": 0.04})
    answers, status, err = run_serve([req, req], lambda *a, **k: [0.0],
                                     extra_poses=["start"], scalars=["gripper"])
    assert [a.get("hello") is not None for a in answers] == [True]  # the hello, then the error
    assert status == 2 and "'start'" in err and err.count("\n") == 1


def test_decode_request_is_answered_with_the_chunk():
    T = np.arange(16.0).reshape(4, 4)
    T[3] = [0, 0, 0, 1]
    seen = {}

    def decode(actions, history, hand_points, world_points):
        seen.update(actions=actions, history=history)
        return np.array([T, T], dtype=np.float32)

    req = {"id": 3, "protocol": 2, "decode": [1, 2, 3], "history": [np.eye(4).ravel().tolist()],
           "hand_points": [], "world_points": []}
    answers, status, _ = run_serve([req, req], lambda *a: [0.0], decode=decode)
    assert status == 0 and answers[1] == {"id": 3, "chunk": [T.ravel().tolist()] * 2}
    assert seen["actions"].tolist() == [1.0, 2.0, 3.0] and seen["history"].shape == (1, 4, 4)


@pytest.mark.parametrize("result, message", [
    (np.zeros((2, 3, 4)), "shape (2, 3, 4)"),
    ([np.zeros((4, 4))], "last row"),
])
def test_decode_results_that_are_not_poses_are_rejected(result, message):
    req = {"id": 3, "decode": [1.0], "history": [np.eye(4).ravel().tolist()]}
    _, status, err = run_serve([req], lambda *a: [0.0], decode=lambda *a: result, hello=False)
    assert status == 1 and message in err


def test_flow_request_gets_actions_observation_and_flow_fields():
    def flow(history, chunk, hand_points, world_points, eps, t):
        return (list(eps) + [t], eps * 2)

    req = request(random_scene(np.random.default_rng(2), K=1), 4, eps=[1, 2, 3], t=0.25)
    answers, status, _ = run_serve([req, req], lambda *a: ([0.0, 0.0, 0.0], [9.0]), flow=flow)
    assert status == 0
    assert answers[1] == {"id": 4, "actions": [0.0, 0.0, 0.0], "observation": [9.0],
                          "flow_input": [1.0, 2.0, 3.0, 0.25], "flow_target": [2.0, 4.0, 6.0]}


@pytest.mark.parametrize("fields, kwargs, message", [
    ({"eps": [1.0, 2.0], "t": 0.5}, {"flow": lambda *a: ([], [])}, "as long as the actions"),
    ({"eps": [1.0, 2.0, 3.0]}, {"flow": lambda *a: ([], [])}, "'t'"),
    ({"eps": [1.0, 2.0, 3.0], "t": 0.5}, {"hello": False}, "declared no flow"),
    ({"decode": [1.0]}, {"hello": False}, "declared no decode"),
])
def test_requests_the_plugin_cannot_answer_exit_2(fields, kwargs, message):
    req = request(random_scene(np.random.default_rng(2), K=1), 4, **fields)
    answers, status, err = run_serve([req, req], lambda *a: [0.0, 0.0, 0.0], **kwargs)
    assert status == 2 and message in err and err.count("\n") == 1


@pytest.mark.parametrize("line", [
    "actions: 1 2 3\n",
    "[1, 2]\n",
    '{"history": [], "chunk": []}\n',                                  # no id
    '{"id": true, "history": [[1]], "chunk": [[1]]}\n',                # a bool is not an id
    json.dumps({"id": 0, "history": [[0.0] * 15], "chunk": [[0.0] * 16]}) + "\n",
    json.dumps({"id": 0, "history": [[0.0] * 16]}) + "\n",            # no chunk
    json.dumps({"id": 0, "history": [[0.0] * 16], "chunk": [[0.0] * 16],
                "hand_points": [[1, 2]]}) + "\n",
    json.dumps({"id": 0, "history": [[0.0] * 16], "chunk": [[None] * 16]}) + "\n",
])
def test_malformed_request_lines_exit_2_with_one_line(line):
    answers, status, err = run_serve([line], lambda *a: [0.0])
    assert answers == [] and status == 2
    assert err.startswith("handcentric_plugin: malformed request on line 1")
    assert err.count("\n") == 1


def test_user_exception_prints_the_traceback_and_exits_1():
    def encode(history, chunk, hand_points, world_points):
        return [1 / 0]

    answers, status, err = run_serve([request(random_scene(np.random.default_rng(3)), 9)], encode)
    assert answers == [] and status == 1
    assert "raised on request 9" in err and "Traceback" in err
    assert err.rstrip().splitlines()[-1] == "ZeroDivisionError: division by zero"


def test_print_in_user_code_goes_to_stderr_not_into_the_protocol():
    def encode(history, chunk, hand_points, world_points):
        print("debugging output")
        return [1.0]

    answers, status, err = run_serve([request(random_scene(np.random.default_rng(3)))], encode)
    assert status == 0 and answers == [{"id": 0, "actions": [1.0]}]
    assert "debugging output" in err


def test_subprocess_exit_statuses_traceback_tail_malformed_and_eof():
    scene = random_scene(np.random.default_rng(4))
    # stderr_long: 40 lines, then an exception; the audit keeps the last 20 lines of stderr.
    audit = FakeAudit([PY, plugin("stderr_long")])
    with pytest.raises(PluginExited):
        audit.ask(request(scene))
    status, _, err = audit.finish()
    tail = err.rstrip().splitlines()[-20:]
    assert status == 1
    assert tail[-1] == "RuntimeError: stderr_long: planted failure after 40 lines"
    assert "stderr_long: line 1 of 40" not in tail
    # A malformed line: status 2, one line on stderr.
    audit = FakeAudit([PY, REPR])
    audit.proc.stdin.write(b"not json\n")
    status, out, err = audit.finish()
    assert (status, out) == (2, "") and err.count("\n") == 1 and "not JSON" in err
    # End of input after two answers: status 0, nothing on stderr.
    audit = FakeAudit([PY, REPR])
    assert [audit.ask(request(scene, i))["id"] for i in (0, 1)] == [0, 1]
    assert audit.finish() == (0, "", "")


# ----------------------------------------------------------------------------- flushing

ANSWER_ZEROS = "lambda history, chunk, hand_points, world_points: [0.0] * 6"
BIG_BUFFER = 'io.BufferedWriter(io.FileIO(1, "w", closefd=False), buffer_size=1 << 20)'


def answers_while_running(argv, env=None, timeout=5.0):
    """The check: does the plug-in's answer reach the audit while it waits for more requests?"""
    audit = FakeAudit(argv, env)
    try:
        audit.ask(request(random_scene(np.random.default_rng(5))), timeout)
        return True, audit
    except NoAnswer:
        return False, audit


def test_serve_flushes_each_answer_even_on_a_block_buffered_stdout(tmp_path):
    # The control for the mutants below: the same 1 MiB buffer, and serve()'s own flush.
    argv = script(tmp_path, "buffered.py", """
        import io, handcentric_plugin as hp
        hp.serve(%s, stdout=io.TextIOWrapper(%s))
        """ % (ANSWER_ZEROS, BIG_BUFFER))
    answered, audit = answers_while_running(argv)
    assert answered
    assert audit.finish()[0] == 0


def test_mutant_helper_whose_flush_does_nothing_is_caught(tmp_path):
    argv = script(tmp_path, "no_flush_helper.py", """
        import io, handcentric_plugin as hp
        class NoFlush(io.TextIOWrapper):
            def flush(self):  # the planted fault: serve()'s flush does nothing
                pass
        hp.serve(%s, stdout=NoFlush(%s))
        """ % (ANSWER_ZEROS, BIG_BUFFER))
    answered, audit = answers_while_running(argv, timeout=2.0)
    assert not answered
    audit.proc.kill()
    audit.proc.communicate()


def test_mutant_no_flush_plugin_is_caught_even_with_pythonunbuffered():
    env = dict(os.environ, PYTHONUNBUFFERED="1")  # no_flush.py must hold its answer anyway
    answered, audit = answers_while_running([PY, "-u", plugin("no_flush")], env, timeout=2.0)
    assert not answered
    status, out, _ = audit.finish()  # the answer was computed: it comes out at exit
    assert status == 0 and json.loads(out)["actions"] == [0.0] * 6


# ============================================================================= the plug-ins

repr_py = load(REPR, "repr_example")
delta_world = load(plugin("delta_world"), "delta_world")
float32_hc = load(plugin("float32_hand_centric"), "float32_hand_centric")
world_raw = load(plugin("world_points_raw"), "world_points_raw")
constant = load(plugin("constant_zeros"), "constant_zeros")
v2 = load(plugin("v2_everything"), "v2_everything")
actionflow = load(plugin("actionflow_v2"), "actionflow_v2")


def world_block_is_in_hand_frame(encode, scene):
    """The check: the observation ends with T_0^-1 q for every world point q."""
    m = len(scene["world_points"])
    observation = encoded(encode, scene)[1]
    T0_inverse = np.linalg.inv(scene["history"][0])
    expected = [(T0_inverse @ np.append(q, 1.0))[:3] for q in scene["world_points"]]
    return np.allclose(observation[-3 * m:], np.ravel(expected), rtol=0, atol=1e-12)


def test_repr_world_points_are_transformed_by_T0_inverse():
    scene = random_scene(np.random.default_rng(6), world=3)
    assert world_block_is_in_hand_frame(repr_py.encode, scene)


def test_mutant_raw_world_points_fail_the_hand_frame_check():
    scene = random_scene(np.random.default_rng(6), world=3)
    assert not world_block_is_in_hand_frame(world_raw.encode, scene)


def test_repr_matches_an_independent_hand_centric_computation():
    rng = np.random.default_rng(7)
    for _ in range(20):
        scene = random_scene(rng, H=int(rng.integers(0, 4)), K=int(rng.integers(1, 6)), world=2)
        actions, observation = encoded(repr_py.encode, scene)
        T0_inverse = np.linalg.inv(scene["history"][0])
        assert len(observation) == 6 * len(scene["history"]) + 3 * 2 + 3 * 2
        for k, T in enumerate(scene["chunk"]):
            relative = T0_inverse @ T
            assert np.allclose(actions[6 * k:6 * k + 3], relative[:3, 3], rtol=0, atol=1e-12)
            assert np.allclose(hp.rotation_matrix(actions[6 * k + 3:6 * k + 6]), relative[:3, :3],
                               rtol=0, atol=1e-12)
        assert np.array_equal(observation[6 * len(scene["history"]):][:6],
                              scene["hand_points"].ravel())


def test_repr_is_invariant_and_raw_world_points_are_not_in_a_third_person_view():
    rng = np.random.default_rng(8)
    for _ in range(10):
        scene, g = random_scene(rng, world=2), random_pose(rng)
        tolerance = 1e-9 * (1 + length_scale(scene, moved(scene, g)))
        assert change(repr_py.encode, scene, g) <= tolerance
        assert change(world_raw.encode, scene, g) > 1e-3  # the mutant: flagged
        eye_in_hand_only = dict(scene, world_points=np.zeros((0, 3)))
        assert change(world_raw.encode, eye_in_hand_only, g) <= tolerance


def naive_rotation_vector(R):
    """acos-based, as often written: inaccurate near 0 and near pi."""
    angle = math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2)))
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return w / 2 if angle == 0 else angle / (2 * math.sin(angle)) * w


ANGLES = [1e-12, 1e-8, 1e-5, 0.5, 3.0, np.pi - 1e-5, np.pi - 1e-9, np.pi - 1e-12]


def rotation_vector_error(log):
    """The check: the worst relative error of log(exp(r)) = r, at angles near 0 and near pi."""
    rng = np.random.default_rng(9)
    worst = 0.0
    for angle in ANGLES:
        for _ in range(20):
            axis = rng.normal(size=3)
            r = angle * axis / np.linalg.norm(axis)
            worst = max(worst, np.abs(log(hp.rotation_matrix(r)) - r).max() / angle)
    return worst


def test_rotation_vector_is_accurate_near_zero_and_pi():
    assert rotation_vector_error(hp.rotation_vector) < 1e-14
    assert np.allclose(hp.rotation_vector(np.diag([1.0, -1, -1])), [np.pi, 0, 0])  # exactly pi
    assert hp.rotation_vector(np.eye(3)).tolist() == [0, 0, 0]


def test_mutant_acos_rotation_vector_fails_the_accuracy_check():
    assert rotation_vector_error(naive_rotation_vector) > 1e-6


def rotation_z(degrees, translation=(0, 0, 0)):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    T = np.eye(4)
    T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    T[:3, 3] = translation
    return T


def test_delta_world_is_translation_invariant_but_not_rotation_invariant():
    # By hand: the hand moves 1 m along x, then turns 90 degrees about z.
    scene = {"history": np.array([rotation_z(0, (2, 0, 0))]),
             "chunk": np.array([rotation_z(0, (3, 0, 0)), rotation_z(90, (3, 0, 0))]),
             "hand_points": np.zeros((0, 3)), "world_points": np.zeros((0, 3))}
    actions = encoded(delta_world.encode, scene)[0]
    assert np.allclose(actions, [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, np.pi / 2], atol=1e-15)
    shift = rotation_z(0, (5, -3, 2))
    assert np.array_equal(encoded(delta_world.encode, moved(scene, shift))[0], actions)
    # A global 90-degree turn about z: the 1 m step along x becomes one along y.
    turned = encoded(delta_world.encode, moved(scene, rotation_z(90)))[0]
    assert np.allclose(turned[:3], [0, 1, 0], atol=1e-15)
    assert change(delta_world.encode, scene, rotation_z(90)) > 0.5
    # The hand-centric control on the same scene and transforms does not move.
    assert change(repr_py.encode, scene, rotation_z(90)) < 1e-15


def test_delta_world_is_not_rotation_invariant_on_random_scenes_but_translation_invariant():
    rng = np.random.default_rng(10)
    scene, g = random_scene(rng), random_pose(rng)
    shift = np.eye(4)
    shift[:3, 3] = g[:3, 3]
    tolerance = 1e-9 * (1 + length_scale(scene, moved(scene, shift)))
    assert change(delta_world.encode, scene, shift) <= tolerance
    assert change(delta_world.encode, scene, g) > 1e-3


def test_float32_plugin_is_float32_rounding_of_repr():
    rng = np.random.default_rng(11)
    scene = random_scene(rng, world=2)
    a32, o32 = encoded(float32_hc.encode, scene)
    a64, o64 = encoded(repr_py.encode, scene)
    scale = 1 + length_scale(scene)
    assert np.abs(a32 - a64).max() < 1e-5 * scale and np.abs(o32 - o64).max() < 1e-5 * scale
    assert np.abs(a32 - a64).max() > 1e-12  # it really ran in float32
    assert np.array_equal(a32.astype(np.float32).astype(np.float64), a32)  # sent exactly
    g = random_pose(rng)
    assert change(float32_hc.encode, scene, g) > 1e-9 * (1 + length_scale(scene, moved(scene, g)))


def test_constant_zeros_gives_6k_zeros_whatever_the_scene():
    rng = np.random.default_rng(12)
    for K in (1, 4):
        scene = random_scene(rng, K=K)
        answers, status, _ = run_serve([request(scene), request(moved(scene, random_pose(rng)))],
                                       constant.encode)
        assert status == 0 and [a["actions"] for a in answers] == [[0.0] * 6 * K] * 2


# ----------------------------------------------------------------------------- v2_everything

def v2_fields(rng):
    return {"extra_poses": {"start": random_pose(rng).ravel().tolist()},
            "scalars": {"gripper": 0.04}}


def roundtrip_error(argv):
    """The check, through the pipe: decode(encode(s)) against the chunk, relative to 1 + L."""
    rng = np.random.default_rng(13)
    audit = FakeAudit(argv)
    worst, rid = 0.0, 0
    for _ in range(5):
        scene = random_scene(rng, K=int(rng.integers(1, 5)))
        fields = v2_fields(rng)
        answer = audit.ask(request(scene, rid, **fields))
        if "hello" in answer:  # the first request: answered with the hello, so ask again
            answer = audit.ask(request(scene, rid, **fields))
        rid += 1
        back = audit.ask({"id": rid, "protocol": 2, "decode": answer["actions"],
                          "history": request(scene)["history"], "hand_points": [],
                          "world_points": [], **fields})
        rid += 1
        chunk = np.array(back["chunk"]).reshape(-1, 4, 4)
        worst = max(worst, np.abs(chunk - scene["chunk"]).max() / (1 + length_scale(scene)))
    assert audit.finish()[0] == 0
    return worst


def test_v2_everything_decode_round_trips_encode():
    assert roundtrip_error([PY, plugin("v2_everything")]) < 1e-12


def test_mutant_decode_that_forgets_T0_fails_the_round_trip(tmp_path):
    argv = script(tmp_path, "decode_without_T0.py", """
        import handcentric_plugin as hp, v2_everything as v2
        def decode(actions, history, hand_points, world_points, extra_poses, scalars):
            return [hp.pose_matrix(a) for a in actions.reshape(-1, 6)]  # planted: no T_0
        hp.serve(v2.encode, decode=decode, flow=v2.flow, extra_poses=["start"], scalars=["gripper"])
        """)
    assert roundtrip_error(argv) > 1e-3


def test_v2_everything_hello_and_invariance_with_a_moving_start_pose():
    rng = np.random.default_rng(14)
    scene, g = random_scene(rng), random_pose(rng)
    start = random_pose(rng)
    gripper = {"gripper": 0.04}  # a scalar: g leaves it alone
    answers, status, _ = run_serve(
        [request(scene, 0),
         request(scene, 0, extra_poses={"start": start.ravel().tolist()}, scalars=gripper),
         request(moved(scene, g), 1, extra_poses={"start": (g @ start).ravel().tolist()},
                 scalars=gripper)],
        v2.encode, decode=v2.decode, flow=v2.flow, extra_poses=["start"], scalars=["gripper"])
    assert status == 0
    assert answers[0]["hello"] == {"protocol": 2, "extra_poses": ["start"], "scalars": ["gripper"],
                                   "decode": True, "flow": True}
    tolerance = 1e-9 * (1 + length_scale(scene, moved(scene, g)))
    for key in ("actions", "observation"):
        assert np.abs(np.subtract(answers[1][key], answers[2][key])).max() <= tolerance
    observation = answers[1]["observation"]
    assert observation[-1] == 0.04  # the gripper width, last
    expected_start = hp.pose_vector(np.linalg.inv(scene["history"][0]) @ start)
    assert np.allclose(observation[-7:-1], expected_start, rtol=0, atol=1e-12)


def rectified_flow_error(flow):
    """The check: flow_input = [t a + (1 - t) eps, t, observation] and flow_target = a - eps."""
    rng = np.random.default_rng(15)
    scene = random_scene(rng, K=2)
    kwargs = {"extra_poses": {"start": random_pose(rng)}, "scalars": {"gripper": 0.5}}
    a, observation = encoded(v2.encode, scene, **kwargs)
    eps, t = rng.normal(size=a.size), 0.3
    flow_input, flow_target = flow(scene["history"], scene["chunk"], scene["hand_points"],
                                   scene["world_points"], eps, t, **kwargs)
    expected_input = np.concatenate([t * a + (1 - t) * eps, [t], observation])
    return max(np.abs(np.ravel(flow_input) - expected_input).max(),
               np.abs(np.ravel(flow_target) - (a - eps)).max())


def test_v2_everything_flow_is_the_rectified_flow():
    assert rectified_flow_error(v2.flow) < 1e-15


def test_mutant_flow_with_the_target_reversed_is_caught():
    def reversed_target(*args, **kwargs):
        flow_input, target = v2.flow(*args, **kwargs)
        return flow_input, -target  # planted: eps - a

    assert rectified_flow_error(reversed_target) > 1e-3


def test_actionflow_target_is_rotation_invariant_in_distribution_only():
    rng = np.random.default_rng(16)
    scene = random_scene(rng, K=3)
    eps = rng.normal(size=9)

    def target(s, e):
        return np.ravel(actionflow.flow(s["history"], s["chunk"], s["hand_points"],
                                        s["world_points"], e, 0.5)[1])

    R = random_pose(rng)
    R[:3, 3] = 0  # a rotation about the origin
    # Pointwise it changes; but f(R s, eps) = f(s, R^T eps), and R^T eps ~ N(0, I) again.
    assert np.abs(target(moved(scene, R), eps) - target(scene, eps)).max() > 1e-3
    rotated_eps = (eps.reshape(3, 3) @ R[:3, :3]).ravel()  # each eps_k -> R^T eps_k
    assert np.allclose(target(moved(scene, R), eps), target(scene, rotated_eps), rtol=0, atol=1e-12)
    # A translation shifts the target by R_k^T p~, whatever eps: a shifted mean, not invariant.
    shift = np.eye(4)
    shift[:3, 3] = [1.0, -2.0, 0.5]
    difference = target(moved(scene, shift), eps) - target(scene, eps)
    expected = np.ravel([T[:3, :3].T @ shift[:3, 3] for T in scene["chunk"]])
    assert np.allclose(difference, expected, rtol=0, atol=1e-12) and np.abs(expected).max() > 0.5
    answers, status, _ = run_serve([request(scene), request(scene, 1, eps=eps.tolist(), t=0.5)],
                                   actionflow.encode, flow=actionflow.flow)
    assert status == 0 and answers[0]["hello"]["flow"] is True
    assert len(answers[1]["actions"]) == 9
    assert len(answers[1]["flow_input"]) == 9 + 1 + 6 * len(scene["history"])


# ----------------------------------------------------------------------------- finding the helper

def test_repr_finds_the_helper_in_an_install_and_says_so_when_it_cannot(tmp_path):
    prefix = tmp_path / "prefix"
    shutil.copytree(HELPER_DIR, prefix / "share" / "handcentric" / "python" / "handcentric_plugin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    (prefix / "bin").mkdir()
    program = prefix / "bin" / "handcentric"
    program.write_text("#!/bin/sh\n")
    program.chmod(0o755)
    elsewhere = tmp_path / "my_project"
    elsewhere.mkdir()
    shutil.copy(REPR, elsewhere / "repr.py")  # a researcher's copy, far from the source tree
    scene = random_scene(np.random.default_rng(17))
    line = json.dumps(request(scene)) + "\n"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "HANDCENTRIC_PYTHON")}

    def run(extra_env):
        return subprocess.run([PY, str(elsewhere / "repr.py")], input=line, text=True,
                              capture_output=True, env=dict(env, **extra_env), timeout=30)

    found = run({"PATH": str(prefix / "bin") + os.pathsep + env.get("PATH", "")})
    assert found.returncode == 0 and json.loads(found.stdout)["id"] == 0
    installed = prefix / "share" / "handcentric" / "python"
    assert run({"HANDCENTRIC_PYTHON": str(installed)}).returncode == 0
    system = [os.path.join(p, "share", "handcentric", "python", "handcentric_plugin", "__init__.py")
              for p in ("/usr/local", "/usr")]
    if not any(map(os.path.exists, system)):  # else repr.py would (rightly) find that one
        lost = run({})
        assert lost.returncode == 1 and lost.stdout == ""
        assert "handcentric_plugin" in lost.stderr and lost.stderr.count("\n") == 1


@pytest.mark.skipif(shutil.which("cmake") is None, reason="no cmake")
def test_cmake_installs_the_helper_into_share_handcentric_python(tmp_path):
    # A throwaway project around python/CMakeLists.txt only: no compiler, nothing built.
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.16)\nproject(p LANGUAGES NONE)\ninclude(GNUInstallDirs)\n"
        "add_subdirectory(%s python)\n" % PYTHON_DIR)
    build, prefix = tmp_path / "build", tmp_path / "prefix"
    for argv in (["cmake", "-S", str(tmp_path / "src"), "-B", str(build)],
                 ["cmake", "--install", str(build), "--prefix", str(prefix)]):
        subprocess.run(argv, check=True, capture_output=True, timeout=120)
    installed = prefix / "share" / "handcentric" / "python" / "handcentric_plugin"
    sources = sorted(name for name in os.listdir(HELPER_DIR) if name.endswith(".py"))
    assert sorted(os.listdir(installed)) == sources  # every module, and nothing else
    for name in sources:
        assert (installed / name).read_text() == open(os.path.join(HELPER_DIR, name)).read()
