"""Builds the extension module `fictus` with the project's CMake (only the library and the bindings)
and installs it; pyproject.toml holds the package's metadata.

- The interpreter must have numpy and wheel (Debian: python3-numpy, python3-wheel; a virtual
  environment made with `/usr/bin/python3 -m venv --system-site-packages` sees them): checked first,
  with a message that says what is missing.
- The module is built with CMake in the project's own build/ when that was configured for an
  interpreter of the same ABI (`make build` does so for /usr/bin/python3): only what changed is built.
  Otherwise in FICTUS_BUILD_DIR, or ~/.cache/fictus/python-<ABI>, kept for the next install.
- Nothing is written into the source tree (setuptools' own files go to a temporary folder).
- `pip install -v` shows CMake's progress.
"""
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile

ROOT = os.path.dirname(os.path.abspath(__file__))


def say(message):
    print(f"fictus: {message}", file=sys.stderr, flush=True)


missing = [name for name in ("numpy", "wheel", "setuptools") if importlib.util.find_spec(name) is None]
if missing:
    say(f"{sys.executable} lacks the Python package(s) {', '.join(missing)}. fictus builds without a package "
        "index: use Debian's python3 with python3-numpy and python3-wheel (apt-get install python3-numpy "
        "python3-wheel python3-venv), e.g. /usr/bin/python3 -m venv --system-site-packages .venv && "
        ".venv/bin/pip install --no-build-isolation .")
    sys.exit(1)

from setuptools import Extension, setup  # noqa: E402
from setuptools.command.build_ext import build_ext  # noqa: E402

ABI = sysconfig.get_config_var("EXT_SUFFIX") or ".so"


def cached(build, key):
    """A value of build/CMakeCache.txt, or None."""
    try:
        with open(os.path.join(build, "CMakeCache.txt")) as handle:
            for line in handle:
                match = re.match(rf"{key}:[A-Z]+=(.*)", line.strip())
                if match:
                    return match.group(1)
    except OSError:
        return None
    return None


def same_abi(python):
    """Does `python` build modules this interpreter can load (the same EXT_SUFFIX and base prefix)?"""
    if not python or not os.path.exists(python):
        return False
    probe = "import sys, sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'), sys.base_prefix)"
    result = subprocess.run([python, "-c", probe], capture_output=True, text=True)
    return result.returncode == 0 and result.stdout.split() == [ABI, sys.base_prefix]


def build_folder():
    """The project's build/ when it builds the module for this ABI; else one of our own."""
    project = os.path.join(ROOT, "build")
    if cached(project, "FICTUS_BUILD_PYTHON") == "ON" and same_abi(cached(project, "FICTUS_PYTHON")):
        return project, False
    own = os.environ.get("FICTUS_BUILD_DIR") or os.path.join(
        os.path.expanduser("~"), ".cache", "fictus", "python" + ABI.replace(".so", ""))
    return os.path.abspath(own), True


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build, own = build_folder()
        jobs = os.environ.get("FICTUS_JOBS", str(os.cpu_count() or 1))
        if own and cached(build, "FICTUS_PYTHON") != sys.executable:
            say(f"configuring the module for {sys.executable} with CMake in {build}")
            subprocess.run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                            "-DFICTUS_BUILD_TESTS=OFF", "-DFICTUS_BUILD_APPS=OFF", "-DFICTUS_BUILD_BENCH=OFF",
                            "-DFICTUS_BUILD_PYTHON=ON", f"-DFICTUS_PYTHON={sys.executable}"], check=True)
        say(f"building the module in {build} on {jobs} jobs (from scratch about 2 minutes on 2 cores; "
            "`pip install -v` shows the steps)")
        subprocess.run(["cmake", "--build", build, "--target", "fictus_python", "-j", jobs], check=True)
        built = [name for name in os.listdir(os.path.join(build, "python"))
                 if name.startswith("fictus") and name.endswith(ABI)]
        if len(built) != 1:
            raise RuntimeError(f"expected one fictus*{ABI} in {build}/python, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(build, "python", built[0]), target)
        say(f"module built: {os.path.join(build, 'python', built[0])}")


# setuptools' own files (build/, *.egg-info) outside the source tree: its build/ is CMake's.
SCRATCH = tempfile.mkdtemp(prefix="fictus-setuptools-")
setup(ext_modules=[Extension("fictus", sources=[])], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": SCRATCH}, "egg_info": {"egg_base": SCRATCH}})
