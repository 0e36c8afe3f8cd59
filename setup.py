"""`pip install .`: the package handcentric (python/handcentric/), its extension handcentric._core
built by the project's own CMake build (target handcentric_python, python/CMakeLists.txt) for
the Python running pip, with handcentric._figure (the drawings, built with it), and the plug-in
helper, the package handcentric_plugin (python/handcentric_plugin/).

    python3 -m venv --system-site-packages venv           # Debian's NumPy and setuptools
    venv/bin/pip install --no-build-isolation .           # offline
    venv/bin/pip install .                                # online: setuptools, NumPy from PyPI

The C++ dependencies are Debian packages (scripts/install-deps.sh installs them); nothing is
downloaded. The CMake tree is kept in build/python-wheel/, so a second install is incremental;
with ccache on PATH it is the compiler launcher. CMAKE_ARGS adds arguments to the configure step.

HANDCENTRIC_CMAKE_BUILD_DIR=DIR builds and packages the module of an existing, configured build
tree instead (e.g. build/, which scripts/build.sh configures for /usr/bin/python3): no
configure step, only the target handcentric_python. Its module must be built for this Python's
ABI (the file name's suffix, e.g. .cpython-311-x86_64-linux-gnu.so, says so); a venv of the
same interpreter qualifies. tests/python_package/ uses it to test the package without
compiling the library a second time."""
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build import build
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
BUILD_BASE = os.path.join("build", "python-wheel")  # relative to ROOT, pip's working directory
TARGET = "handcentric_python"
FIGURE = "_figure"  # the second extension, built by TARGET's dependency handcentric_figure
INSTALL_DEPS = "bash scripts/install-deps.sh"


def cmake_version():
    """The version of project(handcentric VERSION x.y.z) in CMakeLists.txt, the only one."""
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        match = re.search(r"project\(\s*handcentric\s+VERSION\s+([0-9][0-9.]*)", f.read())
    if not match:
        sys.exit("setup.py: no `project(handcentric VERSION ...)` in CMakeLists.txt")
    return match.group(1)


def run(argv, failure):
    print("setup.py: " + " ".join(shlex.quote(a) for a in argv), flush=True)
    try:
        status = subprocess.run(argv, cwd=ROOT).returncode
        reason = "exit status %d, its output above" % status
    except OSError as e:  # no cmake at all
        status, reason = None, str(e)
    if status != 0:
        sys.exit("setup.py: %s (%s). handcentric's dependencies are Debian packages: run `%s` "
                 "(as root or with sudo) in %s, then install again."
                 % (failure, reason, INSTALL_DEPS, ROOT))


class FreshBuild(build):
    """Starts the wheel's tree afresh: setuptools never prunes it, so a file removed from the
    package (or a module of another tree) would otherwise stay in every later wheel."""

    def run(self):
        shutil.rmtree(self.build_lib, ignore_errors=True)
        super().run()


class CMakeBuild(build_ext):
    """Builds the extension with CMake and copies it, and handcentric._figure, where setuptools
    packs them."""

    def build_extension(self, ext):
        reuse = os.environ.get("HANDCENTRIC_CMAKE_BUILD_DIR")
        if reuse:
            build_dir = os.path.abspath(os.path.join(ROOT, reuse))
            if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
                sys.exit("setup.py: HANDCENTRIC_CMAKE_BUILD_DIR=%s is not a configured CMake "
                         "build tree (no CMakeCache.txt)" % reuse)
        else:
            build_dir = os.path.join(os.path.abspath(self.build_temp), "cmake")
            launcher = []
            if shutil.which("ccache"):
                launcher = ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
            # Only the module: the suites, benchmarks and fuzzers are the CMake build's business.
            run(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                 "-DPython3_EXECUTABLE=" + sys.executable, "-DHANDCENTRIC_BUILD_PYTHON=ON",
                 "-DHANDCENTRIC_PYTHON_REQUIRED=ON", "-DHANDCENTRIC_BUILD_TESTS=OFF",
                 "-DHANDCENTRIC_BUILD_BENCH=OFF", "-DHANDCENTRIC_FUZZ=OFF", *launcher,
                 *shlex.split(os.environ.get("CMAKE_ARGS", ""))],
                "CMake could not configure the project")
        run(["cmake", "--build", build_dir, "--target", TARGET, "-j", str(os.cpu_count() or 1)],
            "CMake could not build the module")
        built = os.path.join(build_dir, "python", "handcentric",
                             "_core" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not os.path.isfile(built):
            folder = os.path.dirname(built)
            found = sorted(os.listdir(folder)) if os.path.isdir(folder) else []
            sys.exit("setup.py: %s has no %s: the tree builds for another Python than %s "
                     "(it has %s)" % (build_dir, os.path.basename(built), sys.executable,
                                      ", ".join(found) or "nothing"))
        destination = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(destination), exist_ok=True)
        shutil.copyfile(built, destination)
        # handcentric._figure, the drawings (python/CMakeLists.txt), built with the module and
        # packed beside it.
        figure = os.path.join(os.path.dirname(built),
                              FIGURE + sysconfig.get_config_var("EXT_SUFFIX"))
        if not os.path.isfile(figure):
            sys.exit("setup.py: %s has no %s beside the module" % (build_dir,
                                                                 os.path.basename(figure)))
        shutil.copyfile(figure, os.path.join(os.path.dirname(destination),
                                             os.path.basename(figure)))


os.makedirs(os.path.join(ROOT, BUILD_BASE), exist_ok=True)
setup(
    version=cmake_version(),
    package_dir={"": "python"},
    packages=["handcentric", "handcentric_plugin"],
    ext_modules=[Extension("handcentric._core", sources=[])],
    cmdclass={"build": FreshBuild, "build_ext": CMakeBuild},
    # setuptools' own files under build/ (the CMake build's folder, ignored by git), not in the
    # repository's root or python/.
    options={"build": {"build_base": BUILD_BASE}, "egg_info": {"egg_base": BUILD_BASE}},
)
