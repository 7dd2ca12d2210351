"""Builds the extension module `fictus` with the project's CMake (only the library and the bindings)
and installs it; pyproject.toml holds the package's metadata."""
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
os.makedirs(os.path.join(ROOT, "build-python"), exist_ok=True)  # setuptools' own files, beside build/


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        jobs = os.environ.get("FICTUS_JOBS", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                        "-DFICTUS_BUILD_TESTS=OFF", "-DFICTUS_BUILD_APPS=OFF", "-DFICTUS_BUILD_BENCH=OFF",
                        "-DFICTUS_BUILD_PYTHON=ON", f"-DFICTUS_PYTHON={sys.executable}"], check=True)
        subprocess.run(["cmake", "--build", build, "--target", "fictus_python", "-j", jobs], check=True)
        built = [name for name in os.listdir(os.path.join(build, "python"))
                 if name.startswith("fictus") and name.endswith(".so")]
        if len(built) != 1:
            raise RuntimeError(f"expected one fictus*.so in {build}/python, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(build, "python", built[0]), target)


setup(ext_modules=[Extension("fictus", sources=[])], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build-python"}, "egg_info": {"egg_base": os.path.join(ROOT, "build-python")}})
