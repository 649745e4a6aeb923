"""pip install . (docs/python.md, "Installing with pip"): the package openable built by the
project's CMake, the same build as cmake -S . -B build, restricted to what the package holds.

The wheel holds, under openable/:
  _openable.cpython-3X-<arch>.so   the extension (OpenABLE/python/*.cc)
  __init__.py, __main__.py         OpenABLE/python/openable/
  bin/                             Test_OpenABLE, openable_evaluate, openable_sweep,
                                   openable_snaps, openable_map (python3 -m openable
                                   run|evaluate|sweep|snaps|map)
  modules/                         the run-time modules (libopenable_*.so), where the
                                   module loader looks beside bin/ and the extension
Environment:
  OPENABLE_JOBS             parallel compile jobs (default: the number of CPUs)
  OPENABLE_CMAKE_BUILD_DIR  an already configured build tree to build in and take the files
                            from (e.g. build/), instead of a fresh one under build/pip/
  OPENABLE_CMAKE_ARGS       more arguments for the configuration (space-separated)
"""
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
PROGRAMS = ["Test_OpenABLE", "openable_evaluate", "openable_snaps", "openable_sweep",
            "openable_map"]


BUILD_COMMANDS = {"build", "build_ext", "bdist_wheel", "install", "develop", "egg_info",
                  "dist_info", "editable_wheel"}
VENV_HINT = ("/usr/bin/python3 -m venv --system-site-packages ~/venvs/openable, then "
             "~/venvs/openable/bin/pip install --no-build-isolation . (docs/python.md)")


def importable(name):
    try:
        __import__(name)
    except ImportError:
        return False
    return True


def check_interpreter():
    """One line and exit 1, before anything is built, when this Python cannot build the package.

    pip install --no-build-isolation . runs setup.py with the interpreter of the pip it was
    given: a Python of pyenv or conda, or a venv made from one, often lacks NumPy (which the
    module imports) and wheel (setuptools before 70.1 makes wheels with it), whereas Debian's
    python3-numpy and python3-wheel belong to /usr/bin/python3.
    """
    lacks = []
    if not importable("numpy"):
        lacks.append("NumPy")
    if not (importable("setuptools.command.bdist_wheel") or importable("wheel.bdist_wheel")):
        lacks.append("wheel (bdist_wheel)")
    if lacks:
        which = sys.executable
        if sys.prefix != sys.base_prefix:
            which += ", a venv of " + sys.base_prefix
        sys.stderr.write("setup.py: this Python (%s; %d.%d) has no %s: make the environment with "
                         "Debian's Python: %s\n"
                         % (which, sys.version_info[0], sys.version_info[1],
                            " and no ".join(lacks), VENV_HINT))
        sys.exit(1)


def project_version():
    """The version of CMakeLists.txt's project(), the one openable.__version__ reports."""
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        match = re.search(r"project\(OpenABLE\s+VERSION\s+([0-9.]+)", f.read())
    if not match:
        sys.exit("setup.py: no 'project(OpenABLE VERSION x.y.z)' in CMakeLists.txt")
    return match.group(1)


def run(command):
    print("setup.py: " + " ".join(command), flush=True)
    subprocess.check_call(command, cwd=ROOT)


class CMakeBuild(build_ext):
    """Configures and builds with CMake, then copies the package's files into build_lib."""

    def build_extension(self, ext):
        build_dir = os.environ.get("OPENABLE_CMAKE_BUILD_DIR")
        if build_dir:
            build_dir = os.path.abspath(build_dir)
            if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
                sys.exit("setup.py: OPENABLE_CMAKE_BUILD_DIR=%s is not a configured CMake build "
                         "tree (no CMakeCache.txt)" % build_dir)
        else:
            build_dir = os.path.join(ROOT, "build", "pip", "cmake")
            run(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                 "-DOPENABLE_BUILD_TESTS=OFF", "-DOPENABLE_BUILD_BENCHMARKS=OFF",
                 "-DOPENABLE_BUILD_PYTHON=ON", "-DPython3_EXECUTABLE=" + sys.executable]
                + os.environ.get("OPENABLE_CMAKE_ARGS", "").split())
        jobs = os.environ.get("OPENABLE_JOBS") or str(os.cpu_count() or 1)
        run(["cmake", "--build", build_dir, "-j", jobs, "--target", "openable_python_package"])

        # "<folder of the package> <file>" per line, written by OpenABLE/python/CMakeLists.txt.
        manifest = os.path.join(build_dir, "python", "package_files.txt")
        if not os.path.isfile(manifest):
            sys.exit("setup.py: %s is missing: the build tree %s was configured without the "
                     "Python module (OPENABLE_BUILD_PYTHON=OFF?)" % (manifest, build_dir))
        entries = []
        with open(manifest) as f:
            for line in f:
                if line.strip():
                    folder, path = line.rstrip("\n").split(" ", 1)
                    entries.append((folder, path))
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        for folder, path in entries:
            if folder == "." and not path.endswith(suffix):
                sys.exit("setup.py: the build tree %s made %s, for another Python than this one "
                         "(%s, whose extensions end in %s): %s"
                         % (build_dir, os.path.basename(path), sys.executable, suffix, VENV_HINT))
        target = self.get_ext_fullpath(ext.name)
        package_out = os.path.dirname(target)
        for folder in ("bin", "modules"):
            shutil.rmtree(os.path.join(package_out, folder), ignore_errors=True)
        for folder, path in entries:
            if folder == ".":
                destination = target  # the extension, under the name setuptools expects
            else:
                destination = os.path.join(package_out, folder, os.path.basename(path))
            os.makedirs(os.path.dirname(destination), exist_ok=True)
            shutil.copy2(path, destination)


if BUILD_COMMANDS & set(sys.argv[1:]):
    check_interpreter()
# setuptools' own folders inside build/ (not build/lib.*, next to CMake's build tree) and no
# openable.egg-info/ at the root of the clone.
os.makedirs(os.path.join(ROOT, "build", "pip"), exist_ok=True)
setup(
    version=project_version(),
    packages=["openable"],
    package_dir={"openable": "OpenABLE/python/openable"},
    ext_modules=[Extension("openable._openable", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build/pip"},
             "egg_info": {"egg_base": "build/pip"}},
    zip_safe=False,
)
