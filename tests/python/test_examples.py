"""The examples of python/examples/ run as they are documented (docs/python.md), each in its own
Python process with the build tree's redmax on PYTHONPATH; each must end with its done line."""
import os
import subprocess
import sys

import pytest

from conftest import ROOT, SHARED, shared

import redmax

EXAMPLES = os.path.join(ROOT, "python", "examples")
NEEDS_CORE = {"tour.py", "arrays.py", "forward_analyze.py"}
NEEDS_SHARED = {"forward_analyze.py": "opensim-core/Applications/Analyze/tests/resources/arm26_Setup_StaticOptimization.xml"}


@pytest.mark.parametrize("name", sorted(f for f in os.listdir(EXAMPLES) if f.endswith(".py")))
def test_example_runs(name, tmp_path, redmax_exe):
    if name in NEEDS_CORE and redmax._core is None:
        pytest.skip("redmax._core not built")
    args = [sys.executable, os.path.join(EXAMPLES, name)]
    if name in NEEDS_SHARED:
        shared(NEEDS_SHARED[name])
        args.append(SHARED)
    elif name != "arrays.py":
        args.append(str(tmp_path / "out"))
    p = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    last = p.stdout.strip().splitlines()[-1]
    stem = name[:-3]
    assert last.startswith(f"{stem}: done") or stem == "batch_study", p.stdout
    if name == "arrays.py":
        assert "equal to the trial: True" in p.stdout
    if name == "batch_study.py":
        assert "batch: 6 cells, 0 errors" in p.stdout and "(2 figures)" in p.stdout
        assert (tmp_path / "out" / "results" / "report.md").is_file()
