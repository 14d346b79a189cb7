"""pip's entry to the CMake build (see pyproject.toml): builds the target flexure_python and puts
the module _flexure and libflexure-av.so into the package."""

import glob
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        subprocess.check_call([
            "cmake", "-S", HERE, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DFLEXURE_TESTS=OFF",
            "-DFLEXURE_BENCH=OFF", "-DFLEXURE_PYTHON=ON", f"-DPython_EXECUTABLE={sys.executable}",
        ])
        subprocess.check_call(["cmake", "--build", build, "--target", "flexure_python", "-j", str(os.cpu_count() or 1)])
        built = glob.glob(os.path.join(build, "python", "flexure", "_flexure*.so"))
        if len(built) != 1:
            raise RuntimeError(f"the CMake build made {len(built)} modules: {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)
        # MP4 writing: the module loads libflexure-av.so (built with it) from its own folder
        # (render/libav.cpp).
        shutil.copyfile(os.path.join(build, "libflexure-av.so"), os.path.join(os.path.dirname(target), "libflexure-av.so"))


setup(ext_modules=[Extension("flexure._flexure", sources=[])], cmdclass={"build_ext": CMakeBuild})
