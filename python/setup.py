"""Builds the package polydyn with the repository's CMake build (the extension links its C libraries).

    pip install --no-build-isolation ./python          # or: python3 -m pip install ...

configures BUILD (default: a Release build in setuptools' temporary directory; PD_BUILD_DIR=DIR uses an existing
build of this tree as it is configured, building only the extension there) and copies the extension into the
package. Nothing is downloaded: CMake, a C compiler, python3-dev and python3-numpy come from Debian."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent.parent
VERSION = re.search(r"project\(polydyn VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text()).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("PD_BUILD_DIR")
        if build is None:
            build = str(Path(self.build_temp).resolve() / "cmake")
            subprocess.run(["cmake", "-S", str(ROOT), "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DPD_TESTS=OFF",
                            "-DPD_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}"], check=True)
        jobs = os.environ.get("PD_BUILD_JOBS", "2")
        subprocess.run(["cmake", "--build", build, "--target", "polydyn_python", "-j", jobs], check=True)
        built = sorted((Path(build) / "python" / "polydyn").glob("_polydyn*.so"))
        if not built:
            raise RuntimeError(f"{build}: the CMake build made no polydyn/_polydyn*.so")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[-1], target)


setup(
    name="polydyn",
    version=VERSION,
    description="Rigid convex polyhedra in frictional contact (Goyal, Pinson & Sinden soft contact) and its "
                "validation bench, from Python",
    packages=["polydyn"],
    ext_modules=[Extension("polydyn._polydyn", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.9",
    install_requires=["numpy"],
)
