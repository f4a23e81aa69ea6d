"""pytest suite of the Python side (docs/python.md, docs/testing.md): `import redmax` from the build
tree (build/python, or $REDMAX_BUILD_DIR/python) and the redmax executable beside it."""
import os
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.path.abspath(os.environ.get("REDMAX_BUILD_DIR", os.path.join(ROOT, "build")))
REDMAX_EXE = os.path.join(BUILD, "cli", "redmax")
SHARED = os.path.abspath(os.path.join(ROOT, "..", "shared", "opensim"))
MODELS = os.path.join(ROOT, "osim_models")

sys.path.insert(0, os.path.join(BUILD, "python"))
os.environ["REDMAX_EXE"] = REDMAX_EXE
os.environ["PYTHONPATH"] = os.pathsep.join([os.path.join(BUILD, "python")] +
                                           [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])


@pytest.fixture(scope="session")
def redmax_exe():
    if not os.access(REDMAX_EXE, os.X_OK):
        pytest.skip(f"{REDMAX_EXE} not built")
    return REDMAX_EXE


def shared(*parts):
    """A file of ../shared/opensim, or a visible skip when the shared data is absent."""
    p = os.path.join(SHARED, *parts)
    if not os.path.exists(p):
        pytest.skip(f"../shared/opensim absent ({p}): docs/shared_data.md")
    return p


LEG = os.path.join(MODELS, "running_leg.osim")
SWING = os.path.join(MODELS, "running_leg_swing.mot")


def skip_module_without_core():
    """At a test module's top: skip the module, with the reason, when redmax._core was not built."""
    import redmax
    if redmax._core is None:
        pytest.skip("redmax._core not built (pybind11-dev / python3-dev missing): " + redmax._core_missing,
                    allow_module_level=True)
