"""`pip install` of python/ offline (docs/python.md §1): no package index, Debian's setuptools,
into a fresh virtual environment that sees Debian's packages; the installed redmax, imported
outside the source and build trees, computes what the build tree's computes."""
import os
import shutil
import subprocess
import sys

import pytest

from conftest import BUILD, MODELS, ROOT

import redmax


def test_offline_pip_install(tmp_path):
    if redmax._core is None:
        pytest.skip("redmax._core not built")
    for mod in ("pip", "setuptools"):
        if subprocess.run([sys.executable, "-c", f"import {mod}"], capture_output=True).returncode != 0:
            pytest.skip(f"Debian python3-{mod} is not installed")
    # a copy of python/ (the source tree stays clean of pip's build folders)
    src = tmp_path / "src"
    shutil.copytree(os.path.join(ROOT, "python"), src,
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", "--system-site-packages", str(venv)], check=True)
    py = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "REDMAX_EXE")}
    env.update(REDMAX_BUILD_DIR=BUILD, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    p = subprocess.run([py, "-m", "pip", "install", "--no-index", "--no-build-isolation", str(src)],
                       capture_output=True, text=True, env=env, cwd=tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    leg, swing = os.path.join(MODELS, "running_leg.osim"), os.path.join(MODELS, "running_leg_swing.mot")
    code = ("import redmax, redmax.study, numpy, sys; "
            f"r = redmax.inverse_dynamics({leg!r}, coordinates={swing!r}, muscle_mass='physiological'); "
            "numpy.save(sys.argv[1], r.values); print(redmax.__file__); print(redmax.study.find_redmax())")
    env.pop("REDMAX_BUILD_DIR")
    p = subprocess.run([py, "-c", code, str(tmp_path / "v.npy")], capture_output=True, text=True, env=env,
                       cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    where, exe = p.stdout.split()
    assert where.startswith(str(venv)) and "site-packages" in where  # the installed copy, not the build tree
    assert exe == os.path.join(BUILD, "cli", "redmax")  # recorded at install time for redmax.batch
    import numpy
    here = redmax.inverse_dynamics(leg, coordinates=swing, muscle_mass="physiological")
    assert numpy.array_equal(numpy.load(tmp_path / "v.npy"), here.values)
