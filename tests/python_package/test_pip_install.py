"""`pip install --no-build-isolation <repo>` into a fresh venv (with --system-site-packages, for
Debian's NumPy and setuptools), then the package used from that venv as a user would: imported
from the venv's site-packages, `python -m handcentric`, the plug-in helper, the pytest helpers.

HANDCENTRIC_SOURCE_DIR is the repository; HANDCENTRIC_CMAKE_BUILD_DIR, when set, is a configured
build tree whose module setup.py packages (ctest passes its own tree, built for this
interpreter: a venv of it has the same ABI); unset, setup.py configures and builds from scratch
(minutes). Nothing is downloaded (--no-index)."""
import json
import os
import subprocess
import sys
import tempfile

import pytest

SOURCE = os.environ.get("HANDCENTRIC_SOURCE_DIR",
                        os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", ".."))
POLICIES = os.path.join(os.path.realpath(SOURCE), "tests", "python_module", "policies.py")


class Venv:
    def __init__(self, root):
        self.root = root
        self.python = os.path.join(root, "bin", "python")
        # Nothing from the caller's environment decides what the venv imports.
        self.env = {key: value for key, value in os.environ.items()
                    if key not in ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP")}
        self.env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
        # Asked of the venv itself (Debian's default scheme is not the venv's).
        self.site = self.run(self.python, "-c", "import sysconfig; "
                             "print(sysconfig.get_path('purelib'))").stdout.strip()

    def run(self, *argv, check=True, timeout=240):
        # cwd: a folder with nothing importable, so that only the venv's sys.path counts.
        out = subprocess.run(argv, cwd=self.root, env=self.env, capture_output=True, text=True,
                             timeout=timeout)
        if check:
            assert out.returncode == 0, "%s\n%s\n%s" % (argv, out.stdout, out.stderr)
        return out

    def python_json(self, script):
        return json.loads(self.run(self.python, "-c", script).stdout)


@pytest.fixture(scope="module")
def venv():
    with tempfile.TemporaryDirectory(prefix="handcentric-venv-") as root:
        subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", root], check=True,
                       timeout=120)
        env = Venv(root)
        # --no-cache-dir: the wheel is not kept in ~/.cache/pip, where a later run could reuse it.
        env.run(env.python, "-m", "pip", "install", "--no-index", "--no-build-isolation",
                "--no-cache-dir", os.path.realpath(SOURCE))
        yield env


def test_the_package_is_imported_from_the_venvs_site_packages(venv):
    found = venv.python_json(
        "import json, importlib.metadata, handcentric, handcentric._core, handcentric_plugin\n"
        "import handcentric._figure\n"
        "print(json.dumps({'package': handcentric.__file__, 'core': handcentric._core.__file__,\n"
        "    'figure': handcentric._figure.__file__,\n"
        "    'helper': handcentric_plugin.__file__, 'version': handcentric.__version__,\n"
        "    'metadata': importlib.metadata.version('handcentric'),\n"
        "    'all': handcentric.__all__}))")
    assert found["package"] == os.path.join(venv.site, "handcentric", "__init__.py")
    assert os.path.dirname(found["core"]) == os.path.join(venv.site, "handcentric")
    assert os.path.dirname(found["figure"]) == os.path.join(venv.site, "handcentric")
    assert found["helper"] == os.path.join(venv.site, "handcentric_plugin", "__init__.py")
    assert found["version"] == found["metadata"]  # the wheel's version is the module's (CMake's)
    for name in ("audit", "audit_policy", "assert_invariant", "assert_equivariant", "decode",
                 "encode_actions", "encode_observation", "so3_exp", "so3_log", "se3_exp",
                 "se3_log", "load_demos", "training_scenes", "Error", "ShapeError", "GROUPS",
                 "VIEWS", "REPRESENTATIONS", "MAX_CASES", "MAX_NOISE"):
        assert name in found["all"]


def test_the_plugin_helper_and_the_pytest_helpers_work_from_the_venv(venv):
    result = venv.python_json(
        "import json, sys\n"
        "sys.path.insert(0, %r)\n"
        "import handcentric, handcentric_plugin, policies\n"
        "from handcentric import plugin\n"
        "handcentric.assert_invariant(policies.hand_centric_actions, 'se3', cases=50)\n"
        "try:\n"
        "    handcentric.assert_invariant(policies.absolute_actions, 'translation', cases=50)\n"
        "    caught = None\n"
        "except AssertionError as e:\n"
        "    caught = str(e)\n"
        "print(json.dumps({'same_serve': plugin.serve is handcentric_plugin.serve,\n"
        "                  'caught': caught}))" % os.path.dirname(POLICIES))
    assert result["same_serve"]
    assert result["caught"] and "translation" in result["caught"]


def test_python_m_handcentric_audits_a_representation_file(venv):
    command = [venv.python, "-m", "handcentric", "audit", POLICIES + ":absolute_actions",
               "--group", "translation", "rotation", "--view", "eye_in_hand", "--cases", "50"]
    out = venv.run(*command)
    lines = out.stdout.splitlines()
    assert "absolute_actions" in lines[0]
    # Absolute actions: invariant under nothing; one line per verdict, each a NO.
    verdicts = [line.split() for line in lines if line.split()[:1] == ["eye_in_hand"]]
    checks = json.loads(venv.run(*command, "--json").stdout)["checks"]
    assert len(verdicts) == len(checks) > 0
    assert {(v[1], v[2], v[3], v[4]) for v in verdicts} == {
        (c["component"], c["mode"], c["group"], "yes" if c["invariant"] else "NO")
        for c in checks}
    assert ["actions", "pointwise", "translation", "NO"] in [v[1:5] for v in verdicts]


def test_python_m_handcentric_refuses_bad_arguments_in_one_line(venv):
    out = venv.run(venv.python, "-m", "handcentric", "audit", POLICIES + ":no_such_function",
                   check=False)
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.count("\n") == 1 and "no_such_function" in out.stderr
