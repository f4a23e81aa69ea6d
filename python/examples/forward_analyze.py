"""OpenSim's ForwardTool and AnalyzeTool (static optimization) from Python, on OpenSim's arm26
setups in ../shared (docs/shared_data.md), with and without muscle mass (docs/python.md §2).

    PYTHONPATH=build/python /usr/bin/python3 python/examples/forward_analyze.py [SHARED_OPENSIM]
"""
import os
import sys

import redmax

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SHARED = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "..", "shared", "opensim")
FORWARD = os.path.join(SHARED, "opensim-core/Applications/Forward/tests/resources/arm26_Setup_Forward.xml")
ANALYZE = os.path.join(SHARED, "opensim-core/Applications/Analyze/tests/resources/arm26_Setup_StaticOptimization.xml")
thelen = "Thelen2003Muscle_Deprecated"

f = redmax.forward(setup=FORWARD, muscle_class=thelen, integrator="cvode")
elbow = f.states["/jointset/r_elbow/r_elbow_flex/value"]
print(f"forward: {f.name}, {len(f.states)} rows, {f.steps} steps; elbow {elbow[0]:.4f} -> {elbow[-1]:.4f} rad")

a = redmax.analyze(setup=ANALYZE, muscle_class=thelen)
am = redmax.analyze(setup=ANALYZE, muscle_class=thelen, muscle_mass="physiological")
bic = a.labels.index("BIClong")
print(f"analyze: {len(a.time)} frames ({a.failed} failed); BIClong peak force {a.force.values[:, bic].max():.5g} N, "
      f"{am.force.values[:, bic].max():.5g} N with {am.muscle_mass:.4g} kg of muscle mass")
print("forward_analyze: done")
