"""setuptools hooks for `pip install ./python` (pyproject.toml): the package is python/redmax plus
the extension CMake built (redmax._core), copied in; nothing is compiled here. The build folder is
$REDMAX_BUILD_DIR or build/ beside this folder. The installed package also records the build's
`redmax` executable (redmax/_build_info.py), which `redmax.batch` runs."""
import glob
import os
import re

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))


def build_dir():
    return os.path.abspath(os.environ.get("REDMAX_BUILD_DIR") or os.path.join(HERE, "..", "build"))


def version():
    """The project's VERSION (CMakeLists.txt beside this folder or in the build's source dir)."""
    for cml in (os.path.join(HERE, "..", "CMakeLists.txt"), os.path.join(build_dir(), "..", "CMakeLists.txt")):
        if os.path.exists(cml):
            with open(cml) as fh:
                m = re.search(r"project\(\s*redmax\s+VERSION\s+([0-9.]+)", fh.read(), re.I)
            if m:
                return m.group(1)
    return "0.0.0"


class BuildWithExtension(build_py):
    """build_py plus the CMake-built _core and _build_info.py in the built package."""

    def run(self):
        super().run()
        found = glob.glob(os.path.join(build_dir(), "python", "redmax", "_core*.so"))
        if not found:
            raise SystemExit(f"redmax: no {build_dir()}/python/redmax/_core*.so: build it first "
                             "(cmake --build build --target redmax_py_core), or set REDMAX_BUILD_DIR")
        target = os.path.join(self.build_lib, "redmax")
        for so in found:
            self.copy_file(so, os.path.join(target, os.path.basename(so)))
        exe = os.path.join(build_dir(), "cli", "redmax")
        with open(os.path.join(target, "_build_info.py"), "w") as fh:
            fh.write('"""Written by setup.py at install time."""\n')
            fh.write(f"REDMAX_EXE = {exe!r}\nBUILD_DIR = {build_dir()!r}\n")


setup(version=version(), packages=["redmax"], cmdclass={"build_py": BuildWithExtension},
      package_data={"redmax": ["_core*.so"]}, zip_safe=False)
