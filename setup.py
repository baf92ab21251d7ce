"""Builds the compiled part of the Python package with CMake (pyproject.toml
holds the metadata; docs/python.md says why setuptools drives CMake here).

`build_ext` configures the project (tests, benchmarks and examples off) in
setuptools' temporary folder and builds the one target `appell_python`, or,
with APPELL_BUILD_DIR set, builds that target in an existing CMake build tree
(up to date: nothing to do), then copies the extension `_appell` into the
package. Everything comes from Debian packages (scripts/install-deps.sh):
nothing is downloaded.
"""

import os
import pathlib
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE = pathlib.Path(__file__).resolve().parent


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = os.environ.get("APPELL_BUILD_DIR")
        if build_dir:
            build_dir = pathlib.Path(build_dir).resolve()
            if not (build_dir / "CMakeCache.txt").is_file():
                raise RuntimeError(f"APPELL_BUILD_DIR={build_dir}: not a configured CMake build tree "
                                   "(no CMakeCache.txt)")
        else:
            build_dir = pathlib.Path(self.build_temp).resolve() / "cmake"
            self.configure(build_dir)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "appell_python", "-j", jobs],
                       check=True)
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = build_dir / "python" / "appell" / ("_appell" + suffix)
        if not built.is_file():
            found = sorted((build_dir / "python" / "appell").glob("_appell*"))
            raise RuntimeError(f"{built} was not built for this interpreter ({sys.executable}); the build "
                               f"tree has {[p.name for p in found]}: configure it with "
                               f"-DPython3_EXECUTABLE={sys.executable}")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)

    def configure(self, build_dir):
        args = ["cmake", "-S", str(SOURCE), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                "-DAPPELL_BUILD_TESTS=OFF", "-DAPPELL_BUILD_BENCHMARKS=OFF", "-DAPPELL_BUILD_EXAMPLES=OFF",
                f"-DPython3_EXECUTABLE={sys.executable}"]
        if shutil.which("ninja"):
            args += ["-G", "Ninja"]
        subprocess.run(args, check=True)


# setuptools' own build files go to .pip-build, not to build/ — the folder
# a CMake build of the checkout usually is.
SCRATCH = ".pip-build"
os.makedirs(SOURCE / SCRATCH, exist_ok=True)
setup(ext_modules=[CMakeExtension("appell._appell")], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": SCRATCH}, "egg_info": {"egg_base": SCRATCH}})
